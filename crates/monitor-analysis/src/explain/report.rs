//! Stages 1, 7 and 8 of `explain`: the report of a current-only log, the model recentred
//! on its refitted base parameters when the file's do not fit, and the report with its
//! verdict.

use super::baseline::{ExplainBaseline, FullSeries};
use super::ranking::{CandidateOutcome, RankedCandidate};
use super::{
    ExplainConclusion, ExplainOutput, ExplainReport, NotNamed, SkipReason, Skipped, Standing,
    EXPLAINED_MIN, EXPLAINS_MIN, NOISE_MARGIN,
};
use crate::analysis::{resolve, Analysis, AnalysisError, Options};
use crate::base_range::{base_implausible, base_out_of_range};
use crate::effects::Registry;
use crate::fit::{ActiveEffect, FittedModel};
use crate::refit::BaseRefit;
use crate::simplified_model::Prediction;
use crate::unbalance::UnbalanceAnalysis;
use monitor_laws::EffectId;

/// What stages 2 to 6 found on a log with voltages: the report's material.
pub(super) struct ExplainFindings<'a> {
    /// The effects in the configured model.
    pub(super) names: Vec<EffectId>,
    /// The configured model fitted on the fit series.
    pub(super) base: ExplainBaseline<'a>,
    /// The configured model on the working series.
    pub(super) full: FullSeries,
    /// The candidates, best first.
    pub(super) ranked: Vec<RankedCandidate>,
    /// What the ranking says.
    pub(super) outcome: CandidateOutcome,
    /// Candidates not ranked and why.
    pub(super) skipped: Vec<Skipped>,
    /// The unbalance analysis.
    pub(super) unbalance: UnbalanceAnalysis,
    /// The effects the analysis may use (the library's and the user's laws).
    pub(super) registry: &'a Registry,
}

impl Analysis {
    /// Stage 1: `explain` on a log without voltages: the model cannot run; only the
    /// unbalance analysis.
    pub(super) fn explain_current_only(
        &self,
        names: Vec<EffectId>,
        registry: &Registry,
    ) -> ExplainOutput {
        let unbalance = self.unbalance();
        let skipped = registry
            .names()
            .into_iter()
            .filter(|k| !names.contains(k))
            .map(|effect| Skipped {
                effect,
                because: SkipReason::NoVoltages,
            })
            .collect();
        ExplainOutput {
            report: ExplainReport {
                effects: names,
                baseline_normalized_rms_error: f64::NAN,
                baseline_validation_normalized_rms_error: f64::NAN,
                noise_floor: f64::NAN,
                ranking: vec![],
                no_effect: vec![],
                unexplained: unbalance.suspect_phase.is_none(),
                conclusion: ExplainConclusion::CurrentOnly,
                not_named: vec![],
                model_implausible: vec![],
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
        let conclusion = conclusion(&found);
        let not_named = not_named(&found.ranked);
        let model_implausible = base_implausible(&self.constants, &found.base.fit.base, &self.data);
        let after = match found.ranked.first() {
            Some(r) if !o.unexplained => Some((
                r.candidate.effect,
                self.predict_with(&found.names, r, found.registry)?,
            )),
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
                conclusion,
                not_named,
                model_implausible,
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

    /// The prediction of the configured model (`names`) with candidate `r` added, from
    /// their fitted values, on the working series.
    fn predict_with(
        &self,
        names: &[EffectId],
        r: &RankedCandidate,
        registry: &Registry,
    ) -> Result<Prediction, AnalysisError> {
        let kinds: Vec<EffectId> = names.iter().copied().chain([r.candidate.effect]).collect();
        let boxes = resolve(&kinds, registry);
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
/// trust the log, the ranking stays in the report but the conclusion is that no effect is
/// named (the stage's reasons are the report's `data_quality`), and no effect is added.
pub(super) fn withhold_if_untrusted(mut out: ExplainOutput) -> ExplainOutput {
    if out.report.data_quality.trusted_but_for_the_supply {
        return out;
    }
    out.report.conclusion = ExplainConclusion::Untrusted;
    out.report.unexplained = true;
    out.after = None;
    out
}

/// The candidates whose fits are not physically plausible that would have explained more
/// than the one named (and at least [`EXPLAINS_MIN`]), each with its first reason, so that
/// a user sees why they are not the answer.
fn not_named(ranked: &[RankedCandidate]) -> Vec<NotNamed> {
    let top_plausible = ranked
        .iter()
        .find(|c| c.candidate.plausible)
        .map(|c| c.score())
        .unwrap_or(f64::INFINITY);
    ranked
        .iter()
        .filter(|c| {
            !c.candidate.plausible
                && c.score() < top_plausible
                && c.candidate.explained_fraction >= EXPLAINS_MIN
        })
        .map(|c| NotNamed {
            effect: c.candidate.effect,
            explained: c.candidate.explained_fraction,
            because: c.candidate.implausible_because.first().cloned(),
        })
        .collect()
}

/// What the ranking concludes, with the numbers that decided: nothing to explain at the
/// noise floor, a missing effect named (the first plausible candidate), or why none is.
fn conclusion(found: &ExplainFindings<'_>) -> ExplainConclusion {
    let (full, o) = (&found.full, found.outcome);
    let best = found.ranked.iter().find(|c| c.candidate.plausible);
    match best {
        _ if o.near_noise => ExplainConclusion::NothingToExplain {
            error: full.error,
            noise_floor: full.noise,
            heldback_error: full.heldback_error,
            heldback_noise_floor: full.heldback_noise,
            margin: NOISE_MARGIN,
        },
        Some(r) if !o.unexplained => {
            let c = &r.candidate;
            ExplainConclusion::Missing {
                effect: c.effect,
                explained: c.explained_fraction,
                heldback_before: found.base.heldback_error_fit_series,
                heldback_after: c.validation_normalized_rms_error,
                effects: found.names.iter().copied().chain([c.effect]).collect(),
            }
        }
        Some(r) if r.candidate.standing == Standing::Candidate => ExplainConclusion::TooLittle {
            effect: r.candidate.effect,
            explained: r.candidate.explained_fraction,
            asks: EXPLAINED_MIN,
        },
        Some(_) => ExplainConclusion::NoneExplains { asks: EXPLAINS_MIN },
        None => ExplainConclusion::NothingPlausible,
    }
}
