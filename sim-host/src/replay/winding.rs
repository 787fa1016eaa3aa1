//! The winding's negative-sequence judgement (JSON `unbalance`): which phase a shorted
//! turn sits in, with its confidence, or why that cannot be judged.
//!
//! 1. **Segments.** The least-squares windows ([`super::sequences`]) are grouped into
//!    steady segments: consecutive steady windows whose `I2/I1` stays within
//!    [`SEGMENT_STEP_MIN`] (or [`SEGMENT_STEP_REL`] of itself) of the segment's mean and
//!    whose `|I1|` within [`SEGMENT_I1_STEP`]; a segment counts from
//!    [`MIN_SEGMENT_WINDOWS`] windows on. A short switched on and off within a log (the
//!    real recordings of shorted turns do this) is a segment of its own.
//! 2. **The healthy reference** `R` and its spread `sigma` (the standard deviation of each
//!    component of `I2/I1` that a healthy run's reading has about `R`): the mean of the
//!    `--baseline` runs, with `sigma^2 = (2 s0^2 + sum |h_i - R|^2) / (2 n)` (the default
//!    spread `s0` counts as one run's worth of evidence, the runs add their own); else the
//!    commissioning window's, within [`super::BASELINE_I1_TOLERANCE`] of its `|I1|`, with
//!    `s0`; else none: `R = 0` and `sigma` = [`NO_BASELINE_SPREAD`], a healthy machine's
//!    own asymmetry ([`NO_BASELINE_SPREAD_VOLTAGES`] with voltages). `s0` is [`DEFAULT_SPREAD_CURRENTS`] for a log without voltages (the
//!    supply's unbalance changes between runs, and without voltages it cannot be taken
//!    out) and [`DEFAULT_SPREAD_VOLTAGES`] with them.
//! 3. **The change** of each segment, `c = (I2/I1 - V2/(Z2 I1)) - R'` (the supply's part
//!    `V2/Z2` taken out where voltages are logged, `R'` the reference's winding part),
//!    judged by `monitor_core::sequence::judge_phase`: it names a phase when
//!    `|c| >= 2 sigma'` ([`LEAST_CHANGE_SPREADS`]) and the angle `arg c - arg Z1` lies
//!    inside its phase's sector by more than its uncertainty. Without voltages a segment at
//!    another `|I1|` than the reference's widens the spread, `sigma'^2 = sigma^2 +
//!    (|R| |1 - I1_R/I1|)^2`: the supply's part of `I2` stays as the load moves while `I1`
//!    does not, so `I2/I1` moves with the load. The segment whose change stands out most
//!    from its spread (`|c|/sigma'`) among those that name a phase is reported, else the one
//!    that stands out most.
//! 4. **The reference angle** `arg Z1` (Tallam's loop: `I2/I1 = (mu/3)(Z1/Z_f) a^k`,
//!    `monitor_core::sequence`): measured as `arg(V1/I1)` where voltages are logged;
//!    else the model's at the slip from the speed; else at the slip where the model draws
//!    the measured `|I1|`, when that current is one the parameter file can draw between no
//!    load and [`FULL_LOAD_SLIP_MAX`]; else unknown between those two loads: the middle of
//!    the range, its half-width the uncertainty ([`OperatingPointSource`]).

use super::report::BaselineSource;
use super::sequences::{sensor_phase, SequenceWindow};
use super::{Replay, SensorPhaseReport, UnbalanceBaseline, UnbalanceReport, BASELINE_I1_TOLERANCE};
use monitor_core::sequence::{
    asymmetry_correction_rad, equivalent_impedance, judge_phase, slip_for_current, PhaseJudgement,
    PhaseNotNamed, SinglePhaseGain, INHERENT_ASYMMETRY_RATIO,
};
use monitor_core::{MotorModel, Phase};
use serde::Serialize;

