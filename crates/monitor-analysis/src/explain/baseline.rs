//! Stages 2 to 4 of `explain`: the configured model fitted and measured (the baseline
//! every candidate is compared with), its base parameters refitted with what the log
//! identifies of them, and whether its error is structural.

use super::HOLDOUT_WINDOWS;
use crate::analysis::{align, Analysis, AnalysisError, Options, MAX_FIT_SAMPLES};
use crate::effects::EffectModel;
use crate::fit::{self, ActiveEffect, FitResult};
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::refit::BaseRefit;
use crate::simplified_model::{BaseParams, Prediction};
use crate::transients;
use monitor_laws::EffectId;

/// The configured model fitted and measured: what every candidate is compared with.
pub(super) struct ExplainBaseline<'a> {
    /// The series the fits run on (the working series, or a coarser one for long logs).
    pub(super) fit_series: Prepared,
    /// The fit series' coarsening factor (1: the working series).
    pub(super) coarsening: usize,
    /// Training/held-back split on the fit series.
    pub(super) fit_weights: Weights,
    /// Training/held-back split on the working series.
    pub(super) weights: Weights,
    /// The held-back mask of the working series ([`HOLDOUT_WINDOWS`]).
    pub(super) heldback: Vec<bool>,
    /// The held-back mask of the fit series.
    pub(super) heldback_fit_series: Vec<bool>,
    /// The configured effects set up on the fit series.
    pub(super) active: Vec<ActiveEffect<'a>>,
    /// Their fit.
    pub(super) fit: FitResult,
    /// The whole-log error on the fit series (what a candidate's whole-log error is
    /// compared with; the same as the working series' unless the log was coarsened).
    pub(super) error_fit_series: f64,
    /// The whole-log noise floor on the fit series ([`metrics::noise_floor`]).
    pub(super) noise_fit_series: f64,
    /// The held-back error on the fit series (candidates are ranked there; the same as
    /// the working series' unless the log was coarsened).
    pub(super) heldback_error_fit_series: f64,
    /// The noise floor of the held-back windows of the fit series
    /// ([`metrics::noise_floor_on`]).
    pub(super) heldback_noise_fit_series: f64,
    /// What the fit series offers a dynamics effect: its sample period and whether it
    /// holds a transient of the model's inputs (a start or a supply step,
    /// [`transients::input_transients`]).
    pub(super) span: transients::Span,
    /// The measures on the working series, when the fit series is the working series
    /// (else computed while the candidates are fitted: [`Analysis::full_series`]).
    pub(super) full: Option<FullSeries>,
}

/// The configured model on the working series.
pub(super) struct FullSeries {
    /// Its prediction.
    pub(super) before: Prediction,
    /// Its error over the whole log.
    pub(super) error: f64,
    /// Its error on the held-back windows.
    pub(super) heldback_error: f64,
    /// The noise floor over the whole log.
    pub(super) noise: f64,
    /// The noise floor of the held-back windows, normalized as the held-back error is
    /// ([`metrics::noise_floor_on`]).
    pub(super) heldback_noise: f64,
}

/// Stage 4: whether the configured model's error is structural. Through a start or a
/// supply step, a model without the always-present dynamics (`flux_dynamics` and
/// `current_dynamics`) flags its base parameters because they absorb what it cannot
/// follow: the verdict says so, and recentring on them would judge effects against that
/// error.
pub(super) fn structural_error(base: &ExplainBaseline<'_>, names: &[EffectId]) -> bool {
    base.span.input_transient
        && ![EffectId::FLUX_DYNAMICS, EffectId::CURRENT_DYNAMICS]
            .iter()
            .all(|k| names.contains(k))
}

