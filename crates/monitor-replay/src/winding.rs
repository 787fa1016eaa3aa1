//! The winding's negative-sequence judgement (JSON `unbalance`): which phase a shorted
//! turn sits in, with the probability that it does, or why that cannot be judged.
//!
//! 1. **Stretches** ([`segments`]). The least-squares windows ([`super::sequences`]) are
//!    grouped into steady stretches: consecutive steady windows whose `I2/I1` stays within
//!    [`SEGMENT_STEP_MIN`] (or [`SEGMENT_STEP_REL`] of its size) of the stretch's mean,
//!    whose `I0/I1` and `|I1|` do too (their tolerances grow with the size of `I2/I1`: a
//!    shorted loop's current moves all three), then neighbouring pieces whose means agree
//!    are joined: a fault current that wobbles is one stretch. A stretch counts from
//!    [`MIN_SEGMENT_WINDOWS`] windows on. A short switched on and off within a log (the
//!    real recordings of shorted turns do this) is a stretch of its own.
//! 2. **The reading** of each stretch, `w = I2/I1 - V2/(Z2 I1)`: the sensors' own
//!    negative sequence and, where voltages are logged, the supply's part taken out.
//! 3. **What it is judged against** ([`Against`]), in this order:
//!    - `--baseline` runs (`healthy_runs`) or the commissioning window (`commissioning`):
//!      their mean `R`, each run scattering by `sigma_run` (each component; the runs'
//!      own scatter pooled with the default [`DEFAULT_SPREAD_CURRENTS`] or
//!      [`DEFAULT_SPREAD_VOLTAGES`] counted as one run, [`HealthyReference::sigma`]), so
//!      that a stretch's change scatters by `sigma_run sqrt(1 + 1/n)`;
//!    - without one, **within the log**: the stretch that looks most healthy (the smallest
//!      `|w|`) is the reference of the others, each stretch scattering by
//!      [`WITHIN_LOG_SPREAD`], and a healthy machine's own asymmetry
//!      ([`NO_BASELINE_SPREAD`]) judges whether that reference itself is healthy;
//!    - a log of one stretch and no baseline is judged against **nothing**: `R = 0`, a
//!      healthy machine's own asymmetry as the spread.
//!
//!    Every spread adds the stretches' own standard errors, and, where the reference ran
//!    at another `|I1|`, the part of the reference's negative sequence that moves with the
//!    load: `|R| |1 - I1_R/I1|` (without voltages the supply's part of `I2` stays as `I1`
//!    moves; with voltages the reference's winding part and the model's error on the
//!    supply's part, [`monitor_core::sequence::SUPPLY_PART_UNCERTAINTY`]). A baseline at
//!    another operating point (`|I1|` beyond [`SEGMENT_I1_STEP`], or the speed beyond
//!    [`OPERATING_SPEED_STEP`]) is said so in `unbalance.least_change_widened`.
//! 4. **The probability** (`monitor_core::sequence::phase_posterior`): no short, or
//!    Tallam's shorted loop in phase a, b or c, whose angle is the reference angle
//!    `arg Z1` (step 5) within its uncertainty and the loop's own
//!    ([`monitor_core::sequence::LOOP_ANGLE_SD_DEG`]). Within the log the hypotheses also
//!    say which of the two stretches carries the short, or both (`probability`'s docs). The
//!    stretch whose change stands out most from its spread decides; its most probable
//!    phase is named when it is more probable than no short, with that probability as
//!    `phase_confidence`. A FAULT needs [`WINDING_FAULT_PROBABILITY`].
//! 5. **The reference angle** `arg Z1` (Tallam's loop: `I2/I1 = (mu/3)(Z1/Z_f) a^k`,
//!    `monitor_core::sequence`): measured as `arg(V1/I1)` where voltages are logged;
//!    else the model's at the slip from the speed; else at the slip where the model draws
//!    the measured `|I1|`, when that current is one the parameter file can draw between no
//!    load and [`FULL_LOAD_SLIP_MAX`]; else unknown between those two loads: the middle of
//!    the range, its half-width the uncertainty ([`OperatingPointSource`]).

mod anchor;
mod judgement;
pub mod level;
mod probability;
mod reading;
mod reasons;
mod segments;
mod stage;

