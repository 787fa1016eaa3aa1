//! Fault signature matching (fault signature matrix, paper section 3 and Table 1).
//!
//! Each fault moves a fixed subset of the residuals (1 = moves). The lamps r1..r4 are
//! compared with every row; faults whose signature equals the lamps share the probability
//! equally ("the probability of fault is divided", section 3: Rs/Rr, B/Bl and Ls/Vqs sensor
//! each get 50 %). When no row matches exactly, the rows at Hamming distance one share it
//! and the result is marked inexact.
//!
//! Two matrices:
//! - [`TABLE1`], the paper's Table 1 as printed;
//! - [`ROTOR_FLUX_SIGNATURES`], what the normalised residuals of eq. (37) physically do in
//!   rotor-flux orientation with the current-model angle and faults on the phase-level
//!   sensors, derived from the residuals' structure and confirmed end to end in simulation
//!   (`sim-host table1`, docs/paper-errata.md's Table 1 notes). Differences from Table 1:
//!   - **Rs, Rr, r3**: by eq. (37) `r3 = (B+Bl) r1 - Psi r2`; these faults leave r2 at zero, so
//!     r3 is proportional to r1 and, normalised by its own terms, exactly as large. The
//!     paper's 0 comes from comparing r3 in its own units (V N m s/rad) with a threshold.
//!   - **Rr, r2**: the current-model angle integrates the slip with the nominal rotor time
//!     constant Lr/Rr; an Rr change detunes the field orientation and moves r2.
//!   - **B, r4**: `r4 = Kf Np r1 + Ra r2 = Ra r2` here, and `Ra (B+Bl)` is small against
//!     `Psi Kf Np` (the smallness the paper invokes for Rs): a change of the small machine
//!     friction B barely moves normalised r4, a change of Bl does. The row keeps the 1 (a
//!     large B change does light it); a dark r4 still matches B/Bl at distance one.
//!   - **current sensor, r4**: a gain error on the phase currents also scales i_f, so Psi
//!     and Kf in r4 change too; the paper's cancellation holds only for an error on Iqs.
//!   - **speed sensor, r3**: the current model integrates the encoder speed, so a speed
//!     error detunes the frame; with voltage orientation (PLL, zero crossing) the paper's
//!     `1 1 0 1` is reproduced.

/// The faults of Table 1, the workspace's one fault vocabulary (the simulator injects
/// them, the core names them, the command line and JSON reports use [`Fault::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Fault {
    /// Stator resistance Rs.
    Rs,
    /// Rotor resistance Rr.
    Rr,
    /// Stator *leakage* inductance Lls = Ls - Lm (the paper's simulator, PSIM, names the
    /// leakages Ls and Lr; the model's self inductance is [`crate::MotorModel::ls_h`] =
    /// Lls + Lm). A fault of size k scales Lls by k; on a machine without stator leakage
    /// (a Gamma model) it scales Lm instead.
    Ls,
    /// Rotor *leakage* inductance Llr = Lr - Lm (PSIM's Lr; the model's self inductance is
    /// [`crate::MotorModel::lr_h`] = Llr + Lm). A fault of size k scales Llr by k; without
    /// rotor leakage it scales Lm instead.
    Lr,
    /// Machine friction B.
    B,
    /// Load friction Bl.
    Bl,
    /// Current sensor (Iqs).
    CurrentSensor,
    /// Voltage sensor (Vqs).
    VoltageSensor,
    /// Speed sensor (omega_r).
    SpeedSensor,
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Number of faults in Table 1.
pub const FAULT_COUNT: usize = 9;

impl Fault {
    /// Every fault, in Table 1's order (the index of the probability arrays).
    pub const ALL: [Fault; FAULT_COUNT] = [
        Fault::Rs,
        Fault::Rr,
        Fault::Ls,
        Fault::Lr,
        Fault::B,
        Fault::Bl,
        Fault::CurrentSensor,
        Fault::VoltageSensor,
        Fault::SpeedSensor,
    ];

    /// The name in scenario files, on the command line and in JSON reports (`rs, rr, ls, lr,
    /// b, bl, current_sensor, voltage_sensor, speed_sensor`; `docs/design.md`).
    pub fn name(self) -> &'static str {
        match self {
            Fault::Rs => "rs",
            Fault::Rr => "rr",
            Fault::Ls => "ls",
            Fault::Lr => "lr",
            Fault::B => "b",
            Fault::Bl => "bl",
            Fault::CurrentSensor => "current_sensor",
            Fault::VoltageSensor => "voltage_sensor",
            Fault::SpeedSensor => "speed_sensor",
        }
    }

    /// Parses a name of [`Fault::name`] (exact, lower case).
    pub fn from_name(s: &str) -> Option<Fault> {
        Fault::ALL.into_iter().find(|f| f.name() == s)
    }

    /// Index into [`Fault::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The paper's Table 1 row for this fault (r1..r4).
    pub fn paper_signature(self) -> [bool; 4] {
        TABLE1.get(self.index()).copied().unwrap_or([false; 4])
    }

    /// True for the sensor faults.
    pub fn is_sensor(self) -> bool {
        matches!(
            self,
            Fault::CurrentSensor | Fault::VoltageSensor | Fault::SpeedSensor
        )
    }
}

/// The paper's Table 1, rows in [`Fault::ALL`] order, columns r1..r4.
pub const TABLE1: [[bool; 4]; FAULT_COUNT] = [
    [true, false, false, true], // Rs
    [true, false, false, true], // Rr
    [true, false, true, true],  // Ls
    [true, true, true, true],   // Lr
    [false, true, true, true],  // B
    [false, true, true, true],  // Bl
    [true, true, true, false],  // current sensor (Iqs)
    [true, false, true, true],  // voltage sensor (Vqs)
    [true, true, false, true],  // speed sensor (omega_r)
];

