//! Stages 5 and 6 of `explain`: which effects of the library are candidates and which of
//! them cannot be ranked on this log (and why), and each rankable candidate added to the
//! configured model, fitted and measured on the held-back windows.

use super::baseline::{Baseline, FullSeries};
use super::ranking::RankedCandidate;
use super::{explained_fraction, EffectCandidate};
use crate::analysis::effects::{EffectModel, SetupError};
use crate::analysis::fit::{self, ActiveEffect, FitResult};
use crate::analysis::simplified_model::BaseParameter;
use crate::analysis::{align, base_out_of_range, metrics, transients};
use crate::analysis::{Analysis, AnalysisError, FittedEffect, Options};
use monitor_core::EffectKind;

/// Stage 5: the effects of the library `lib` that are not in the model (`names`), the
/// candidates `explain` tries.
pub(super) fn candidates<'a>(
    lib: &'a [Box<dyn EffectModel>],
    names: &[EffectKind],
) -> Vec<&'a dyn EffectModel> {
    lib.iter()
        .map(|e| e.as_ref())
        .filter(|e| !names.contains(&e.kind()))
        .collect()
}

/// Why `explain` does not rank a candidate on this log (the report's `skipped`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum NotRanked {
    /// Effects it needs in the model first ([`EffectModel::requires`]).
    #[error("needs {} in the model first", names(.0))]
    Requires(Vec<EffectKind>),
    /// Its time constant `tau_s` [s] is shorter than 3 samples of the fit series (period
    /// `dt_s` [s]).
    #[error("the fit series of this long log ({:.0} Hz) cannot resolve a {:.1} ms time constant; analyse a shorter window with --from/--to", 1.0 / dt_s, 1000.0 * tau_s)]
    Unresolved {
        /// Sample period of the fit series [s].
        dt_s: f64,
        /// The effect's time constant [s].
        tau_s: f64,
    },
    /// A dynamics effect (time constant `tau_s` [s]) on a log without a start or a supply
    /// step.
    #[error("no start or supply step in the analysed span (voltage and frequency within {:.0} %): its {:.1} ms dynamics have nothing to act on", 100.0 * transients::STEP_MIN, 1000.0 * tau_s)]
    NoTransient {
        /// The effect's time constant [s].
        tau_s: f64,
    },
    /// The log lacks a channel, or the set-up refuses the data.
    #[error(transparent)]
    Setup(SetupError),
}

