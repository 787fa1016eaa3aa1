//! The one rule for a FAULT: what a detection is called, shared by `diagnose`'s verdict
//! (sim-host `Replay::finish`), the panel of the HMI, the demo and `diagnose`'s timeline
//! (sim-host `Replay::panel`) and the board's FAULT lamp (`drive_monitor::app::panel_input`).
//! Each of them describes what it saw as a [`Sighting`]; [`fault_call`] answers.
//!
//! # The rule
//!
//! A FAULT sends a crew to a motor, so a detection (a residual lamp lit, a sensor's
//! impossible reading, or the isolation naming a fault against a commissioned baseline) is
//! a FAULT only when what is named stands clear of what a healthy motor's parameters and
//! temperature move:
//!
//! 1. nothing detected: [`FaultCall::Clear`];
//! 2. a sensor fault (a reading no machine gives: bad samples, not a residual judgement):
//!    [`FaultCall::Fault`];
//! 3. against the parameter file's nominal values (not commissioned) the residuals measure
//!    the machine against the file, and a file from a nameplate is 10-30 % off
//!    ([`NOMINAL_UNCERTAINTY`]); a winding 60 K warmer than the file assumes moves Rs and Rr
//!    by 24 %. So a FAULT needs a named fault (or the friction class) larger than
//!    [`NOMINAL_UNCERTAINTY`]; lamps with a smaller name, or with a change that fits no
//!    single fault, are [`FaultCall::NotCommissioned`]: no judgement, commission first;
//! 4. a named fault smaller than [`MIN_FAULT_CHANGE`] (5 %) is watched, not reported
//!    ([`FaultCall::Watching`]): 5 % is what 13 K of heating does to a winding's resistance
//!    and about what a commissioned parameter file's error leaves at other operating points;
//! 5. anything else detected: [`FaultCall::Fault`] (with nothing named, the lamps' own
//!    detection against a commissioned baseline: the paper's method).
//!
//! The order matters only where two apply: a small name against the nominal values is
//! [`FaultCall::NotCommissioned`] (3 before 4), a sensor fault beside a small name a FAULT
//! (2 before 4). What each caller adds is its own: the host withholds a verdict for reasons
//! the log gives (too short, never settled, the load outside the commissioned range), the
//! panels show the amber "operating point moved" state instead of a FAULT where the load
//! left the commissioned range, and shorted turns named against a healthy reference are a
//! fault of the negative-sequence analysis, not of this rule.

/// The least relative change of a named fault for a FAULT (a sensor's gain error, a
/// parameter's change, the friction class in Bl's terms): 5 %, what 13 K of heating does to
/// a winding's resistance (copper, 0.393 %/K) and about what a commissioned parameter file's
/// error leaves at other operating points. Below it the fault is watched
/// ([`FaultCall::Watching`], [`super::Named::stands_clear`]).
pub const MIN_FAULT_CHANGE: f32 = 0.05;

/// How far a parameter file's values may be off the machine's: nameplate estimates are
/// 10-30 % off (and a winding 60 K warmer than the file assumes moves Rs and Rr by 24 %).
/// Against the nominal values (not commissioned) a FAULT needs a name larger than this
/// ([`FaultCall::NotCommissioned`]), and the host does not name a change this small with
/// every lamp dark ([`within_nominal_uncertainty`]).
pub const NOMINAL_UNCERTAINTY: f32 = 0.3;

/// What a monitor saw, as the rule reads it ([`fault_call`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sighting {
    /// A fault was detected: a residual lamp or a sensor-fault flag lit, or the isolation
    /// named a fault against a commissioned baseline (each caller's own detection, after
    /// its own exclusions such as heating or a load move).
    pub detected: bool,
    /// A sensor flagged an impossible reading (saturated ADC, currents or voltages that do
    /// not sum to zero, an encoder jump).
    pub sensor_fault: bool,
    /// The relative size of what the isolation names ([`super::Named::change`]: the
    /// fault's change, a sensor's gain error, Bl's change for the friction class; 0.3 for
    /// +30 %), `None` when nothing is named. A size that is not a number counts as too
    /// small to report.
    pub named_change: Option<f32>,
    /// The isolation judges against a baseline learned in commissioning (else against the
    /// parameter file's nominal values).
    pub commissioned: bool,
}