/// Fewest least-squares windows a steady segment holds (0.5 s at 60 Hz).
pub const MIN_SEGMENT_WINDOWS: usize = 3;
/// A window whose `I2/I1` lies farther than this (fraction of `|I1|`) from its segment's
/// mean, and farther than [`SEGMENT_STEP_REL`] of the mean's size, starts a new segment:
/// three times the window-to-window scatter of a healthy motor's reading at 1 kHz.
pub const SEGMENT_STEP_MIN: f32 = 0.015;
/// The same for the voltages' `V2/V1` and `V0/V1` (a voltage sensor's 5 % gain step
/// moves them by 1.7 %).
pub const SEGMENT_VOLTAGE_STEP_MIN: f32 = 0.005;
/// See [`SEGMENT_STEP_MIN`]: a large negative sequence scatters in proportion.
pub const SEGMENT_STEP_REL: f32 = 0.15;
/// Unsteady windows in a row that a segment may hold (left out of its means).
pub const MAX_UNSTEADY_INSIDE: usize = 2;
/// A window whose `|I1|` differs from its segment's mean by more than this fraction starts
/// a new segment (the operating point moved).
pub const SEGMENT_I1_STEP: f32 = 0.05;
/// The default spread `s0` of a healthy reference without voltages (fraction of `|I1|`,
/// each component): a healthy motor's `I2/I1` moves by about 2 % between runs on the same
/// grid as the supply's unbalance changes (measured on the ITSC recordings' healthy
/// runs, `docs/isolation.md`).
pub const DEFAULT_SPREAD_CURRENTS: f32 = 0.015;
/// The default spread with voltages logged: the supply's part is taken out of every
/// reading; what is left is the model's negative-sequence impedance error and the sensors.
pub const DEFAULT_SPREAD_VOLTAGES: f32 = 0.0025;
/// Without any healthy reference and without voltages, the spread is a healthy machine's
/// own asymmetry ([`INHERENT_ASYMMETRY_RATIO`], 3 %): with the supply's unbalance, which
/// the currents alone cannot tell from it, a healthy motor's `I2/I1` reaches twice that.
pub const NO_BASELINE_SPREAD: f32 = INHERENT_ASYMMETRY_RATIO;
/// Without a healthy reference but with voltages (the supply's part taken out): half of
/// it, so that a winding part above the machine's own asymmetry (3 %) may name a phase.
pub const NO_BASELINE_SPREAD_VOLTAGES: f32 = 0.5 * INHERENT_ASYMMETRY_RATIO;
/// The least change that may name a phase, in spreads.
pub const LEAST_CHANGE_SPREADS: f32 = 2.0;
/// The largest slip taken for "full load" where the operating point is not known (rated
/// slips run from 1 % for large motors to 5 % for small ones).
pub const FULL_LOAD_SLIP_MAX: f32 = 0.05;
/// How far a parameter file's current may be off the machine's (for the slip read from the
/// current's magnitude: its uncertainty).
pub const CURRENT_MODEL_UNCERTAINTY: f32 = 0.15;
/// Uncertainty of a reference angle measured as `arg(V1/I1)` [deg]: the sensors' phase
/// errors and the loop impedance's own angle.
pub const MEASURED_REFERENCE_UNCERTAINTY_DEG: f32 = 3.0;
/// How far the slip's model reading may be off for a reference from the measured speed
/// (the rotor resistance of a parameter file, 30 %).
pub const SLIP_MODEL_UNCERTAINTY: f32 = 0.3;
/// Most segments the report lists (the judged one always among them).
pub const MAX_SEGMENTS: usize = 50;

/// Where the reference angle `arg Z1` of a judgement comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OperatingPointSource {
    /// Measured: `arg(V1/I1)` from the logged voltages.
    Voltages,
    /// The model's `arg Z1` at the slip from the measured speed.
    Speed,
    /// The model's `arg Z1` at the slip where it draws the measured `|I1|`.
    CurrentMagnitude,
    /// Not known: between no load and [`FULL_LOAD_SLIP_MAX`] (the current's magnitude is
    /// not one the parameter file draws: a scale or a file that does not fit).
    AssumedRange,
}

impl OperatingPointSource {
    /// In words, for the text report.
    pub fn describe(self) -> &'static str {
        match self {
            OperatingPointSource::Voltages => "measured from the voltages",
            OperatingPointSource::Speed => "the model's at the measured speed",
            OperatingPointSource::CurrentMagnitude => "the model's at the current's magnitude",
            OperatingPointSource::AssumedRange => {
                "unknown operating point: no load to full load (the current's magnitude does not fit the parameter file)"
            }
        }
    }
}

/// One steady stretch of the log's negative sequence (JSON `unbalance.segments`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SequenceSegment {
    /// Start and end [s since the log's first row].
    pub from_s: f64,
    /// See `from_s`.
    pub to_s: f64,
    /// Least-squares windows in it.
    pub windows: u32,
    /// Mean |I1| [A, peak].
    pub i1_peak_a: f32,
    /// |I2/I1| of the segment's mean.
    pub negative_sequence_ratio: f32,
    /// arg(I2/I1) [deg].
    pub angle_deg: f32,
    /// Mean `I2/I1` (re, im) and its standard error (each component) over the windows.
    #[serde(skip)]
    r: (f32, f32),
    #[serde(skip)]
    sem: f32,
    /// Mean `V2/I1` and `V1/I1` [ohm] where every window has voltages.
    #[serde(skip)]
    v2: Option<(f32, f32)>,
    #[serde(skip)]
    v1: Option<(f32, f32)>,
    /// Mean phasors (one rotation) of the currents' and the voltages' positive, negative
    /// and zero sequences, for the sensor check.
    #[serde(skip)]
    pnz: [(f32, f32); 3],
    #[serde(skip)]
    v_pnz: Option<[(f32, f32); 3]>,
    #[serde(skip)]
    we: f32,
    #[serde(skip)]
    wr: Option<f32>,
    #[serde(skip)]
    learning: bool,
}

