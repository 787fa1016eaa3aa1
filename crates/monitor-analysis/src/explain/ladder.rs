//! `explain --ladder`: forward selection over the effect library, from the configured model
//! to the noise floor.
//!
//! Each step fits every effect of the library not yet in the model (the dynamics effects
//! are candidates like the others; one that needs another first, such as
//! `cross_coupling_dynamics` after `d_axis_dynamics`, is tried together with it), each
//! starting from the previous step's fit (nested fits: the step's solver starts where the
//! model stood, so a candidate can only lower the training error). The plausible candidate
//! with the lowest held-back error (each parameter costing [`PARAM_PENALTY`] of it) is kept
//! when the step passes its test ([`STEP_MIN`]) and lowers the whole-log error; the ladder
//! stops when the error is within the noise-floor band ([`FLOOR_BAND`], on the whole log and
//! on the held-back part) or when no plausible candidate passes, and says which.
//!
//! # The held-back split
//! The log is cut into strata by its events ([`strata`]: the start, supply or speed
//! transients, load moves, steady stretches), and every stratum into an even number of
//! alternating windows ([`stratified_heldback`]), so that each kind of event the log holds
//! falls in both the fitted and the held-back part. A fixed interleave of the whole log
//! can put a log's only load step in the fitted part and leave the held-back windows blind
//! to the effect that explains it.
//!
//! # The test a step passes
//! A step is kept when the candidate removes at least [`STEP_MIN`] (20 %) of the held-back
//! error beyond the noise floor that the model had before the step
//! ([`super::explained_fraction`], each parameter costing [`PARAM_PENALTY`] of the
//! held-back error), and lowers the whole-log error. The held-back error is an
//! out-of-sample estimate: a candidate that only fits noise does not lower it, and one that
//! absorbs another effect lowers it less than the effect itself. An information criterion
//! (AIC, BIC) would count each of the log's 10⁴-10⁶ samples as an independent observation,
//! while a model's error is structural and correlated over whole events: every candidate
//! would pass. The threshold is the largest share a candidate without effect removed on the
//! effect-free control logs of the test matrix (a textbook machine written inside the test,
//! three sizes, starts and steps: under 10 %), doubled (docs/model-vs-measurement.md).

use super::{explained_fraction, NOISE_MARGIN, PARAM_PENALTY};
use crate::effects::{self, EffectModel};
use crate::fit::{self, ActiveEffect, FitResult};
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::simplified_model::{BaseParameter, BaseParams, MachineConstants};
use crate::DataInfo;
use crate::{align, base_out_of_range, resolve, transients, Analysis, AnalysisError, Options};
use monitor_core::EffectKind;
use serde::Serialize;
use std::collections::BTreeMap;

/// A step must remove at least this share (20 %) of the held-back error beyond the noise
/// floor that the model had before it (module doc, "The test a step passes").
pub const STEP_MIN: f64 = 0.1;
/// The noise-floor band: an error within this factor of its noise floor, on the whole log
/// and on the held-back part, has nothing left to explain (the same margin as
/// [`NOISE_MARGIN`]: a model error beyond the noise of half the noise floor).
pub const FLOOR_BAND: f64 = NOISE_MARGIN;
/// Longest held-back or fitted window of a stratum [s] before it is cut further: a steady
/// stretch is interleaved at least this finely.
pub const WINDOW_MAX_S: f64 = 0.5;
/// Longest window of an event's stratum (a start, a transient, a load move) [s]: an event
/// is interleaved finely, so that its fastest part (a start's acceleration) is in both
/// parts.
pub const EVENT_WINDOW_MAX_S: f64 = 0.08;
/// Largest number of samples a ladder's fit simulates (a longer log is fitted on a coarser
/// copy and measured on the working series). A third of explain's
/// ([`crate::MAX_FIT_SAMPLES`]): a round fits every candidate, a ladder has several rounds,
/// and a few parameters are fitted as well from 20 000 samples (a 10 s log at 2 kHz still
/// resolves the stator transient time constant, 3 samples or more of it: the dynamics
/// effects are refused on a series that does not, [`transients::not_proposed`]).
pub const LADDER_FIT_SAMPLES: usize = 20_000;
/// Supply periods in the shortest window of a stratum (an event's stratum is cut into two
/// windows at least, each this long where the event allows).
pub const WINDOW_MIN_PERIODS: f64 = 2.0;

/// One fitted value of a ladder step, with its physical range.
#[derive(Debug, Clone, Serialize)]
pub struct RangedValue {
    /// The value.
    pub value: f64,
    /// Its unit.
    pub unit: String,
    /// The smallest physically plausible value on this log.
    pub low: f64,
    /// The largest physically plausible value on this log.
    pub high: f64,
}

/// One step of the ladder (JSON `ladder[]`).
#[derive(Debug, Clone, Serialize)]
pub struct LadderStep {
    /// The effect added (for a pair, the one that needed the other).
    pub effect: EffectKind,
    /// Every effect the step added: `effect`, and before it one it needs first
    /// ([`EffectModel::requires`]) when the model lacked it.
    pub added: Vec<EffectKind>,
    /// The added effects' fitted values with their physical ranges, by parameter name
    /// (prefixed `effect.` when the step added two).
    pub fitted: BTreeMap<String, RangedValue>,
    /// The effects' values in words.
    pub summary: String,
    /// `normalized_rms_error` over the whole log after the step.
    pub error: f64,
    /// `normalized_rms_error` on the held-back windows after the step.
    pub heldback_error: f64,
    /// The whole log's noise floor for the model after the step.
    pub noise_floor: f64,
    /// The held-back windows' noise floor.
    pub heldback_noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
    /// `heldback_error / heldback_noise_floor`.
    pub heldback_ratio_to_floor: f64,
    /// The step's test statistic: the share of the held-back error beyond the noise floor
    /// removed by the step, each parameter costing [`PARAM_PENALTY`] ([`STEP_MIN`]).
    pub significance: f64,
    /// Share of the whole-log error beyond the noise floor the step removed.
    pub explained: f64,
    /// Share of the held-back error beyond the noise floor the step removed.
    pub heldback_explained: f64,
}

