//! Stages 5 and 6 of `explain`: which effects of the library are candidates and which of
//! them cannot be ranked on this log (and why), and each rankable candidate added to the
//! configured model, fitted and measured on the held-back windows.

use super::baseline::{ExplainBaseline, FullSeries};
use super::ranking::RankedCandidate;
use super::{explained_fraction, EffectCandidate, SkipReason, Skipped, Standing};
use crate::analysis::{align, Analysis, AnalysisError, FittedEffect, Options};
use crate::base_range::base_newly_out_of_range;
use crate::effects::{self, EffectModel};
use crate::fit::{self, ActiveEffect, FitResult};
use crate::{metrics, transients};
use monitor_laws::EffectId;

/// Stage 5: the effects of the library `lib` that are not in the model (`names`), the
/// candidates `explain` tries.
pub(super) fn candidates<'a>(
    lib: &'a [Box<dyn EffectModel>],
    names: &[EffectId],
) -> Vec<&'a dyn EffectModel> {
    lib.iter()
        .map(|e| e.as_ref())
        .filter(|e| !names.contains(&e.kind()))
        .collect()
}

/// The configured effects of `base`, each starting from its baseline fit, with candidate
/// `c` (set up as `setup`) added last.
fn with_candidate<'a>(
    base: &ExplainBaseline<'a>,
    c: &'a dyn EffectModel,
    setup: crate::effects::FitSetup,
) -> Vec<ActiveEffect<'a>> {
    let mut set: Vec<ActiveEffect<'a>> = base
        .active
        .iter()
        .zip(&base.fit.effect_params)
        .map(|(a, p)| {
            let mut s = a.setup.clone();
            s.start_from(p);
            ActiveEffect {
                effect: a.effect,
                setup: s,
            }
        })
        .collect();
    set.push(ActiveEffect { effect: c, setup });
    set
}

impl Analysis {
    /// Stage 5: the candidates of `cands` that cannot be ranked on this log, each as
    /// `name: why` ([`Analysis::cannot_rank`]).
    pub(super) fn skipped(
        &self,
        cands: &[&dyn EffectModel],
        base: &ExplainBaseline<'_>,
    ) -> Vec<Skipped> {
        cands
            .iter()
            .filter_map(|c| {
                self.cannot_rank(*c, base).map(|because| Skipped {
                    effect: c.kind(),
                    because,
                })
            })
            .collect()
    }

    /// Why a candidate cannot be ranked on this log, if it cannot: the rule `compare`'s
    /// advice follows too ([`Analysis::not_proposed`]), a missing channel, or a set-up the
    /// data refuse (e.g. `load_torque` on a log without a load change: said, not dropped).
    fn cannot_rank(&self, c: &dyn EffectModel, base: &ExplainBaseline<'_>) -> Option<SkipReason> {
        if let Some(m) = self.not_proposed(c, base) {
            return Some(SkipReason::NotProposed { why: m });
        }
        let setup = c
            .needs()
            .met_by(&self.data)
            .and_then(|()| c.setup(&base.fit_series, &self.constants).map(|_| ()));
        setup.err().map(|why| SkipReason::Setup { why })
    }

    /// Whether candidate `c` is proposed on the fit series of `base` with the configured
    /// model's effects ([`transients::not_proposed`], the rule `compare`'s advice prints).
    fn not_proposed(
        &self,
        c: &dyn EffectModel,
        base: &ExplainBaseline<'_>,
    ) -> Option<transients::NotProposed> {
        let in_model: Vec<EffectId> = base.active.iter().map(|a| a.effect.kind()).collect();
        transients::not_proposed(c, base.span, &self.constants, &in_model)
    }

