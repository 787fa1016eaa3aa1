//! Stages 1, 7 and 8 of `explain`: the report of a current-only log, the model recentred
//! on its refitted base parameters when the file's do not fit, and the report with its
//! verdict.

use super::baseline::{ExplainBaseline, FullSeries};
use super::ranking::{CandidateOutcome, RankedCandidate};
use super::{ExplainOutput, ExplainReport, Standing, EXPLAINED_MIN, EXPLAINS_MIN, NOISE_MARGIN};
use crate::analysis::{resolve, Analysis, AnalysisError, Options};
use crate::base_range::{base_implausible, base_out_of_range};
use crate::effects::SetupError;
use crate::fit::{ActiveEffect, FittedModel};
use crate::refit::BaseRefit;
use crate::simplified_model::Prediction;
use crate::unbalance::UnbalanceAnalysis;
use monitor_core::EffectKind;
use monitor_replay::OptionField;

/// What stages 2 to 6 found on a log with voltages: the report's material.
pub(super) struct ExplainFindings<'a> {
    /// The effects in the configured model.
    pub(super) names: Vec<EffectKind>,
    /// The configured model fitted on the fit series.
    pub(super) base: ExplainBaseline<'a>,
    /// The configured model on the working series.
    pub(super) full: FullSeries,
    /// The candidates, best first.
    pub(super) ranked: Vec<RankedCandidate>,
    /// What the ranking says.
    pub(super) outcome: CandidateOutcome,
    /// Candidates not ranked and why.
    pub(super) skipped: Vec<String>,
    /// The unbalance analysis.
    pub(super) unbalance: UnbalanceAnalysis,
}

impl Analysis {
    /// Stage 1: `explain` on a log without voltages: the model cannot run; only the
    /// unbalance analysis.
    pub(super) fn explain_current_only(&self, names: Vec<EffectKind>) -> ExplainOutput {
        let unbalance = self.unbalance();
        let skipped = EffectKind::ALL
            .iter()
            .filter(|k| !names.contains(k))
            .map(|k| {
                format!(
                    "{k}: {}; see the unbalance analysis",
                    SetupError::NoVoltages
                )
            })
            .collect();
        let verdict = format!(
            "current-only log: only the unbalance analysis ran: {}",
            unbalance.summary
        );
        ExplainOutput {
            report: ExplainReport {
                effects: names,
                baseline_normalized_rms_error: f64::NAN,
                baseline_validation_normalized_rms_error: f64::NAN,
                noise_floor: f64::NAN,
                ranking: vec![],
                no_effect: vec![],
                unexplained: unbalance.suspect_phase.is_none(),
                verdict,
                skipped,
                unbalance,
                data: self.info(),
                data_quality: self.quality.clone(),
                base_refit: None,
            },
            before: Prediction::default(),
            after: None,
        }
    }

    /// Stage 7 (the decision): why the model is recentred on the refitted base
    /// parameters, or `None` when it is not. Recentred only when nothing could be named on
    /// the file's model (a missing effect also pushes the base parameters out of range,
    /// and then naming it is the answer), the error is not at the noise floor nor
    /// structural, and the log identifies a base parameter whose refit is out of range.
    pub(super) fn recentre_because(
        &self,
        found: &ExplainFindings<'_>,
        refit: &BaseRefit,
        structural: bool,
    ) -> Option<Vec<String>> {
        let o = found.outcome;
        if !o.unexplained || o.near_noise || structural {
            return None;
        }
        let flagged = base_out_of_range(&self.constants, &found.base.fit.base, &self.data);
        flagged
            .iter()
            .any(|(k, _)| refit.identifies(*k))
            .then(|| flagged.into_iter().map(|(_, why)| why).collect())
    }

    /// Stage 7: `explain` again on the model recentred on the identified refitted base
    /// parameters (`refit`, the file's values out of range `because`), with the refit
    /// reported.
    pub(super) fn explain_recentred(
        &self,
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
        mut refit: BaseRefit,
        because: Vec<String>,
    ) -> Result<ExplainOutput, AnalysisError> {
        let recentred = self.recentred(refit.recentred_params(&self.params));
        let mut out = recentred.explain_once(opts, progress, false)?;
        refit.recentred = true;
        refit.because = because;
        out.report.base_refit = Some(refit);
        Ok(out)
    }

    /// Stage 8: the report of `found`, with the verdict and the prediction of the model
    /// with the candidate it names.
    pub(super) fn explain_report(
        &self,
        found: ExplainFindings<'_>,
        refit: BaseRefit,
    ) -> Result<ExplainOutput, AnalysisError> {
        let o = found.outcome;
        let verdict = self.verdict(&found);
        let after = match found.ranked.first() {
            Some(r) if !o.unexplained => {
                Some((r.candidate.effect, self.predict_with(&found.names, r)?))
            }
            _ => None,
        };
        Ok(ExplainOutput {
            report: ExplainReport {
                effects: found.names,
                baseline_normalized_rms_error: found.full.error,
                baseline_validation_normalized_rms_error: found.full.heldback_error,
                noise_floor: found.full.noise,
                no_effect: found
                    .ranked
                    .iter()
                    .filter(|c| c.candidate.standing == Standing::NoEffect)
                    .map(|c| c.candidate.effect)
                    .collect(),
                ranking: found.ranked.into_iter().map(|c| c.candidate).collect(),
                unexplained: o.unexplained,
                verdict,
                skipped: found.skipped,
                unbalance: found.unbalance,
                data: self.info(),
                data_quality: self.quality.clone(),
                base_refit: Some(refit),
            },
            before: found.full.before,
            after,
        })
    }

