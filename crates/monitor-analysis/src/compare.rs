//! `compare`: the configured model's errors against the log, and where it fails.

use super::analysis::{
    align, resolve, Analysis, AnalysisError, DataInfo, FittedEffect, Options, ParamValue,
};
use super::metrics::{self, ErrorSummary, Weights, WorstWindow};
use super::simplified_model::{BaseParams, Prediction};
use super::unbalance::UnbalanceAnalysis;
use monitor_core::EffectKind;
use serde::Serialize;

/// Result of `compare` (its JSON document).
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// Effects in the model.
    pub effects: Vec<EffectKind>,
    /// Mean normalised RMS error over the channels.
    pub normalized_rms_error: f64,
    /// Where the model's prediction diverged [s] ([`metrics::diverged_at`]): then
    /// `normalized_rms_error` measures nothing. Absent (JSON) when it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diverged_at_s: Option<f64>,
    /// The error a perfect model would show (sensor noise) on the same measure.
    pub noise_floor: f64,
    /// Per-channel errors.
    pub channels: Vec<metrics::ChannelError>,
    /// Where the model fails most.
    pub worst_windows: Vec<WorstWindow>,
    /// What to do when the worst windows are transients (a start, a step): the dynamics
    /// effects that cover them and the `--from` past a start. Empty otherwise.
    pub advice: Vec<String>,
    /// Fitted base parameters.
    pub base_parameters: std::collections::BTreeMap<String, ParamValue>,
    /// Fitted effects.
    pub fitted_effects: Vec<FittedEffect>,
    /// False when a fitted value (base parameter or effect) is outside its physical range.
    pub plausible: bool,
    /// Why not (one line per value out of range; empty when plausible).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible_because: Vec<String>,
    /// What the log identifies: rank and conditioning of the fit's Jacobian and each base
    /// parameter's sensitivity (null when the base parameters were not refitted).
    pub identifiability: Option<super::fit::Jacobian>,
    /// The base parameters the log does not identify, in words ("j_kgm2 is not identified:
    /// the speed never changes in this log"); their values stay near the nominal ones.
    pub not_identified: Vec<String>,
    /// Analyses that could not run and why.
    pub skipped: Vec<String>,
    /// Unbalance analysis.
    pub unbalance: UnbalanceAnalysis,
    /// Rows read, working rate, frame.
    pub data: DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: monitor_io::log::quality::DataQuality,
}

/// Everything `compare` computed, for plots and the report.
pub struct CompareOutput {
    /// The JSON-facing report.
    pub report: CompareReport,
    /// The prediction.
    pub prediction: Prediction,
    /// All windows (for error-vs-condition plots).
    pub all_windows: Vec<WorstWindow>,
}

impl Analysis {
    /// `compare`: fit the configured model and measure where it fails.
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub fn compare(&self, opts: &Options) -> Result<CompareOutput, AnalysisError> {
        let d = &self.data;
        let unbalance = self.unbalance();
        let info = self.info();
        if !d.channels.voltages {
            return Ok(self.compare_current_only(opts, unbalance, info));
        }
        let mut skipped = Vec::new();
        if !d.channels.speed {
            skipped.push("omega_r not compared: the log has no wm_rad_s column (the model still predicts it)".into());
        }
        let list = resolve(&opts.effects);
        let fitted = self.fit_for_compare(&list, opts)?;
        let active = self.setup_all(d, &list)?;
        // Data-dependent set-ups (load steps) are recomputed on the full series; keep the
        // fitted values where the parameter count agrees.
        let f = align(&active, fitted.fit);
        let m = self.measure_compare(&active, &f, &list, fitted.span)?;
        let fitted_effects = self.fitted_effects(&active, &f)?;
        let implausible_because = self.compare_implausible(&f, &m, &fitted_effects);
        Ok(CompareOutput {
            report: CompareReport {
                effects: list.iter().map(|e| e.kind()).collect(),
                normalized_rms_error: m.err.normalized_rms_error,
                diverged_at_s: m.diverged_at_s,
                noise_floor: m.noise_floor,
                channels: m.err.channels,
                worst_windows: m.worst,
                advice: m.advice,
                base_parameters: self.base_table(&f.base),
                fitted_effects,
                plausible: implausible_because.is_empty(),
                implausible_because,
                identifiability: fitted.jacobian,
                not_identified: fitted.not_identified,
                skipped,
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
            },
            prediction: m.prediction,
            all_windows: m.all_windows,
        })
    }

