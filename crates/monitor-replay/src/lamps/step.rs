//! The lamps' per-row steps after the monitor's output ([`super::LampStage::update`]): each
//! reads the output by reference and updates the fields it is given.

use super::commission::CommissionTracker;
use crate::stage::RowFlags;
use monitor_core::{Fault, Monitor, MonitorOutput, FAULT_COUNT};
use serde::{Serialize, Serializer};

/// A fault the lamps named (the top of the signature matching while a lamp was lit), with
/// the first time it was named [s]. JSON: the pair `[fault, t_s]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// The fault.
    pub fault: Fault,
    /// When it was first named [s since the log's first row].
    pub t_s: f64,
}

impl Serialize for Detection {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.fault, self.t_s).serialize(s)
    }
}

/// No bands (centre and half-width 0): what is passed where the bands are not needed.
pub(crate) const NO_BANDS: [(f32, f32); 4] = [(0.0, 0.0); 4];

/// Books the residuals of `out`: whether the lamps were ever evaluated, and the largest
/// |residual| of each while evaluating.
#[inline]
pub(crate) fn note_residuals(evaluated: &mut bool, max_abs: &mut [f32; 4], out: &MonitorOutput) {
    *evaluated |= out.evaluating;
    if out.evaluating {
        for (m, r) in max_abs.iter_mut().zip(out.residuals) {
            *m = m.max(r.abs());
        }
    }
}

/// The threshold bands in force: they only matter (and are only looked up) while the gate
/// holds the lamps or a lamp is lit ([`NO_BANDS`] otherwise).
#[inline]
pub(crate) fn bands_needed(mon: &Monitor, out: &MonitorOutput) -> [(f32, f32); 4] {
    if out.quasi_steady && !out.fault_detected {
        NO_BANDS
    } else {
        mon.threshold_bands()
    }
}

/// The bands a row needs of `needed` (what [`bands_needed`] gave): for the quasi-steady
/// gate's held stretch ([`NO_BANDS`] while the gate is open) and for a counted detection's
/// first look inside the range (`detected`: one was found already, and that stays), else
/// [`NO_BANDS`].
#[inline]
pub(crate) fn bands_for(
    needed: [(f32, f32); 4],
    out: &MonitorOutput,
    counts: bool,
    detected: bool,
) -> [(f32, f32); 4] {
    if !out.quasi_steady || (out.fault_detected && counts && !detected) {
        needed
    } else {
        NO_BANDS
    }
}

/// Books a counted detection at `t` in `out` (with the bands in force `bands`): whether
/// one was inside the commissioned range (`in_range`, once true it stays:
/// [`detected_in_range`]), the first one's time, and each fault the output ranks first
/// ([`note_detection`]).
#[inline]
pub(crate) fn book_detection(
    (in_range, first): (&mut bool, &mut Option<f64>),
    booked: (&mut Vec<Detection>, &mut [f32; FAULT_COUNT]),
    commission: &CommissionTracker,
    (t, out, bands): (f64, &MonitorOutput, [(f32, f32); 4]),
) {
    *in_range = *in_range || detected_in_range(commission, out, bands);
    note_detection(first, booked, t, out);
}

/// After a restart of the monitor's estimators (a long gap, a clock reset) the isolation
/// waits out the monitor's settling time too: the restarted frame's vectors look steady
/// before they are right.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RestartHold {
    /// The monitor's count of timing faults (estimator restarts) at the last row.
    timing_faults_seen: u32,
    /// The isolation ignores points until this time [s].
    hold_until: f64,
    /// The monitor's settling time after a restart [s].
    settle_s: f64,
}

impl RestartHold {
    /// No restart yet; `settle_s`: the monitor's settling time [s].
    pub(crate) fn new(settle_s: f64) -> Self {
        RestartHold {
            timing_faults_seen: 0,
            hold_until: f64::NEG_INFINITY,
            settle_s,
        }
    }

