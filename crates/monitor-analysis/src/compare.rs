//! `compare`: the configured model's errors against the log, and where it fails.

use super::analysis::{
    align, resolve, Analysis, AnalysisError, DataInfo, FittedEffect, Options, ParamValue,
};
use super::metrics::{self, ErrorSummary, Weights, WorstWindow};
use super::simplified_model::{BaseParams, Prediction};
use super::unbalance::UnbalanceAnalysis;
use monitor_laws::EffectId;
use serde::Serialize;

/// Result of `compare` (its JSON document).
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// Effects in the model.
    pub effects: Vec<EffectId>,
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
    /// effects that cover them and the window past a start. Empty otherwise. (JSON
    /// `advice_values`, beside the sentences `advice`.)
    #[serde(rename = "advice_values")]
    pub advice: Vec<super::transients::Advice>,
    /// Fitted base parameters.
    pub base_parameters: std::collections::BTreeMap<String, ParamValue>,
    /// Fitted effects.
    pub fitted_effects: Vec<FittedEffect>,
    /// False when a fitted value (base parameter or effect) is outside its physical range.
    pub plausible: bool,
    /// Why not: each base parameter and effect value out of range (a prediction that
    /// diverged, `diverged_at_s`, is said before them at the door).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible_because: Vec<String>,
    /// What the log identifies: rank and conditioning of the fit's Jacobian and each base
    /// parameter's sensitivity (null when the base parameters were not refitted).
    pub identifiability: Option<super::fit::Jacobian>,
    /// The base parameters the log does not identify, each with why (JSON
    /// `not_identified_values`, beside the sentences `not_identified`: "j_kgm2 is not
    /// identified: the speed never changes in this log"); their values stay near the
    /// nominal ones.
    #[serde(rename = "not_identified_values")]
    pub not_identified: Vec<NotIdentifiedBase>,
    /// Analyses that could not run and why (JSON `skipped_reasons`, beside the sentences
    /// `skipped`).
    #[serde(rename = "skipped_reasons")]
    pub skipped: Vec<CompareSkip>,
    /// Unbalance analysis.
    pub unbalance: UnbalanceAnalysis,
    /// Rows read, working rate, frame.
    pub data: DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: monitor_io::log::quality::DataQuality,
    /// Where the model's error lives: its equations, windows, spectral lines and what it
    /// follows ([`crate::leftover`]); null where the model could not run or diverged.
    pub leftover: Option<crate::leftover::Leftover>,
}

/// An analysis `compare` could not run on a log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CompareSkip {
    /// The log has no speed column: omega_r is not compared (the model still predicts it).
    NoSpeed,
    /// The log has no voltages: the model's prediction is skipped (it is driven by V_qs);
    /// the unbalance analysis ran on the currents.
    NoVoltages,
}

/// A base parameter the log does not identify, with why and the numbers that decided.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NotIdentifiedBase {
    /// The parameter.
    pub parameter: super::simplified_model::BaseParameter,
    /// Why the log does not identify it.
    pub because: NotIdentifiedWhy,
    /// How much a 10 % change of it moves the model error.
    pub error_change_per_10_percent: f64,
    /// The least change that identifies a parameter ([`super::fit::IDENTIFIED_MIN`]).
    pub identified_min: f64,
}