type C = (f32, f32);

fn cdiv(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    if d.is_nan() || d <= 0.0 {
        return (0.0, 0.0);
    }
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

fn sub(a: C, b: C) -> C {
    (a.0 - b.0, a.1 - b.1)
}

fn abs(a: C) -> f32 {
    monitor_core::fast_hypot(a.0, a.1)
}

/// Mean of complex values.
fn mean(xs: impl Iterator<Item = C>) -> C {
    let (mut s, mut n) = ((0.0f64, 0.0f64), 0u32);
    for x in xs {
        s.0 += f64::from(x.0);
        s.1 += f64::from(x.1);
        n += 1;
    }
    if n == 0 {
        return (0.0, 0.0);
    }
    ((s.0 / f64::from(n)) as f32, (s.1 / f64::from(n)) as f32)
}

/// A window's features that a segment holds still: `I2/I1`, `I0/I1` and, with voltages,
/// `V2/V1`, `V0/V1` (a sensor's gain step moves the zero sequences, a winding or the
/// supply the negative ones).
fn features(w: &SequenceWindow) -> [C; 4] {
    let p = w.i.positive();
    let v = w.v.map_or([(0.0, 0.0); 2], |v| {
        let p = v.positive();
        [cdiv(v.negative(), p), cdiv(v.zero(), p)]
    });
    [cdiv(w.i.negative(), p), cdiv(w.i.zero(), p), v[0], v[1]]
}

/// Running sums of a segment's [`features`] and `|I1|`, so that each new window is judged
/// against the segment's means in constant time (a steady hour at 60 Hz is 21 600 windows:
/// recomputing the means for each window was quadratic). The sums are taken in the windows'
/// order, in the precision [`mean`] uses, so the means are the same to the last bit.
#[derive(Default)]
struct SegmentSums {
    features: [(f64, f64); 4],
    i1: f32,
    n: u32,
}

impl SegmentSums {
    fn add(&mut self, w: &SequenceWindow) {
        for (s, f) in self.features.iter_mut().zip(features(w)) {
            s.0 += f64::from(f.0);
            s.1 += f64::from(f.1);
        }
        self.i1 += abs(w.i.positive());
        self.n += 1;
    }

    fn of(w: &SequenceWindow) -> Self {
        let mut s = SegmentSums::default();
        s.add(w);
        s
    }

    /// Whether window `w` lies outside the segment (its features or its `|I1|`).
    fn departs(&self, w: &SequenceWindow) -> bool {
        let n = f64::from(self.n.max(1));
        let f = features(w);
        let moved = (0..4).any(|k| {
            let s = self.features[k];
            let m = if self.n == 0 {
                (0.0, 0.0)
            } else {
                ((s.0 / n) as f32, (s.1 / n) as f32)
            };
            let floor = if k < 2 {
                SEGMENT_STEP_MIN
            } else {
                SEGMENT_VOLTAGE_STEP_MIN
            };
            abs(sub(f[k], m)) > floor.max(SEGMENT_STEP_REL * abs(m))
        });
        let i1_mean = self.i1 / self.n.max(1) as f32;
        moved || (abs(w.i.positive()) - i1_mean).abs() > SEGMENT_I1_STEP * i1_mean
    }
}

/// The steady segments of `windows` (module docs, step 1). A step must hold for two
/// windows: one window out of line (a burst of noise) is left out of its segment, two in a
/// row start the next one.
pub fn segments(windows: &[SequenceWindow]) -> Vec<SequenceSegment> {
    let mut out = Vec::new();
    let mut cur: Vec<&SequenceWindow> = Vec::new();
    let mut sums = SegmentSums::default();
    let mut pending: Option<&SequenceWindow> = None;
    let close =
        |cur: &mut Vec<&SequenceWindow>, sums: &mut SegmentSums, out: &mut Vec<SequenceSegment>| {
            if cur.len() >= MIN_SEGMENT_WINDOWS {
                out.push(segment_of(cur));
            }
            cur.clear();
            *sums = SegmentSums::default();
        };
    let mut unsteady = 0usize;
    for w in windows {
        if !w.steady {
            // One or two unsteady windows (a PLL disturbance, a burst of bad samples) are
            // left out of the segment; more end it (a run-up, a ramp).
            unsteady += 1;
            if unsteady > MAX_UNSTEADY_INSIDE {
                close(&mut cur, &mut sums, &mut out);
                pending = None;
            }
            continue;
        }
        unsteady = 0;
        if cur.is_empty() || !sums.departs(w) {
            pending = None;
            cur.push(w);
            sums.add(w);
            continue;
        }
        match pending.take() {
            None => pending = Some(w),
            Some(p) => {
                close(&mut cur, &mut sums, &mut out);
                // The first window after a step may straddle it: it starts the new segment
                // only when the second agrees with it.
                if !SegmentSums::of(p).departs(w) {
                    cur.push(p);
                    sums.add(p);
                }
                cur.push(w);
                sums.add(w);
            }
        }
    }
    close(&mut cur, &mut sums, &mut out);
    out
}

/// One segment's means.
fn segment_of(ws: &[&SequenceWindow]) -> SequenceSegment {
    let n = ws.len();
    let rs: Vec<C> = ws
        .iter()
        .map(|w| cdiv(w.i.negative(), w.i.positive()))
        .collect();
    let r = mean(rs.iter().copied());
    let var =
        rs.iter().map(|x| abs(sub(*x, r)).powi(2)).sum::<f32>() / (2.0 * (n.max(2) - 1) as f32);
    let volts: Option<Vec<_>> = ws
        .iter()
        .map(|w| w.v.map(|v| (v, w.i.positive())))
        .collect();
    let (v1, v2) = match volts {
        Some(v) => (
            Some(mean(v.iter().map(|(v, i1)| cdiv(v.positive(), *i1)))),
            Some(mean(v.iter().map(|(v, i1)| cdiv(v.negative(), *i1)))),
        ),
        None => (None, None),
    };
    SequenceSegment {
        from_s: ws.first().map_or(0.0, |w| w.from_s),
        to_s: ws.last().map_or(0.0, |w| w.to_s),
        windows: n as u32,
        i1_peak_a: ws.iter().map(|w| abs(w.i.positive())).sum::<f32>() / n as f32,
        negative_sequence_ratio: abs(r),
        angle_deg: r.1.atan2(r.0).to_degrees(),
        r,
        sem: (var / n as f32).sqrt(),
        v2,
        v1,
        pnz: [
            mean(ws.iter().map(|w| w.i.positive())),
            mean(ws.iter().map(|w| w.i.negative())),
            mean(ws.iter().map(|w| w.i.zero())),
        ],
        v_pnz: ws.iter().map(|w| w.v).collect::<Option<Vec<_>>>().map(|v| {
            [
                mean(v.iter().map(|v| v.positive())),
                mean(v.iter().map(|v| v.negative())),
                mean(v.iter().map(|v| v.zero())),
            ]
        }),
        we: ws.iter().map(|w| w.we_rad_s).sum::<f32>() / n as f32,
        wr: ws.last().and_then(|w| w.wr_rad_s),
        learning: ws.iter().all(|w| w.learning),
    }
}

/// The healthy machine's negative sequence from several runs: their mean, how many, and
/// their scatter (JSON `unbalance.baseline_runs`, `unbalance.baseline_spread`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HealthyReference {
    /// The runs' mean (`I2/I1`, `V2/I1` where every run has voltages, `|I1|`).
    pub mean: UnbalanceBaseline,
    /// How many runs.
    pub runs: u32,
    /// `sum |h_i - mean|^2` of the runs' `I2/I1` (0 for one run).
    pub sum_sq_dev: f32,
}

