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
//! A step is kept when the candidate removes at least [`STEP_MIN`] (10 %) of the held-back
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

mod base;
mod choice;
mod end;
mod passes;
mod round;
mod rounds;
mod split;
mod stepwise;
#[cfg(test)]
mod tests;

pub use base::{base_changes, base_in_words, BaseChange, BASE_CHANGE_MIN};
pub use end::FinalFit;
pub use split::stratified_heldback;

use super::{NOISE_MARGIN, PARAM_PENALTY};
use crate::effects::{self, EffectModel};
use crate::fit::machine::MachineScales;
use crate::simplified_model::BaseParams;
use crate::DataInfo;
use crate::{resolve, transients, Analysis, AnalysisError, Options};
use monitor_core::EffectKind;
use round::{LadderSeries, Rung};
use serde::Serialize;
use split::{mask_on, weights_for};
use std::collections::BTreeMap;

/// A step must remove at least this share (10 %) of the held-back error beyond the noise
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
/// Largest fit copy of a long log whose dynamics need more samples than
/// [`LADDER_FIT_SAMPLES`] ([`fit_thinning`]): three times as many (a 60 s log at 2 kHz at
/// 1 kHz), beyond which the copy is thinned to this size and the dynamics effects are
/// refused as unresolved.
pub const LADDER_MAX_FIT_SAMPLES: usize = 60_000;
/// Iterations of a round's screening fit of every candidate ([`round`]): enough to rank
/// them; the [`FINALISTS`] best are then fitted in full.
pub const SCREEN_ITER: usize = 6;
/// How many screened candidates of a round are fitted in full (plus the best by held-back
/// error alone when it is not among them).
pub const FINALISTS: usize = 3;
/// Pairs are tried only while the held-back error is above this multiple (2) of its noise
/// floor: two effects that need each other leave a large error alone (the windage
/// scenario's flux dynamics and load torque, 65x the floor without them); near the floor a
/// pair's test would weigh two effects' worth of parameters against a few per cent of noise,
/// and the round took 40 % of a ladder's time.
pub const PAIRS_ABOVE: f64 = 2.0;
/// How many single candidates the pair search pairs: those that lowered the training cost
/// most. With 3 the windage scenario's second step (flux dynamics with a load torque, the
/// fourth single of its round) is not found and the ladder stops at 65x its floor.
pub const PAIR_FROM: usize = 4;
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

