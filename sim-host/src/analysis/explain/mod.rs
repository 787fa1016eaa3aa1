//! `explain`: which physical effect of the library is missing from the model, ranked by the
//! error it removes on held-back windows.

use super::effects::{self, EffectEvidence, EffectModel, FitSetup, SetupError};
use super::fit::{self, ActiveEffect, FitResult, FittedModel};
use super::metrics::{self, Weights};
use super::prep::Prepared;
use super::refit::BaseRefit;
use super::simplified_model::{BaseParams, MachineConstants, Prediction};
use super::transients;
use super::unbalance::UnbalanceAnalysis;
use super::{align, resolve, Analysis, AnalysisError, DataInfo, Options, ParamValue};
use monitor_core::EffectKind;
use serde::Serialize;

/// A candidate explaining less than this fraction of the held-back error is not claimed.
pub const EXPLAINED_MIN: f64 = 0.5;
/// A baseline within this factor of the noise floor has nothing left to explain
/// (1.12 = a model error beyond the noise of half the noise floor).
pub const NOISE_MARGIN: f64 = 1.12;
/// Below this `normalized_rms_error` (0.4 %) the model is as good as the frame estimate and
/// the working-rate reconstruction allow; nothing is claimed even on noise-free data.
pub const MIN_MODEL_ERROR: f64 = 0.004;
/// Ranking penalty per parameter: a candidate's held-back error is multiplied by
/// `1 + PARAM_PENALTY * n_parameters`, so a richer effect must fit clearly better.
pub const PARAM_PENALTY: f64 = 0.02;
/// Interleaved held-back windows for ranking (the log is cut into 2x this many windows).
///
/// A fixed interleave can alias with a log's events. With 5 (10 windows), a 3.4 s log's
/// start and three supply steps all fell in training windows, and thermal drift on an
/// 11 kW machine, seen mostly in the transients, read as unexplained; with 10, the one
/// flux peak of a 7 s voltage sweep fell only in held-back windows, and the saturation fit
/// had to extrapolate past its knee there. 8 serves both (docs/model-vs-measurement.md, "How it works"); a
/// split stratified by the operating point is the real fix and is not built.
pub const HOLDOUT_WINDOWS: usize = 8;

/// Fraction of the model error beyond the sensor noise that a candidate removes:
/// `1 - S_with / S_base`, `S = sqrt(max(E^2 - N^2, 0))` (E the held-back error, N the
/// noise floor), clamped to 0..1. A candidate that brings the error down to the noise floor
/// explains everything there was to explain. When the baseline's excess `S_base` is below
/// half the noise floor (the baseline within [`NOISE_MARGIN`] of it) there is nothing to
/// explain and the fraction is 0: a ratio of two noise-sized numbers means nothing.
pub fn explained_fraction(e_base: f64, e_with: f64, noise: f64) -> f64 {
    let s = |e: f64| (e * e - noise * noise).max(0.0).sqrt();
    let sb = s(e_base);
    if sb <= 0.0 || sb < 0.5 * noise {
        return 0.0;
    }
    (1.0 - s(e_with) / sb).clamp(0.0, 1.0)
}

/// One candidate effect of `explain`.
#[derive(Debug, Clone, Serialize)]
pub struct EffectCandidate {
    /// Which effect.
    pub effect: EffectKind,
    /// `normalized_rms_error` over the whole log with this effect added.
    pub normalized_rms_error: f64,
    /// Fraction of the held-back model error beyond the noise floor explained
    /// (see [`explained_fraction`]).
    pub explained_fraction: f64,
    /// `normalized_rms_error` on the held-back windows.
    pub validation_normalized_rms_error: f64,
    /// Number of parameters the effect adds.
    pub n_parameters: usize,
    /// Fitted parameters.
    pub parameters: std::collections::BTreeMap<String, ParamValue>,
    /// In words.
    pub summary: String,
    /// What the effect is.
    pub description: String,
    /// False when a fitted value (the effect's, or a base parameter refitted with it) is
    /// outside its physical range ([`effects::plausible`]): such a candidate is ranked after
    /// every plausible one and never named by the verdict.
    pub plausible: bool,
    /// Why not (one entry per value out of range; empty when plausible).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible_because: Vec<String>,
    /// How the candidate's fit ended: `{iterations, cost, termination}` (`converged`,
    /// `slow_progress`, `iteration_limit`, `stalled`, `nothing_to_fit`), from [`super::lm`].
    pub fit: super::lm::Report,
}

