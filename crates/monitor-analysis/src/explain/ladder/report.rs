//! The ladder's report and the values it is made of (JSON of `explain --ladder`): the
//! start, each step with its fitted values and base changes, the chosen model refitted on
//! the whole log, the split, the rule; where the ladder is for a progress bar. Values only:
//! the climb that fills them is [`super::climb`], the words a crew reads are spelled from
//! them at the door (`monitor-words`).

use super::refusal::{Stop, StopReason, Tried};
use crate::analysis::{DataInfo, FittedEffect};
use crate::effects::ApartBy;
use crate::explain::Skipped;
use crate::fit::machine::BaseKey;
use monitor_laws::EffectId;
use serde::Serialize;
use std::collections::BTreeMap;

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
    /// in for (stepwise selection both ways, `stepwise.rs`).
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
    /// removed by the step, each parameter costing [`crate::explain::PARAM_PENALTY`] ([`super::rules::STEP_MIN`]).
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
/// must earn ([`super::rules::STEP_MIN`]).
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

/// Where a ladder is, for a progress bar ([`crate::analysis::Analysis::ladder`]'s `progress`).
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

/// The rule each step passed and the ladder stops by (JSON `test_rule`, beside the sentence
/// `test`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TestRule {
    /// The share of the held-back error beyond the floor a step must remove ([`super::rules::STEP_MIN`]).
    pub step_min: f64,
    /// The held-back error each parameter costs ([`crate::explain::PARAM_PENALTY`]).
    pub param_penalty: f64,
    /// The noise-floor band the ladder stops within ([`super::rules::FLOOR_BAND`]).
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

/// One base parameter against the user's file (JSON `ladder[].base[]`, `base_changes[]`).
#[derive(Debug, Clone, Serialize)]
pub struct BaseChange {
    /// Which (`rs`, `rr`, `leakage`, `lm`, `j`, `b`).
    pub base: BaseKey,
    /// The relative change from the file (0.19 = +19 %); for B + Bl where the file has
    /// none, the value itself [N m s/rad].
    pub change: f64,
    /// The 95 % interval of `change` (`None`: the log does not determine it).
    pub interval: Option<[f64; 2]>,
    /// The file's value.
    pub file_value: f64,
    /// The refitted value.
    pub value: f64,
    /// The unit of the two values.
    pub unit: &'static str,
    /// True when the log determines the value within ±[`crate::fit::machine::UNIDENTIFIED_SD`].
    pub identified: bool,
    /// True when the change is one the ladder names: identified, at least
    /// [`super::rules::BASE_CHANGE_MIN`], its interval excludes no change, and it is the log's own
    /// evidence (not [`BaseChange::not_separable`]).
    pub changed: bool,
    /// The change the fit reads, but the same model without it still explains the log
    /// (the ladder's end, `Ladder::final_fit`): it trades with the effects' values on this
    /// log and is no finding.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_separable: Option<NotSeparable>,
    /// The change the fit reads on the whole log differs between the log's two halves
    /// (the ladder's end, `Ladder::halves`): not a constant of the machine, so no finding.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unsteady: Option<Unsteady>,
    /// A library effect outside the chosen model fits the log as well with the parameter
    /// at the file's value (the ladder's end, `Ladder::in_place`): the log cannot tell the
    /// change from that effect, so no finding.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub in_place: Option<InPlace>,
}

impl BaseChange {
    /// True when the ladder's end found the change not to be the log's own evidence: it
    /// trades with the effects' values ([`NotSeparable`]), it differs between the log's
    /// halves ([`Unsteady`]), or an effect fits as well in its place ([`InPlace`]).
    pub fn questioned(&self) -> bool {
        self.not_separable.is_some() || self.unsteady.is_some() || self.in_place.is_some()
    }
}

/// A base change that is not the same in the log's two halves (JSON
/// `base_changes[].unsteady`, `final_fit.base[].unsteady`): the chosen model refitted with
/// the base parameters free on each half of the working series alone (by samples). A
/// machine's parameter is one value over a log; a change that moves by more than both
/// halves' 95 % intervals together and by more than half of itself carries what the model
/// lacks (a law whose shape is not the machine's), not a change of the machine.
#[derive(Debug, Clone, Serialize)]
pub struct Unsteady {
    /// The change read on the first half (relative, as [`BaseChange::change`]).
    pub first: f64,
    /// The change read on the second half.
    pub second: f64,
}

/// A library effect that fits the log as well as a base change does (JSON
/// `base_changes[].in_place`, `final_fit.base[].in_place`): the chosen model with that
/// effect added and the parameter held at the file's value, refitted as the final fit is
/// (one value for one: no more freedom than the change).
#[derive(Debug, Clone, Serialize)]
pub struct InPlace {
    /// The effect that fits in the change's place.
    pub effect: EffectId,
    /// What kind of log tells the two apart.
    pub apart_by: ApartBy,
    /// The chosen model's whole-log error over its noise floor (with the change).
    pub ratio_with_change: f64,
    /// The same with the effect in the change's place.
    pub ratio_in_place: f64,
    /// True when the effect in the change's place removes at least
    /// [`super::rules::STEP_MIN`] of the error beyond the floor the change leaves: the log
    /// reads the effect better than the change (a log with a start and a fan), not only as
    /// well.
    pub better: bool,
    /// The effect's values in the change's place, as the effect states them.
    pub fitted: FittedEffect,
}

