//! The sizes a named fault must reach to send a crew: [`MIN_FAULT_CHANGE`] and, against the
//! parameter file's nominal values, [`NOMINAL_UNCERTAINTY`]. The verdict that reads them,
//! for `diagnose`, the HMI and the board's FAULT lamp alike, is the decision table of
//! [`crate::verdict`] ([`crate::verdict::Named::stands_clear`]).

/// The least relative change of a named fault for a FAULT (a sensor's gain error, a
/// parameter's change): 5 %, what 13 K of heating does to a winding's resistance (copper,
/// 0.393 %/K) and about what a commissioned parameter file's error leaves at other
/// operating points. Below it the fault is watched ([`crate::verdict::Verdict::Watching`],
/// [`super::Named::stands_clear`]).
pub const MIN_FAULT_CHANGE: f32 = 0.05;

/// How far a parameter file's values may be off the machine's: nameplate estimates are
/// 10-30 % off (and a winding 60 K warmer than the file assumes moves Rs and Rr by 24 %).
/// Against the nominal values (not commissioned) a FAULT needs a name larger than this (the
/// decision table's "the parameter file does not fit" row otherwise), and the host does not
/// name a change this small with every lamp dark ([`within_nominal_uncertainty`]).
pub const NOMINAL_UNCERTAINTY: f32 = 0.3;

/// A named change within the parameter file's own uncertainty:
/// `|change| <= NOMINAL_UNCERTAINTY` ([`NOMINAL_UNCERTAINTY`]).
pub fn within_nominal_uncertainty(change: f32) -> bool {
    change.abs() <= NOMINAL_UNCERTAINTY
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_files_uncertainty_includes_its_bounds_and_not_beyond() {
        assert!(within_nominal_uncertainty(NOMINAL_UNCERTAINTY));
        assert!(within_nominal_uncertainty(-NOMINAL_UNCERTAINTY));
        assert!(!within_nominal_uncertainty(NOMINAL_UNCERTAINTY + 1e-3));
        // Not a number is no size within the file's uncertainty.
        assert!(!within_nominal_uncertainty(f32::NAN));
    }
}