/// What [`fault_call`] makes of a [`Sighting`] (module docs, "The rule").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultCall {
    /// Nothing detected.
    Clear,
    /// A FAULT: the FAULT lamp, `diagnose`'s verdict `fault`.
    Fault,
    /// A fault is named, smaller than [`MIN_FAULT_CHANGE`]: watched, no FAULT (`diagnose`'s
    /// verdict `watching`, the HMI's `WATCHING`, the board's FAULT lamp dark).
    Watching,
    /// Against the nominal values, no name larger than [`NOMINAL_UNCERTAINTY`]: no
    /// judgement until commissioned (`diagnose`'s verdict `could_not_judge`, the FAULT lamp
    /// dark).
    NotCommissioned,
}

impl FaultCall {
    /// The FAULT lamp is lit (a FAULT, nothing else).
    pub const fn is_fault(self) -> bool {
        matches!(self, FaultCall::Fault)
    }

    /// A short name for logs and the board's status line (`call=`): `clear`, `fault`,
    /// `watching`, `not-commissioned`.
    pub const fn name(self) -> &'static str {
        match self {
            FaultCall::Clear => "clear",
            FaultCall::Fault => "fault",
            FaultCall::Watching => "watching",
            FaultCall::NotCommissioned => "not-commissioned",
        }
    }

    /// The call of a [`FaultCall::name`].
    pub fn from_name(name: &str) -> Option<FaultCall> {
        [
            FaultCall::Clear,
            FaultCall::Fault,
            FaultCall::Watching,
            FaultCall::NotCommissioned,
        ]
        .into_iter()
        .find(|c| c.name() == name)
    }
}

/// A named change within the parameter file's own uncertainty:
/// `|change| <= NOMINAL_UNCERTAINTY` ([`NOMINAL_UNCERTAINTY`]).
pub fn within_nominal_uncertainty(change: f32) -> bool {
    change.abs() <= NOMINAL_UNCERTAINTY
}

/// The one rule for a FAULT (module docs, "The rule"): what `s` is called.
pub fn fault_call(s: &Sighting) -> FaultCall {
    if !s.detected {
        return FaultCall::Clear;
    }
    if s.sensor_fault {
        return FaultCall::Fault;
    }
    let beyond_file = s
        .named_change
        .is_some_and(|c| !within_nominal_uncertainty(c) && !c.is_nan());
    if !s.commissioned && !beyond_file {
        return FaultCall::NotCommissioned;
    }
    match s.named_change {
        Some(c) if !(c.abs() >= MIN_FAULT_CHANGE) => FaultCall::Watching,
        _ => FaultCall::Fault,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(named_change: Option<f32>, commissioned: bool) -> Sighting {
        Sighting {
            detected: true,
            sensor_fault: false,
            named_change,
            commissioned,
        }
    }

    #[test]
    fn each_step_of_the_rule() {
        let quiet = Sighting {
            detected: false,
            ..seen(Some(0.5), true)
        };
        assert_eq!(fault_call(&quiet), FaultCall::Clear);
        // Commissioned: a name of 5 % or more, or none, is a FAULT; a smaller one watched.
        assert_eq!(fault_call(&seen(Some(0.5), true)), FaultCall::Fault);
        assert_eq!(fault_call(&seen(Some(-0.05), true)), FaultCall::Fault);
        assert_eq!(fault_call(&seen(None, true)), FaultCall::Fault);
        assert_eq!(fault_call(&seen(Some(0.049), true)), FaultCall::Watching);
        assert_eq!(fault_call(&seen(Some(-0.005), true)), FaultCall::Watching);
        assert_eq!(fault_call(&seen(Some(f32::NAN), true)), FaultCall::Watching);
        // Against the nominal values: only a name beyond +-30 %.
        assert_eq!(fault_call(&seen(Some(0.31), false)), FaultCall::Fault);
        assert_eq!(fault_call(&seen(Some(-0.5), false)), FaultCall::Fault);
        for c in [Some(0.3), Some(-0.24), Some(0.02), Some(f32::NAN), None] {
            assert_eq!(
                fault_call(&seen(c, false)),
                FaultCall::NotCommissioned,
                "{c:?}"
            );
        }
        // A sensor fault is a FAULT whatever is named.
        for (c, commissioned) in [(Some(0.01), true), (None, false), (Some(0.1), false)] {
            let s = Sighting {
                sensor_fault: true,
                ..seen(c, commissioned)
            };
            assert_eq!(fault_call(&s), FaultCall::Fault);
        }
    }

    #[test]
    fn only_a_fault_lights_the_lamp_and_names_read_back() {
        for call in [
            FaultCall::Clear,
            FaultCall::Fault,
            FaultCall::Watching,
            FaultCall::NotCommissioned,
        ] {
            assert_eq!(call.is_fault(), call == FaultCall::Fault);
            assert_eq!(FaultCall::from_name(call.name()), Some(call));
        }
        assert_eq!(FaultCall::from_name("FAULT"), None);
    }
}