    /// The configured model (`list`) fitted on the fit series (coarse for a long log),
    /// with what the log identifies of its base parameters.
    fn fit_for_compare(
        &self,
        list: &[Box<dyn super::effects::EffectModel>],
        opts: &Options,
    ) -> Result<FittedForCompare, AnalysisError> {
        let (fd, _) = self.fit_data();
        let active_fit = self.setup_all(&fd, list)?;
        let wf = Weights::new(&fd, 0, super::MAX_FIT_SAMPLES);
        let nominal = BaseParams::nominal(&self.constants);
        let fit = self.fit_set(&fd, &active_fit, &wf, &nominal, opts.fit_base)?;
        let jacobian =
            super::fit::jacobian(&fd, &self.constants, &active_fit, &wf, &fit, opts.fit_base)?;
        let not_identified = jacobian
            .as_ref()
            .map(|j| not_identified_in_words(j, &self.data, &self.constants))
            .unwrap_or_default();
        Ok(FittedForCompare {
            fit,
            jacobian,
            not_identified,
            span: super::transients::Span::of(&fd, &self.constants),
        })
    }

    /// The fitted model `f` of the effects `active` (the configured `list`) run over the
    /// working series and measured: its errors, noise floor, windows (the worst tagged
    /// with the transient they lie in) and the advice on them, by the rule `explain` skips
    /// dynamics effects by on the fit series' `span` ([`super::transients::dynamics_plan`]).
    fn measure_compare(
        &self,
        active: &[super::fit::ActiveEffect<'_>],
        f: &super::fit::FitResult,
        list: &[Box<dyn super::effects::EffectModel>],
        span: super::transients::Span,
    ) -> Result<CompareMeasures, AnalysisError> {
        let d = &self.data;
        let w = Weights::new(d, 0, usize::MAX);
        let (pred, renoised) = self.predict_and_renoised(d, active, f)?;
        let noise_floor = metrics::noise_floor(d, &w, Some((&pred, &renoised)));
        let err: ErrorSummary = metrics::errors(d, &pred, None);
        let v_rated = self.params.supply.v_phase_peak();
        let (mut worst, all) = metrics::windows(d, &pred, &w, v_rated, self.constants.np, 40, 3);
        let in_model: Vec<EffectKind> = list.iter().map(|e| e.kind()).collect();
        let plan = super::transients::dynamics_plan(span, &self.constants, &in_model);
        let (tags, advice) =
            super::transients::advice(d, &self.constants, &worst, &in_model, &plan, &*self.words);
        for (w, t) in worst.iter_mut().zip(tags) {
            w.transient = t;
        }
        Ok(CompareMeasures {
            diverged_at_s: metrics::diverged_at(d, &pred),
            noise_floor,
            err,
            worst,
            all_windows: all,
            advice,
            prediction: pred,
        })
    }

    /// Why `compare`'s fit `f` is not plausible: a diverged prediction first, then the
    /// base parameters and the fitted effects out of their physical ranges.
    fn compare_implausible(
        &self,
        f: &super::fit::FitResult,
        m: &CompareMeasures,
        fitted_effects: &[FittedEffect],
    ) -> Vec<String> {
        let mut why = super::base_implausible(&self.constants, &f.base, &self.data);
        if let Some(t) = m.diverged_at_s {
            why.insert(
                0,
                format!(
                    "the model diverged at {t:.3} s (its predicted current left {}x the largest measured): the error \
                     {:.4} measures nothing; add the effects the advice names, or leave the start out ({})",
                    metrics::DIVERGED_CURRENT_RATIO,
                    m.err.normalized_rms_error,
                    self.words.hint(monitor_replay::OptionField::From, "")
                ),
            );
        }
        for fe in fitted_effects {
            why.extend(
                fe.implausible_because
                    .iter()
                    .map(|w| format!("{}: {w}", fe.effect)),
            );
        }
        why
    }
}

/// `compare`'s fit on the fit series and what the log identifies.
struct FittedForCompare {
    /// The fit.
    fit: super::fit::FitResult,
    /// The fit's Jacobian (`None` when the base parameters were not fitted).
    jacobian: Option<super::fit::Jacobian>,
    /// The base parameters not identified, in words.
    not_identified: Vec<String>,
    /// What the fit series offers the dynamics effects (the advice's rule).
    span: super::transients::Span,
}

/// `compare`'s measures of the fitted model on the working series.
struct CompareMeasures {
    /// Where the prediction diverged [s].
    diverged_at_s: Option<f64>,
    /// The noise floor.
    noise_floor: f64,
    /// The errors over the whole log.
    err: ErrorSummary,
    /// The worst windows, tagged with their transients.
    worst: Vec<WorstWindow>,
    /// Every window.
    all_windows: Vec<WorstWindow>,
    /// The advice on the worst windows.
    advice: Vec<String>,
    /// The prediction.
    prediction: Prediction,
}

impl Analysis {
    /// `compare` on a log without voltages: the model cannot run; only the unbalance
    /// analysis.
    fn compare_current_only(
        &self,
        opts: &Options,
        unbalance: UnbalanceAnalysis,
        info: DataInfo,
    ) -> CompareOutput {
        CompareOutput {
            report: CompareReport {
                effects: opts.effects.clone(),
                normalized_rms_error: f64::NAN,
                diverged_at_s: None,
                noise_floor: f64::NAN,
                channels: vec![],
                worst_windows: vec![],
                advice: vec![],
                base_parameters: Default::default(),
                fitted_effects: vec![],
                plausible: true,
                implausible_because: vec![],
                identifiability: None,
                not_identified: vec![],
                skipped: vec!["model prediction (I_qs, omega_r, phase currents) skipped: the log has no voltage columns va_V, vb_V, vc_V, and the model is driven by V_qs; the unbalance analysis ran on the currents".into()],
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
            },
            prediction: Prediction::default(),
            all_windows: vec![],
        }
    }
}

/// How much the log's measured speed, flux current and load current change, each
/// relative to its largest magnitude (the speed `None` without a speed column): what
/// identifies the base parameters.
struct Spans {
    speed: Option<f64>,
    flux: f64,
    load: f64,
    /// The log's highest synchronous speed [rpm].
    sync_rpm: f64,
}

impl Spans {
    fn of(d: &super::prep::Prepared, n: &super::simplified_model::MachineConstants) -> Self {
        let span = |x: &[f64]| {
            let (lo, hi) = x
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let scale = x.iter().fold(0.0f64, |a, &v| a.max(v.abs())).max(1e-9);
            if hi >= lo {
                (hi - lo) / scale
            } else {
                0.0
            }
        };
        Spans {
            speed: d.channels.speed.then(|| span(&d.omega_r)),
            flux: span(&d.i_f),
            load: span(&d.iq),
            sync_rpm: super::effects::sync_speed_mech(d, n) * 60.0 / (2.0 * std::f64::consts::PI),
        }
    }