pub use reasons::{PhaseNotJudged, Widened, BALANCED_RATIO};
pub use segments::segments;
pub(crate) use stage::{WindingClosing, WindingStage};

pub use super::baseline::HealthyReference;
use super::baseline::{abs, mean, of_pair, pair, pooled_change_sigma, UnbalanceBaseline};
use crate::windows::{SensorPhaseReport, SequenceWindow};
use monitor_core::sequence::{Complex32, INHERENT_ASYMMETRY_RATIO};
use monitor_core::Phase;
use serde::Serialize;

/// Fewest least-squares windows a steady stretch holds (0.5 s at 60 Hz).
pub const MIN_SEGMENT_WINDOWS: usize = 3;
/// A window whose `I2/I1` lies farther than this (fraction of `|I1|`) from its stretch's
/// mean, and farther than [`SEGMENT_STEP_REL`] of the mean's size, starts a new stretch:
/// three times the window-to-window scatter of a healthy motor's reading at 1 kHz.
pub const SEGMENT_STEP_MIN: f32 = 0.015;
/// The same for the voltages' `V2/V1` and `V0/V1` (a voltage sensor's 5 % gain step
/// moves them by 1.7 %).
pub const SEGMENT_VOLTAGE_STEP_MIN: f32 = 0.005;
/// See [`SEGMENT_STEP_MIN`]: a large negative sequence scatters in proportion. A shorted
/// loop's current wobbles: on the real recordings' 40 % shorts `I2/I1` moves between 31
/// and 36 % and its angle by 10 deg from window to window, and drifts as much over a
/// second; a quarter of its size keeps it one stretch while a short switched on or off
/// (a change of the whole size) still parts two.
pub const SEGMENT_STEP_REL: f32 = 0.25;
/// Unsteady windows in a row that a stretch may hold (left out of its means).
pub const MAX_UNSTEADY_INSIDE: usize = 2;
/// A window whose `|I1|` differs from its stretch's mean by more than this fraction (or
/// [`SEGMENT_STEP_REL`] of `|I2/I1|`, a shorted loop's share of `I1`) starts a new
/// stretch (the operating point moved).
pub const SEGMENT_I1_STEP: f32 = 0.05;
/// What two healthy runs of one motor differ by, currents only: the magnitude of the
/// change of `I2/I1` between the two healthy ITSC runs (2.0 %; `docs/isolation.md`), which
/// the supply's unbalance makes as it changes between runs and which the currents alone
/// cannot take out.
pub const HEALTHY_RUN_DIFFERENCE_CURRENTS: f32 = 0.021;
/// The same with voltages logged (the supply's part taken out): two healthy runs of a
/// 1.1 kW motor, measured on recordings not in this repository, differ by 1.3 %.
pub const HEALTHY_RUN_DIFFERENCE_VOLTAGES: f32 = 0.013;
/// `|Z1/Z2|` of the ITSC motor at no load (its parameter file): how much its negative-
/// sequence current magnifies the supply's `V2/V1`, where the spreads below were measured.
pub const MEASURED_Z_RATIO: f32 = 5.1;
/// The default spread `s0` of a healthy run's reading without voltages, each component:
/// half of [`HEALTHY_RUN_DIFFERENCE_CURRENTS`], so that the RMS size of the change between
/// two healthy runs, `2 s0`, is what two healthy runs of one motor were measured to
/// differ by (never less). A motor that magnifies the supply's unbalance more gets more
/// ([`SUPPLY_DRIFT_BETWEEN_RUNS`]).
pub const DEFAULT_SPREAD_CURRENTS: f32 = 0.5 * HEALTHY_RUN_DIFFERENCE_CURRENTS;
/// The same with voltages: half of [`HEALTHY_RUN_DIFFERENCE_VOLTAGES`].
pub const DEFAULT_SPREAD_VOLTAGES: f32 = 0.5 * HEALTHY_RUN_DIFFERENCE_VOLTAGES;
/// How much the supply's `V2/V1` drifts between runs (each component): the ITSC runs'
/// [`DEFAULT_SPREAD_CURRENTS`] through their motor's [`MEASURED_Z_RATIO`]. Without
/// voltages a healthy run's spread is at least this times the motor's `|Z1/Z2|`.
pub const SUPPLY_DRIFT_BETWEEN_RUNS: f32 = DEFAULT_SPREAD_CURRENTS / MEASURED_Z_RATIO;
/// Spread of a healthy stretch's reading about another stretch of the same log, each
/// component: 0.4 % of `|I1|`, what the healthy stretches of different runs of one
/// session of the ITSC recordings (minutes apart, run 001) scatter by (0.38 %); stretches
/// of one run (seconds apart) scatter by 0.15 %. Without voltages a motor that magnifies
/// the supply's drift more gets more, in proportion to `|Z1/Z2|`.
pub const WITHIN_LOG_SPREAD: f32 = 0.004;
/// A supply's `V2/V1`, each component: its size then stays below 1.7 % 95 % of the time
/// (public grids keep it below 2 % 95 % of the week, EN 50160; the ITSC recordings' supply
/// read 0.5-0.7 % through their motor's `|Z1/Z2|`). Without voltages and without any
/// healthy reference, a healthy machine reads this times its `|Z1/Z2|` on top of its own
/// asymmetry.
pub const SUPPLY_UNBALANCE_SPREAD: f32 = 0.007;
/// A healthy machine's own asymmetry as a spread ([`INHERENT_ASYMMETRY_RATIO`], 3 % each
/// component), judged against nothing; without voltages the supply's part
/// ([`SUPPLY_UNBALANCE_SPREAD`] times `|Z1/Z2|`) is added.
pub const NO_BASELINE_SPREAD: f32 = INHERENT_ASYMMETRY_RATIO;
/// Without a healthy reference but with voltages (the supply's part taken out): half of
/// it.
pub const NO_BASELINE_SPREAD_VOLTAGES: f32 = 0.5 * INHERENT_ASYMMETRY_RATIO;
/// The least probability of the named phase for a FAULT: the one verdict's
/// (`monitor_core::verdict::FAULT_CONFIDENCE`, a named finding at a calibrated confidence of
/// at least one half).
pub const WINDING_FAULT_PROBABILITY: f32 = monitor_core::verdict::FAULT_CONFIDENCE;
/// A baseline whose speed differs from the stretch's by more than this fraction of the
/// synchronous speed ran at another operating point (a tenth of a small motor's rated
/// slip; two runs at one load differ by less).
pub const OPERATING_SPEED_STEP: f32 = 0.003;
/// The largest slip taken for "full load" where the operating point is not known (rated
/// slips run from 1 % for large motors to 5 % for small ones).
pub const FULL_LOAD_SLIP_MAX: f32 = 0.05;
pub use crate::windows::CURRENT_MODEL_UNCERTAINTY;
/// Uncertainty of a reference angle measured as `arg(V1/I1)` [deg]: the sensors' phase
/// errors and the loop impedance's own angle.
pub const MEASURED_REFERENCE_UNCERTAINTY_DEG: f32 = 3.0;
/// How far the slip's model reading may be off for a reference from the measured speed
/// (the rotor resistance of a parameter file, 30 %).
pub const SLIP_MODEL_UNCERTAINTY: f32 = 0.3;
/// Most stretches the report lists (the judged one always among them).
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

