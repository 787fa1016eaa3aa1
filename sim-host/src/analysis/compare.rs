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
    /// The error a perfect model would show (sensor noise) on the same measure.
    pub noise_floor: f64,
    /// Per-channel errors.
    pub channels: Vec<metrics::ChannelError>,
    /// Where the model fails most.
    pub worst_windows: Vec<WorstWindow>,
    /// Fitted base parameters.
    pub base_parameters: std::collections::BTreeMap<String, ParamValue>,
    /// Fitted effects.
    pub fitted_effects: Vec<FittedEffect>,
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
            skipped.push("model prediction (I_qs, omega_r, phase currents) skipped: the log has no voltage columns va_V, vb_V, vc_V, and the model is driven by V_qs; the unbalance analysis ran on the currents".into());
            return Ok(CompareOutput {
                report: CompareReport {
                    effects: opts.effects.clone(),
                    normalized_rms_error: f64::NAN,
                    noise_floor: f64::NAN,
                    channels: vec![],
                    worst_windows: vec![],
                    base_parameters: Default::default(),
                    fitted_effects: vec![],
                    skipped,
                    unbalance,
                    data: info,
                    data_quality: self.quality.clone(),
                },
                prediction: Prediction::default(),
                all_windows: vec![],
            });
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
        );
        let active = self.setup_all(d, &list)?;
        // Data-dependent set-ups (load steps) are recomputed on the full series; keep the
        // fitted values where the parameter count agrees.
        let f = align(&active, f);
        let pred = super::fit::predict(d, &self.constants, &active, &f);
        let w = Weights::new(d, 0, usize::MAX);
        let err: ErrorSummary = metrics::errors(d, &pred, None);
        let (worst, all) = metrics::windows(
            d,
            &pred,
            &w,
            self.params.supply.v_phase_peak(),
            self.constants.np,
            40,
            3,
        );
        Ok(CompareOutput {
            report: CompareReport {
                effects: list.iter().map(|e| e.kind()).collect(),
                normalized_rms_error: err.normalized_rms_error,
                noise_floor: self.model_noise_floor(d, &active, &f, &pred, &w),
                channels: err.channels,
                worst_windows: worst,
                base_parameters: self.base_table(&f.base),
                fitted_effects: self.fitted_effects(&active, &f),
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