    /// Why the log does not identify base parameter `p`, in words.
    fn why_not(&self, p: super::simplified_model::BaseParameter) -> String {
        use super::simplified_model::BaseParameter::{BPlusBl, Ls, Ra, J};
        match (p, self.speed) {
            (J, Some(s)) if s < 0.02 => format!(
                "the speed never changes in this log (it spans {:.1} % of its largest value)",
                100.0 * s
            ),
            (J, Some(_)) => "the speed changes too little or too slowly for the inertia torque to matter next to the other torques".into(),
            (J | BPlusBl, None) => "the log has no speed column, and the currents alone hardly depend on it".into(),
            (BPlusBl, Some(s)) if s < 0.02 => format!(
                "the speed never changes in this log (spans {:.1} %, synchronous {:.0} rpm): a viscous torque cannot be told from a constant one",
                100.0 * s,
                self.sync_rpm
            ),
            (BPlusBl, Some(_)) => "the speed-dependent load torque is too small next to the other torques".into(),
            (Ls, _) if self.flux < 0.05 => format!(
                "the flux current hardly changes (spans {:.1} %), so Ls trades off against Ra at one operating point",
                100.0 * self.flux
            ),
            (Ra, _) if self.load < 0.05 => format!(
                "the load current hardly changes (spans {:.1} %), so Ra trades off against Ls at one operating point",
                100.0 * self.load
            ),
            _ => "the other fitted parameters compensate its change".into(),
        }
    }
}

/// The base parameters a Jacobian finds unidentified, each with the reason the log gives:
/// how much the measured speed, flux current and load current change over it.
fn not_identified_in_words(
    j: &super::fit::Jacobian,
    d: &super::prep::Prepared,
    n: &super::simplified_model::MachineConstants,
) -> Vec<String> {
    let spans = Spans::of(d, n);
    j.base
        .iter()
        .filter(|p| !p.identified)
        .map(|p| {
            format!(
                "{} is not identified: {} (a 10 % change moves the error by {:.4}, below {})",
                p.parameter,
                spans.why_not(p.parameter),
                p.error_change_per_10_percent,
                super::fit::IDENTIFIED_MIN
            )
        })
        .collect()
}