/// Why a log does not identify a base parameter: how little what identifies it changes.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum NotIdentifiedWhy {
    /// J: the speed never changes (it spans `span` of its largest value).
    SpeedConstant {
        /// The speed's span over its largest value.
        span: f64,
    },
    /// J: the speed changes too little or too slowly for the inertia torque to matter.
    SpeedSlow,
    /// J or B + Bl: no speed column, and the currents alone hardly depend on it.
    NoSpeed,
    /// B + Bl: the speed never changes (spans `span`, synchronous `sync_rpm`): a viscous
    /// torque cannot be told from a constant one.
    ViscousAtOneSpeed {
        /// The speed's span over its largest value.
        span: f64,
        /// The log's highest synchronous speed [rpm].
        sync_rpm: f64,
    },
    /// B + Bl: the speed-dependent load torque is too small next to the other torques.
    ViscousSmall,
    /// Ls: the flux current hardly changes (spans `span`).
    FluxConstant {
        /// The flux current's span over its largest value.
        span: f64,
    },
    /// Ra: the load current hardly changes (spans `span`).
    LoadConstant {
        /// The load current's span over its largest value.
        span: f64,
    },
    /// The other fitted parameters compensate its change.
    Compensated,
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
            skipped.push(CompareSkip::NoSpeed);
        }
        let list = resolve(&opts.effects, &opts.laws);
        let fitted = self.fit_for_compare(&list, opts)?;
        let active = self.setup_all(d, &list)?;
        // Data-dependent set-ups (load steps) are recomputed on the full series; keep the
        // fitted values where the parameter count agrees.
        let f = align(&active, fitted.fit);
        let m = self.measure_compare(&active, &f, &list, fitted.span)?;
        let fitted_effects = self.fitted_effects(&active, &f)?;
        let implausible_because = self.compare_implausible(&f, &fitted_effects);
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
                plausible: m.diverged_at_s.is_none() && implausible_because.is_empty(),
                implausible_because,
                identifiability: fitted.jacobian,
                not_identified: fitted.not_identified,
                skipped,
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
                leftover: m.leftover,
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
            .map(|j| not_identified(j, &self.data, &self.constants))
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
        let in_model: Vec<EffectId> = list.iter().map(|e| e.kind()).collect();
        let plan = super::transients::dynamics_plan(span, &self.constants, &in_model);
        let (tags, advice) =
            super::transients::advice(d, &self.constants, &worst, &in_model, &plan);
        for (w, t) in worst.iter_mut().zip(tags) {
            w.transient = t;
        }
        let diverged_at_s = metrics::diverged_at(d, &pred);
        let leftover = diverged_at_s.is_none().then(|| {
            let m = crate::leftover::Measured {
                error: err.normalized_rms_error,
                noise_floor,
                band: super::explain::NOISE_MARGIN,
            };
            crate::leftover::locate(d, &self.constants, &pred, m)
        });
        Ok(CompareMeasures {
            diverged_at_s,
            leftover: leftover.flatten(),
            noise_floor,
            err,
            worst,
            all_windows: all,
            advice,
            prediction: pred,
        })
    }

    /// Why `compare`'s fit `f` is not plausible: the base parameters and the fitted effects
    /// out of their physical ranges (a diverged prediction is the report's
    /// `diverged_at_s`).
    fn compare_implausible(
        &self,
        f: &super::fit::FitResult,
        fitted_effects: &[FittedEffect],
    ) -> Vec<String> {
        let mut why = super::base_range::base_implausible(&self.constants, &f.base, &self.data);
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
    /// The base parameters not identified, with why.
    not_identified: Vec<NotIdentifiedBase>,
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
    advice: Vec<super::transients::Advice>,
    /// The prediction.
    prediction: Prediction,
    /// Where its error lives (`None` where it diverged).
    leftover: Option<crate::leftover::Leftover>,
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
                skipped: vec![CompareSkip::NoVoltages],
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
                leftover: None,
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

    /// Why the log does not identify base parameter `p`.
    fn why_not(&self, p: super::simplified_model::BaseParameter) -> NotIdentifiedWhy {
        use super::simplified_model::BaseParameter::{BPlusBl, Ls, Ra, J};
        match (p, self.speed) {
            (J, Some(span)) if span < 0.02 => NotIdentifiedWhy::SpeedConstant { span },
            (J, Some(_)) => NotIdentifiedWhy::SpeedSlow,
            (J | BPlusBl, None) => NotIdentifiedWhy::NoSpeed,
            (BPlusBl, Some(span)) if span < 0.02 => NotIdentifiedWhy::ViscousAtOneSpeed {
                span,
                sync_rpm: self.sync_rpm,
            },
            (BPlusBl, Some(_)) => NotIdentifiedWhy::ViscousSmall,
            (Ls, _) if self.flux < 0.05 => NotIdentifiedWhy::FluxConstant { span: self.flux },
            (Ra, _) if self.load < 0.05 => NotIdentifiedWhy::LoadConstant { span: self.load },
            _ => NotIdentifiedWhy::Compensated,
        }
    }
}

/// The base parameters a Jacobian finds unidentified, each with the reason the log gives:
/// how much the measured speed, flux current and load current change over it.
fn not_identified(
    j: &super::fit::Jacobian,
    d: &super::prep::Prepared,
    n: &super::simplified_model::MachineConstants,
) -> Vec<NotIdentifiedBase> {
    let spans = Spans::of(d, n);
    j.base
        .iter()
        .filter(|p| !p.identified)
        .map(|p| NotIdentifiedBase {
            parameter: p.parameter,
            because: spans.why_not(p.parameter),
            error_change_per_10_percent: p.error_change_per_10_percent,
            identified_min: super::fit::IDENTIFIED_MIN,
        })
        .collect()
}
