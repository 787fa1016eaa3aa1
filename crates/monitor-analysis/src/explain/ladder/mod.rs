//! `explain --ladder`: forward selection over the effect library, from the configured model
//! to the noise floor.
//!
//! The ladder is a type of its own ([`climb`]'s `Ladder`): it holds the user's analysis,
//! the effect library, the fit series with its held-back split, and where it stands (the
//! rung, the analysis of that rung's base parameters, the steps so far). It climbs round by
//! round; one function states a round's rung order (`Ladder::round`, [`round`]): the base
//! rung (the six base parameters refitted) first, then the single effects, then pairs.
//!
//! Each round fits every effect of the library not yet in the model (the dynamics effects
//! are candidates like the others; one that needs another first, such as
//! `cross_coupling_dynamics` after `d_axis_dynamics`, is tried together with it), each
//! starting from the previous step's fit (nested fits: the step's solver starts where the
//! model stood, so a candidate can only lower the training error). The plausible candidate
//! with the lowest held-back error (each parameter costing [`PARAM_PENALTY`] of it) is kept
//! when the step passes its test ([`STEP_MIN`]) and lowers the whole-log error; the ladder
//! stops when the error is within the noise-floor band ([`FLOOR_BAND`], on the whole log and
//! on the held-back part) or when no plausible candidate passes, and says which
//! ([`StopReason`]). A candidate not kept carries why ([`Refusal`]), with the numbers that
//! decided; the ladder decides by matching on these values, and the sentences a crew reads
//! are spelled from them by `monitor-words`.
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

mod apart;
mod base;
mod climb;
mod end;
mod refusal;
mod round;
mod rung;
mod split;
mod stepwise;
#[cfg(test)]
mod tests;

pub use apart::{Alike, AsOne, AS_ONE_WITHIN};
pub use base::{base_changes, BaseChange, NotSeparable, BASE_CHANGE_MIN};
pub use end::FinalFit;
pub use refusal::{Refusal, StopReason, WhatIsLeft, WhyNotPhysical};
pub use split::stratified_heldback;

use super::{Skipped, NOISE_MARGIN, PARAM_PENALTY};
use crate::analysis::{resolve, Analysis, AnalysisError, DataInfo, Options};
use climb::Ladder;
use monitor_laws::EffectId;
use serde::Serialize;
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
/// effects are refused on a series that does not, [`crate::transients::not_proposed`]).
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
    pub effect: Option<EffectId>,
    /// Every effect the step added: `effect`, and before it one it needs first
    /// ([`crate::effects::EffectModel::requires`]) when the model lacked it (empty on a
    /// base rung).
    pub added: Vec<EffectId>,
    /// The base rung's six base parameters against the user's file, each with its change,
    /// its 95 % interval and whether the rung names it; on an effect's step, the base
    /// parameters refitted beside it where it names a change (else empty).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub base: Vec<BaseChange>,
    /// Effects of earlier steps the step removed: the step's effect explains what they stood
    /// in for (stepwise selection both ways, [`stepwise`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<EffectId>,
    /// Why each of `dropped` was removed, with the numbers that decided.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dropped_because: Vec<Dropped>,
    /// The added effects' fitted values with their physical ranges, by parameter name
    /// (prefixed `effect.` when the step added two).
    pub fitted: BTreeMap<String, RangedValue>,
    /// Each added effect's values as the effect describes them
    /// ([`crate::effects::FitSetup::describe`]); the step's sentence (JSON `summary`) is
    /// spelled from them and the base changes at the door.
    #[serde(skip)]
    pub described: Vec<String>,
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
    /// The model's error over time after the step on the working series, as (time [s],
    /// `normalized_rms_error` over one supply period or more)
    /// ([`crate::metrics::error_over_time`]):
    /// the charts draw it falling. Not in the JSON.
    #[serde(skip)]
    pub error_over_time: Vec<(f64, f64)>,
}

/// An effect a step removed (JSON `ladder[].dropped_because[]`): the model without it
/// loses `loses` of its held-back error beyond the noise floor, less than the `asks` a step
/// must earn ([`STEP_MIN`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Dropped {
    /// The effect removed.
    pub effect: EffectId,
    /// The share of the held-back error beyond the floor the model loses without it.
    pub loses: f64,
    /// The share a step must earn.
    pub asks: f64,
}

/// Where the model stood before the first step (JSON `start`).
#[derive(Debug, Clone, Serialize)]
pub struct LadderStart {
    /// The configured effects.
    pub effects: Vec<EffectId>,
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
    /// The model's error over time before the first step, as [`LadderStep::error_over_time`].
    #[serde(skip)]
    pub error_over_time: Vec<(f64, f64)>,
}

/// Where a ladder is, for a progress bar ([`Analysis::ladder`]'s `progress`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LadderProgress {
    /// Round `round` (1-based) fits its candidates; `kept` steps are kept so far (the round
    /// may keep one more, or none: then the ladder stops); `fraction` (0..1) of its fits
    /// done.
    Round {
        /// The round, from 1.
        round: usize,
        /// The steps kept before it.
        kept: usize,
        /// The share of its fits done.
        fraction: f64,
    },
    /// The chosen model of `kept` steps refitted on the whole log; `fraction` done.
    FinalFit {
        /// The steps kept.
        kept: usize,
        /// The share done (0 or 1).
        fraction: f64,
    },
}