impl Analysis {
    /// Stage 2: fits the configured model and measures it on the fit series (for a long
    /// log, the coarser series the candidates are ranked on); when that is the working
    /// series, on the whole log and the held-back windows too ([`ExplainBaseline::full`]).
    pub(super) fn baseline<'a>(
        &self,
        configured: &'a [Box<dyn EffectModel>],
        opts: &Options,
    ) -> Result<ExplainBaseline<'a>, AnalysisError> {
        let (fd, m) = self.fit_data();
        let wf = Weights::new(&fd, HOLDOUT_WINDOWS, MAX_FIT_SAMPLES);
        let w_full = Weights::new(&self.data, HOLDOUT_WINDOWS, usize::MAX);
        let heldback: Vec<bool> = w_full.train.iter().map(|t| !t).collect();
        let active = self.setup_all(&fd, configured)?;
        let nominal = BaseParams::nominal(&self.constants);
        let f0 = self.fit_set(&fd, &active, &wf, &nominal, opts.fit_base)?;
        let heldback_fit_series: Vec<bool> = wf.train.iter().map(|t| !t).collect();
        let span = transients::Span::of(&fd, &self.constants);
        let mut base = ExplainBaseline {
            fit_series: fd,
            coarsening: m,
            fit_weights: wf,
            weights: w_full,
            heldback,
            heldback_fit_series,
            active,
            fit: f0,
            error_fit_series: f64::NAN,
            noise_fit_series: f64::NAN,
            heldback_error_fit_series: f64::NAN,
            heldback_noise_fit_series: f64::NAN,
            span,
            full: None,
        };
        self.measure_baseline(configured, &mut base)?;
        Ok(base)
    }

    /// The baseline's whole-log and held-back errors and noise floors on the fit series: from the
    /// working series' measures when the fit series is the working series (kept in
    /// [`ExplainBaseline::full`]); for a long log (fitted on a coarser series) on that series,
    /// where the candidates are ranked too.
    fn measure_baseline(
        &self,
        configured: &[Box<dyn EffectModel>],
        base: &mut ExplainBaseline<'_>,
    ) -> Result<(), AnalysisError> {
        if base.coarsening == 1 {
            let full = self.full_series(configured, base)?;
            base.error_fit_series = full.error;
            base.noise_fit_series = full.noise;
            base.heldback_error_fit_series = full.heldback_error;
            base.heldback_noise_fit_series = full.heldback_noise;
            base.full = Some(full);
        } else {
            let fd = &base.fit_series;
            let b = fit::predict(fd, &self.constants, &base.active, &base.fit)?;
            base.heldback_error_fit_series =
                metrics::errors(fd, &b, Some(&base.heldback_fit_series)).normalized_rms_error;
            let renoised = self.renoised(fd, &base.active, &base.fit)?;
            base.error_fit_series = metrics::errors(fd, &b, None).normalized_rms_error;
            base.noise_fit_series =
                metrics::noise_floor(fd, &base.fit_weights, Some((&b, &renoised)));
            base.heldback_noise_fit_series =
                metrics::noise_floor_on(fd, &base.heldback_fit_series, Some((&b, &renoised)));
        }
        Ok(())
    }

    /// Stage 3: the configured model's base parameters as refitted in `base`, with what
    /// the log identifies of them ([`fit::jacobian`] on the fit series).
    pub(super) fn base_refit(
        &self,
        base: &ExplainBaseline<'_>,
        opts: &Options,
    ) -> Result<BaseRefit, AnalysisError> {
        let jac = fit::jacobian(
            &base.fit_series,
            &self.constants,
            &base.active,
            &base.fit_weights,
            &base.fit,
            opts.fit_base,
        )?;
        Ok(BaseRefit::new(
            &self.constants,
            &base.fit.base,
            jac.as_ref(),
        ))
    }

    /// The configured model fitted in `base`, run over the working series and measured
    /// there: over the whole log, on the held-back windows, and its noise floor.
    pub(super) fn full_series(
        &self,
        configured: &[Box<dyn EffectModel>],
        base: &ExplainBaseline<'_>,
    ) -> Result<FullSeries, AnalysisError> {
        let d = &self.data;
        let active_full = self.setup_all(d, configured)?;
        let f0_full = align(&active_full, base.fit.clone());
        let (before, renoised) = self.predict_and_renoised(d, &active_full, &f0_full)?;
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
}