/// One step of the ladder (JSON `ladder[]`): an effect added (`effect`), or the base rung
/// (`base`: the base parameters refitted against the user's file).
#[derive(Debug, Clone, Serialize)]
pub struct LadderStep {
    /// The effect added (for a pair, the one that needed the other); absent on a base rung.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effect: Option<EffectKind>,
    /// Every effect the step added: `effect`, and before it one it needs first
    /// ([`EffectModel::requires`]) when the model lacked it (empty on a base rung).
    pub added: Vec<EffectKind>,
    /// The base rung's six base parameters against the user's file, each with its change,
    /// its 95 % interval and whether the rung names it (absent on an effect's step).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub base: Vec<BaseChange>,
    /// Effects of earlier steps the step removed: the step's effect explains what they stood
    /// in for (stepwise selection both ways, [`stepwise`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<EffectKind>,
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
    /// True for the base rung (the base parameters refitted; `added` is then empty).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub base: bool,
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
    /// What was found, then why it stopped: the base changes and the effects with their
    /// sizes, the end against the noise floor, the stop.
    pub summary: String,
    /// The base parameters that differ from the user's file, from the chosen model refitted
    /// on the whole log ([`FinalFit::base`]; only the named changes).
    pub base_changes: Vec<BaseChange>,
    /// The chosen model refitted on the whole log: the final figures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_fit: Option<FinalFit>,
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
        let (held, strata) = stratified_heldback(&self.data, &self.constants);
        let mut report = self.report_before(opts, &held, strata);
        if let Some((stop, why)) = self.refused() {
            report.stop = stop;
            report.stopped_because = why.clone();
            report.summary = why;
            return Ok(report);
        }
        let sr = self.ladder_series(held, opts.fit_base);
        let configured = resolve(&opts.effects);
        let active = self.setup_all(&sr.fd, &configured)?;
        let nominal = BaseParams::nominal(&self.constants);
        let f0 = self.fit_set(&sr.fd, &active, &sr.wf, &nominal, opts.fit_base)?;
        let models: Vec<&dyn EffectModel> = configured.iter().map(|e| e.as_ref()).collect();
        let rung = self.measure_rung(models, f0, &sr, MachineScales::of_file(&self.params))?;
        let lib = effects::ladder_library();
        report.start = LadderStart {
            effects: opts.effects.clone(),
            error: rung.error,
            heldback_error: rung.heldback_error,
            noise_floor: rung.noise,
            heldback_noise_floor: rung.heldback_noise,
            ratio_to_floor: rung.error / rung.noise,
        };
        let rung = self.walk(&lib, rung, &sr, opts, progress, &mut report)?;
        let step_no = report.ladder.len() + 1;
        self.finish(&rung, &sr, &mut report, &|f| progress(step_no, f))?;
        Ok(report)
    }

    /// The ladder's report before its first step: the split (`held`, `strata`), the test,
    /// the data, no steps.
    fn report_before(&self, opts: &Options, held: &[bool], strata: Vec<Stratum>) -> LadderReport {
        LadderReport {
            summary: String::new(),
            base_changes: Vec::new(),
            final_fit: None,
            start: LadderStart {
                effects: opts.effects.clone(),
                error: f64::NAN,
                heldback_error: f64::NAN,
                noise_floor: f64::NAN,
                heldback_noise_floor: f64::NAN,
                ratio_to_floor: f64::NAN,
            },
            ladder: Vec::new(),
            stop: Stop::NoModel,
            stopped_because: String::new(),
            final_effects: opts.effects.clone(),
            last_round: Vec::new(),
            skipped: Vec::new(),
            split: SplitInfo {
                heldback_share: held.iter().filter(|h| **h).count() as f64
                    / self.data.len().max(1) as f64,
                strata,
            },
            test: format!(
                "a step is kept when it removes at least {:.0} % of the held-back error beyond the noise floor (each parameter costing {:.0} % of the held-back error) and lowers the whole-log error; the ladder stops within {FLOOR_BAND}x the noise floor on the whole log and the held-back part",
                100.0 * STEP_MIN,
                100.0 * PARAM_PENALTY
            ),
            data: self.info(),
            data_quality: self.quality.clone(),
        }
    }

    /// Why the ladder cannot start on this log, if it cannot: no voltages (the model cannot
    /// run), or a log the data-quality stage does not trust.
    fn refused(&self) -> Option<(Stop, String)> {
        if !self.data.channels.voltages {
            return Some((Stop::NoModel, "the log has no voltages: the model cannot run, so no effect can be added (the unbalance analysis needs only the currents: explain without the ladder gives it)".to_string()));
        }
        (!self.quality.trusted).then(|| {
            (
                Stop::Untrusted,
                format!(
                    "could not judge: the data-quality stage does not trust the log ({})",
                    self.quality.not_trusted_because.join("; ")
                ),
            )
        })
    }

    /// The series the ladder's fits run on: a copy of at most [`LADDER_FIT_SAMPLES`] samples
    /// (a round fits every candidate, and a ladder has several rounds), thinned no further
    /// than the machine's fastest dynamics allow ([`fit_thinning`]), with the held-back mask
    /// `held` of the working series carried over.
    fn ladder_series(&self, held: Vec<bool>, fit_base: bool) -> LadderSeries {
        let m = fit_thinning(
            self.data.len(),
            self.data.dt_s,
            fastest_dynamics_s(&self.constants),
        );
        let fd = crate::coarsen(&self.data, m);
        let held_fd = if m == 1 {
            held.clone()
        } else {
            mask_on(&fd, &self.data, &held)
        };
        LadderSeries {
            wf: weights_for(&fd, &held_fd, LADDER_FIT_SAMPLES),
            span: transients::Span::of(&fd, &self.constants),
            file: self.params,
            fit_base,
            fd,
            m,
            held,
            held_fd,
        }
    }

    /// The steps from `rung` until the floor band or nothing helps, into `report`: each
    /// round fits the candidates of `lib` and the base rung (then pairs, when no single one
    /// passes), keeps at most one, and drops the earlier effects it explains better. The
    /// rung the ladder ended on.
    fn walk<'a>(
        &self,
        lib: &'a [Box<dyn EffectModel>],
        mut rung: Rung<'a>,
        sr: &LadderSeries,
        opts: &Options,
        progress: &(dyn Fn(usize, f64) + Sync),
        report: &mut LadderReport,
    ) -> Result<Rung<'a>, AnalysisError> {
        let mut step_no = 0;
        // The analysis of the rung's model: the file recentred on its base parameters
        // (`None`: the file itself).
        let mut recentred: Option<Analysis> = None;
        let (stop, why) = loop {
            let cur: &Analysis = recentred.as_ref().unwrap_or(self);
            if let Some(why) = at_floor(&rung) {
                break (Stop::NoiseFloor, why);
            }
            step_no += 1;
            let base_after_base = report.ladder.last().is_some_and(|s| !s.base.is_empty());
            let round = cur.round(lib, &rung, sr, !base_after_base, &|f| progress(step_no, f))?;
            report.skipped = round.skipped;
            report.last_round = round.tried;
            if round.exhausted {
                let why = "no effect of the library is left to add on this log";
                break (Stop::LibraryExhausted, why.to_string());
            }
            let Some((next, step)) = round.kept else {
                break (
                    Stop::NothingHelps,
                    nothing_helps(
                        &rung,
                        &report.last_round,
                        round.base_tried || base_after_base,
                        &report.skipped,
                    ),
                );
            };
            // The step's model is relative to its own base parameters.
            let moved = next.scales != rung.scales;
            let next_an = moved.then(|| self.rebased(next.scales.apply(&sr.file)));
            let an = next_an.as_ref().unwrap_or(cur);
            let (next, step) = an.drop_stand_ins(next, step, &rung, sr, &opts.effects)?;
            report.ladder.push(step);
            rung = next;
            if moved {
                recentred = next_an;
            }
        };
        report.stop = stop;
        report.stopped_because = why;
        report.final_effects = rung.kinds.clone();
        Ok(rung)
    }
}

