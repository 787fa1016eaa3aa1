//! Rs and Rr read apart at the isolation's steady points
//! ([`monitor_core::isolation::resistance_split`]): the stator's resistance change beyond
//! the rotor's, which a warm winding does not move and a loosening connection does.

use monitor_core::isolation::{resistance_split, SteadyPoint};
use monitor_core::MotorModel;
use serde::Serialize;

/// The mean of the splits read at the isolation's points (`diagnose --json`
/// `isolation.resistances`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct ResistanceReading {
    /// `Rs / Rs_file`, the mean over the points.
    pub rs_factor: f64,
    /// `Rr / Rr_file`, the mean over the points.
    pub rr_factor: f64,
    /// The mean of `(Rs/Rs_file) / (Rr/Rr_file) - 1` [fraction]: the stator's change
    /// beyond the rotor's, free of the winding's temperature (a loosening connection, a
    /// stator conductor's resistance).
    pub stator_excess: f64,
    /// The steady points read.
    pub points: u32,
}

/// Sums of the splits read so far.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ResistanceSums {
    rs: f64,
    rr: f64,
    excess: f64,
    n: u32,
}

impl ResistanceSums {
    /// Reads the split at `q` against `motor`'s inductances; a point that cannot carry it
    /// adds nothing.
    pub(super) fn add(&mut self, motor: &MotorModel, q: &SteadyPoint) {
        if let Some(s) = resistance_split(motor, q) {
            self.rs += s.rs_factor;
            self.rr += s.rr_factor;
            self.excess += s.stator_excess();
            self.n += 1;
        }
    }

    /// The mean reading, `None` before any point.
    pub(super) fn reading(&self) -> Option<ResistanceReading> {
        (self.n > 0).then(|| {
            let n = f64::from(self.n);
            ResistanceReading {
                rs_factor: self.rs / n,
                rr_factor: self.rr / n,
                stator_excess: self.excess / n,
                points: self.n,
            }
        })
    }
}
