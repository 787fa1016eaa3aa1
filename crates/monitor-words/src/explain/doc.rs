//! `explain`'s report as its JSON document carries it ([`ExplainReportDoc`]): its typed
//! values, each sentence spelled here beside the value it is spelled from. The whole
//! document, which opens with the one verdict, is the diagnose words' `ExplainDoc`.

use super::verdict;
use crate::analysis::{skipped, UnbalanceDoc};
use crate::Spelling;
use monitor_analysis::explain::{
    EffectCandidate, ExplainConclusion, ExplainReport, NotNamed, Skipped,
};
use monitor_analysis::refit::BaseRefit;
use monitor_analysis::{DataInfo, EffectId};
use monitor_io::log::quality::DataQuality;
use serde::Serialize;

/// `explain`'s report as its document carries it: each of [`ExplainReport`]'s values under
/// its own key (by reference; a field added to the report is a compile error in
/// [`ExplainReportDoc::new`] until the document carries it), with its sentences beside them:
/// `verdict` beside `conclusion`, `skipped` beside `skipped_reasons`, and the unbalance's
/// `summary` and `cannot_judge_because`.
#[derive(Debug, Clone, Serialize)]
pub struct ExplainReportDoc<'a> {
    /// Effects already in the model.
    pub effects: &'a [EffectId],
    /// Error of the model as configured (whole log).
    pub baseline_normalized_rms_error: f64,
    /// Error of the model as configured on the held-back windows.
    pub baseline_validation_normalized_rms_error: f64,
    /// Noise floor.
    pub noise_floor: f64,
    /// Every fitted candidate, the ranked ones first.
    pub ranking: &'a [EffectCandidate],
    /// The plausible fits that explain too little to be candidates.
    pub no_effect: &'a [EffectId],
    /// True when no candidate explains the error well.
    pub unexplained: bool,
    /// The conclusion, with the numbers that decided.
    pub conclusion: &'a ExplainConclusion,
    /// The same in words ([`verdict`]).
    pub verdict: String,
    /// The candidates not named because their fits are not physical (absent when none).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub not_named: &'a [NotNamed],
    /// Why the configured model's own fit is not plausible (absent when it is).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub model_implausible: &'a [String],
    /// Candidates not evaluated and why, typed.
    pub skipped_reasons: &'a [Skipped],
    /// The same in words, as `name: why`.
    pub skipped: Vec<String>,
    /// The unbalance analysis with its sentences.
    pub unbalance: UnbalanceDoc<'a>,
    /// Facts about the data.
    pub data: &'a DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: &'a DataQuality,
    /// The base parameters refitted to the log before effects were judged (null where the
    /// model did not run).
    pub base_refit: Option<&'a BaseRefit>,
}

impl<'a> ExplainReportDoc<'a> {
    /// The document of `r`, its sentences in `spell`'s words (the options advice refers to).
    pub fn new(r: &'a ExplainReport, spell: &dyn Spelling) -> Self {
        let ExplainReport {
            effects,
            baseline_normalized_rms_error,
            baseline_validation_normalized_rms_error,
            noise_floor,
            ranking,
            no_effect,
            unexplained,
            conclusion,
            not_named,
            model_implausible,
            skipped: skipped_reasons,
            unbalance,
            data,
            data_quality,
            base_refit,
        } = r;
        ExplainReportDoc {
            effects,
            baseline_normalized_rms_error: *baseline_normalized_rms_error,
            baseline_validation_normalized_rms_error: *baseline_validation_normalized_rms_error,
            noise_floor: *noise_floor,
            ranking,
            no_effect,
            unexplained: *unexplained,
            conclusion,
            verdict: verdict(r, spell),
            not_named,
            model_implausible,
            skipped_reasons,
            skipped: skipped_reasons.iter().map(|s| skipped(s, spell)).collect(),
            unbalance: UnbalanceDoc::new(unbalance, spell),
            data,
            data_quality,
            base_refit: base_refit.as_ref(),
        }
    }
}