/// Result of `explain` (its JSON document).
#[derive(Debug, Clone, Serialize)]
pub struct ExplainReport {
    /// Effects already in the model.
    pub effects: Vec<EffectKind>,
    /// Error of the model as configured (whole log).
    pub baseline_normalized_rms_error: f64,
    /// Error of the model as configured on the held-back windows.
    pub baseline_validation_normalized_rms_error: f64,
    /// Noise floor.
    pub noise_floor: f64,
    /// Candidates, best first.
    pub ranking: Vec<EffectCandidate>,
    /// True when no candidate explains the error well.
    pub unexplained: bool,
    /// The conclusion in words.
    pub verdict: String,
    /// Candidates not evaluated and why.
    pub skipped: Vec<String>,
    /// Unbalance analysis.
    pub unbalance: UnbalanceAnalysis,
    /// Facts about the data.
    pub data: DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: crate::log::quality::DataQuality,
    /// The base parameters refitted to the log before effects were judged, file value
    /// against refitted value, and whether the model was recentred on them because the
    /// file's values did not fit ([`super::refit`]). `None` when the model did not run
    /// (a current-only log).
    pub base_refit: Option<BaseRefit>,
}

/// Everything `explain` computed.
pub struct ExplainOutput {
    /// The JSON-facing report.
    pub report: ExplainReport,
    /// Prediction of the configured model.
    pub before: Prediction,
    /// Prediction with the top-ranked candidate added (None when nothing was fitted).
    pub after: Option<(EffectKind, Prediction)>,
}

/// The configured model fitted and measured: what every candidate is compared with.
struct Baseline<'a> {
    /// The series the fits run on (the working series, or a coarser one for long logs)
    /// and its coarsening factor.
    fit_series: Prepared,
    coarsening: usize,
    /// Training/held-back split on the fit series and on the working series, and the
    /// held-back masks of both.
    fit_weights: Weights,
    weights: Weights,
    heldback: Vec<bool>,
    heldback_fit_series: Vec<bool>,
    /// The configured effects set up on the fit series, and the fit.
    active: Vec<ActiveEffect<'a>>,
    fit: FitResult,
    /// The held-back error and the noise floor of the held-back windows
    /// ([`metrics::noise_floor_on`]) on the fit series (candidates are ranked there; the
    /// same as the working series' unless the log was coarsened).
    heldback_error_fit_series: f64,
    heldback_noise_fit_series: f64,
    /// Whether the fit series holds a transient of the model's inputs (a start or a
    /// supply step, [`transients::input_transients`]).
    has_input_transient: bool,
    /// The measures on the working series, when the fit series is the working series
    /// (else computed while the candidates are fitted: [`Analysis::full_series`]).
    full: Option<FullSeries>,
}

/// The configured model on the working series.
struct FullSeries {
    /// Its prediction.
    before: Prediction,
    /// Its error over the whole log, on the held-back windows, and the noise floor of
    /// each (the held-back one normalized as the held-back error is,
    /// [`metrics::noise_floor_on`]).
    error: f64,
    heldback_error: f64,
    noise: f64,
    heldback_noise: f64,
}

/// A ranked candidate with its fit, kept to rebuild the best one's prediction.
struct RankedCandidate {
    candidate: EffectCandidate,
    fit: FitResult,
    setups: Vec<FitSetup>,
}

