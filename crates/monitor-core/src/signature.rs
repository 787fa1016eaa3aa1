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

/// Number of faults in Table 1 (the length of the one list, [`FAULTS`]).
pub const FAULT_COUNT: usize = 9;

/// A machine parameter a fault scales by its factor `k = 1 + change`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MachineParameter {
    /// The stator resistance Rs.
    Rs,
    /// The rotor resistance Rr.
    Rr,
    /// The stator leakage inductance Lls (Lm instead on a machine without it, [`Fault::Ls`]).
    StatorLeakage,
    /// The rotor leakage inductance Llr (Lm instead on a machine without it, [`Fault::Lr`]).
    RotorLeakage,
    /// The machine's friction B.
    MachineFriction,
    /// The load's friction Bl.
    LoadFriction,
}

/// A sensor whose gain a fault changes (its reading `k` times the truth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SensorChannel {
    /// The phase currents (the model's Iqs).
    Current,
    /// The phase voltages (the model's Vqs).
    Voltage,
    /// The shaft speed (the encoder, omega_r).
    Speed,
}

/// What a fault changes: a machine parameter or a sensor (the simulator injects it there,
/// the isolation hypothesises it there).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaultTarget {
    /// A parameter of the machine, scaled.
    Parameter(MachineParameter),
    /// A sensor's gain.
    Sensor(SensorChannel),
}

/// One fault of the list: everything the workspace derives from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultEntry {
    /// The fault (its index in the list is its [`Fault::index`]).
    pub fault: Fault,
    /// Its name ([`Fault::name`]).
    pub name: &'static str,
    /// What it changes ([`Fault::target`]).
    pub target: FaultTarget,
    /// The paper's Table 1 row, r1..r4 ([`TABLE1`]).
    pub table1: [bool; 4],
    /// The physical row in rotor-flux orientation, r1..r4 ([`ROTOR_FLUX_SIGNATURES`],
    /// module docs).
    pub rotor_flux: [bool; 4],
}

/// The faults of Table 1, in its order: the one list the fault vocabulary derives from
/// ([`Fault::ALL`], [`Fault::name`], [`Fault::target`], [`TABLE1`],
/// [`ROTOR_FLUX_SIGNATURES`]; the panel's blink codes, the HMI's keys, the isolation's
/// hypotheses and the simulator's fault injection through them). docs/architecture.md,
/// "Adding a fault", says what else a new fault needs.
pub const FAULTS: [FaultEntry; FAULT_COUNT] = {
    use FaultTarget::{Parameter, Sensor};
    use MachineParameter as P;
    const fn row(
        fault: Fault,
        name: &'static str,
        target: FaultTarget,
        table1: [bool; 4],
        rotor_flux: [bool; 4],
    ) -> FaultEntry {
        FaultEntry {
            fault,
            name,
            target,
            table1,
            rotor_flux,
        }
    }
    let (t, f) = (true, false);
    [
        row(
            Fault::Rs,
            "rs",
            Parameter(P::Rs),
            [t, f, f, t],
            [t, f, t, t],
        ),
        row(
            Fault::Rr,
            "rr",
            Parameter(P::Rr),
            [t, f, f, t],
            [t, t, t, t],
        ),
        row(
            Fault::Ls,
            "ls",
            Parameter(P::StatorLeakage),
            [t, f, t, t],
            [t, f, t, t],
        ),
        row(
            Fault::Lr,
            "lr",
            Parameter(P::RotorLeakage),
            [t, t, t, t],
            [t, t, t, t],
        ),
        row(
            Fault::B,
            "b",
            Parameter(P::MachineFriction),
            [f, t, t, t],
            [f, t, t, t],
        ),
        row(
            Fault::Bl,
            "bl",
            Parameter(P::LoadFriction),
            [f, t, t, t],
            [f, t, t, t],
        ),
        // Current sensor: the paper's Iqs; physically the phase currents.
        row(
            Fault::CurrentSensor,
            "current_sensor",
            Sensor(SensorChannel::Current),
            [t, t, t, f],
            [t, t, t, t],
        ),
        row(
            Fault::VoltageSensor,
            "voltage_sensor",
            Sensor(SensorChannel::Voltage),
            [t, f, t, t],
            [t, f, t, t],
        ),
        // Speed sensor: omega_r, the encoder.
        row(
            Fault::SpeedSensor,
            "speed_sensor",
            Sensor(SensorChannel::Speed),
            [t, t, f, t],
            [t, t, t, t],
        ),
    ]
};

/// Column `what` of [`FAULTS`] (0: the fault, for the check that row `k` is fault `k`).
#[allow(clippy::indexing_slicing)] // const evaluation: an index out of range does not compile
const fn column(what: u8) -> ([Fault; FAULT_COUNT], [[bool; 4]; FAULT_COUNT]) {
    let mut faults = [Fault::Rs; FAULT_COUNT];
    let mut rows = [[false; 4]; FAULT_COUNT];
    let mut k = 0;
    while k < FAULT_COUNT {
        faults[k] = FAULTS[k].fault;
        assert!(
            FAULTS[k].fault as usize == k,
            "FAULTS is in the enum's order"
        );
        rows[k] = if what == 1 {
            FAULTS[k].table1
        } else {
            FAULTS[k].rotor_flux
        };
        k += 1;
    }
    (faults, rows)
}

impl Fault {
    /// Every fault, in Table 1's order (the index of the probability arrays; [`FAULTS`]).
    pub const ALL: [Fault; FAULT_COUNT] = column(0).0;

    /// The name in scenario files, on the command line and in JSON reports (`rs, rr, ls, lr,
    /// b, bl, current_sensor, voltage_sensor, speed_sensor`; `docs/design.md`; [`FAULTS`]).
    pub fn name(self) -> &'static str {
        FAULTS.get(self.index()).map_or("", |e| e.name)
    }

    /// Parses a name of [`Fault::name`] (exact, lower case).
    pub fn from_name(s: &str) -> Option<Fault> {
        Fault::ALL.into_iter().find(|f| f.name() == s)
    }

    /// Index into [`Fault::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// What the fault changes ([`FAULTS`]).
    pub fn target(self) -> FaultTarget {
        FAULTS
            .get(self.index())
            .map_or(FaultTarget::Sensor(SensorChannel::Speed), |e| e.target)
    }

    /// The paper's Table 1 row for this fault (r1..r4).
    pub fn paper_signature(self) -> [bool; 4] {
        TABLE1.get(self.index()).copied().unwrap_or([false; 4])
    }

    /// True for the sensor faults.
    pub fn is_sensor(self) -> bool {
        matches!(self.target(), FaultTarget::Sensor(_))
    }
}

/// The paper's Table 1, rows in [`Fault::ALL`] order, columns r1..r4 ([`FAULTS`]).
pub const TABLE1: [[bool; 4]; FAULT_COUNT] = column(1).1;

/// Physical signatures for rotor-flux orientation (module docs), rows in [`Fault::ALL`]
/// order, columns r1..r4 ([`FAULTS`]).
pub const ROTOR_FLUX_SIGNATURES: [[bool; 4]; FAULT_COUNT] = column(2).1;

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
