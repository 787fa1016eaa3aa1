//! Rs and Rr read apart at the isolation's steady points
//! ([`monitor_core::isolation::resistance_split`]): the stator's resistance change beyond
//! the rotor's, which a warm winding does not move and a loosening connection does.

use monitor_core::isolation::{resistance_split, ResistanceSplit, SteadyPoint};
use monitor_core::MotorModel;
use serde::Serialize;

/// The mean of the splits read at the later half of the isolation's points
/// (`diagnose --json` `isolation.resistances`).
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
    /// The steady points the means are over (the later half of those read).
    pub points: u32,
}

/// The most splits kept: the earlier half is dropped when full (an hour's log keeps its
/// last stretch, in bounded memory).
const MAX_KEPT: usize = 4096;

/// The splits read so far (at most one per isolation: a few per second of steady running).
#[derive(Debug, Clone, Default)]
pub(super) struct ResistanceSums {
    read: Vec<ResistanceSplit>,
}

impl ResistanceSums {
    /// Reads the split at `q` against `motor`'s inductances; a point that cannot carry it
    /// adds nothing.
    pub(super) fn add(&mut self, motor: &MotorModel, q: &SteadyPoint) {
        if let Some(s) = resistance_split(motor, q) {
            if self.read.len() >= MAX_KEPT {
                self.read.drain(..MAX_KEPT / 2);
            }
            self.read.push(s);
        }
    }

    /// The mean over the later half of the points read (the earlier ones may still carry a
    /// start's or a step's tail: on a 4 s log with a start, the mean over all of them put
    /// a 30 K warm winding's Rs 0.7 % below its Rr), `None` before any point.
    pub(super) fn reading(&self) -> Option<ResistanceReading> {
        let later = self
            .read
            .get(self.read.len() / 2..)
            .filter(|l| !l.is_empty())?;
        let n = later.len() as f64;
        let mean = |f: fn(&ResistanceSplit) -> f64| later.iter().map(f).sum::<f64>() / n;
        Some(ResistanceReading {
            rs_factor: mean(|s| s.rs_factor),
            rr_factor: mean(|s| s.rr_factor),
            stator_excess: mean(ResistanceSplit::stator_excess),
            points: u32::try_from(later.len()).unwrap_or(u32::MAX),
        })
    }
}
