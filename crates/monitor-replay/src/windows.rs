//! What the sequence stage hands the winding and the rotor: the least-squares windows
//! ([`SequenceWindow`]), one phase's sensor read from a window's zero sequence
//! ([`SensorPhaseReport`]), and the steady operating point the winding measured for the
//! rotor's load ([`MeasuredPoint`]). The stages that make them and the stages that read
//! them import only this.

use monitor_core::sequence::{single_phase_gain, Complex32, SinglePhaseGain, ThreePhasors};
use monitor_core::Phase;
use serde::Serialize;

/// Zero sequence (|3 I0|/|I1|) from which one phase's sensor gain error is reported: 0.5 %,
/// about ten times what 12-bit sensors with 0.1 % noise and 0.2 % gain mismatch leave after
/// the sequence analysis' 2 Hz filters (a one-phase gain error `g` gives about `g`).
pub const SENSOR_PHASE_MIN_RATIO: f32 = 0.005;

/// Supply periods per least-squares window (at the nominal frequency): 0.17 s at 60 Hz,
/// 0.2 s at 50 Hz. Short enough to see a fault switched on and off within a few seconds,
/// long enough that harmonics and noise average out.
pub const WINDOW_PERIODS: f64 = 10.0;

/// Least share of a window's samples the fit must have used (bad samples are held out).
pub const MIN_WINDOW_FILL: f64 = 0.8;

/// How far a parameter file's current may be off the machine's (for the slip read from the
/// current's magnitude: its uncertainty); also the winding's reference angle's
/// (`crate::winding`).
pub const CURRENT_MODEL_UNCERTAINTY: f32 = 0.15;

/// One window of the least-squares analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SequenceWindow {
    /// Time of the window's first and last sample [s since the log's first row].
    pub from_s: f64,
    /// See `from_s`.
    pub to_s: f64,
    /// The currents' phase phasors.
    pub i: ThreePhasors,
    /// The voltages' phase phasors, where logged and good in the whole window.
    pub v: Option<ThreePhasors>,
    /// Mean supply angular frequency over the window [rad/s].
    pub we_rad_s: f32,
    /// Mean over the window of the reference angle less `w0 t` (the nominal frequency's
    /// angle), unwrapped [rad]: how far the reference turned from a fixed-frequency frame,
    /// so that windows can be put into one frame ([`SequenceWindow::offset_rad`]).
    pub offset_rad: f64,
    /// The monitor's electrical rotor speed at the window's end [rad/s], where the log
    /// has a speed (encoder or speed column).
    pub wr_rad_s: Option<f32>,
    /// The fit used at least [`MIN_WINDOW_FILL`] of the window's samples.
    pub complete: bool,
    /// Complete, and the supply frequency held still.
    pub steady: bool,
    /// The window lies in the commissioning window's learning.
    pub learning: bool,
}

/// One phase's sensor gain error in a set of phasors (the zero sequence,
/// [`single_phase_gain`]), evidence from [`SENSOR_PHASE_MIN_RATIO`] on: `p`, `n`, `z` the
/// positive, negative and zero sequences with one rotation.
pub(super) fn sensor_phase(p: Complex32, n: Complex32, z: Complex32) -> Option<SinglePhaseGain> {
    single_phase_gain(p, n, z, SENSOR_PHASE_MIN_RATIO)
}

/// One phase's sensor gain error found from the zero sequence
/// ([`monitor_core::sequence::single_phase_gain`]; JSON `unbalance.current_sensor_phase`,
/// `unbalance.voltage_sensor_phase`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SensorPhaseReport {
    /// The phase (JSON `a`, `b` or `c`).
    pub phase: Phase,
    /// The sensor's gain error (0.2: it reads 20 % high).
    pub gain_error: f32,
    /// |3 I0| / |I1|: the zero sequence the error leaves in the measured set.
    pub zero_sequence_ratio: f32,
}

impl From<&SinglePhaseGain> for SensorPhaseReport {
    fn from(g: &SinglePhaseGain) -> Self {
        SensorPhaseReport {
            phase: g.phase,
            gain_error: g.gain_error,
            zero_sequence_ratio: g.zero_sequence_ratio,
        }
    }
}

/// What the log measured of the operating point beyond the rotor's own record: the
/// positive-sequence voltage and current phasors over a steady stretch (peak), where the log
/// has voltages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredPoint {
    /// `|V1|` [V, phase peak].
    pub v1_peak_v: f64,
    /// `|I1|` [A, phase peak].
    pub i1_peak_a: f64,
    /// The power factor angle `arg(V1 / I1)` [rad].
    pub angle_rad: f64,
}

/// What the winding's windows take of one row ([`crate::sequences::SequenceStep`] with the
/// lamps' output after the row before).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct WindowRow {
    /// The open window was closed before the row's sample (a gap the data-quality stage
    /// does not bridge).
    pub(crate) closed_before: bool,
    /// The open window was closed after the row's sample (full).
    pub(crate) closed_after: bool,
    /// The monitor was learning its commissioning window after the row before.
    pub(crate) learning: bool,
    /// The monitor's electrical speed after the row before [rad/s], where the log has a
    /// speed.
    pub(crate) wr_rad_s: Option<f32>,
}
