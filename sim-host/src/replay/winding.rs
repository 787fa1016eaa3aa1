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

mod judgement;

use super::sequences::SequenceWindow;
use super::UnbalanceBaseline;
use monitor_core::sequence::INHERENT_ASYMMETRY_RATIO;
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
