//! One stretch's reading of the winding's part of the negative sequence, ready to judge
//! (below the anchor and the probability that read it).

use super::{
    Complex32, OperatingPointSource, DEFAULT_SPREAD_CURRENTS, DEFAULT_SPREAD_VOLTAGES,
    MEASURED_Z_RATIO, NO_BASELINE_SPREAD, NO_BASELINE_SPREAD_VOLTAGES, SUPPLY_DRIFT_BETWEEN_RUNS,
    SUPPLY_UNBALANCE_SPREAD, WITHIN_LOG_SPREAD,
};
use monitor_core::sequence::ShortModel;

/// One stretch's reading, ready to judge (module docs of [`super`], step 2).
#[derive(Debug, Clone, Copy)]
pub(super) struct PhaseReading {
    /// Index of the stretch.
    pub index: usize,
    /// The winding's part of `I2/I1` (sensors' and, with voltages, the supply's parts out).
    pub w: Complex32,
    /// The supply's part `|V2/Z2|/|I1|` that was taken out (0 without voltages).
    pub supply: f32,
    /// The stretch has voltages.
    pub voltages: bool,
    /// `|I1|` [A, peak].
    pub i1: f32,
    /// The electrical rotor speed [rad/s], where the log has a speed.
    pub wr: Option<f32>,
    /// The supply's angular frequency [rad/s].
    pub we: f32,
    /// The standard error of `w` over the stretch's windows (each component).
    pub sem: f32,
    /// The reference angle `(arg Z1, uncertainty)` [rad], the slip used and its source.
    pub op: (f32, f32, Option<f32>, OperatingPointSource),
    /// The model's `arg Z1` at the stretch's operating point where the speed or the
    /// current's magnitude gives it (to turn a reference's supply part to the stretch's
    /// load), else `None`.
    pub z1_angle: Option<f32>,
    /// The model's `|Z1/Z2|` there (the largest over the range of loads where the
    /// operating point is not known): how much the supply's `V2/V1` shows in `I2/I1`.
    pub z_ratio: f32,
}

impl PhaseReading {
    /// The short's model at this stretch's reference angle.
    pub fn model(&self) -> ShortModel {
        match self.op.3 {
            OperatingPointSource::Voltages | OperatingPointSource::CurrentMagnitude => {
                ShortModel::on_faulty_current(self.op.0, self.op.1)
            }
            OperatingPointSource::Speed | OperatingPointSource::AssumedRange => {
                ShortModel::new(self.op.0, self.op.1)
            }
        }
    }

    /// A healthy machine's own asymmetry as a spread for this stretch (with the supply's
    /// unbalance through `|Z1/Z2|` without voltages), with its own standard error.
    pub(super) fn alone_sigma(&self) -> f32 {
        let own = if self.voltages {
            NO_BASELINE_SPREAD_VOLTAGES
        } else {
            NO_BASELINE_SPREAD.hypot(SUPPLY_UNBALANCE_SPREAD * self.z_ratio)
        };
        own.hypot(self.sem)
    }

    /// The default spread of one healthy run's reading at this stretch (each component).
    pub fn run_sigma(&self) -> f32 {
        if self.voltages {
            DEFAULT_SPREAD_VOLTAGES
        } else {
            DEFAULT_SPREAD_CURRENTS.max(SUPPLY_DRIFT_BETWEEN_RUNS * self.z_ratio)
        }
    }

    /// The spread of a healthy stretch about another of the same log (each component).
    pub(super) fn within_sigma(&self) -> f32 {
        if self.voltages {
            WITHIN_LOG_SPREAD
        } else {
            WITHIN_LOG_SPREAD.max(WITHIN_LOG_SPREAD / MEASURED_Z_RATIO * self.z_ratio)
        }
    }
}