    /// Stage 6 (fit): every candidate of `cands` that can be ranked, fitted in parallel
    /// (`progress` told the fraction done), and, unless `full` already holds them, the
    /// configured model's measures on the working series ([`Analysis::full_series`]).
    /// Predictions are not kept per candidate (memory on long logs); the top one is
    /// recomputed from its fitted values (`Analysis::predict_with`).
    pub(super) fn fit_candidates(
        &self,
        configured: &[Box<dyn EffectModel>],
        base: &ExplainBaseline<'_>,
        full: Option<FullSeries>,
        cands: &[&dyn EffectModel],
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<(FullSeries, Vec<RankedCandidate>), AnalysisError> {
        use rayon::prelude::*;
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = cands.len().max(1);
        let candidates = || -> Result<Vec<Option<RankedCandidate>>, AnalysisError> {
            cands
                .par_iter()
                .map(|c| {
                    let r = self.evaluate_candidate(*c, base, opts);
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(k as f64 / total as f64);
                    r
                })
                .collect()
        };
        // A long log's candidates are ranked on the coarse series: the configured model's
        // run over the working series is only reported, so it runs beside them.
        let (full, results) = match full {
            Some(f) => (f, candidates()?),
            None => {
                let (f, r) = rayon::join(|| self.full_series(configured, base), candidates);
                (f?, r?)
            }
        };
        Ok((full, results.into_iter().flatten().collect()))
    }

    /// Adds candidate `c` to the configured model, fits both on the fit series and
    /// measures the result; `None` when the candidate cannot be ranked on this log.
    fn evaluate_candidate(
        &self,
        c: &dyn EffectModel,
        base: &ExplainBaseline<'_>,
        opts: &Options,
    ) -> Result<Option<RankedCandidate>, AnalysisError> {
        if self.cannot_fit(c, base) {
            return Ok(None);
        }
        let Ok(setup) = c.setup(&base.fit_series, &self.constants) else {
            return Ok(None);
        };
        let n_parameters = setup.len();
        let set = with_candidate(base, c, setup);
        let fd = &base.fit_series;
        let f = self.fit_set(fd, &set, &base.fit_weights, &base.fit.base, opts.fit_base)?;
        let (error, heldback_error) = self.candidate_errors(base, &set, &f)?;
        let Some(full) = self.on_working_series(base, &set) else {
            return Ok(None);
        };
        let f = align(&full, f);
        let Some(me) = self.fitted_effects(&full, &f)?.pop() else {
            return Ok(None);
        };
        let why = self.implausible(c, base, &me, &f)?;
        let summary = if why.is_empty() {
            me.summary
        } else {
            effects::not_physical(&why)
        };
        Ok(Some(RankedCandidate {
            candidate: EffectCandidate {
                effect: c.kind(),
                // Given by `stand` once every candidate is ranked.
                rank: None,
                standing: Standing::Candidate,
                normalized_rms_error: error,
                explained_fraction: explained_fraction(
                    base.heldback_error_fit_series,
                    heldback_error,
                    base.heldback_noise_fit_series,
                ),
                whole_log_explained_fraction: explained_fraction(
                    base.error_fit_series,
                    error,
                    base.noise_fit_series,
                ),
                validation_normalized_rms_error: heldback_error,
                n_parameters,
                parameters: me.parameters,
                summary,
                description: c.description().to_string(),
                plausible: why.is_empty(),
                implausible_because: why,
                fit: f.report,
            },
            fit: f,
            setups: full.into_iter().map(|a| a.setup).collect(),
        }))
    }

    /// True when candidate `c` cannot be fitted on this log: a channel it needs is
    /// missing, or it is not proposed on it ([`Analysis::cannot_rank`] says why).
    fn cannot_fit(&self, c: &dyn EffectModel, base: &ExplainBaseline<'_>) -> bool {
        c.needs().met_by(&self.data).is_err() || self.not_proposed(c, base).is_some()
    }

    /// A candidate model's errors over the whole log and on the held-back windows, on the
    /// series it was fitted on (the working series, or its coarse copy).
    fn candidate_errors(
        &self,
        base: &ExplainBaseline<'_>,
        set: &[ActiveEffect<'_>],
        f: &FitResult,
    ) -> Result<(f64, f64), AnalysisError> {
        let (series, mask) = if base.coarsening == 1 {
            (&*self.data, &base.heldback)
        } else {
            (&base.fit_series, &base.heldback_fit_series)
        };
        let pred = fit::predict(series, &self.constants, set, f)?;
        let e = metrics::errors(series, &pred, None).normalized_rms_error;
        let ev = metrics::errors(series, &pred, Some(mask)).normalized_rms_error;
        Ok((e, ev))
    }

    /// The effects of `set` set up on the working series (data-dependent set-ups redone
    /// when the fit ran on a coarse copy); `None` when a set-up refuses it.
    fn on_working_series<'a>(
        &self,
        base: &ExplainBaseline<'_>,
        set: &[ActiveEffect<'a>],
    ) -> Option<Vec<ActiveEffect<'a>>> {
        set.iter()
            .map(|a| {
                let setup = if base.coarsening == 1 {
                    a.setup.clone()
                } else {
                    a.effect.setup(&self.data, &self.constants).ok()?
                };
                Some(ActiveEffect {
                    effect: a.effect,
                    setup,
                })
            })
            .collect()
    }

    /// Why candidate `c`'s fit (its fitted effect `me`, the whole fit `f`) is not
    /// plausible: its own values out of range, what a measurement of the log independent
    /// of the fit says against them ([`EffectModel::contradicted_by`]), and a base
    /// parameter its refit takes out of range. One the configured model's own fit already
    /// has out of range does not count against it (the verdict reports that apart).
    fn implausible(
        &self,
        c: &dyn EffectModel,
        base: &ExplainBaseline<'_>,
        me: &FittedEffect,
        f: &FitResult,
    ) -> Result<Vec<String>, AnalysisError> {
        let d = &self.data;
        let mut why = me.implausible_because.clone();
        let fitted = f.reported().last().map_or(&[][..], Vec::as_slice);
        why.extend(c.contradicted_by(d, &self.constants, fitted)?);
        why.extend(base_newly_out_of_range(
            &self.constants,
            &base.fit.base,
            &f.base,
            d,
        ));
        Ok(why)
    }
}