    /// The verdict ([`verdict`]) with the notes on implausible candidates and on an
    /// implausible fit of the configured model itself.
    fn verdict(&self, found: &ExplainFindings<'_>) -> String {
        let first_plausible = found.ranked.iter().find(|c| c.candidate.plausible);
        let mut v = verdict(found, first_plausible, &*self.words);
        v.push_str(&implausible_note(&found.ranked));
        let base_why = base_implausible(&self.constants, &found.base.fit.base, &self.data);
        if !base_why.is_empty() {
            v.push_str(&format!(
                ". The configured model's own fit is not plausible ({}): the base parameters absorb an error the model cannot follow; if the log has a start or steps, see compare's advice (dynamics effects or {})",
                base_why.join("; "),
                self.words.hint(monitor_replay::OptionField::From, "")
            ));
        }
        v
    }

    /// The prediction of the configured model (`names`) with candidate `r` added, from
    /// their fitted values, on the working series.
    fn predict_with(
        &self,
        names: &[EffectKind],
        r: &RankedCandidate,
    ) -> Result<Prediction, AnalysisError> {
        let kinds: Vec<EffectKind> = names.iter().copied().chain([r.candidate.effect]).collect();
        let boxes = resolve(&kinds);
        let model = FittedModel {
            effects: boxes
                .iter()
                .zip(&r.setups)
                .map(|(e, s)| ActiveEffect {
                    effect: e.as_ref(),
                    setup: s.clone(),
                })
                .collect(),
            fit: r.fit.clone(),
        };
        Ok(model.predict(&self.data, &self.constants)?)
    }
}

/// A verdict never rests on data the data-quality stage rejected: when the stage does not
/// trust the log, the ranking stays in the report but the verdict says why no effect is
/// named, and no effect is added.
pub(super) fn withhold_if_untrusted(mut out: ExplainOutput) -> ExplainOutput {
    let q = &out.report.data_quality;
    if q.trusted {
        return out;
    }
    out.report.verdict = format!(
        "could not judge: the data-quality stage does not trust this log ({}); the ranking below is not a verdict",
        q.not_trusted_because.join("; ")
    );
    out.report.unexplained = true;
    out.after = None;
    out
}

/// The verdict's note on candidates whose fits are not physically plausible: those that
/// would have explained more than the one named (and at least [`EXPLAINS_MIN`]) are listed
/// with the first reason, so that a user sees why they are not the answer.
fn implausible_note(ranked: &[RankedCandidate]) -> String {
    let top_plausible = ranked
        .iter()
        .find(|c| c.candidate.plausible)
        .map(|c| c.score())
        .unwrap_or(f64::INFINITY);
    let listed: Vec<String> = ranked
        .iter()
        .filter(|c| {
            !c.candidate.plausible
                && c.score() < top_plausible
                && c.candidate.explained_fraction >= EXPLAINS_MIN
        })
        .map(|c| {
            format!(
                "{} would explain {:.0} % but {}",
                c.candidate.effect,
                100.0 * c.candidate.explained_fraction,
                c.candidate
                    .implausible_because
                    .first()
                    .map(String::as_str)
                    .unwrap_or("a value is out of range")
            )
        })
        .collect();
    if listed.is_empty() {
        String::new()
    } else {
        format!(
            ". Not plausible, so not ranked and not named: {}",
            listed.join("; ")
        )
    }
}

/// The conclusion in words, `best` the first plausible candidate (`words`: a field's).
fn verdict(
    found: &ExplainFindings<'_>,
    best: Option<&RankedCandidate>,
    words: &dyn crate::words_shim::Spelling,
) -> String {
    let (full, o) = (&found.full, found.outcome);
    match best {
        _ if o.near_noise => nothing_to_explain(full),
        Some(r) if !o.unexplained => {
            let c = &r.candidate;
            format!(
                "missing effect: {} explains {:.0} % of the held-back error ({:.4} -> {:.4}); {}. Add it with {}",
                c.effect,
                100.0 * c.explained_fraction,
                found.base.heldback_error_fit_series,
                c.validation_normalized_rms_error,
                c.summary,
                words.hint(
                    OptionField::Effects,
                    &found
                        .names
                        .iter()
                        .chain([&c.effect])
                        .map(|e| e.name())
                        .collect::<Vec<_>>()
                        .join(",")
                )
            )
        }
        Some(r) if r.candidate.standing == Standing::Candidate => format!(
            "unexplained: the best candidate ({}) explains only {:.0} % of the held-back error (threshold {:.0} %); the error is not one of the library's effects",
            r.candidate.effect,
            100.0 * r.candidate.explained_fraction,
            100.0 * EXPLAINED_MIN
        ),
        Some(_) => format!(
            "unexplained: no plausible effect of the library explains {:.0} % of the held-back error or more; the error is not one of the library's effects",
            100.0 * EXPLAINS_MIN
        ),
        None => "unexplained: no candidate could be fitted with physically plausible values".into(),
    }
}

/// The verdict when the configured model is at its noise floor ([`CandidateOutcome`]),
/// naming the numbers that decided: the whole-log and the held-back error, each against
/// its own floor.
fn nothing_to_explain(full: &FullSeries) -> String {
    format!(
        "nothing to explain: the model's error {:.4} is {:.2}x its noise floor {:.4} and the held-back error {:.4} is {:.2}x its floor {:.4} (both within {NOISE_MARGIN}x)",
        full.error,
        full.error / full.noise,
        full.noise,
        full.heldback_error,
        full.heldback_error / full.heldback_noise,
        full.heldback_noise,
    )
}