/// A candidate of the last round that was not kept, and why (JSON `last_round`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tried {
    /// True for the base rung (the base parameters refitted; `added` is then empty).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub base: bool,
    /// The effect (with what it needed first, as in [`LadderStep::added`]).
    pub added: Vec<EffectId>,
    /// Its held-back error.
    pub heldback_error: f64,
    /// Its test statistic ([`LadderStep::significance`]).
    pub significance: f64,
    /// Why it was not kept.
    pub refusal: Refusal,
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

/// The rule each step passed and the ladder stops by (JSON `test_rule`, beside the sentence
/// `test`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TestRule {
    /// The share of the held-back error beyond the floor a step must remove ([`STEP_MIN`]).
    pub step_min: f64,
    /// The held-back error each parameter costs ([`PARAM_PENALTY`]).
    pub param_penalty: f64,
    /// The noise-floor band the ladder stops within ([`FLOOR_BAND`]).
    pub floor_band: f64,
}

/// The ladder's report (JSON of `explain --ladder`, with the sentences spelled beside the
/// typed values at the door: `summary`, `stopped_because`, `skipped`, `test`,
/// `ladder[].summary`, `last_round[].because`).
#[derive(Debug, Clone, Serialize)]
pub struct LadderReport {
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
    /// The same with the numbers that decided.
    pub stopped_reason: StopReason,
    /// The effects in the model at the end.
    pub final_effects: Vec<EffectId>,
    /// The last round's candidates that were not kept, best first.
    pub last_round: Vec<Tried>,
    /// Effects never fitted on this log, with why.
    pub skipped_reasons: Vec<Skipped>,
    /// The held-back split: the strata of the log and how much of it is held back.
    pub split: SplitInfo,
    /// The rule each step passed.
    pub test_rule: TestRule,
    /// Facts about the data.
    pub data: DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: monitor_io::log::quality::DataQuality,
    /// Where the chosen model's error lives, when the ladder stops above the noise floor
    /// ([`crate::leftover`]: its equations, windows, spectral lines and what it follows;
    /// null at the floor or where the model could not run).
    pub leftover: Option<crate::leftover::Leftover>,
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
    /// model (module doc; the climb is [`climb`]'s `Ladder`). `progress` gets where the
    /// ladder is ([`LadderProgress`]).
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub fn ladder(
        &self,
        opts: &Options,
        progress: &(dyn Fn(LadderProgress) + Sync),
    ) -> Result<LadderReport, AnalysisError> {
        let (held, strata) = stratified_heldback(&self.data, &self.constants);
        let mut report = self.report_before(opts, &held, strata);
        if let Some(reason) = self.ladder_refused() {
            report.stop = reason.stop();
            report.stopped_reason = reason;
            return Ok(report);
        }
        let library = opts.laws.ladder_models();
        let configured = resolve(&opts.effects, &opts.laws);
        let mut ladder = Ladder::start(self, &library, &configured, opts, held, progress)?;
        report.start = ladder.start_figures();
        let reason = ladder.climb()?;
        ladder.report(reason, &mut report)?;
        Ok(report)
    }

    /// The ladder's report before its first step: the split (`held`, `strata`), the test,
    /// the data, no steps.
    fn report_before(&self, opts: &Options, held: &[bool], strata: Vec<Stratum>) -> LadderReport {
        LadderReport {
            base_changes: Vec::new(),
            final_fit: None,
            start: LadderStart {
                effects: opts.effects.clone(),
                error: f64::NAN,
                heldback_error: f64::NAN,
                noise_floor: f64::NAN,
                heldback_noise_floor: f64::NAN,
                ratio_to_floor: f64::NAN,
                error_over_time: Vec::new(),
            },
            ladder: Vec::new(),
            stop: Stop::NoModel,
            stopped_reason: StopReason::NoVoltages,
            final_effects: opts.effects.clone(),
            last_round: Vec::new(),
            skipped_reasons: Vec::new(),
            split: SplitInfo {
                heldback_share: held.iter().filter(|h| **h).count() as f64
                    / self.data.len().max(1) as f64,
                strata,
            },
            test_rule: TestRule {
                step_min: STEP_MIN,
                param_penalty: PARAM_PENALTY,
                floor_band: FLOOR_BAND,
            },
            data: self.info(),
            data_quality: self.quality.clone(),
            leftover: None,
        }
    }

    /// Why the ladder cannot start on this log, if it cannot: no voltages (the model cannot
    /// run), or a log the data-quality stage does not trust.
    fn ladder_refused(&self) -> Option<StopReason> {
        if !self.data.channels.voltages {
            return Some(StopReason::NoVoltages);
        }
        (!self.quality.trusted_but_for_the_supply).then_some(StopReason::Untrusted)
    }
}

/// The thinning factor of the fit copy of a working series of `len` samples at `dt_s`: the
/// factor that brings it to [`LADDER_FIT_SAMPLES`], but never so coarse that the fastest
/// dynamics time constant `tau_s` has fewer than 3 samples (the rule of
/// [`crate::transients::not_proposed`]) while the copy stays within
/// [`LADDER_MAX_FIT_SAMPLES`]: a 24 s log at 2 kHz is fitted at 1 kHz (24 000 samples)
/// where a factor of 3 (667 Hz) left a 3.6 ms stator transient unresolved and every
/// dynamics effect refused.
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