/// Where the model stood before the first step (JSON `start`).
#[derive(Debug, Clone, Serialize)]
pub struct LadderStart {
    /// The configured effects.
    pub effects: Vec<EffectKind>,
    /// `normalized_rms_error` over the whole log.
    pub error: f64,
    /// On the held-back windows.
    pub heldback_error: f64,
    /// The whole log's noise floor.
    pub noise_floor: f64,
    /// The held-back windows' noise floor.
    pub heldback_noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
}

/// A candidate of the last round that was not kept, and why (JSON `last_round`).
#[derive(Debug, Clone, Serialize)]
pub struct Tried {
    /// The effect (with what it needed first, as in [`LadderStep::added`]).
    pub added: Vec<EffectKind>,
    /// Its held-back error.
    pub heldback_error: f64,
    /// Its test statistic ([`LadderStep::significance`]).
    pub significance: f64,
    /// Why it was not kept.
    pub because: String,
}

/// Why the ladder stopped (JSON `stop`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The error is within the noise-floor band on the whole log and the held-back part.
    NoiseFloor,
    /// No plausible candidate passed the step's test.
    NothingHelps,
    /// Every effect of the library is in the model.
    LibraryExhausted,
    /// The model cannot run on the log (no voltages).
    NoModel,
    /// The data-quality stage does not trust the log: nothing is claimed from it.
    Untrusted,
}

/// The ladder's report (JSON of `explain --ladder`).
#[derive(Debug, Clone, Serialize)]
pub struct LadderReport {
    /// The model before the first step.
    pub start: LadderStart,
    /// The steps in order.
    pub ladder: Vec<LadderStep>,
    /// Why it stopped ([`Stop`]).
    pub stop: Stop,
    /// The same in words, naming the numbers that decided.
    pub stopped_because: String,
    /// The effects in the model at the end.
    pub final_effects: Vec<EffectKind>,
    /// The last round's candidates that were not kept, best first.
    pub last_round: Vec<Tried>,
    /// Effects never fitted on this log, each as `name: why`.
    pub skipped: Vec<String>,
    /// The held-back split: the strata of the log and how much of it is held back.
    pub split: SplitInfo,
    /// The rule each step passed (in words, for the report).
    pub test: String,
    /// Facts about the data.
    pub data: DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: monitor_io::log::quality::DataQuality,
}

/// The held-back split of the ladder (JSON `split`).
#[derive(Debug, Clone, Serialize)]
pub struct SplitInfo {
    /// The strata, each `{kind, t_start_s, t_end_s, windows}`.
    pub strata: Vec<Stratum>,
    /// Share of the log's samples held back.
    pub heldback_share: f64,
}

/// One stratum of the log.
#[derive(Debug, Clone, Serialize)]
pub struct Stratum {
    /// `start`, `transient` (a supply or speed step), `load_move` or `steady`.
    pub kind: &'static str,
    /// Its start [s].
    pub t_start_s: f64,
    /// Its end [s].
    pub t_end_s: f64,
    /// Its windows, half of them held back.
    pub windows: usize,
}

/// The model of a ladder step: its effects, their set-ups on the fit series, and the fit.
struct Rung<'a> {
    kinds: Vec<EffectKind>,
    models: Vec<&'a dyn EffectModel>,
    fit: FitResult,
    /// Whole-log and held-back error and floors on the working series.
    error: f64,
    heldback_error: f64,
    noise: f64,
    heldback_noise: f64,
    /// The held-back error on the fit series (what candidates are ranked on).
    heldback_fit_series: f64,
    heldback_noise_fit_series: f64,
}

/// A candidate fitted in one round.
struct Fitted<'a> {
    models: Vec<&'a dyn EffectModel>,
    fit: FitResult,
    n_parameters: usize,
    heldback_fit_series: f64,
    implausible: Vec<String>,
}

impl Fitted<'_> {
    fn score(&self) -> f64 {
        self.heldback_fit_series * (1.0 + PARAM_PENALTY * self.n_parameters as f64)
    }
    fn added(&self, before: usize) -> Vec<EffectKind> {
        self.models.iter().skip(before).map(|m| m.kind()).collect()
    }
}

/// The kinds of stretch [`strata`] tells apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Start,
    Transient,
    LoadMove,
    Steady,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Start => "start",
            Kind::Transient => "transient",
            Kind::LoadMove => "load_move",
            Kind::Steady => "steady",
        }
    }
}

/// A load move: the active current's 50 ms mean moves by more than this share of its
/// median magnitude within [`LOAD_LOOK_S`].
const LOAD_MOVE_MIN: f64 = 0.1;
/// How far back a load move is looked for [s] (and how long after it a stretch stays one).
const LOAD_LOOK_S: f64 = 0.3;