impl From<UnbalanceBaseline> for HealthyReference {
    fn from(b: UnbalanceBaseline) -> Self {
        HealthyReference {
            mean: b,
            runs: 1,
            sum_sq_dev: 0.0,
        }
    }
}

impl HealthyReference {
    /// The reference made of several healthy runs (`diagnose --baseline` with several
    /// logs); `None` for none.
    pub fn from_runs(runs: &[UnbalanceBaseline]) -> Option<Self> {
        let n = runs.len();
        if n == 0 {
            return None;
        }
        let c = |x: [f32; 2]| (x[0], x[1]);
        let i2 = mean(runs.iter().map(|r| c(r.i2_over_i1)));
        let v2 = runs
            .iter()
            .map(|r| r.v2_over_i1.map(c))
            .collect::<Option<Vec<_>>>()
            .map(|v| mean(v.into_iter()));
        Some(HealthyReference {
            mean: UnbalanceBaseline {
                i2_over_i1: [i2.0, i2.1],
                v2_over_i1: v2.map(|v| [v.0, v.1]),
                i1_peak_a: runs.iter().map(|r| r.i1_peak_a).sum::<f32>() / n as f32,
            },
            runs: n as u32,
            sum_sq_dev: runs
                .iter()
                .map(|r| abs(sub(c(r.i2_over_i1), i2)).powi(2))
                .sum(),
        })
    }

    /// The runs' RMS distance from their mean, `sqrt(sum / (n - 1))`; `None` for one run.
    pub fn measured_spread(&self) -> Option<f32> {
        (self.runs >= 2).then(|| (self.sum_sq_dev / (self.runs - 1) as f32).sqrt())
    }

    /// The spread `sigma` with the default `s0` counted as one run (module docs, step 2).
    pub fn sigma(&self, s0: f32) -> f32 {
        ((2.0 * s0 * s0 + self.sum_sq_dev) / (2 * self.runs.max(1)) as f32).sqrt()
    }
}