/// What the winding's change was judged against (JSON `unbalance.judged_against`): the
/// verdict's own vocabulary (`monitor_core::verdict::Against`: `commissioning`,
/// `healthy_runs`, `within_the_log`, `nothing`).
pub use monitor_core::verdict::Against;

/// The probabilities of no short and of a short in each phase (JSON
/// `unbalance.phase_probabilities`; they sum to 1).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PhaseProbabilities {
    /// No short.
    pub no_short: f32,
    /// A short in phase a.
    pub a: f32,
    /// A short in phase b.
    pub b: f32,
    /// A short in phase c.
    pub c: f32,
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
    /// Mean `I2/I1` and its standard error (each component) over the windows.
    #[serde(skip)]
    r: Complex32,
    #[serde(skip)]
    sem: f32,
    /// Mean `V2/I1` and `V1/I1` [ohm] where every window has voltages.
    #[serde(skip)]
    v2: Option<Complex32>,
    #[serde(skip)]
    v1: Option<Complex32>,
    /// Mean phasors (one rotation) of the currents' and the voltages' positive, negative
    /// and zero sequences, for the sensor check.
    #[serde(skip)]
    pnz: [Complex32; 3],
    #[serde(skip)]
    v_pnz: Option<[Complex32; 3]>,
    #[serde(skip)]
    we: f32,
    #[serde(skip)]
    wr: Option<f32>,
    #[serde(skip)]
    learning: bool,
}