/// The samples of a log whose active current `iq` (sampled every `dt` s) is in a load move:
/// its 50 ms mean differs by more than [`LOAD_MOVE_MIN`] of its median magnitude over the log (at least 2 % of its peak) from the
/// mean [`LOAD_LOOK_S`] before (the look-back span is part of the move).
fn load_moves(iq: &[f64], dt: f64) -> Vec<bool> {
    let len = iq.len();
    let dt = dt.max(1e-9);
    let w = ((0.05 / dt).round() as usize).max(1);
    let look = ((LOAD_LOOK_S / dt).round() as usize).max(1);
    let mut cum = Vec::with_capacity(len + 1);
    cum.push(0.0);
    for &x in iq {
        let last = cum.last().copied().unwrap_or(0.0);
        cum.push(last + x);
    }
    let mean = |a: usize, b: usize| (cum[b] - cum[a]) / (b - a).max(1) as f64;
    // The scale: the median magnitude of the active current (a start's inrush, a few per
    // cent of a log, does not move it), at least 2 % of its peak (a log at no load).
    let mut mags: Vec<f64> = iq
        .iter()
        .map(|x| x.abs())
        .filter(|x| x.is_finite())
        .collect();
    mags.sort_by(f64::total_cmp);
    let median = mags.get(mags.len() / 2).copied().unwrap_or(0.0);
    let peak = mags.last().copied().unwrap_or(0.0);
    let range = median.max(0.02 * peak).max(1e-9);
    let mut moved = vec![false; len];
    for k in (w + look)..len {
        let now = mean(k + 1 - w, k + 1);
        let before = mean(k + 1 - w - look, k + 1 - look);
        if (now - before).abs() > LOAD_MOVE_MIN * range {
            for m in moved.iter_mut().take(k + 1).skip(k + 1 - look) {
                *m = true;
            }
        }
    }
    moved
}

/// Runs of equal kinds in `kinds`, as `(kind, first, end)` sample ranges.
fn runs(kinds: impl IntoIterator<Item = Kind>) -> Vec<(Kind, usize, usize)> {
    let mut out: Vec<(Kind, usize, usize)> = Vec::new();
    for (k, c) in kinds.into_iter().enumerate() {
        match out.last_mut() {
            Some((last, _, end)) if *last == c => *end = k + 1,
            _ => out.push((c, k, k + 1)),
        }
    }
    out
}

/// The log's strata: runs of samples of one kind (the start up to its settling, a supply or
/// speed transient, a load move, a steady stretch), as `(kind, first, end)` sample ranges.
fn strata(d: &Prepared, n: &MachineConstants) -> Vec<(Kind, usize, usize)> {
    let input = transients::input_transients(d, n);
    let start_until = transients::start_end_s(d).map(|te| te + transients::settling_s(n));
    let moved = load_moves(&d.iq, d.dt_s);
    runs((0..d.len()).map(|k| {
        if start_until.is_some_and(|u| d.t_s[k] <= u) {
            Kind::Start
        } else if input.get(k).copied().unwrap_or(false) {
            Kind::Transient
        } else if moved.get(k).copied().unwrap_or(false) {
            Kind::LoadMove
        } else {
            Kind::Steady
        }
    }))
}

/// The held-back mask of the working series `d`, stratified by its events (module doc):
/// each stratum of [`strata`] cut into alternating windows ([`alternate`]).
pub fn stratified_heldback(d: &Prepared, n: &MachineConstants) -> (Vec<bool>, Vec<Stratum>) {
    // The supply frequency: the frame's mean speed (50 Hz where it does not turn).
    let w_mean = d.omega_s.iter().map(|w| w.abs()).sum::<f64>() / d.len().max(1) as f64;
    let f_hz = if w_mean > 1.0 {
        w_mean / std::f64::consts::TAU
    } else {
        50.0
    };
    alternate(&strata(d, n), &d.t_s, d.dt_s, f_hz)
}

/// Each stratum of `strata` cut into an even number of alternating windows, each at most
/// [`WINDOW_MAX_S`] ([`EVENT_WINDOW_MAX_S`] in an event's stratum) and, where the stratum allows, at least [`WINDOW_MIN_PERIODS`] supply
/// periods (of `f_hz`) long; the strata alternate which half comes first, so that the
/// onsets of successive events fall in both parts. Returns the held-back mask and the
/// strata as reported.
fn alternate(
    strata: &[(Kind, usize, usize)],
    t_s: &[f64],
    dt: f64,
    f_hz: f64,
) -> (Vec<bool>, Vec<Stratum>) {
    let len = strata.last().map_or(0, |s| s.2);
    let mut held = vec![false; len];
    let mut info = Vec::new();
    let dt = dt.max(1e-9);
    let min_len = ((WINDOW_MIN_PERIODS / f_hz.max(1e-3) / dt).round() as usize).max(1);
    for (i, &(kind, a, b)) in strata.iter().enumerate() {
        let longest = if kind == Kind::Steady {
            WINDOW_MAX_S
        } else {
            EVENT_WINDOW_MAX_S
        };
        let max_len = ((longest / dt).round() as usize).max(min_len);
        let span = b - a;
        let mut windows = span.div_ceil(max_len).max(2);
        windows += windows % 2;
        if span / windows < min_len {
            windows = (span / min_len).max(1);
            if windows > 1 {
                windows -= windows % 2;
            }
        }
        for (j, h) in held[a..b].iter_mut().enumerate() {
            let win = j * windows / span.max(1);
            *h = (win + i) % 2 == 1;
        }
        info.push(Stratum {
            kind: kind.name(),
            t_start_s: t_s.get(a).copied().unwrap_or(0.0),
            t_end_s: t_s.get(b.saturating_sub(1)).copied().unwrap_or(0.0),
            windows,
        });
    }
    (held, info)
}

/// The held-back mask of `d`'s coarse copy `fd` (samples at the same times).
fn mask_on(fd: &Prepared, d: &Prepared, held: &[bool]) -> Vec<bool> {
    fd.t_s
        .iter()
        .map(|t| {
            let k = d
                .t_s
                .partition_point(|x| x < t)
                .min(d.len().saturating_sub(1));
            held.get(k).copied().unwrap_or(false)
        })
        .collect()
}