/// Effect names, comma separated.
fn names(kinds: &[EffectKind]) -> String {
    kinds
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The effects `c` needs in the model first ([`EffectModel::requires`]) that the
/// configured model lacks, as the reason it is not proposed yet.
fn missing_requirement(c: &dyn EffectModel, base: &Baseline<'_>) -> Option<NotRanked> {
    let missing: Vec<EffectKind> = c
        .requires()
        .iter()
        .copied()
        .filter(|k| !base.active.iter().any(|a| a.effect.kind() == *k))
        .collect();
    (!missing.is_empty()).then_some(NotRanked::Requires(missing))
}

/// The configured effects of `base`, each starting from its baseline fit, with candidate
/// `c` (set up as `setup`) added last.
fn with_candidate<'a>(
    base: &Baseline<'a>,
    c: &'a dyn EffectModel,
    setup: crate::analysis::effects::FitSetup,
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
    pub(super) fn skipped(&self, cands: &[&dyn EffectModel], base: &Baseline<'_>) -> Vec<String> {
        cands
            .iter()
            .filter_map(|c| {
                self.cannot_rank(*c, base)
                    .map(|m| format!("{}: {m}", c.kind()))
            })
            .collect()
    }

    /// Why a candidate cannot be ranked on this log, if it cannot: an effect it needs in
    /// the model first, a dynamics effect whose time constant the (coarse) fit series of a
    /// long log cannot resolve or that has no transient to act on, a missing channel, or a
    /// set-up the data refuse (e.g. `load_torque` on a log without a load change: said,
    /// not dropped).
    fn cannot_rank(&self, c: &dyn EffectModel, base: &Baseline<'_>) -> Option<NotRanked> {
        if let Some(m) = missing_requirement(c, base) {
            return Some(m);
        }
        if let Some(m) = self.not_dynamic(c, base) {
            return Some(m);
        }
        let setup = c
            .needs()
            .met_by(&self.data)
            .and_then(|()| c.setup(&base.fit_series, &self.constants).map(|_| ()));
        setup.err().map(NotRanked::Setup)
    }

    /// Why a dynamics effect (one that declares a time constant,
    /// [`EffectModel::time_constant_s`]) is not proposed on this log: its time constant is
    /// shorter than 3 samples of the (coarse) fit series of a long log, or the log has no
    /// transient of the model's inputs for its dynamics to act on. Without a start or a
    /// supply step the electrical states follow the inputs quasi-statically (a load step
    /// moves the speed at the mechanical rate), the full-order machine's steady state is
    /// the paper's model, and what a dynamics effect's extra states gain there they gain by
    /// absorbing another effect (docs/model-vs-measurement.md, "How it works").
    fn not_dynamic(&self, c: &dyn EffectModel, base: &Baseline<'_>) -> Option<NotRanked> {
        let tau_s = c.time_constant_s(&self.constants)?;
        let dt_s = base.fit_series.dt_s;
        if dt_s > tau_s / 3.0 {
            return Some(NotRanked::Unresolved { dt_s, tau_s });
        }
        (!base.has_input_transient).then_some(NotRanked::NoTransient { tau_s })
    }

    /// Stage 6 (fit): every candidate of `cands` that can be ranked, fitted in parallel
    /// (`progress` told the fraction done), and, unless `full` already holds them, the
    /// configured model's measures on the working series ([`Analysis::full_series`]).
    /// Predictions are not kept per candidate (memory on long logs); the top one is
    /// recomputed from its fitted values (`Analysis::predict_with`).
    pub(super) fn fit_candidates(
        &self,
        configured: &[Box<dyn EffectModel>],
        base: &Baseline<'_>,
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
        base: &Baseline<'_>,
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
        Ok(Some(RankedCandidate {
            candidate: EffectCandidate {
                effect: c.kind(),
                normalized_rms_error: error,
                explained_fraction: explained_fraction(
                    base.heldback_error_fit_series,
                    heldback_error,
                    base.heldback_noise_fit_series,
                ),
                validation_normalized_rms_error: heldback_error,
                n_parameters,
                parameters: me.parameters,
                summary: me.summary,
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
    /// missing, an effect it needs is not in the model, or it is a dynamics effect the log
    /// cannot show ([`Analysis::cannot_rank`] says why).
    fn cannot_fit(&self, c: &dyn EffectModel, base: &Baseline<'_>) -> bool {
        c.needs().met_by(&self.data).is_err()
            || missing_requirement(c, base).is_some()
            || self.not_dynamic(c, base).is_some()
    }

    /// A candidate model's errors over the whole log and on the held-back windows, on the
    /// series it was fitted on (the working series, or its coarse copy).
    fn candidate_errors(
        &self,
        base: &Baseline<'_>,
        set: &[ActiveEffect<'_>],
        f: &FitResult,
    ) -> Result<(f64, f64), AnalysisError> {
        let (series, mask) = if base.coarsening == 1 {
            (&self.data, &base.heldback)
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
        base: &Baseline<'_>,
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
        base: &Baseline<'_>,
        me: &FittedEffect,
        f: &FitResult,
    ) -> Result<Vec<String>, AnalysisError> {
        let d = &self.data;
        let already: Vec<BaseParameter> = base_out_of_range(&self.constants, &base.fit.base, d)
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        let mut why = me.implausible_because.clone();
        let fitted = f.effect_params.last().map_or(&[][..], Vec::as_slice);
        why.extend(c.contradicted_by(d, &self.constants, fitted)?);
        why.extend(
            base_out_of_range(&self.constants, &f.base, d)
                .into_iter()
                .filter(|(k, _)| !already.contains(k))
                .map(|(_, w)| w),
        );
        Ok(why)
    }
}