impl RankedCandidate {
    /// Held-back error with each extra parameter costing [`PARAM_PENALTY`] of it.
    fn score(&self) -> f64 {
        let c = &self.candidate;
        c.validation_normalized_rms_error * (1.0 + PARAM_PENALTY * c.n_parameters as f64)
    }
}

impl Analysis {
    /// `explain`: rank the library effects not in the model by the held-back error they
    /// remove. `progress` gets the fraction of candidates done.
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub fn explain(
        &self,
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<ExplainOutput, AnalysisError> {
        self.explain_once(opts, progress, true)
    }

    /// [`Analysis::explain`]; when `may_recentre` and the configured model's own fit is
    /// not physically plausible, the model is recentred on the identified refitted base
    /// parameters and explained again ([`super::refit`]).
    fn explain_once(
        &self,
        opts: &Options,
        progress: &(dyn Fn(f64) + Sync),
        may_recentre: bool,
    ) -> Result<ExplainOutput, AnalysisError> {
        let unbalance = self.unbalance();
        let info = self.info();
        let configured = resolve(&opts.effects);
        let names: Vec<EffectKind> = configured.iter().map(|e| e.kind()).collect();
        if !self.data.channels.voltages {
            return Ok(withhold_if_untrusted(explain_current_only(
                names,
                unbalance,
                info,
                self.quality.clone(),
            )));
        }
        let mut base = self.baseline(&configured, opts)?;
        let mut refit = self.base_refit(&base, opts);
        let flagged = super::base_out_of_range(&self.constants, &base.fit.base, &self.data);
        // Through a start or a supply step, a model without the always-present dynamics
        // flags its base parameters because they absorb what it cannot follow: the verdict
        // says so, and recentring on them would judge effects against that error.
        let structural = base.has_input_transient
            && ![EffectKind::FluxDynamics, EffectKind::CurrentDynamics]
                .iter()
                .all(|k| names.contains(k));
        let full = base.full.take();
        let base = base;
        let lib = effects::library();
        let cands: Vec<&dyn EffectModel> = lib
            .iter()
            .map(|e| e.as_ref())
            .filter(|e| !names.contains(&e.kind()))
            .collect();
        let skipped: Vec<String> = cands
            .iter()
            .filter_map(|c| {
                self.cannot_rank(*c, &base)
                    .map(|m| format!("{}: {m}", c.kind()))
            })
            .collect();
        let (full, mut ranked) =
            self.fit_candidates(&configured, &base, full, &cands, opts, progress)?;
        rank(&mut ranked, &unbalance, self.constants.torque_scale_nm);
        let best = ranked
            .first()
            .filter(|c| c.candidate.plausible)
            .map(|c| c.candidate.explained_fraction)
            .unwrap_or(0.0);
        let near_noise =
            full.heldback_error <= (NOISE_MARGIN * full.heldback_noise).max(MIN_MODEL_ERROR);
        let unexplained = best < EXPLAINED_MIN || near_noise;
        // Recentred only when nothing could be named on the file's model: a missing effect
        // also pushes the base parameters out of range, and then naming it is the answer.
        if may_recentre
            && unexplained
            && !near_noise
            && !structural
            && flagged.iter().any(|(k, _)| refit.identifies(k))
        {
            let because = flagged.into_iter().map(|(_, why)| why).collect();
            let params = refit.recentred_params(&self.params);
            let recentred = Analysis {
                data: self.data.clone(),
                constants: MachineConstants::from_params(&params),
                params,
                quality: self.quality.clone(),
            };
            let mut out = recentred.explain_once(opts, progress, false)?;
            refit.recentred = true;
            refit.because = because;
            out.report.base_refit = Some(refit);
            return Ok(out);
        }
        let verdict = self.verdict(&names, &base, &full, &ranked, near_noise, unexplained);
        let after = match ranked.first() {
            Some(r) if !unexplained => Some((r.candidate.effect, self.predict_with(&names, r))),
            _ => None,
        };
        Ok(withhold_if_untrusted(ExplainOutput {
            report: ExplainReport {
                effects: names,
                baseline_normalized_rms_error: full.error,
                baseline_validation_normalized_rms_error: full.heldback_error,
                noise_floor: full.noise,
                ranking: ranked.into_iter().map(|c| c.candidate).collect(),
                unexplained,
                verdict,
                skipped,
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
                base_refit: Some(refit),
            },
            before: full.before,
            after,
        }))
    }

    /// Fits every candidate of `cands` that can be ranked (in parallel, `progress` told the
    /// fraction done) and, unless `full` already holds them, the configured model's
    /// measures on the working series ([`Analysis::full_series`]). Predictions are not kept
    /// per candidate (memory on long logs); the top one is recomputed from its fitted
    /// values ([`Analysis::predict_with`]).
    fn fit_candidates(
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
        let candidates = || -> Vec<Option<RankedCandidate>> {
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
            Some(f) => (f, candidates()),
            None => {
                let (f, r) = rayon::join(|| self.full_series(configured, base), candidates);
                (f?, r)
            }
        };
        Ok((full, results.into_iter().flatten().collect()))
    }

    /// The verdict ([`verdict`]) with the notes on implausible candidates and on an
    /// implausible fit of the configured model itself.
    fn verdict(
        &self,
        names: &[EffectKind],
        base: &Baseline<'_>,
        full: &FullSeries,
        ranked: &[RankedCandidate],
        near_noise: bool,
        unexplained: bool,
    ) -> String {
        let first_plausible = ranked.iter().find(|c| c.candidate.plausible);
        let mut v = verdict(names, base, full, first_plausible, near_noise, unexplained);
        v.push_str(&implausible_note(ranked));
        let base_why = super::base_implausible(&self.constants, &base.fit.base, &self.data);
        if !base_why.is_empty() {
            v.push_str(&format!(
                ". The configured model's own fit is not plausible ({}): the base parameters absorb an error the model cannot follow; if the log has a start or steps, see compare's advice (dynamics effects or --from)",
                base_why.join("; ")
            ));
        }
        v
    }

    /// The prediction of the configured model (`names`) with candidate `r` added, from
    /// their fitted values, on the working series.
    fn predict_with(&self, names: &[EffectKind], r: &RankedCandidate) -> Prediction {
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
        model.predict(&self.data, &self.constants)
    }

    /// Fits the configured model and measures it on the fit series (for a long log, the
    /// coarser series the candidates are ranked on); when that is the working series, on
    /// the whole log and the held-back windows too ([`Baseline::full`]).
    fn baseline<'a>(
        &self,
        configured: &'a [Box<dyn EffectModel>],
        opts: &Options,
    ) -> Result<Baseline<'a>, AnalysisError> {
        let d = &self.data;
        let (fd, m) = self.fit_data();
        let wf = Weights::new(&fd, HOLDOUT_WINDOWS, super::MAX_FIT_SAMPLES);
        let w_full = Weights::new(d, HOLDOUT_WINDOWS, usize::MAX);
        let heldback: Vec<bool> = w_full.train.iter().map(|t| !t).collect();
        let active = self.setup_all(&fd, configured)?;
        let f0 = self.fit_set(
            &fd,
            &active,
            &wf,
            &BaseParams::nominal(&self.constants),
            opts.fit_base,
        );
        let heldback_fit_series: Vec<bool> = wf.train.iter().map(|t| !t).collect();
        let has_input_transient = transients::input_transients(&fd, &self.constants)
            .iter()
            .any(|&t| t);
        let mut base = Baseline {
            fit_series: fd,
            coarsening: m,
            fit_weights: wf,
            weights: w_full,
            heldback,
            heldback_fit_series,
            active,
            fit: f0,
            heldback_error_fit_series: f64::NAN,
            heldback_noise_fit_series: f64::NAN,
            has_input_transient,
            full: None,
        };
        if m == 1 {
            let full = self.full_series(configured, &base)?;
            base.heldback_error_fit_series = full.heldback_error;
            base.heldback_noise_fit_series = full.heldback_noise;
            base.full = Some(full);
        } else {
            // Long logs (fitted on a coarser series): candidates are ranked on that series,
            // so the baseline they are compared with is measured there too.
            let fd = &base.fit_series;
            let b = fit::predict(fd, &self.constants, &base.active, &base.fit);
            base.heldback_error_fit_series =
                metrics::errors(fd, &b, Some(&base.heldback_fit_series)).normalized_rms_error;
            let renoised = self.renoised(fd, &base.active, &base.fit);
            base.heldback_noise_fit_series =
                metrics::noise_floor_on(fd, &base.heldback_fit_series, Some((&b, &renoised)));
        }
        Ok(base)
    }

    /// The configured model's base parameters as refitted in `base`, with what the log
    /// identifies of them ([`fit::jacobian`] on the fit series).
    fn base_refit(&self, base: &Baseline<'_>, opts: &Options) -> BaseRefit {
        let jac = fit::jacobian(
            &base.fit_series,
            &self.constants,
            &base.active,
            &base.fit_weights,
            &base.fit,
            opts.fit_base,
        );
        BaseRefit::new(&self.constants, &base.fit.base, jac.as_ref())
    }

    /// The configured model fitted in `base`, run over the working series and measured
    /// there: over the whole log, on the held-back windows, and its noise floor.
    fn full_series(
        &self,
        configured: &[Box<dyn EffectModel>],
        base: &Baseline<'_>,
    ) -> Result<FullSeries, AnalysisError> {
        let d = &self.data;
        let active_full = self.setup_all(d, configured)?;
        let f0_full = align(&active_full, base.fit.clone());
        let (before, renoised) = self.predict_and_renoised(d, &active_full, &f0_full);
        let noise = metrics::noise_floor(d, &base.weights, Some((&before, &renoised)));
        let heldback_noise = metrics::noise_floor_on(d, &base.heldback, Some((&before, &renoised)));
        let error = metrics::errors(d, &before, None).normalized_rms_error;
        let heldback_error = metrics::errors(d, &before, Some(&base.heldback)).normalized_rms_error;
        Ok(FullSeries {
            before,
            error,
            heldback_error,
            noise,
            heldback_noise,
        })
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

    /// Adds candidate `c` to the configured model, fits both on the fit series and
    /// measures the result; `None` when the candidate cannot be ranked on this log.
    fn evaluate_candidate(
        &self,
        c: &dyn EffectModel,
        base: &Baseline<'_>,
        opts: &Options,
    ) -> Option<RankedCandidate> {
        let d = &self.data;
        let fd = &base.fit_series;
        c.needs().met_by(d).ok()?;
        if missing_requirement(c, base).is_some() || self.not_dynamic(c, base).is_some() {
            return None;
        }
        // The configured effects start from their baseline fit.
        let mut set: Vec<ActiveEffect<'_>> = base
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
        let s = c.setup(fd, &self.constants).ok()?;
        let np = s.len();
        set.push(ActiveEffect {
            effect: c,
            setup: s,
        });
        let f = self.fit_set(fd, &set, &base.fit_weights, &base.fit.base, opts.fit_base);
        // Ranked on the series it was fitted on (the working series, or its coarse copy).
        let (series, mask) = if base.coarsening == 1 {
            (d, &base.heldback)
        } else {
            (fd, &base.heldback_fit_series)
        };
        let pred = fit::predict(series, &self.constants, &set, &f);
        let e = metrics::errors(series, &pred, None).normalized_rms_error;
        let ev = metrics::errors(series, &pred, Some(mask)).normalized_rms_error;
        // The fitted values on the full working series (data-dependent set-ups redone).
        let mut full: Vec<ActiveEffect<'_>> = Vec::with_capacity(set.len());
        for a in &set {
            full.push(ActiveEffect {
                effect: a.effect,
                setup: if base.coarsening == 1 {
                    a.setup.clone()
                } else {
                    a.effect.setup(d, &self.constants).ok()?
                },
            });
        }
        let f = align(&full, f);
        let setups: Vec<FitSetup> = full.iter().map(|a| a.setup.clone()).collect();
        let me = self.fitted_effects(&full, &f).pop()?;
        // A base parameter the candidate's refit takes out of range counts against it; one
        // the configured model's own fit already has out of range does not (the verdict
        // reports that apart).
        let already: Vec<&str> = super::base_out_of_range(&self.constants, &base.fit.base, d)
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        let mut why = me.implausible_because.clone();
        // A cage asymmetry is named only when the current spectrum agrees with the fit.
        if c.kind() == EffectKind::RotorAsymmetry {
            let delta = me.parameters.get("delta").map(|p| p.value);
            why.extend(delta.and_then(|dl| {
                super::rotor_asymmetry::spectrum_contradicts(d, self.constants.np, dl)
            }));
        }
        why.extend(
            super::base_out_of_range(&self.constants, &f.base, d)
                .into_iter()
                .filter(|(k, _)| !already.contains(k))
                .map(|(_, w)| w),
        );
        Some(RankedCandidate {
            candidate: EffectCandidate {
                effect: c.kind(),
                normalized_rms_error: e,
                explained_fraction: explained_fraction(
                    base.heldback_error_fit_series,
                    ev,
                    base.heldback_noise_fit_series,
                ),
                validation_normalized_rms_error: ev,
                n_parameters: np,
                parameters: me.parameters,
                summary: me.summary,
                description: c.description().to_string(),
                plausible: why.is_empty(),
                implausible_because: why,
                fit: f.report,
            },
            fit: f,
            setups,
        })
    }
}