/// The weights of a fit on `d` that trains on the samples `held` does not hold back.
fn weights_for(d: &Prepared, held: &[bool], max_fit: usize) -> Weights {
    let mut w = Weights::new(d, 0, max_fit);
    w.train = held.iter().map(|h| !h).collect();
    w
}

impl Analysis {
    /// `explain --ladder`: forward selection over the effect library from the configured
    /// model (module doc). `progress` gets the step (1-based) and the fraction of its
    /// candidates fitted.
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub fn ladder(
        &self,
        opts: &Options,
        progress: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<LadderReport, AnalysisError> {
        let configured = resolve(&opts.effects);
        let lib = effects::library();
        let d = &self.data;
        let (held, strata) = stratified_heldback(d, &self.constants);
        let split = SplitInfo {
            heldback_share: held.iter().filter(|h| **h).count() as f64 / d.len().max(1) as f64,
            strata,
        };
        let test = format!(
            "a step is kept when it removes at least {:.0} % of the held-back error beyond the noise floor (each parameter costing {:.0} % of the held-back error) and lowers the whole-log error; the ladder stops within {FLOOR_BAND}x the noise floor on the whole log and the held-back part",
            100.0 * STEP_MIN,
            100.0 * PARAM_PENALTY
        );
        let refused = if !d.channels.voltages {
            Some((Stop::NoModel, "the log has no voltages: the model cannot run, so no effect can be added (the unbalance analysis needs only the currents: explain without the ladder gives it)".to_string()))
        } else if !self.quality.trusted {
            Some((
                Stop::Untrusted,
                format!(
                    "could not judge: the data-quality stage does not trust the log ({})",
                    self.quality.not_trusted_because.join("; ")
                ),
            ))
        } else {
            None
        };
        if let Some((stop, stopped_because)) = refused {
            return Ok(LadderReport {
                start: LadderStart {
                    effects: opts.effects.clone(),
                    error: f64::NAN,
                    heldback_error: f64::NAN,
                    noise_floor: f64::NAN,
                    heldback_noise_floor: f64::NAN,
                    ratio_to_floor: f64::NAN,
                },
                ladder: Vec::new(),
                stop,
                stopped_because,
                final_effects: opts.effects.clone(),
                last_round: Vec::new(),
                skipped: Vec::new(),
                split,
                test,
                data: self.info(),
                data_quality: self.quality.clone(),
            });
        }
        // The fits run on a coarser copy than explain's ([`LADDER_FIT_SAMPLES`]): a round
        // fits every candidate, and a ladder has several rounds.
        let m = self.data.len().div_ceil(LADDER_FIT_SAMPLES).max(1);
        let fd = crate::coarsen(&self.data, m);
        let held_fd = if m == 1 {
            held.clone()
        } else {
            mask_on(&fd, d, &held)
        };
        let wf = weights_for(&fd, &held_fd, LADDER_FIT_SAMPLES);
        let span = transients::Span::of(&fd, &self.constants);
        // The configured model, fitted from nominal.
        let models: Vec<&dyn EffectModel> = configured.iter().map(|e| e.as_ref()).collect();
        let active = self.setup_all(&fd, &configured)?;
        let nominal = BaseParams::nominal(&self.constants);
        let f0 = self.fit_set(&fd, &active, &wf, &nominal, opts.fit_base)?;
        let mut rung = self.measure_rung(models, f0, &fd, m, &held, &held_fd)?;
        let start = LadderStart {
            effects: opts.effects.clone(),
            error: rung.error,
            heldback_error: rung.heldback_error,
            noise_floor: rung.noise,
            heldback_noise_floor: rung.heldback_noise,
            ratio_to_floor: rung.error / rung.noise,
        };
        let mut steps = Vec::new();
        let mut last_round = Vec::new();
        let mut skipped = Vec::new();
        let mut step_no = 0;
        let stop = loop {
            if let Some(why) = at_floor(&rung) {
                break (Stop::NoiseFloor, why);
            }
            step_no += 1;
            let (cands, skip) = self.ladder_candidates(&lib, &rung, &fd, span);
            skipped = skip;
            if cands.is_empty() {
                break (
                    Stop::LibraryExhausted,
                    "no effect of the library is left to add on this log".to_string(),
                );
            }
            let fitted = self.fit_round(&cands, &rung, &fd, &wf, &held_fd, m, opts, &|f| {
                progress(step_no, 0.7 * f)
            })?;
            let pairs = pairs_of(&fitted, rung.models.len());
            let (mut kept, mut tried) = self.choose(fitted, &rung, &fd, m, &held, &held_fd)?;
            if kept.is_none() && !pairs.is_empty() {
                // No single effect passes: two that need each other (a load torque and the
                // cross coupling of a start, two hidden effects at once) are tried together.
                let fitted = self.fit_round(&pairs, &rung, &fd, &wf, &held_fd, m, opts, &|f| {
                    progress(step_no, 0.7 + 0.3 * f)
                })?;
                let (k2, t2) = self.choose(fitted, &rung, &fd, m, &held, &held_fd)?;
                kept = k2;
                tried.extend(t2);
            }
            last_round = tried;
            let Some((next, step)) = kept else {
                break (Stop::NothingHelps, nothing_helps(&rung, &last_round));
            };
            steps.push(step);
            rung = next;
        };
        Ok(LadderReport {
            start,
            ladder: steps,
            stop: stop.0,
            stopped_because: stop.1,
            final_effects: rung.kinds.clone(),
            last_round,
            skipped,
            split,
            test,
            data: self.info(),
            data_quality: self.quality.clone(),
        })
    }

    /// The model `models` fitted as `fit` on the fit series, measured on the working
    /// series: whole log, held-back part, and their noise floors.
    fn measure_rung<'a>(
        &self,
        models: Vec<&'a dyn EffectModel>,
        fit: FitResult,
        fd: &Prepared,
        m: usize,
        held: &[bool],
        held_fd: &[bool],
    ) -> Result<Rung<'a>, AnalysisError> {
        let d = &self.data;
        let active: Vec<ActiveEffect<'a>> = models
            .iter()
            .map(|e| {
                e.setup(d, &self.constants)
                    .map(|setup| ActiveEffect { effect: *e, setup })
                    .map_err(|source| AnalysisError::Effect {
                        effect: e.kind(),
                        source,
                    })
            })
            .collect::<Result<_, _>>()?;
        let f_full = align(&active, fit.clone());
        let (pred, renoised) = self.predict_and_renoised(d, &active, &f_full)?;
        let w = weights_for(d, held, usize::MAX);
        let noise = metrics::noise_floor(d, &w, Some((&pred, &renoised)));
        let heldback_noise = metrics::noise_floor_on(d, held, Some((&pred, &renoised)));
        let error = metrics::errors(d, &pred, None).normalized_rms_error;
        let heldback_error = metrics::errors(d, &pred, Some(held)).normalized_rms_error;
        let (hb_fd, hn_fd) = if m == 1 {
            (heldback_error, heldback_noise)
        } else {
            let fa = self.setup_list(fd, &models)?;
            let fit_a = align(&fa, fit.clone());
            let (p, r) = self.predict_and_renoised(fd, &fa, &fit_a)?;
            (
                metrics::errors(fd, &p, Some(held_fd)).normalized_rms_error,
                metrics::noise_floor_on(fd, held_fd, Some((&p, &r))),
            )
        };
        Ok(Rung {
            kinds: models.iter().map(|e| e.kind()).collect(),
            models,
            fit,
            error,
            heldback_error,
            noise,
            heldback_noise,
            heldback_fit_series: hb_fd,
            heldback_noise_fit_series: hn_fd,
        })
    }

    /// `models` set up on `d`.
    fn setup_list<'a>(
        &self,
        d: &Prepared,
        models: &[&'a dyn EffectModel],
    ) -> Result<Vec<ActiveEffect<'a>>, AnalysisError> {
        models
            .iter()
            .map(|e| {
                e.needs()
                    .met_by(d)
                    .and_then(|()| e.setup(d, &self.constants))
                    .map(|setup| ActiveEffect { effect: *e, setup })
                    .map_err(|source| AnalysisError::Effect {
                        effect: e.kind(),
                        source,
                    })
            })
            .collect()
    }

    /// The round's candidates: each library effect not in the model, preceded by what it
    /// needs first and the model lacks; and the effects that cannot be fitted on this log,
    /// each as `name: why` (a missing channel, a set-up the data refuse, a time constant
    /// the fit series cannot resolve, no start or supply step for a dynamics effect).
    fn ladder_candidates<'a>(
        &self,
        lib: &'a [Box<dyn EffectModel>],
        rung: &Rung<'_>,
        fd: &Prepared,
        span: transients::Span,
    ) -> (Vec<Vec<&'a dyn EffectModel>>, Vec<String>) {
        let cannot = |e: &dyn EffectModel| -> Option<String> {
            // What an effect needs first is tried with it (below), not a reason to skip.
            let all: Vec<EffectKind> = lib.iter().map(|x| x.kind()).collect();
            // A dynamics effect competes on any log (its held-back error decides), unless
            // the fit series cannot resolve its time constant.
            let resolvable = transients::Span {
                input_transient: true,
                ..span
            };
            if let Some(t) = transients::not_proposed(e, resolvable, &self.constants, &all) {
                return Some(t.to_string());
            }
            e.needs()
                .met_by(&self.data)
                .and_then(|()| e.setup(fd, &self.constants).map(|_| ()))
                .err()
                .map(|s| s.to_string())
        };
        let mut out = Vec::new();
        let mut skipped = Vec::new();
        for e in lib.iter().map(|e| e.as_ref()) {
            if rung.kinds.contains(&e.kind()) {
                continue;
            }
            if let Some(why) = cannot(e) {
                skipped.push(format!("{}: {why}", e.kind()));
                continue;
            }
            let mut set: Vec<&dyn EffectModel> = Vec::new();
            let mut ok = true;
            for r in e.requires() {
                if rung.kinds.contains(r) {
                    continue;
                }
                match lib.iter().find(|x| x.kind() == *r) {
                    Some(x) if cannot(x.as_ref()).is_none() => set.push(x.as_ref()),
                    _ => ok = false,
                }
            }
            if !ok {
                skipped.push(format!(
                    "{}: needs {} first, which cannot be fitted on this log",
                    e.kind(),
                    transients::names(e.requires())
                ));
                continue;
            }
            set.push(e);
            out.push(set);
        }
        // The full-order machine at once: every dynamics effect the model lacks (those with
        // a time constant, and what needs one of them), when two or more can be fitted. A
        // start or a step can need all of them before any one fits with values a machine
        // has (one alone takes its time constant out of range to follow the others' part).
        let dynamics: Vec<&dyn EffectModel> = lib
            .iter()
            .map(|e| e.as_ref())
            .filter(|e| !rung.kinds.contains(&e.kind()) && cannot(*e).is_none())
            .filter(|e| {
                e.time_constant_s(&self.constants).is_some()
                    || e.requires()
                        .iter()
                        .any(|r| model_of_has_time_constant(lib, *r, &self.constants))
            })
            .collect();
        if dynamics.len() >= 2 {
            out.push(dynamics);
        }
        (out, skipped)
    }

    /// Every candidate of the round added to the model of `rung`, fitted from its fit on the
    /// fit series `fd` (in parallel), with its held-back error there and what makes it
    /// implausible.
    #[allow(clippy::too_many_arguments)]
    fn fit_round<'a>(
        &self,
        cands: &[Vec<&'a dyn EffectModel>],
        rung: &Rung<'a>,
        fd: &Prepared,
        wf: &Weights,
        held_fd: &[bool],
        m: usize,
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Vec<Fitted<'a>>, AnalysisError> {
        use rayon::prelude::*;
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = cands.len().max(1);
        let out: Vec<Option<Fitted<'a>>> = cands
            .par_iter()
            .map(|c| {
                let r = self.fit_candidate(c, rung, fd, wf, held_fd, m, opts);
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(k as f64 / total as f64);
                r
            })
            .collect::<Result<_, _>>()?;
        Ok(out.into_iter().flatten().collect())
    }

    /// One candidate `c` (effects to add, in order) fitted with the model of `rung`.
    #[allow(clippy::too_many_arguments)]
    fn fit_candidate<'a>(
        &self,
        c: &[&'a dyn EffectModel],
        rung: &Rung<'a>,
        fd: &Prepared,
        wf: &Weights,
        held_fd: &[bool],
        m: usize,
        opts: &Options,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let mut set: Vec<ActiveEffect<'a>> = Vec::new();
        for (e, p) in rung.models.iter().zip(&rung.fit.effect_params) {
            let Ok(mut s) = e.setup(fd, &self.constants) else {
                return Ok(None);
            };
            s.start_from(p);
            set.push(ActiveEffect {
                effect: *e,
                setup: s,
            });
        }
        let mut n_parameters = 0;
        for e in c {
            let Ok(s) = e.setup(fd, &self.constants) else {
                return Ok(None);
            };
            n_parameters += s.len();
            set.push(ActiveEffect {
                effect: *e,
                setup: s,
            });
        }
        // Nested: from where the model stood. A pair (or an effect with what it needs
        // first) can trade off against a base parameter (a load torque against B + Bl,
        // which absorbed it while the model had no load torque): it is also fitted from the
        // nominal base parameters, and the lower training cost wins, so the nested fit's
        // cost is never exceeded.
        let mut f = self.fit_set(fd, &set, wf, &rung.fit.base, opts.fit_base)?;
        if opts.fit_base && c.len() > 1 {
            let nominal = BaseParams::nominal(&self.constants);
            let g = self.fit_set(fd, &set, wf, &nominal, true)?;
            if g.report.cost < f.report.cost {
                f = g;
            }
        }
        let pred = fit::predict(fd, &self.constants, &set, &f)?;
        let hb = metrics::errors(fd, &pred, Some(held_fd)).normalized_rms_error;
        // Plausibility: the added effects' values, what the log says against them, and a
        // base parameter the fit takes out of range that the model's own fit had in range.
        let d = &self.data;
        let already: Vec<BaseParameter> = base_out_of_range(&self.constants, &rung.fit.base, d)
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        let mut why = Vec::new();
        let first_new = rung.models.len();
        for (i, a) in set.iter().enumerate().skip(first_new) {
            let p = f.effect_params.get(i).map_or(&[][..], Vec::as_slice);
            // The plausible ranges are those of the working series' set-up (a long log's
            // coarse copy may have fewer load segments: its own set-up then).
            let s_full = if m == 1 {
                None
            } else {
                a.effect.setup(d, &self.constants).ok()
            };
            let setup = s_full
                .as_ref()
                .filter(|s| s.len() == p.len())
                .unwrap_or(&a.setup);
            why.extend(
                setup
                    .implausible(p)
                    .into_iter()
                    .map(|w| format!("{}: {w}", a.effect.kind())),
            );
            // A value pinned at a bound of its fit is no minimum the log shows: the solver
            // pushed it as far as it was let (a fit of the model's numerical residue).
            for (q, v) in a.setup.params.iter().zip(p) {
                let pinned = |b: f64| b.is_finite() && b != 0.0 && (v - b).abs() <= 1e-3 * b.abs();
                if pinned(q.lo) || pinned(q.hi) {
                    why.push(format!(
                        "{}: {} = {} {} is at the bound of its fit ({}..{}), not a value the log shows",
                        a.effect.kind(),
                        q.name,
                        effects::sig(*v),
                        q.unit(),
                        effects::sig(q.lo),
                        effects::sig(q.hi)
                    ));
                }
            }
            why.extend(a.effect.contradicted_by(d, &self.constants, p)?);
        }
        why.extend(
            base_out_of_range(&self.constants, &f.base, d)
                .into_iter()
                .filter(|(k, _)| !already.contains(k))
                .map(|(_, w)| w),
        );
        Ok(Some(Fitted {
            models: set.iter().map(|a| a.effect).collect(),
            fit: f,
            n_parameters,
            heldback_fit_series: hb,
            implausible: why,
        }))
    }

    /// The round's choice: the plausible candidates by their penalised held-back error,
    /// the first that passes the step's test and lowers the whole-log error; the others
    /// tried with why they were not kept.
    fn choose<'a>(
        &self,
        mut fitted: Vec<Fitted<'a>>,
        rung: &Rung<'a>,
        fd: &Prepared,
        m: usize,
        held: &[bool],
        held_fd: &[bool],
    ) -> Result<(Option<(Rung<'a>, LadderStep)>, Vec<Tried>), AnalysisError> {
        fitted.sort_by(|a, b| {
            a.implausible
                .is_empty()
                .cmp(&b.implausible.is_empty())
                .reverse()
                .then(a.score().total_cmp(&b.score()))
        });
        let before = rung.models.len();
        self.evidence_decides(&mut fitted, before);
        let mut tried = Vec::new();
        let mut kept = None;
        for c in fitted {
            let sig = significance(rung, &c);
            let mut say = |because: String| {
                tried.push(Tried {
                    added: c.added(before),
                    heldback_error: c.heldback_fit_series,
                    significance: sig,
                    because,
                })
            };
            if kept.is_some() {
                say("a better candidate was kept".into());
                continue;
            }
            if !(c.heldback_fit_series.is_finite() && c.heldback_fit_series > 0.0) {
                say("the model with it could not be run through the log (it diverged)".into());
                continue;
            }
            if !c.implausible.is_empty() {
                say(format!("not physical: {}", c.implausible.join("; ")));
                continue;
            }
            if sig < STEP_MIN {
                say(format!(
                    "removes {:.0} % of the held-back error beyond the noise floor (the test asks {:.0} %)",
                    100.0 * sig,
                    100.0 * STEP_MIN
                ));
                continue;
            }
            let added = c.added(before);
            let next = self.measure_rung(c.models.clone(), c.fit.clone(), fd, m, held, held_fd)?;
            if !next.error.is_finite() || !next.heldback_error.is_finite() {
                say(
                    "the model with it could not be run through the whole log (it diverged)".into(),
                );
                continue;
            }
            if next.error >= rung.error {
                say(format!(
                    "the whole-log error would rise {} -> {} (held-back windows only improved)",
                    effects::sig(rung.error),
                    effects::sig(next.error)
                ));
                continue;
            }
            let step = self.step_of(&c, &added, rung, &next, sig)?;
            kept = Some((next, step));
        }
        Ok((kept, tried))
    }

    /// When the first two plausible single candidates of `fitted` (in the round's order)
    /// are effects that declare each other confusable and score within the declared factor,
    /// the log's evidence decides, as in `explain`'s ranking: a first one it contradicts goes
    /// second unless it contradicts the other too (a constant load torque and Coulomb
    /// friction are one equation at a speed that never reverses).
    fn evidence_decides<'a>(&self, fitted: &mut [Fitted<'a>], before: usize) {
        let (Some(a), Some(b)) = (fitted.first(), fitted.get(1)) else {
            return;
        };
        if !a.implausible.is_empty() || !b.implausible.is_empty() {
            return;
        }
        let single = |c: &Fitted<'a>| -> Option<&'a dyn EffectModel> {
            (c.models.len() == before + 1)
                .then(|| c.models.get(before).copied())
                .flatten()
        };
        let (Some(ea), Some(eb)) = (single(a), single(b)) else {
            return;
        };
        let Some(conf) = ea.confused_with().iter().find(|c| c.with == eb.kind()) else {
            return;
        };
        if b.score() > conf.within * a.score() {
            return;
        }
        let unbalance = self.unbalance();
        let says = |c: &Fitted<'a>, e: &dyn EffectModel| {
            let fitted = c.fit.effect_params.last().map(Vec::as_slice).unwrap_or(&[]);
            e.evidence(&effects::EffectEvidence {
                voltage_unbalance: unbalance.voltage_negative_sequence_ratio,
                winding_suspected: unbalance.suspect_phase.is_some(),
                torque_scale_nm: self.constants.torque_scale_nm,
                fitted,
            })
        };
        if says(a, ea) == Some(false) && says(b, eb) != Some(false) {
            fitted.swap(0, 1);
        }
    }

    /// The ladder step that took the model from `rung` to `next` by adding `c`.
    fn step_of(
        &self,
        c: &Fitted<'_>,
        added: &[EffectKind],
        rung: &Rung<'_>,
        next: &Rung<'_>,
        sig: f64,
    ) -> Result<LadderStep, AnalysisError> {
        let d = &self.data;
        let before = rung.models.len();
        let mut fitted = BTreeMap::new();
        let mut words = Vec::new();
        for (i, e) in c.models.iter().enumerate().skip(before) {
            let p = c.fit.effect_params.get(i).map_or(&[][..], Vec::as_slice);
            let Ok(setup) = e.setup(d, &self.constants) else {
                continue;
            };
            // A long log's coarse copy may have fewer load segments than the working series.
            if setup.len() != p.len() {
                continue;
            }
            for (q, v) in setup.params.iter().zip(p) {
                let key = if added.len() > 1 {
                    format!("{}.{}", e.kind(), q.name)
                } else {
                    q.name.clone()
                };
                fitted.insert(
                    key,
                    RangedValue {
                        value: *v,
                        unit: q.unit().to_string(),
                        low: q.plausible.lo,
                        high: q.plausible.hi,
                    },
                );
            }
            words.push(setup.describe(p, d, &self.constants)?);
        }
        Ok(LadderStep {
            effect: added.last().copied().unwrap_or(EffectKind::LoadTorque),
            added: added.to_vec(),
            fitted,
            summary: words.join("; "),
            error: next.error,
            heldback_error: next.heldback_error,
            noise_floor: next.noise,
            heldback_noise_floor: next.heldback_noise,
            ratio_to_floor: next.error / next.noise,
            heldback_ratio_to_floor: next.heldback_error / next.heldback_noise,
            significance: sig,
            explained: explained_fraction(rung.error, next.error, next.noise),
            heldback_explained: explained_fraction(
                rung.heldback_error,
                next.heldback_error,
                next.heldback_noise,
            ),
        })
    }
}

