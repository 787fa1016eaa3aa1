//! What the monitor reports: [`MonitorOutput`] and the flags and states in it.

use crate::residuals::Operating;
use crate::sequence::NegativeSequence;
use crate::signature::{Diagnosis, Fault};

/// Sensor-fault flags from impossible readings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SensorFlags {
    /// A current reading was impossible (NaN, out of range, saturated, sum not zero).
    pub current: bool,
    /// A voltage reading was impossible.
    pub voltage: bool,
    /// The encoder jumped faster than the maximum speed allows.
    pub speed: bool,
}

impl SensorFlags {
    /// Any flag set.
    pub fn any(&self) -> bool {
        self.current || self.voltage || self.speed
    }
}

/// Commissioning state: which thresholds are in force, or that a run is active (the run
/// itself, with its id, progress and outcome: [`Monitor::commissioning`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum CommissioningState {
    /// No calibration: fixed thresholds are in use.
    #[default]
    NotCommissioned,
    /// A run is active; the fraction of its evaluated blocks learned, in [0, 1] (1 while
    /// the learned calibration awaits storage). Lamps are held off.
    Learning(f32),
    /// Calibrated thresholds are in use.
    Commissioned,
}

/// What the monitor did about its time base and its own state since it was built.
///
/// Counts blocks (of `decimation` samples) at whose end the timestamps showed a gap or a
/// fault, and restarts after a non-finite internal state. Bridged gaps leave the lamps
/// evaluating; a timing fault or a recovery restarts the estimators and the settling time,
/// so the lamps hold for `settle_s`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TimingEvents {
    /// Gaps up to `max_bridged_gap_s` (samples missing from the stream) bridged.
    pub gaps_bridged: u32,
    /// Longer gaps, stalled or backward timestamps: estimators restarted.
    pub timing_faults: u32,
    /// Non-finite internal states (for example after garbage input) from which the monitor
    /// restarted its estimators and filters.
    pub recoveries: u32,
}

/// Everything the monitor reports after a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MonitorOutput {
    /// Normalised residuals r1..r4 (dimensionless, [-1, 1]) from the last slow-path run.
    pub residuals: [f32; 4],
    /// Residual lamps r1..r4.
    pub lamps: [bool; 4],
    /// Sensor faults seen from impossible readings (held for one second).
    pub sensor_fault: SensorFlags,
    /// Fault candidates and probabilities.
    pub diagnosis: Diagnosis,
    /// Any lamp or sensor fault.
    pub fault_detected: bool,
    /// Filtered model quantities in the chosen frame.
    pub operating: Operating,
    /// Filtered d-axis voltage V_ds in the chosen frame [V] (with `operating`'s I_qs, i_ds
    /// and V_qs: the full stator voltage and current vectors, for the fault isolation of
    /// [`crate::isolation`]). Taken from each block's last sample, low-pass filtered at
    /// `filter_hz`.
    pub vds: f32,
    /// Mechanical speed from the encoder [rad/s].
    pub speed_rad_s: f32,
    /// Frame angular frequency [rad/s] (supply frequency in steady state).
    pub frame_omega_rad_s: f32,
    /// True while lamps are being evaluated (voltage present, settled, quasi-steady, not
    /// commissioning).
    pub evaluating: bool,
    /// False while the operating point is changing (see `steady_gate_per_s`).
    pub quasi_steady: bool,
    /// Commissioning state.
    pub commissioning: CommissioningState,
    /// Negative-sequence analysis of the currents.
    pub unbalance: NegativeSequence,
    /// Gaps bridged, timing faults and recoveries so far.
    pub timing: TimingEvents,
    /// With [`AngleSource::ZeroCrossing`](crate::AngleSource::ZeroCrossing): whether the detector has measured a valid supply
    /// period since it (re)started (until then the frame turns at the nominal frequency
    /// from an arbitrary phase, so the d-q quantities mean nothing). `None` with the other
    /// angle sources.
    pub zero_crossing_locked: Option<bool>,
}

impl MonitorOutput {
    /// The most probable fault candidate and its probability.
    pub fn top(&self) -> Option<(Fault, f32)> {
        self.diagnosis.top()
    }
}