/// Why `explain` does not rank a candidate on this log (the report's `skipped`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum NotRanked {
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

/// `explain` on a log without voltages: the model cannot run; only the unbalance analysis.
/// A verdict never rests on data the data-quality stage rejected: when the stage does not
/// trust the log, the ranking stays in the report but the verdict says why no effect is
/// named, and no effect is added.
fn withhold_if_untrusted(mut out: ExplainOutput) -> ExplainOutput {
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

fn explain_current_only(
    names: Vec<EffectKind>,
    unbalance: UnbalanceAnalysis,
    info: DataInfo,
    quality: crate::log::quality::DataQuality,
) -> ExplainOutput {
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
            unexplained: unbalance.suspect_phase.is_none(),
            verdict,
            skipped,
            unbalance,
            data: info,
            data_quality: quality,
            base_refit: None,
        },
        before: Prediction::default(),
        after: None,
    }
}

/// Ranks by held-back error, each extra parameter costing [`PARAM_PENALTY`] of it,
/// plausible candidates first; then, when the first two are effects that declare each other
/// confusable ([`EffectModel::confused_with`]) and are within the declared factor, the
/// log's evidence ([`EffectModel::evidence`]) decides: a first one it contradicts goes
/// second unless it contradicts the other too. No rule names a particular effect.
fn rank(ranked: &mut [RankedCandidate], unbalance: &UnbalanceAnalysis, torque_scale_nm: f64) {
    ranked.sort_by(|a, b| {
        b.candidate
            .plausible
            .cmp(&a.candidate.plausible)
            .then(a.score().total_cmp(&b.score()))
            .then(a.candidate.n_parameters.cmp(&b.candidate.n_parameters))
    });
    // Only ever reorders two plausible candidates.
    if ranked.len() < 2 || !ranked[1].candidate.plausible {
        return;
    }
    let (first, second) = (&ranked[0], &ranked[1]);
    let model = effects::model_of(first.candidate.effect);
    let Some(conf) = model
        .confused_with()
        .iter()
        .find(|c| c.with == second.candidate.effect)
    else {
        return;
    };
    if second.score() > conf.within * first.score() {
        return;
    }
    let says = |r: &RankedCandidate| {
        let fitted = r.fit.effect_params.last().map(Vec::as_slice).unwrap_or(&[]);
        effects::model_of(r.candidate.effect).evidence(&EffectEvidence {
            voltage_unbalance: unbalance.voltage_negative_sequence_ratio,
            winding_suspected: unbalance.suspect_phase.is_some(),
            torque_scale_nm,
            fitted,
        })
    };
    if says(first) == Some(false) && says(second) != Some(false) {
        ranked.swap(0, 1);
    }
}