/// True when the library's effect `k` declares a time constant (a dynamics effect).
fn model_of_has_time_constant(
    lib: &[Box<dyn EffectModel>],
    k: EffectKind,
    n: &MachineConstants,
) -> bool {
    lib.iter()
        .any(|e| e.kind() == k && e.time_constant_s(n).is_some())
}

/// How many single candidates [`pairs_of`] pairs: those that lowered the training cost
/// most.
pub const PAIR_FROM: usize = 4;

/// The pairs a round tries when no single candidate passes: every two of the [`PAIR_FROM`]
/// single-effect candidates of `fitted` (plausible or not, not diverged) (fits of one round, the model's own `before` effects
/// first in each) that lowered the training cost most, each pair's effects in the order
/// fitted. A held-back error can rise with one effect of a pair and fall with both: with a
/// start's cross coupling but no load torque, the fit uses the coupling to follow the
/// acceleration a missing load explains.
fn pairs_of<'a>(fitted: &[Fitted<'a>], before: usize) -> Vec<Vec<&'a dyn EffectModel>> {
    // Implausible fits too: one effect alone may take its values out of range to carry its
    // partner's part.
    let mut by_cost: Vec<&Fitted<'a>> = fitted
        .iter()
        .filter(|c| {
            c.models.len() == before + 1
                && c.heldback_fit_series.is_finite()
                && c.heldback_fit_series > 0.0
        })
        .collect();
    by_cost.sort_by(|a, b| a.fit.report.cost.total_cmp(&b.fit.report.cost));
    let top: Vec<Vec<&'a dyn EffectModel>> = by_cost
        .iter()
        .take(PAIR_FROM)
        .map(|c| c.models.iter().skip(before).copied().collect())
        .collect();
    let mut out = Vec::new();
    for i in 0..top.len() {
        for j in (i + 1)..top.len() {
            let mut set = top[i].clone();
            for e in &top[j] {
                if !set.iter().any(|x| x.kind() == e.kind()) {
                    set.push(*e);
                }
            }
            out.push(set);
        }
    }
    out
}