/// A base change the log cannot tell from the effects' values (JSON
/// `base_changes[].not_separable`, `final_fit.base[].not_separable`): the chosen model
/// refitted with the parameter at the file's value. Either that model still reaches the
/// noise-floor band (`shape: None`), or the chosen model ends far from its floor and, with
/// the change held off, an effect's law runs to the end of its range ([`LawShape`]).
#[derive(Debug, Clone, Serialize)]
pub struct NotSeparable {
    /// The whole-log error without the change.
    pub error_without: f64,
    /// Its ratio to the noise floor.
    pub ratio_without: f64,
    /// The share of the error beyond the floor the change removes.
    pub removes: f64,
    /// The effects whose values took the change up (by more than 0.5 %; empty: none did,
    /// the other base parameters or nothing carry it).
    pub traded_with: Vec<monitor_laws::EffectId>,
    /// The law that ran to the end of its range with the change held off (`None`: the
    /// model without the change reaches the floor's band, the first reason).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shape: Option<LawShape>,
}

/// An effect's parameter the refit without a base change took to the end of its fit range
/// (JSON `not_separable.shape`), where the chosen model ends far from its noise floor
/// (above [`super::rules::PAIRS_ABOVE`]): the change and the shape of that effect's law
/// trade on this log, and the law of the machine is not the library's (motulator's
/// saturating 2.2 kW machine, whose curve acts on the stator flux of a Gamma circuit: Rr
/// -23 % beside the library's law, whose knee exponent runs from 8 to its bound 14 with Rr
/// at the file's value). The change is what the law's shape left, not a finding.
#[derive(Debug, Clone, Serialize)]
pub struct LawShape {
    /// The effect whose law ran out.
    pub effect: monitor_laws::EffectId,
    /// Its parameter's JSON key.
    pub parameter: String,
    /// The parameter's value in the model with the change.
    pub with_change: f64,
    /// The end of the fit range it reached without the change.
    pub bound: f64,
}

/// The chosen model refitted on the whole log (JSON `final_fit`).
#[derive(Debug, Clone, Serialize)]
pub struct FinalFit {
    /// The effects of the chosen model.
    pub effects: Vec<EffectId>,
    /// `normalized_rms_error` over the whole log.
    pub error: f64,
    /// The whole log's noise floor for the model.
    pub noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
    /// The start's error over this one.
    pub below_start: f64,
    /// True when the model ends far from its noise floor (more than
    /// [`super::rules::PAIRS_ABOVE`], 2x): its base changes are read beside a model that
    /// leaves most of the error beyond the noise unexplained, where a law of the model that
    /// is not the machine's can move them (motulator's saturating machine: Rr -25 % beside
    /// the library's saturation law, at 3.09x).
    pub far_from_floor: bool,
    /// The six base parameters against the user's file, with their intervals.
    pub base: Vec<BaseChange>,
    /// The effects with their values.
    pub fitted: Vec<FittedEffect>,
    /// Pairs of its load laws the log shows only as one load torque of speed
    /// (`apart.rs`, `Ladder::as_one`): neither of the two is a finding alone.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub as_one: Vec<AsOne>,
    /// Its effects that a confusable effect of the library fits as well in their place
    /// (`apart.rs`, `Ladder::alike`): the log cannot tell the two apart.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub alike: Vec<Alike>,
    /// Samples the fit used.
    pub fit_samples: usize,
    /// Its error over time on the working series, as [`LadderStep::error_over_time`].
    #[serde(skip)]
    pub error_over_time: Vec<(f64, f64)>,
}

/// Two load laws of the chosen model that the log shows only as one load torque of speed
/// (JSON `final_fit.as_one[]`; `apart.rs` says how they are found).
#[derive(Debug, Clone, Serialize)]
pub struct AsOne {
    /// The two effects, in the model's order.
    pub effects: [EffectId; 2],
    /// The exponent `n` of the one law `T (|w| / w_s)^n` that fits in their place.
    pub exponent: f64,
    /// Its torque at the log's synchronous speed `w_s` [N m].
    pub torque_at_sync_nm: f64,
    /// The log's synchronous speed (mechanical) [rad/s].
    pub sync_speed_rad_s: f64,
    /// The whole-log error with the one law in place of the two.
    pub error_as_one: f64,
    /// Its ratio to the noise floor.
    pub ratio_as_one: f64,
    /// The whole-log error of the chosen model (the pair's).
    pub error_apart: f64,
}

/// An effect of the chosen model and a confusable one of the library that fit the log
/// alike (JSON `final_fit.alike[]`; `apart.rs`).
#[derive(Debug, Clone, Serialize)]
pub struct Alike {
    /// The chosen model's effect (the one reported with its values).
    pub effect: EffectId,
    /// The library's effect that fits as well in its place.
    pub other: EffectId,
    /// What kind of log tells the two apart.
    pub apart_by: ApartBy,
    /// The chosen model's whole-log error over its noise floor.
    pub ratio: f64,
    /// The same with `other` in the place of `effect`.
    pub ratio_other: f64,
}
