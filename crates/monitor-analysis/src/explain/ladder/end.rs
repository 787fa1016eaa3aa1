//! The ladder's end: the chosen model (its effects and its base parameters) refitted on the
//! whole log, and the summary that opens with what was found.
//!
//! The steps are chosen on held-back windows and fitted on a thinned copy of the training
//! windows: an honest choice, but short of what the chosen model reaches on the whole log
//! (`effect_load_torque.toml` ended at 2.85x its floor where `compare` with the same
//! effects reached 1.5x). So the final figures come from one more fit of the chosen model,
//! on every sample of the working series (thinned only beyond [`crate::MAX_FIT_SAMPLES`],
//! as `compare`'s), from the last step's values, with the six base parameters free
//! ([`crate::fit::machine`]): the base changes are read there, with their intervals.

use super::base::{base_changes, base_in_words, BaseChange};
use super::round::{LadderSeries, Rung};
use super::LadderReport;
use crate::effects::{self, EffectModel};
use crate::fit::machine::{self, MachineFit};
use crate::fit::{ActiveEffect, BaseSpec, FitResult};
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::simplified_model::BaseParams;
use crate::{align, Analysis, AnalysisError, FittedEffect, MAX_ITER};
use monitor_core::EffectKind;
use serde::Serialize;

/// The chosen model refitted on the whole log (JSON `final_fit`).
#[derive(Debug, Clone, Serialize)]
pub struct FinalFit {
    /// The effects of the chosen model.
    pub effects: Vec<EffectKind>,
    /// `normalized_rms_error` over the whole log.
    pub error: f64,
    /// The whole log's noise floor for the model.
    pub noise_floor: f64,
    /// `error / noise_floor`.
    pub ratio_to_floor: f64,
    /// The start's error over this one.
    pub below_start: f64,
    /// The six base parameters against the user's file, with their intervals.
    pub base: Vec<BaseChange>,
    /// The effects with their values.
    pub fitted: Vec<FittedEffect>,
    /// Samples the fit used.
    pub fit_samples: usize,
}