/// The reference angle at a segment's operating point: `(arg Z1, uncertainty)` [rad], the
/// slip where one is used, and where it came from (module docs, step 4).
fn reference_angle(
    seg: &SequenceSegment,
    m: &MotorModel,
    v_peak_nominal: f32,
    speed: bool,
) -> (f32, f32, Option<f32>, OperatingPointSource) {
    let we = seg.we;
    let corr = |s: f32| asymmetry_correction_rad(m, we, s);
    if let Some(v1) = seg.v1 {
        return (
            v1.1.atan2(v1.0),
            MEASURED_REFERENCE_UNCERTAINTY_DEG.to_radians(),
            None,
            OperatingPointSource::Voltages,
        );
    }
    let spread = |s: f32, lo: f32, hi: f32| {
        let c = corr(s);
        (c, (corr(lo) - c).abs().max((corr(hi) - c).abs()))
    };
    if let (true, Some(wr)) = (speed, seg.wr) {
        let s = (1.0 - wr / we).clamp(1e-4, 0.5);
        let (c, u) = spread(
            s,
            s / (1.0 + SLIP_MODEL_UNCERTAINTY),
            s * (1.0 + SLIP_MODEL_UNCERTAINTY),
        );
        return (c, u, Some(s), OperatingPointSource::Speed);
    }
    let i_at = |s: f32| {
        let z = equivalent_impedance(m, we, s);
        v_peak_nominal / abs(z)
    };
    let i1 = seg.i1_peak_a;
    let (i_lo, i_hi) = (
        (1.0 - CURRENT_MODEL_UNCERTAINTY) * i_at(1e-4),
        (1.0 + CURRENT_MODEL_UNCERTAINTY) * i_at(FULL_LOAD_SLIP_MAX),
    );
    if i1 >= i_lo && i1 <= i_hi {
        let s_of = |i: f32| slip_for_current(m, v_peak_nominal, we, i);
        let s = s_of(i1);
        let (c, u) = spread(
            s,
            s_of((1.0 - CURRENT_MODEL_UNCERTAINTY) * i1),
            s_of((1.0 + CURRENT_MODEL_UNCERTAINTY) * i1),
        );
        return (c, u, Some(s), OperatingPointSource::CurrentMagnitude);
    }
    let (c0, c1) = (corr(1e-4), corr(FULL_LOAD_SLIP_MAX));
    (
        0.5 * (c0 + c1),
        0.5 * (c0 - c1).abs(),
        None,
        OperatingPointSource::AssumedRange,
    )
}

/// The winding part `I2/I1 - V2/(Z2 I1)` of a reading (module docs, step 3), and the
/// supply's part `|V2/Z2|/|I1|` (0 without voltages).
fn winding_part(i2: C, v2: Option<C>, m: &MotorModel, we: f32, s: f32) -> (C, f32) {
    match v2 {
        Some(v2) => {
            let z2 = equivalent_impedance(m, we, 2.0 - s);
            let supply = cdiv(v2, z2);
            (sub(i2, supply), abs(supply))
        }
        None => (i2, 0.0),
    }
}

/// What was measured: the longest steady segment's `I2/I1`, `V2/I1` and `|I1|` (a
/// healthy log's are the `--baseline` of a later one: its settled running, a start or a
/// load step left out), and the whole log's least-squares `|I2|/|I1|`.
fn measured_of(windows: &[SequenceWindow], segs: &[SequenceSegment]) -> (UnbalanceBaseline, f32) {
    let longest = segs.iter().max_by_key(|s| s.windows);
    let measured = longest.map_or(
        UnbalanceBaseline {
            i2_over_i1: [0.0, 0.0],
            v2_over_i1: None,
            i1_peak_a: 0.0,
        },
        |s| UnbalanceBaseline {
            i2_over_i1: [s.r.0, s.r.1],
            v2_over_i1: s.v2.map(|v| [v.0, v.1]),
            i1_peak_a: s.i1_peak_a,
        },
    );
    // The whole log's least-squares ratio: the phasors of every complete window averaged
    // (one rotation), the supply frequency within 5 % of nominal-or-median: a run-up is
    // left out, a settling PLL is not (the fit does not need a settled reference).
    let mut ws: Vec<f32> = windows
        .iter()
        .filter(|w| w.complete)
        .map(|w| w.we_rad_s)
        .collect();
    ws.sort_by(f32::total_cmp);
    let w_med = ws.get(ws.len() / 2).copied().unwrap_or(0.0);
    let whole: Vec<&SequenceWindow> = windows
        .iter()
        .filter(|w| w.complete && (w.we_rad_s - w_med).abs() <= 0.05 * w_med)
        .collect();
    // Into one frame turning at the log's mean frequency: the reference's offset from it
    // (a line through the windows' offsets) turned back, as a fit over the whole log at
    // one frequency sees the phasors.
    let line = fit_line(
        whole
            .iter()
            .map(|w| (0.5 * (w.from_s + w.to_s), w.offset_rad)),
    );
    let turned = |w: &SequenceWindow, x: C| {
        let d = (w.offset_rad - line.0 - line.1 * 0.5 * (w.from_s + w.to_s)) as f32;
        let (sn, cs) = d.sin_cos();
        (x.0 * cs - x.1 * sn, x.0 * sn + x.1 * cs)
    };
    let p = mean(whole.iter().map(|w| turned(w, w.i.positive())));
    let n = mean(whole.iter().map(|w| turned(w, w.i.negative())));
    let whole = if abs(p) > 0.0 { abs(n) / abs(p) } else { 0.0 };
    (measured, whole)
}