/// The verdict's note on candidates whose fits are not physically plausible: those that
/// would have explained more than the one named (or the threshold) are listed with the
/// first reason, so that a user sees why they are not the answer.
fn implausible_note(ranked: &[RankedCandidate]) -> String {
    let top_plausible = ranked
        .iter()
        .find(|c| c.candidate.plausible)
        .map(|c| c.score())
        .unwrap_or(f64::INFINITY);
    let listed: Vec<String> = ranked
        .iter()
        .filter(|c| !c.candidate.plausible && c.score() < top_plausible)
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
            ". Not plausible, so ranked last and not named: {}",
            listed.join("; ")
        )
    }
}

/// The conclusion in words.
fn verdict(
    names: &[EffectKind],
    base: &Baseline<'_>,
    full: &FullSeries,
    best: Option<&RankedCandidate>,
    near_noise: bool,
    unexplained: bool,
) -> String {
    match best {
        _ if near_noise => format!(
            "nothing to explain: the model's error {:.4} (held-back {:.4}) is within {:.2}x the noise floor {:.4} (held-back {:.4}) or below {:.3}",
            full.error, full.heldback_error, NOISE_MARGIN, full.noise, full.heldback_noise, MIN_MODEL_ERROR
        ),
        Some(r) if !unexplained => {
            let c = &r.candidate;
            format!(
                "missing effect: {} explains {:.0} % of the held-back error ({:.4} -> {:.4}); {}. Add it with --effects {}",
                c.effect,
                100.0 * c.explained_fraction,
                base.heldback_error_fit_series,
                c.validation_normalized_rms_error,
                c.summary,
                names
                    .iter()
                    .chain([&c.effect])
                    .map(|e| e.name())
                    .collect::<Vec<_>>()
                    .join(",")
            )
        }
        Some(r) => format!(
            "unexplained: the best candidate ({}) explains only {:.0} % of the held-back error (threshold {:.0} %); the error is not one of the library's effects",
            r.candidate.effect,
            100.0 * r.candidate.explained_fraction,
            100.0 * EXPLAINED_MIN
        ),
        None => "unexplained: no candidate could be fitted with physically plausible values".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::explained_fraction;

    #[test]
    fn explained_fraction_of_the_excess_over_noise() {
        // Baseline 5x the noise, candidate at the noise floor: everything explained.
        assert!((explained_fraction(0.05, 0.01, 0.01) - 1.0).abs() < 1e-12);
        // Candidate halves the excess: sqrt(0.05^2 - 0.01^2) -> half of it.
        let sb = (0.05f64.powi(2) - 0.01f64.powi(2)).sqrt();
        let e_with = ((0.5 * sb).powi(2) + 0.01f64.powi(2)).sqrt();
        assert!((explained_fraction(0.05, e_with, 0.01) - 0.5).abs() < 1e-9);
        // A baseline within the noise margin has nothing to explain.
        assert_eq!(explained_fraction(0.0105, 0.0100, 0.0100), 0.0);
        // A candidate that makes things worse explains nothing.
        assert_eq!(explained_fraction(0.05, 0.06, 0.01), 0.0);
    }
}