impl Analysis {
    /// The end of the ladder that stopped at `rung`: the final refit on the whole log
    /// ([`FinalFit`]), the base changes, and the summary (what was found, then why it
    /// stopped). `self` is the analysis of the user's file; `progress` gets the fraction.
    pub(super) fn finish(
        &self,
        rung: &Rung<'_>,
        sr: &LadderSeries,
        report: &mut LadderReport,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<(), AnalysisError> {
        progress(0.0);
        let fin = self.final_fit(rung, sr, report.start.error)?;
        progress(1.0);
        report.summary = summary(report, fin.as_ref());
        if let Some(f) = &fin {
            report.base_changes = f.base.iter().filter(|c| c.changed).cloned().collect();
        }
        report.final_fit = fin;
        Ok(())
    }

    /// The model of `rung` refitted on the whole working series (coarsened as `compare`'s
    /// fit), from its values; `None` when a set-up refuses the series.
    fn final_fit(
        &self,
        rung: &Rung<'_>,
        sr: &LadderSeries,
        start_error: f64,
    ) -> Result<Option<FinalFit>, AnalysisError> {
        let (fdata, _) = self.fit_data();
        let an = self.rebased(rung.scales.apply(&sr.file));
        let Some(set) = an.nested_from(&rung.models, &rung.fit.effect_params, &[], &fdata) else {
            return Ok(None);
        };
        let (mf, half) = an.machine_on(&fdata, rung, sr, &set)?;
        let fin = self.rebased(mf.params(&sr.file));
        let models: Vec<&dyn EffectModel> = rung.models.clone();
        let active = fin.setup_list(&self.data, &models)?;
        let fit = align(
            &active,
            FitResult {
                base: BaseParams::nominal(&fin.constants),
                effect_params: mf.effect_params.clone(),
                report: mf.report,
            },
        );
        let (pred, renoised) = fin.predict_and_renoised(&self.data, &active, &fit)?;
        let all = Weights::new(&self.data, 0, usize::MAX);
        let noise = metrics::noise_floor(&self.data, &all, Some((&pred, &renoised)));
        let error = metrics::errors(&self.data, &pred, None).normalized_rms_error;
        let fitted = fin.fitted_effects(&active, &fit)?;
        Ok(Some(FinalFit {
            effects: rung.kinds.clone(),
            error,
            noise_floor: noise,
            ratio_to_floor: error / noise,
            below_start: start_error / error,
            base: base_changes(&mf.scales, &sr.file, &half),
            fitted,
            fit_samples: fdata.len(),
        }))
    }
}

impl Analysis {
    /// The model of `rung` (its effects set up as `set`) fitted on `fdata` from the last
    /// step's values: with the six base parameters free beside its effects
    /// ([`machine::fit_machine`], their 95 % half-widths), or, where the log cannot refit the
    /// base parameters, its effects alone on the rung's base (no half-widths).
    fn machine_on(
        &self,
        fdata: &Prepared,
        rung: &Rung<'_>,
        sr: &LadderSeries,
        set: &[ActiveEffect<'_>],
    ) -> Result<(MachineFit, [Option<f64>; 6]), AnalysisError> {
        let w = Weights::new(fdata, 0, usize::MAX);
        if sr.fit_base {
            let mf = machine::fit_machine(
                fdata,
                &sr.file,
                set,
                &w,
                &rung.scales.with_paper(&rung.fit.base),
                super::base::prior_weight(rung.noise),
                MAX_ITER,
            )?;
            let half = machine::machine_half_widths(fdata, &sr.file, set, &w, &mf)?;
            return Ok((mf, half));
        }
        let f = self.fit_spec(
            fdata,
            set,
            &w,
            &rung.fit.base,
            BaseSpec::FIXED.for_effects(set),
        )?;
        let mf = MachineFit {
            scales: rung.scales,
            effect_params: f.effect_params,
            report: f.report,
        };
        Ok((mf, [None; 6]))
    }
}

/// The ladder's summary: what was found (the base changes and the effects the steps added,
/// with their sizes), where the chosen model ends on the whole log, then why it stopped.
fn summary(r: &LadderReport, fin: Option<&FinalFit>) -> String {
    let mut found: Vec<String> = Vec::new();
    if let Some(f) = fin {
        if f.base.iter().any(|c| c.changed) {
            found.push(format!("base parameters: {}", base_in_words(&f.base)));
        }
        let dynamics: Vec<&str> = f
            .fitted
            .iter()
            .filter(|e| e.effect.name().ends_with("_dynamics"))
            .map(|e| e.effect.name())
            .filter(|k| !r.start.effects.iter().any(|s| s.name() == *k))
            .collect();
        if !dynamics.is_empty() {
            found.push(format!(
                "the machine's own dynamics ({})",
                dynamics.join(", ")
            ));
        }
        for e in f.fitted.iter().filter(|e| {
            !e.effect.name().ends_with("_dynamics") && !r.start.effects.contains(&e.effect)
        }) {
            found.push(format!("{}: {}", e.effect, e.summary));
        }
    } else {
        for s in &r.ladder {
            if let Some(e) = s.effect {
                found.push(e.name().to_string());
            }
        }
    }
    let dropped: Vec<String> = r
        .ladder
        .iter()
        .flat_map(|s| s.dropped.iter().map(|k| k.name().to_string()))
        .collect();
    let mut out = if found.is_empty() {
        "found: nothing the model lacks on this log".to_string()
    } else {
        format!("found: {}", found.join("; "))
    };
    if !dropped.is_empty() {
        out.push_str(&format!(
            " (removed on the way: {}, explained better by a later step)",
            dropped.join(", ")
        ));
    }
    if let Some(f) = fin {
        out.push_str(&format!(
            ". The chosen model refitted on the whole log: error {} = {:.2}x its noise floor {}, {:.1}x below the start",
            effects::sig(f.error),
            f.ratio_to_floor,
            effects::sig(f.noise_floor),
            f.below_start
        ));
    }
    out.push_str(&format!(". Stopped: {}", r.stopped_because));
    out
}