impl SequenceSegment {
    /// The voltages' operating point over the segment (`[from, to]` [s], `|V1|`, `|I1|`,
    /// `arg(V1/I1)`), where every window had voltages: what the rotor's load estimate reads
    /// without a speed (`crate::rotor::RotorLoad::from_power`).
    pub(crate) fn measured_point(&self) -> Option<([f64; 2], crate::windows::MeasuredPoint)> {
        let z = self.v1?;
        let i1 = f64::from(self.i1_peak_a);
        Some((
            [self.from_s, self.to_s],
            crate::windows::MeasuredPoint {
                v1_peak_v: f64::from(abs(z)) * i1,
                i1_peak_a: i1,
                angle_rad: f64::from(z.im.atan2(z.re)),
            },
        ))
    }
}

/// `a / b`, 0 for a zero or non-number `|b|`.
fn cdiv(a: Complex32, b: Complex32) -> Complex32 {
    let d = b.norm_sqr();
    if d.is_nan() || d <= 0.0 {
        return Complex32::new(0.0, 0.0);
    }
    a / b
}

/// `arg a` [deg].
fn arg_deg(a: Complex32) -> f32 {
    a.im.atan2(a.re).to_degrees()
}

/// One segment's means.
pub(super) fn segment_of(ws: &[&SequenceWindow]) -> SequenceSegment {
    let n = ws.len();
    let rs: Vec<Complex32> = ws
        .iter()
        .map(|w| cdiv(w.i.negative(), w.i.positive()))
        .collect();
    let r = mean(rs.iter().copied());
    let var = rs.iter().map(|x| abs(*x - r).powi(2)).sum::<f32>() / (2.0 * (n.max(2) - 1) as f32);
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
        angle_deg: arg_deg(r),
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

/// Result of the negative-sequence analysis (JSON key `unbalance`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct UnbalanceReport {
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// The winding's faulty phase (JSON "a", "b", "c"), or null.
    pub suspect_phase: Option<Phase>,
    /// The probability that the winding has a short in `suspect_phase` (that there is a
    /// short, and in that phase), 0..1; 0 without a phase. A phase is named when it is
    /// more probable than no short; a FAULT needs
    /// [`WINDING_FAULT_PROBABILITY`]. How it is computed and calibrated:
    /// `docs/isolation.md`, "The phase's probability".
    pub phase_confidence: f32,
    /// The probabilities of no short and of a short in each phase.
    pub phase_probabilities: PhaseProbabilities,
    /// Why no phase is named although the currents are unbalanced, or null (JSON
    /// `phase_not_judged_reason`, `{"kind": ..}` with its numbers; the door spells it as
    /// `phase_not_judged`).
    #[serde(rename = "phase_not_judged_reason")]
    pub phase_not_judged: Option<PhaseNotJudged>,
    /// arg(I2w/I1) [deg]: the winding's part (the supply's part taken out).
    pub angle_deg: f32,
    /// |I2w|/|I1|: the winding's part of the negative sequence.
    pub winding_ratio: f32,
    /// |V2/Z2|/|I1|: the part the supply's voltage unbalance drives (0 without voltages).
    pub supply_ratio: f32,
    /// |V2|/|V1| (null without voltage columns).
    pub voltage_negative_sequence_ratio: Option<f32>,
    /// The reference angle arg Z1 (the power-factor angle, shorted turns) used [deg].
    pub correction_deg: f32,
    /// Its uncertainty [deg] (it widens the phase's confidence).
    pub correction_uncertainty_deg: f32,
    /// Where the reference angle comes from (null when nothing was judged).
    pub operating_point: Option<OperatingPointSource>,
    /// The slip the reference angle was taken at, where one was used.
    pub slip: Option<f32>,
    /// The least change of the winding's negative sequence (fraction of |I1|) that names
    /// a phase at [`WINDING_FAULT_PROBABILITY`] (on its sector's centre, with the
    /// judged spread and reference angle); 0 when none does.
    pub least_change: f32,
    /// Where the reference ran at another operating point than the judged stretch: how it
    /// differed and how much the least change was widened for it; else null (JSON
    /// `least_change_widened_by`; the door spells it as `least_change_widened`).
    #[serde(rename = "least_change_widened_by")]
    pub least_change_widened: Option<reasons::Widened>,
    /// The spread the change is judged with (each component, fraction of |I1|): the
    /// healthy reference's, the judged stretch's own and, at another operating point,
    /// what the load moves.
    pub spread: f32,
    /// What the change was judged against (null when nothing was judged).
    pub judged_against: Option<Against>,
    /// How many healthy runs `--baseline` gave (0: none).
    pub baseline_runs: u32,
    /// Their RMS distance from their mean (`|I2/I1|` units), null for fewer than two.
    pub baseline_spread: Option<f32>,
    /// Index into `segments` of the one judged (the largest change), null without one.
    pub judged_segment: Option<usize>,
    /// Index into `segments` of the stretch it was judged against, when judged within
    /// the log; else null.
    pub reference_segment: Option<usize>,
    /// The log's steady stretches of negative sequence, in time order.
    pub segments: Vec<SequenceSegment>,
    /// The negative sequence over the log: `(t, |I2|/|I1|)` of each complete least-squares
    /// window ([`crate::windows::WINDOW_PERIODS`] supply periods; `t` its middle [s since
    /// the log's first row]), in time order, as measured (before the sensors' and the
    /// baseline's parts are taken out). What `diagnose --report` draws where the monitor's
    /// timeline has none (a log with the currents only). Not in the JSON (`segments` are).
    #[serde(skip)]
    pub ratio_over_time: Vec<(f64, f32)>,
    /// One phase's current sensor with a gain error, from the zero sequence of the three
    /// measured currents (zero for a star without neutral, whatever the machine does), or
    /// null; its part of the negative sequence is taken out before a winding is blamed.
    pub current_sensor_phase: Option<SensorPhaseReport>,
    /// The same for the voltage sensors (phase voltages against the star point), or null.
    pub voltage_sensor_phase: Option<SensorPhaseReport>,
    /// What was measured, before the baseline is taken out (sensor-corrected): `I2/I1` and
    /// `V2/I1` (re, im); a healthy log's are the `--baseline` of a later one.
    pub measured: UnbalanceBaseline,
    /// The healthy negative sequence the winding is judged against ([`BaselineSource`]),
    /// or null (none: the supply's part alone is taken out).
    pub baseline: Option<BaselineSource>,
    /// How many turns are shorted in the named phase, with its interval and where it comes
    /// from (`basis`: `physics`, or `calibration` where one was given); null without a
    /// named phase ([`level`]).
    pub shorted_turns: Option<level::ShortedTurns>,
    /// The model's estimate, also where a calibration gave `shorted_turns`; null without a
    /// named phase.
    pub shorted_turns_physics: Option<level::ShortedTurns>,
    /// Where no phase is named: how large a short this log could hide, in the fraction of a
    /// phase's turns whose loop draws the least change ([`level::TurnReach`]); null where
    /// a phase is named or nothing was judged.
    pub shorted_turns_reach: Option<level::TurnReach>,
}

impl UnbalanceReport {
    /// Whether the winding's finding carries a FAULT: a phase named at a probability of
    /// at least [`WINDING_FAULT_PROBABILITY`].
    pub fn names_a_short(&self) -> bool {
        self.suspect_phase.is_some() && self.phase_confidence >= WINDING_FAULT_PROBABILITY
    }
}

/// Where the healthy negative sequence the winding is judged against comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BaselineSource {
    /// Learned in the commissioning window, used while |I1| is within
    /// [`crate::baseline::BASELINE_I1_TOLERANCE`] of its value there.
    Commissioning,
    /// The healthy log given with `--baseline`.
    File,
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
            wr_rad_s: None,
        },
        |s| UnbalanceBaseline {
            i2_over_i1: pair(s.r),
            v2_over_i1: s.v2.map(pair),
            i1_peak_a: s.i1_peak_a,
            wr_rad_s: s.wr,
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
    let turned = |w: &SequenceWindow, x: Complex32| {
        let d = (w.offset_rad - line.0 - line.1 * 0.5 * (w.from_s + w.to_s)) as f32;
        let (sn, cs) = d.sin_cos();
        x * Complex32::new(cs, sn)
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