/// The least-squares line `y = a + b x` through `(x, y)` points, as `(a, b)`; `(mean, 0)`
/// for fewer than two distinct `x`.
fn fit_line(points: impl Iterator<Item = (f64, f64)>) -> (f64, f64) {
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (x, y) in points {
        n += 1.0;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    if n == 0.0 {
        return (0.0, 0.0);
    }
    let d = n * sxx - sx * sx;
    if d.is_nan() || d.abs() <= 1e-12 * n * sxx.max(1e-300) {
        return (sy / n, 0.0);
    }
    let b = (n * sxy - sx * sy) / d;
    ((sy - b * sx) / n, b)
}

/// The healthy reference a segment is judged against (module docs, step 2).
struct Reference {
    r: C,
    v2: Option<C>,
    i1: f32,
    sigma: f32,
    source: Option<BaselineSource>,
}

/// A segment's judgement.
struct Judged {
    index: usize,
    change: C,
    supply_ratio: f32,
    judgement: PhaseJudgement,
    reference: (f32, f32, Option<f32>, OperatingPointSource),
    sigma: f32,
    least_change: f32,
    source: Option<BaselineSource>,
}

/// What every segment is judged with: the model, the nominal supply, whether the speed is
/// measured, and the healthy references.
struct Judge {
    m: MotorModel,
    v_nominal: f32,
    speed: bool,
    file: Option<HealthyReference>,
    learned: Option<Reference>,
    s0: f32,
}

impl Judge {
    /// The healthy reference a segment is judged against (module docs, step 2).
    fn reference_for(&self, seg: &SequenceSegment) -> Reference {
        if let Some(f) = self.file {
            let c = |x: [f32; 2]| (x[0], x[1]);
            return Reference {
                r: c(f.mean.i2_over_i1),
                v2: f.mean.v2_over_i1.map(c),
                i1: f.mean.i1_peak_a,
                sigma: f.sigma(self.s0),
                source: Some(BaselineSource::File),
            };
        }
        match &self.learned {
            Some(l) if (seg.i1_peak_a - l.i1).abs() <= BASELINE_I1_TOLERANCE * l.i1 => Reference {
                r: l.r,
                v2: l.v2,
                i1: l.i1,
                sigma: l.sigma,
                source: l.source,
            },
            _ => Reference {
                r: (0.0, 0.0),
                v2: None,
                i1: seg.i1_peak_a,
                sigma: if seg.v2.is_some() {
                    NO_BASELINE_SPREAD_VOLTAGES
                } else {
                    NO_BASELINE_SPREAD
                },
                source: None,
            },
        }
    }

    /// One segment's change from its reference, judged (module docs, steps 3 and 4).
    fn judge(&self, index: usize, seg: &SequenceSegment) -> Judged {
        let m = &self.m;
        let reference = self.reference_for(seg);
        let op = reference_angle(seg, m, self.v_nominal, self.speed);
        let s = op.2.unwrap_or(0.0).max(1e-4);
        // A sensor's own negative sequence is not the winding's (nor the supply's); with one
        // voltage sensor wrong the voltages cannot say how much of I2 the supply drives, and
        // the currents alone judge.
        let (gi, gv) = sensor_phases(seg);
        let [p, n, z] = seg.pnz;
        let r = match gi {
            Some(g) => {
                let d = sub(cdiv(g.corrected_negative(p, n, z), p), cdiv(n, p));
                (seg.r.0 + d.0, seg.r.1 + d.1)
            }
            None => seg.r,
        };
        let v2 = seg.v2.filter(|_| gv.is_none());
        let (w, supply_ratio) = winding_part(r, v2, m, seg.we, s);
        let ref_v2 = reference.v2.filter(|_| v2.is_some());
        let (w_ref, _) = winding_part(reference.r, ref_v2, m, seg.we, s);
        let change = sub(w, w_ref);
        // Another operating point than the reference's, without the voltages to take the
        // supply's part out: I2/I1 moves with I1.
        let moved = if v2.is_none() && seg.i1_peak_a > 0.0 {
            abs(w_ref) * (1.0 - reference.i1 / seg.i1_peak_a).abs()
        } else {
            0.0
        };
        let healthy = reference.sigma.hypot(moved);
        let sigma = healthy.hypot(seg.sem);
        let least_change = LEAST_CHANGE_SPREADS * healthy;
        Judged {
            index,
            change,
            supply_ratio,
            judgement: judge_phase(change, op.0, op.1, sigma, least_change),
            reference: op,
            sigma,
            least_change,
            source: reference.source,
        }
    }
}

impl Replay {
    /// The negative-sequence report (module docs).
    pub(super) fn unbalance_report(&self) -> UnbalanceReport {
        let windows = self.book.windows();
        let segs = segments(windows);
        let (measured, whole_ratio) = measured_of(windows, &segs);
        let s0 = if self.channels.voltages {
            DEFAULT_SPREAD_VOLTAGES
        } else {
            DEFAULT_SPREAD_CURRENTS
        };
        let learned = learned_reference(windows, s0);
        let judge = Judge {
            m: self.params.motor.model(),
            v_nominal: self.params.supply.v_phase_peak() as f32,
            speed: self.monitor.is_some(),
            file: self.opts.unbalance_baseline,
            learned,
            s0,
        };
        let judged: Vec<Judged> = segs
            .iter()
            .enumerate()
            .map(|(k, seg)| judge.judge(k, seg))
            .collect();
        let pick = standing_out(&judged);
        // The sensors at the log's end (as the isolation's candidates are).
        let (gi, gv) = segs.last().map_or((None, None), sensor_phases);
        let file = self.opts.unbalance_baseline;
        let mut report = UnbalanceReport {
            negative_sequence_ratio: whole_ratio,
            suspect_phase: None,
            phase_confidence: 0.0,
            phase_not_judged: None,
            angle_deg: 0.0,
            winding_ratio: 0.0,
            supply_ratio: 0.0,
            voltage_negative_sequence_ratio: measured_voltage_ratio(windows),
            correction_deg: 0.0,
            correction_uncertainty_deg: 0.0,
            operating_point: None,
            slip: None,
            least_change: 0.0,
            spread: 0.0,
            baseline_runs: file.map_or(0, |f| f.runs),
            baseline_spread: file.and_then(|f| f.measured_spread()),
            judged_segment: None,
            segments: Vec::new(),
            current_sensor_phase: gi.as_ref().map(SensorPhaseReport::from),
            voltage_sensor_phase: gv.as_ref().map(SensorPhaseReport::from),
            measured,
            baseline: file.map(|_| BaselineSource::File),
        };
        match pick {
            None => report.phase_not_judged = Some(no_stretch_reason(self.params.supply.f_hz)),
            Some(j) => fill_judgement(&mut report, j, &segs),
        }
        report.segments = listed_segments(segs, pick.map(|j| j.index));
        report
    }
}

/// The commissioning window's reference: its steady windows' (`s0`: the default spread),
/// where there are enough of them.
fn learned_reference(windows: &[SequenceWindow], s0: f32) -> Option<Reference> {
    let learned: Vec<&SequenceWindow> = windows.iter().filter(|w| w.steady && w.learning).collect();
    (learned.len() >= MIN_SEGMENT_WINDOWS).then(|| {
        let s = segment_of(&learned);
        Reference {
            r: s.r,
            v2: s.v2,
            i1: s.i1_peak_a,
            sigma: s0,
            source: Some(BaselineSource::Commissioning),
        }
    })
}

/// The segment whose change stands out most from its spread among those that name a
/// phase, else the one that stands out most (a short segment's own scatter counts).
fn standing_out(judged: &[Judged]) -> Option<&Judged> {
    let z = |j: &Judged| abs(j.change) / j.sigma.max(1e-6);
    let largest = |it: &mut dyn Iterator<Item = &Judged>| {
        it.max_by(|a, b| z(a).total_cmp(&z(b))).map(|j| j.index)
    };
    largest(&mut judged.iter().filter(|j| j.judgement.phase.is_some()))
        .or_else(|| largest(&mut judged.iter()))
        .and_then(|k| judged.get(k))
}

/// Why the phase is not judged when no segment is steady long enough (`f_hz`: the supply
/// frequency).
fn no_stretch_reason(f_hz: f64) -> String {
    format!(
        "cannot judge the phase: no steady stretch of at least {} least-squares windows ({:.2} s): the log is too short or its operating point never settled",
        MIN_SEGMENT_WINDOWS,
        MIN_SEGMENT_WINDOWS as f64 * super::sequences::WINDOW_PERIODS / f_hz
    )
}

/// The judged segment's keys of the report.
fn fill_judgement(report: &mut UnbalanceReport, j: &Judged, segs: &[SequenceSegment]) {
    report.suspect_phase = j.judgement.phase;
    report.phase_confidence = j.judgement.confidence;
    report.angle_deg = j.change.1.atan2(j.change.0).to_degrees();
    report.winding_ratio = abs(j.change);
    report.supply_ratio = j.supply_ratio;
    report.correction_deg = j.reference.0.to_degrees();
    report.correction_uncertainty_deg = j.reference.1.to_degrees();
    report.operating_point = Some(j.reference.3);
    report.slip = j.reference.2;
    report.least_change = j.least_change;
    report.spread = j.sigma;
    report.baseline = j.source;
    report.phase_not_judged = segs.get(j.index).and_then(|s| not_judged_reason(j, s));
    report.judged_segment = Some(j.index.min(MAX_SEGMENTS - 1));
}

/// One phase's current sensor and voltage sensor with a gain error in a segment (the zero
/// sequence, `monitor_core::sequence::single_phase_gain`).
fn sensor_phases(seg: &SequenceSegment) -> (Option<SinglePhaseGain>, Option<SinglePhaseGain>) {
    let [p, n, z] = seg.pnz;
    (
        sensor_phase(p, n, z),
        seg.v_pnz.and_then(|[p, n, z]| sensor_phase(p, n, z)),
    )
}

/// The segments the report lists: the first [`MAX_SEGMENTS`], the judged one last among
/// them when it lies beyond (then at index `MAX_SEGMENTS - 1`).
fn listed_segments(mut segs: Vec<SequenceSegment>, judged: Option<usize>) -> Vec<SequenceSegment> {
    if segs.len() > MAX_SEGMENTS {
        let keep = judged
            .filter(|&k| k >= MAX_SEGMENTS - 1)
            .map(|k| segs[k].clone());
        segs.truncate(MAX_SEGMENTS);
        if let Some(k) = keep {
            segs[MAX_SEGMENTS - 1] = k;
        }
    }
    segs
}

/// |V2|/|V1| of the log's steady windows (null without voltages).
fn measured_voltage_ratio(windows: &[SequenceWindow]) -> Option<f32> {
    let vs: Vec<_> = windows
        .iter()
        .filter(|w| w.steady)
        .map(|w| w.v)
        .collect::<Option<Vec<_>>>()?;
    if vs.is_empty() {
        return None;
    }
    let p = mean(vs.iter().map(|v| v.positive()));
    let n = mean(vs.iter().map(|v| v.negative()));
    (abs(p) > 0.0).then(|| abs(n) / abs(p))
}

/// A change of `I2/I1` below this is no asymmetry to speak of (the noise of 12-bit sensors):
/// no reason is given for naming no phase.
pub const BALANCED_RATIO: f32 = 0.005;

/// Why the judged segment names no phase, in a sentence; `None` when it names one, or when
/// the change is below [`BALANCED_RATIO`] (nothing to judge).
fn not_judged_reason(j: &Judged, seg: &SequenceSegment) -> Option<String> {
    let why = j.judgement.not_named?;
    if why == PhaseNotNamed::BelowLeastChange && abs(j.change) < BALANCED_RATIO {
        return None;
    }
    let at = format!("{:.1}..{:.1} s", seg.from_s, seg.to_s);
    let change = 100.0 * abs(j.change);
    Some(match (why, j.source) {
        (PhaseNotNamed::BelowLeastChange, None) => format!(
            "cannot judge the phase: the negative sequence ({change:.1} % of I1 at {at}) is within what a healthy machine's own asymmetry may reach ({:.0} %) and there is no healthy baseline (give --baseline with healthy logs of this motor, or commission)",
            100.0 * j.least_change
        ),
        (PhaseNotNamed::BelowLeastChange, Some(_)) => format!(
            "no phase: the change of the negative sequence ({change:.1} % of I1 at {at}) is within what healthy runs differ by (least change {:.1} %)",
            100.0 * j.least_change
        ),
        (PhaseNotNamed::NearBorder, _) => {
            let dev = j.judgement.deviation_rad.to_degrees();
            let u = j.judgement.uncertainty_rad.to_degrees();
            let next = neighbour(j);
            format!(
                "cannot judge the phase: the change ({change:.1} % of I1 at {at}) points {:.0} deg from phase {}'s centre, towards phase {}, and its angle is uncertain by {u:.0} deg (reference angle +/-{:.0} deg, {})",
                dev,
                j.judgement.nearest.name(),
                next.name(),
                j.reference.1.to_degrees(),
                j.reference.3.describe()
            )
        }
    })
}

/// The phase on the other side of the nearest sector border.
fn neighbour(j: &Judged) -> Phase {
    let third = std::f32::consts::TAU / 3.0;
    let ang = j.change.1.atan2(j.change.0) - j.reference.0;
    let x = monitor_core::frames::wrap_angle(ang) / third;
    let k = x.round();
    let other = if x > k { k + 1.0 } else { k - 1.0 };
    Phase::from_turns(other as i32)
}
