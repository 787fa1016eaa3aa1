//! `compare`: the configured model's errors against the log, and where it fails.

use super::metrics::{self, ErrorSummary, Weights, WorstWindow};
use super::simplified_model::{BaseParams, Prediction};
use super::unbalance::UnbalanceAnalysis;
use super::{align, resolve, Analysis, AnalysisError, DataInfo, FittedEffect, Options, ParamValue};
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
    pub data_quality: crate::log::quality::DataQuality,
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
        let mut skipped = Vec::new();
        let unbalance = self.unbalance();
        let info = self.info();
        if !d.channels.voltages {
            return Ok(self.compare_current_only(opts, unbalance, info));
        }
        if !d.channels.speed {
            skipped.push("omega_r not compared: the log has no wm_rad_s column (the model still predicts it)".into());
        }
        let list = resolve(&opts.effects);
        let (fd, _) = self.fit_data();
        let active_fit = self.setup_all(&fd, &list)?;
        let wf = Weights::new(&fd, 0, super::MAX_FIT_SAMPLES);
        let f = self.fit_set(
            &fd,
            &active_fit,
            &wf,
            &BaseParams::nominal(&self.constants),
            opts.fit_base,
        )?;
        let jac = super::fit::jacobian(&fd, &self.constants, &active_fit, &wf, &f, opts.fit_base)?;
        let not_identified = jac
            .as_ref()
            .map(|j| not_identified_in_words(j, d, &self.constants))
            .unwrap_or_default();
        let active = self.setup_all(d, &list)?;
        // Data-dependent set-ups (load steps) are recomputed on the full series; keep the
        // fitted values where the parameter count agrees.
        let f = align(&active, f);
        let w = Weights::new(d, 0, usize::MAX);
        let (pred, renoised) = self.predict_and_renoised(d, &active, &f)?;
        let noise_floor = metrics::noise_floor(d, &w, Some((&pred, &renoised)));
        let err: ErrorSummary = metrics::errors(d, &pred, None);
        let (mut worst, all) = metrics::windows(
            d,
            &pred,
            &w,
            self.params.supply.v_phase_peak(),
            self.constants.np,
            40,
            3,
        );
        let in_model: Vec<EffectKind> = list.iter().map(|e| e.kind()).collect();
        let (tags, advice) = super::transients::advice(d, &self.constants, &worst, &in_model);
        for (w, t) in worst.iter_mut().zip(tags) {
            w.transient = t;
        }
        let base_parameters = self.base_table(&f.base);
        let fitted_effects = self.fitted_effects(&active, &f)?;
        let mut implausible_because = super::base_implausible(&self.constants, &f.base, d);
        let diverged_at_s = metrics::diverged_at(d, &pred);
        if let Some(t) = diverged_at_s {
            implausible_because.insert(
                0,
                format!(
                    "the model diverged at {t:.3} s (its predicted current left {}x the largest measured): the error \
                     {:.4} measures nothing; add the effects the advice names, or leave the start out (--from)",
                    metrics::DIVERGED_CURRENT_RATIO,
                    err.normalized_rms_error
                ),
            );
        }
        for fe in &fitted_effects {
            implausible_because.extend(
                fe.implausible_because
                    .iter()
                    .map(|w| format!("{}: {w}", fe.effect)),
            );
        }
        Ok(CompareOutput {
            report: CompareReport {
                effects: list.iter().map(|e| e.kind()).collect(),
                normalized_rms_error: err.normalized_rms_error,
                diverged_at_s,
                noise_floor,
                channels: err.channels,
                worst_windows: worst,
                advice,
                base_parameters,
                fitted_effects,
                plausible: implausible_because.is_empty(),
                implausible_because,
                identifiability: jac,
                not_identified,
                skipped,
                unbalance,
                data: info,
                data_quality: self.quality.clone(),
            },
            prediction: pred,
            all_windows: all,
        })
    }
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

/// The base parameters a Jacobian finds unidentified, each with the reason the log gives:
/// how much the measured speed, flux current and load current change over it.
fn not_identified_in_words(
    j: &super::fit::Jacobian,
    d: &super::prep::Prepared,
    n: &super::simplified_model::MachineConstants,
) -> Vec<String> {
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
    let speed_span = if d.channels.speed {
        Some(span(&d.omega_r))
    } else {
        None
    };
    let flux_span = span(&d.i_f);
    let load_span = span(&d.iq);
    let sync_rpm = super::effects::sync_speed_mech(d, n) * 60.0 / (2.0 * std::f64::consts::PI);
    j.base
        .iter()
        .filter(|p| !p.identified)
        .map(|p| {
            let why = match (p.parameter, speed_span) {
                ("j_kgm2", Some(s)) if s < 0.02 => format!(
                    "the speed never changes in this log (it spans {:.1} % of its largest value)",
                    100.0 * s
                ),
                ("j_kgm2", Some(_)) => "the speed changes too little or too slowly for the inertia torque to matter next to the other torques".into(),
                ("j_kgm2" | "b_plus_bl_nms", None) => "the log has no speed column, and the currents alone hardly depend on it".into(),
                ("b_plus_bl_nms", Some(s)) if s < 0.02 => format!(
                    "the speed never changes in this log (spans {:.1} %, synchronous {:.0} rpm): a viscous torque cannot be told from a constant one",
                    100.0 * s,
                    sync_rpm
                ),
                ("b_plus_bl_nms", Some(_)) => "the speed-dependent load torque is too small next to the other torques".into(),
                ("ls_h", _) if flux_span < 0.05 => format!(
                    "the flux current hardly changes (spans {:.1} %), so Ls trades off against Ra at one operating point",
                    100.0 * flux_span
                ),
                ("ra_ohm", _) if load_span < 0.05 => format!(
                    "the load current hardly changes (spans {:.1} %), so Ra trades off against Ls at one operating point",
                    100.0 * load_span
                ),
                _ => "the other fitted parameters compensate its change".into(),
            };
            format!(
                "{} is not identified: {why} (a 10 % change moves the error by {:.4}, below {})",
                p.parameter,
                p.error_change_per_10_percent,
                super::fit::IDENTIFIED_MIN
            )
        })
        .collect()
}