/// Physical signatures for rotor-flux orientation (module docs), rows in [`Fault::ALL`]
/// order, columns r1..r4.
pub const ROTOR_FLUX_SIGNATURES: [[bool; 4]; FAULT_COUNT] = [
    [true, false, true, true], // Rs
    [true, true, true, true],  // Rr
    [true, false, true, true], // Ls
    [true, true, true, true],  // Lr
    [false, true, true, true], // B
    [false, true, true, true], // Bl
    [true, true, true, true],  // current sensor (phase currents)
    [true, false, true, true], // voltage sensor
    [true, true, true, true],  // speed sensor (encoder)
];

/// The fault signature matrix for a frame: the physical one ([`ROTOR_FLUX_SIGNATURES`])
/// in rotor-flux orientation, the paper's [`TABLE1`] in voltage orientation (module docs).
pub fn signatures_for(angle_source: crate::AngleSource) -> &'static [[bool; 4]; FAULT_COUNT] {
    match angle_source {
        crate::AngleSource::RotorFluxCurrentModel => &ROTOR_FLUX_SIGNATURES,
        crate::AngleSource::Pll | crate::AngleSource::ZeroCrossing => &TABLE1,
    }
}

/// Result of matching lamps against Table 1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnosis {
    /// Probability of each fault, indexed like [`Fault::ALL`]; sums to 1 when any lamp is
    /// lit and a row is within distance one, else all 0.
    pub probabilities: [f32; FAULT_COUNT],
    /// True when the lamps equal at least one row exactly.
    pub exact: bool,
}

impl Diagnosis {
    /// The most probable fault and its probability (first in Table 1 order on ties).
    pub fn top(&self) -> Option<(Fault, f32)> {
        // (The first strictly largest positive probability: a running maximum from 0,
        // without the option in the loop.)
        let (mut best, mut bp) = (0, 0.0f32);
        for (k, p) in self.probabilities.iter().enumerate() {
            if *p > bp {
                (best, bp) = (k, *p);
            }
        }
        if bp > 0.0 {
            Fault::ALL.get(best).map(|f| (*f, bp))
        } else {
            None
        }
    }
}

/// Matches lamp states against a signature matrix ([`TABLE1`] or
/// [`ROTOR_FLUX_SIGNATURES`]).
pub fn match_signature(lamps: [bool; 4], matrix: &[[bool; 4]; FAULT_COUNT]) -> Diagnosis {
    let mut d = Diagnosis::default();
    if !lamps.iter().any(|x| *x) {
        return d;
    }
    let dist = |row: &[bool; 4]| row.iter().zip(lamps).filter(|(a, b)| **a != *b).count();
    for max_dist in 0..2 {
        let n = matrix.iter().filter(|r| dist(r) == max_dist).count();
        if n > 0 {
            let p = 1.0 / n as f32;
            for (prob, row) in d.probabilities.iter_mut().zip(matrix.iter()) {
                if dist(row) == max_dist {
                    *prob = p;
                }
            }
            d.exact = max_dist == 0;
            return d;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_signatures_share_the_probability() {
        let d = match_signature([true, false, false, true], &TABLE1);
        assert!(d.exact);
        assert_eq!(d.probabilities[Fault::Rs.index()], 0.5);
        assert_eq!(d.probabilities[Fault::Rr.index()], 0.5);
        let d = match_signature([true, true, true, true], &TABLE1);
        assert_eq!(d.top(), Some((Fault::Lr, 1.0)));
        let d = match_signature([true, false, true, true], &TABLE1);
        assert_eq!(d.probabilities[Fault::Ls.index()], 0.5);
        assert_eq!(d.probabilities[Fault::VoltageSensor.index()], 0.5);
        assert_eq!(match_signature([false; 4], &TABLE1).top(), None);
    }

    #[test]
    fn physical_matrix_differs_from_table1_only_where_documented() {
        let differ: [usize; 5] = [0, 1, 6, 8, 4];
        for (k, (a, b)) in TABLE1.iter().zip(ROTOR_FLUX_SIGNATURES.iter()).enumerate() {
            if a != b {
                assert!(differ.contains(&k), "row {k} differs");
            }
        }
        // Rs: only r3 differs (1 0 0 1 -> 1 0 1 1), from r3 = (B+Bl) r1 - Psi r2 with r2 = 0.
        assert_eq!(ROTOR_FLUX_SIGNATURES[0], [true, false, true, true]);
        let d = match_signature([true, false, true, true], &ROTOR_FLUX_SIGNATURES);
        assert!((d.probabilities[Fault::Rs.index()] - 1.0 / 3.0).abs() < 1e-6);
        // A dark r4 on a friction fault still names B/Bl (distance one).
        let d = match_signature([false, true, true, false], &ROTOR_FLUX_SIGNATURES);
        assert!(
            !d.exact
                && d.probabilities[Fault::B.index()] == 0.5
                && d.probabilities[Fault::Bl.index()] == 0.5
        );
    }

    #[test]
    fn every_row_matches_itself_and_names_round_trip() {
        for f in Fault::ALL {
            let d = match_signature(f.paper_signature(), &TABLE1);
            assert!(d.exact && d.probabilities[f.index()] > 0.0);
            assert_eq!(Fault::from_name(f.name()), Some(f));
        }
    }
}