/// The step's test statistic for candidate `c` on the model of `rung`: the share of the
/// held-back error beyond the noise floor it removes, its held-back error first raised by
/// [`PARAM_PENALTY`] per parameter.
fn significance(rung: &Rung<'_>, c: &Fitted<'_>) -> f64 {
    explained_fraction(
        rung.heldback_fit_series,
        c.score(),
        rung.heldback_noise_fit_series,
    )
}

/// Why the ladder stops at `rung` for the noise floor, if it does: both the whole-log and
/// the held-back error within [`FLOOR_BAND`] of their floors (the sentence names both).
fn at_floor(rung: &Rung<'_>) -> Option<String> {
    let r = rung.error / rung.noise;
    let rh = rung.heldback_error / rung.heldback_noise;
    (r <= FLOOR_BAND && rh <= FLOOR_BAND).then(|| {
        format!(
            "at the noise floor: the whole-log error {} is {r:.2}x its noise floor {} and the held-back error {} is {rh:.2}x its floor {} (both within {FLOOR_BAND}x): nothing is left to explain",
            effects::sig(rung.error),
            effects::sig(rung.noise),
            effects::sig(rung.heldback_error),
            effects::sig(rung.heldback_noise)
        )
    })
}

/// Why no candidate helps, naming the numbers that decided.
fn nothing_helps(rung: &Rung<'_>, tried: &[Tried]) -> String {
    let r = rung.error / rung.noise;
    let rh = rung.heldback_error / rung.heldback_noise;
    // The plausible candidate that came closest to passing (else the first tried).
    let closest = tried
        .iter()
        .filter(|t| !t.because.starts_with("not physical") && !t.because.contains("diverged"))
        .max_by(|a, b| a.significance.total_cmp(&b.significance));
    let best = closest
        .or(tried.first())
        .map(|t| {
            format!(
                "{} ({})",
                t.added
                    .iter()
                    .map(|k| k.name())
                    .collect::<Vec<_>>()
                    .join("+"),
                t.because
            )
        })
        .unwrap_or_else(|| "no candidate could be fitted".into());
    format!(
        "no plausible candidate passes the step's test: the whole-log error {} is {r:.2}x its noise floor and the held-back error {} is {rh:.2}x its floor; the best candidate was {best}. What is left is beyond the effect library (or below what the log can show)",
        effects::sig(rung.error),
        effects::sig(rung.heldback_error),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_falls_in_both_parts() {
        // 4 s at 10 kHz, load steps at 1.0 s and 3.0 s: two load moves, three steady
        // stretches; each stratum is held back in part and fitted in part.
        let dt = 1e-4;
        let t: Vec<f64> = (0..40_000).map(|k| k as f64 * dt).collect();
        let iq: Vec<f64> = t
            .iter()
            .map(|t| if (1.0..3.0).contains(t) { 8.0 } else { 4.0 })
            .collect();
        let moved = load_moves(&iq, dt);
        let strata = runs(
            moved
                .iter()
                .map(|&m| if m { Kind::LoadMove } else { Kind::Steady }),
        );
        let (held, info) = alternate(&strata, &t, dt, 50.0);
        let moves: Vec<&Stratum> = info.iter().filter(|s| s.kind == "load_move").collect();
        assert_eq!(moves.len(), 2, "{info:?}");
        // Each move covers its step.
        assert!(
            moves[0].t_start_s < 1.0 && moves[0].t_end_s > 1.0,
            "{:?}",
            moves[0]
        );
        assert!(
            moves[1].t_start_s < 3.0 && moves[1].t_end_s > 3.0,
            "{:?}",
            moves[1]
        );
        for &(_, a, b) in &strata {
            let h = held[a..b].iter().filter(|x| **x).count();
            assert!(h > 0 && h < b - a, "{a}..{b}: {h} held back");
        }
        let share = held.iter().filter(|x| **x).count() as f64 / held.len() as f64;
        assert!((0.35..0.65).contains(&share), "{share}");
    }

    #[test]
    fn a_steady_log_has_no_load_move() {
        let iq: Vec<f64> = (0..20_000).map(|k| 5.0 + 0.01 * ((k % 7) as f64)).collect();
        assert!(!load_moves(&iq, 1e-4).iter().any(|m| *m));
    }
}