/// The fastest time constant of the library's dynamics effects on machine `n` [s] (the
/// stator's transient sigma Ls / Ra: a few ms).
fn fastest_dynamics_s(n: &crate::simplified_model::MachineConstants) -> f64 {
    effects::library()
        .iter()
        .filter_map(|e| e.time_constant_s(n))
        .filter(|t| t.is_finite() && *t > 0.0)
        .fold(f64::INFINITY, f64::min)
}

/// The thinning factor of the fit copy of a working series of `len` samples at `dt_s`: the
/// factor that brings it to [`LADDER_FIT_SAMPLES`], but never so coarse that the fastest
/// dynamics time constant `tau_s` has fewer than 3 samples (the rule of
/// [`transients::not_proposed`]) while the copy stays within [`LADDER_MAX_FIT_SAMPLES`]: a
/// 24 s log at 2 kHz is fitted at 1 kHz (24 000 samples) where a factor of 3 (667 Hz) left
/// a 3.6 ms stator transient unresolved and every dynamics effect refused.
pub fn fit_thinning(len: usize, dt_s: f64, tau_s: f64) -> usize {
    let budget = len.div_ceil(LADDER_FIT_SAMPLES).max(1);
    let resolving = if tau_s.is_finite() && dt_s > 0.0 {
        ((tau_s / (3.0 * dt_s)).floor() as usize).max(1)
    } else {
        budget
    };
    if budget <= resolving {
        budget
    } else {
        resolving.max(len.div_ceil(LADDER_MAX_FIT_SAMPLES).max(1))
    }
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

/// Why no candidate helps, naming the numbers that decided. "Beyond the effect library"
/// only when the base rung was a candidate of the last round (the effects were tried on a
/// refitted base) and every effect of the library could be fitted (`skipped` is empty);
/// otherwise what was not tried.
fn nothing_helps(rung: &Rung<'_>, tried: &[Tried], base_tried: bool, skipped: &[String]) -> String {
    let r = rung.error / rung.noise;
    let rh = rung.heldback_error / rung.heldback_noise;
    // The plausible candidate that came closest to passing (else the first tried).
    let closest = tried
        .iter()
        .filter(|t| !t.because.starts_with("not physical") && !t.because.contains("diverged"))
        .max_by(|a, b| a.significance.total_cmp(&b.significance));
    let best = closest
        .or(tried.first())
        .map(|t| format!("{} ({})", tried_name(t), t.because))
        .unwrap_or_else(|| "no candidate could be fitted".into());
    let what_is_left = if base_tried && skipped.is_empty() {
        "What is left is beyond the effect library (or below what the log can show)".to_string()
    } else if !skipped.is_empty() {
        format!(
            "What is left is not explained by the effects that could be fitted on this log; not tried: {}",
            skipped
                .iter()
                .map(|s| s.split(':').next().unwrap_or(s))
                .collect::<Vec<_>>()
                .join(", ")
        )
    } else {
        "What is left is not explained by the effects of the library on the file's base parameters"
            .to_string()
    };
    format!(
        "no plausible candidate passes the step's test: the whole-log error {} is {r:.2}x its noise floor and the held-back error {} is {rh:.2}x its floor; the best candidate was {best}. {what_is_left}",
        effects::sig(rung.error),
        effects::sig(rung.heldback_error),
    )
}

/// A tried candidate's name: its effects joined with `+`, or `the base parameters
/// refitted`.
pub fn tried_name(t: &Tried) -> String {
    // An effect fitted with the base parameters refitted beside it is named by its effects.
    if t.added.is_empty() {
        return "the base parameters refitted".to_string();
    }
    t.added
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join("+")
}