    /// Whether the isolation may use the point at `t` [s] (a restart counted in `out`
    /// starts a new hold).
    #[inline]
    pub(crate) fn settled(&mut self, t: f64, out: &MonitorOutput) -> bool {
        if out.timing.timing_faults != self.timing_faults_seen {
            self.timing_faults_seen = out.timing.timing_faults;
            self.hold_until = t + self.settle_s;
        }
        t >= self.hold_until
    }
}

/// Whether a counted detection in `out` is one inside the commissioned range: a sensor
/// fault, or lamps evaluated (quasi-steady) with a lit lamp's residual outside its band
/// (`bands`) inside the learned range. A lamp held through a transient, or after its
/// residual came back (the load returned into the range), detects nothing new there.
#[inline]
pub(crate) fn detected_in_range(
    commission: &CommissionTracker,
    out: &MonitorOutput,
    bands: [(f32, f32); 4],
) -> bool {
    let current = out.evaluating && lit_outside_band(out, bands);
    out.sensor_fault.any() || (current && !commission.outside_learned_range(out))
}

/// Books a counted detection at `t` [s]: the first one's time, and each fault the output
/// ranks first the first time it does. `seen`: the probabilities whose first fault is
/// booked already (the diagnosis changes only with the lamps: the same one is not ranked
/// again).
#[inline]
pub(crate) fn note_detection(
    first: &mut Option<f64>,
    (detections, seen): (&mut Vec<Detection>, &mut [f32; FAULT_COUNT]),
    t: f64,
    out: &MonitorOutput,
) {
    if first.is_none() {
        *first = Some(t);
    }
    if same_bits(seen, &out.diagnosis.probabilities) {
        return;
    }
    *seen = out.diagnosis.probabilities;
    if let Some((fault, _)) = out.top() {
        if !detections.iter().any(|d| d.fault == fault) {
            detections.push(Detection { fault, t_s: t });
        }
    }
}

/// Whether `a` and `b` hold the same bits (a cheaper test than `==`, without branches; it
/// differs from `==` only for NaN and signed zeros, where [`note_detection`] books the same
/// once more, and nothing changes).
#[inline]
fn same_bits(a: &[f32; FAULT_COUNT], b: &[f32; FAULT_COUNT]) -> bool {
    a.iter()
        .zip(b)
        .fold(0, |acc, (x, y)| acc | (x.to_bits() ^ y.to_bits()))
        == 0
}

/// What the rows up to the monitor's next revision ([`Monitor::revision`]) take from its
/// output, as the revision's first row found it.
#[derive(Debug, Clone, Default)]
pub(crate) struct BlockView {
    /// The revision it was taken at (`None`: none yet).
    pub(crate) revision: Option<u32>,
    /// The output's flags.
    pub(crate) flags: RowFlags,
    /// The lamps are judged: evaluated, quasi-steady, on thresholds that count
    /// (`MIN_JUDGED_S`).
    pub(crate) judging: bool,
    /// A lamp is lit.
    pub(crate) lamps_lit: bool,
    /// The note on the commissioned range for the timeline.
    pub(crate) range_note: Option<Vec<super::commission::RangeDeparture>>,
}

/// What a replay keeps of the monitor's output after a row for the next one.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LastOutput {
    /// The commissioning window is being learned.
    pub(crate) learning: bool,
    /// The electrical rotor speed [rad/s].
    pub(crate) wr_rad_s: f32,
    /// A sensor fault is flagged.
    pub(crate) sensor_fault: bool,
}

impl LastOutput {
    /// What the next row needs of `out` (with its `flags`).
    #[inline]
    pub(crate) fn of(out: &MonitorOutput, flags: RowFlags) -> Self {
        LastOutput {
            learning: flags.learning(),
            wr_rad_s: out.operating.wr_rad_s,
            sensor_fault: flags.sensor_fault(),
        }
    }
}

/// Whether a lit lamp's residual lies outside its band `(centre, half-width)` now.
#[inline]
pub(crate) fn lit_outside_band(out: &MonitorOutput, bands: [(f32, f32); 4]) -> bool {
    out.lamps
        .iter()
        .zip(out.residuals)
        .zip(bands)
        .any(|((lit, r), (c, h))| *lit && (r - c).abs() > h)
}
