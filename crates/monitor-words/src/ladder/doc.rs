//! `explain --ladder --json`'s document: the ladder's typed values with the sentences
//! spelled from them beside them ([`LadderDoc`]).

use super::{refusal, step, stopped, summary, test};
use crate::analysis::skipped;
use crate::leftover::LeftoverDoc;
use crate::Spelling;
use monitor_analysis::explain::ladder::{
    BaseChange, FinalFit, LadderReport, LadderStart, LadderStep, SplitInfo, Stop, StopReason,
    TestRule, Tried,
};
use monitor_analysis::explain::Skipped;
use monitor_analysis::{DataInfo, EffectId};
use monitor_io::log::quality::DataQuality;
use serde::Serialize;

/// The ladder's report as its JSON document carries it: each of [`LadderReport`]'s values
/// under its own key (by reference; a field added to the report is a compile error in
/// [`LadderDoc::new`] until the document carries it), each step and each refused
/// candidate with its sentence, the leftover with its lines, and the report's sentences.
#[derive(Debug, Clone, Serialize)]
pub struct LadderDoc<'a> {
    /// The base parameters that differ from the user's file.
    pub base_changes: &'a [BaseChange],
    /// The chosen model refitted on the whole log (absent where there is none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_fit: Option<&'a FinalFit>,
    /// The model before the first step.
    pub start: &'a LadderStart,
    /// The steps in order, each with its sentence.
    pub ladder: Vec<StepDoc<'a>>,
    /// Why it stopped.
    pub stop: Stop,
    /// The same with the numbers that decided.
    pub stopped_reason: &'a StopReason,
    /// The effects in the model at the end.
    pub final_effects: &'a [EffectId],
    /// The last round's candidates that were not kept, each with why in words.
    pub last_round: Vec<TriedDoc<'a>>,
    /// Effects never fitted on this log, with why (typed).
    pub skipped_reasons: &'a [Skipped],
    /// The held-back split.
    pub split: &'a SplitInfo,
    /// The rule each step passed.
    pub test_rule: &'a TestRule,
    /// Facts about the data.
    pub data: &'a DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: &'a DataQuality,
    /// Where the chosen model's error lives, with its lines (null at the floor or where the
    /// model could not run).
    pub leftover: Option<LeftoverDoc<'a>>,
    /// What the ladder found, in one sentence ([`summary`]).
    pub summary: String,
    /// Why it stopped, naming the numbers that decided ([`stopped`]).
    pub stopped_because: String,
    /// The rule each step passed, in words ([`fn@test`]).
    pub test: String,
    /// Each of `skipped_reasons` as `name: why`.
    pub skipped: Vec<String>,
}

impl<'a> LadderDoc<'a> {
    /// The document of `r`, its sentences in `spell`'s words (the options advice refers to).
    pub fn new(r: &'a LadderReport, spell: &dyn Spelling) -> Self {
        let LadderReport {
            base_changes,
            final_fit,
            start,
            ladder,
            stop,
            stopped_reason,
            final_effects,
            last_round,
            skipped_reasons,
            split,
            test_rule,
            data,
            data_quality,
            leftover,
        } = r;
        LadderDoc {
            base_changes,
            final_fit: final_fit.as_ref(),
            start,
            ladder: ladder.iter().map(StepDoc::new).collect(),
            stop: *stop,
            stopped_reason,
            final_effects,
            last_round: last_round.iter().map(TriedDoc::new).collect(),
            skipped_reasons,
            split,
            test_rule,
            data,
            data_quality,
            leftover: leftover.as_ref().map(LeftoverDoc::new),
            summary: summary(r),
            stopped_because: stopped(r),
            test: test(test_rule),
            skipped: skipped_reasons.iter().map(|s| skipped(s, spell)).collect(),
        }
    }
}

/// One step of the ladder as its document carries it (`ladder[]`): its typed values and
/// its sentence.
#[derive(Debug, Clone, Serialize)]
pub struct StepDoc<'a> {
    /// The step's typed values.
    #[serde(flatten)]
    pub step: &'a LadderStep,
    /// The step in one sentence ([`step`]).
    pub summary: String,
}

impl<'a> StepDoc<'a> {
    /// The document of the step `s`.
    pub fn new(s: &'a LadderStep) -> Self {
        StepDoc {
            step: s,
            summary: step(s),
        }
    }
}

/// A candidate of the last round as its document carries it (`last_round[]`): its typed
/// values (with its typed `refusal`) and why it was not kept in words.
#[derive(Debug, Clone, Serialize)]
pub struct TriedDoc<'a> {
    /// The candidate's typed values.
    #[serde(flatten)]
    pub tried: &'a Tried,
    /// Why it was not kept ([`refusal`]).
    pub because: String,
}

impl<'a> TriedDoc<'a> {
    /// The document of the candidate `t`.
    pub fn new(t: &'a Tried) -> Self {
        TriedDoc {
            tried: t,
            because: refusal(&t.refusal),
        }
    }
}
