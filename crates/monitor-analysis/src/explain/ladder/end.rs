//! The ladder's end: the chosen model (its effects and its base parameters) refitted on the
//! whole log.
//!
//! The steps are chosen on held-back windows and fitted on a thinned copy of the training
//! windows: an honest choice, but short of what the chosen model reaches on the whole log
//! (`effect_load_torque.toml` ended at 2.85x its floor where `compare` with the same
//! effects reached 1.5x). So the final figures come from one more fit of the chosen model,
//! on every sample of the working series (thinned only beyond [`crate::MAX_FIT_SAMPLES`],
//! as `compare`'s), from the last step's values, with the six base parameters free
//! ([`crate::fit::machine`]): the base changes are read there, with their intervals.

use super::base::{base_changes, prior_weight};
use super::climb::Ladder;
use super::report::{FinalFit, NotSeparable};
use super::rung::{nested_from, setup_list};
use crate::analysis::{align, Analysis, AnalysisError, FittedEffect, MAX_ITER};
use crate::effects::EffectModel;
use crate::fit::machine::{self, BaseKey, MachineFit};
use crate::fit::{ActiveEffect, BaseSpec, FitResult};
use crate::leftover::Leftover;
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::simplified_model::BaseParams;

/// The chosen model on the whole working series (`Ladder::on_whole_log`).
pub(super) struct WholeLog {
    pub(super) error: f64,
    noise: f64,
    pub(super) fitted: Vec<FittedEffect>,
    leftover: Option<Leftover>,
    error_over_time: Vec<(f64, f64)>,
}

impl Ladder<'_> {
    /// The model of the rung the ladder stopped on refitted on the whole working series
    /// (coarsened as `compare`'s fit), from its values (`start_error`: the start's
    /// whole-log error), with where its error lives ([`crate::leftover::locate`]); `None`
    /// when a set-up refuses the series.
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn final_fit(
        &self,
        start_error: f64,
    ) -> Result<Option<(FinalFit, Option<Leftover>)>, AnalysisError> {
        let (file, rung, sr) = (self.file, &self.rung, &self.series);
        let (fdata, _) = file.fit_data();
        let an = file.rebased(rung.scales.apply(&sr.file));
        let Some(set) = nested_from(&an, &rung.models, &rung.fit.effect_params, &[], &fdata) else {
            return Ok(None);
        };
        let (mf, half) = self.machine_on(&an, &fdata, &set, true)?;
        let whole = self.on_whole_log(&rung.models, &mf, true)?;
        let (error, noise) = (whole.error, whole.noise);
        let mut base = base_changes(&mf.scales, &sr.file, &half);
        if sr.fit_base {
            for c in base.iter_mut().filter(|c| c.changed) {
                c.not_separable = self.without_change(&fdata, &set, &mf, c.base, error, noise)?;
                c.changed = c.not_separable.is_none();
            }
        }
        let as_one = self.as_one(&an, &fdata, &mf, error, noise)?;
        let alike = self.alike(&an, &fdata, &mf, error, noise)?;
        let chosen = FinalFit {
            effects: rung.kinds.clone(),
            error,
            noise_floor: noise,
            ratio_to_floor: error / noise,
            below_start: start_error / error,
            base,
            fitted: whole.fitted,
            as_one,
            alike,
            fit_samples: fdata.len(),
            error_over_time: whole.error_over_time,
        };
        Ok(Some((chosen, whole.leftover)))
    }

    /// The model of the effects `models` at the machine fit `mf` on the whole working
    /// series: its error, its noise floor and its effects' values; with `story`, its error
    /// over time and where that error lives ([`crate::leftover::locate`]).
    pub(super) fn on_whole_log(
        &self,
        models: &[&dyn EffectModel],
        mf: &MachineFit,
        story: bool,
    ) -> Result<WholeLog, AnalysisError> {
        let (file, sr) = (self.file, &self.series);
        let fin = file.rebased(mf.params(&sr.file));
        let active = setup_list(&fin, &file.data, models)?;
        let fit = align(
            &active,
            FitResult {
                base: BaseParams::nominal(&fin.constants),
                effect_params: mf.effect_params.clone(),
                report: mf.report,
            },
        );
        let (pred, renoised) = fin.predict_and_renoised(&file.data, &active, &fit)?;
        let all = Weights::new(&file.data, 0, usize::MAX);
        let noise = metrics::noise_floor(&file.data, &all, Some((&pred, &renoised)));
        let error = metrics::errors(&file.data, &pred, None).normalized_rms_error;
        let fitted = fin.fitted_effects(&active, &fit)?;
        if !story {
            return Ok(WholeLog {
                error,
                noise,
                fitted,
                leftover: None,
                error_over_time: Vec::new(),
            });
        }
        let leftover = (metrics::diverged_at(&file.data, &pred).is_none())
            .then(|| {
                let m = crate::leftover::Measured {
                    error,
                    noise_floor: noise,
                    band: self.series.band.ratio,
                };
                crate::leftover::locate(&file.data, &fin.constants, &pred, m)
            })
            .flatten();
        Ok(WholeLog {
            error,
            noise,
            fitted,
            leftover,
            error_over_time: metrics::error_over_time(&file.data, &pred, &all.inv_rms),
        })
    }

    /// Whether the change of `key` the fit `mf` reads (whole-log error `error`, floor
    /// `noise`) is the log's own evidence: the same model refitted with `key` held at the
    /// file's value. Where that model still explains the log within the log's noise-floor
    /// band ([`super::rules::FLOOR_BAND`] on a short log, [`super::rules::FloorBand`]), the change only trades with the effects' values (or the
    /// other base parameters): it is not separable on this log ([`NotSeparable`]), not a
    /// finding. (A model above the band keeps its changes: the error the effects leave is
    /// not the change's to carry, and a small true change removes little of it.)
    fn without_change(
        &self,
        fdata: &Prepared,
        set: &[ActiveEffect<'_>],
        mf: &MachineFit,
        key: BaseKey,
        error: f64,
        noise: f64,
    ) -> Result<Option<NotSeparable>, AnalysisError> {
        let (rung, sr) = (&self.rung, &self.series);
        let w = Weights::new(fdata, 0, usize::MAX);
        let pinned = machine::fit_machine_pinned(
            fdata,
            &sr.file,
            set,
            &w,
            &mf.scales,
            prior_weight(rung.noise),
            MAX_ITER,
            Some(key),
        )?;
        let e_pin = self.on_whole_log(&rung.models, &pinned, false)?.error;
        let removes = if e_pin > noise {
            (e_pin - error) / (e_pin - noise)
        } else {
            0.0
        };
        if e_pin / noise > sr.band.ratio {
            return Ok(None);
        }
        let traded_with = rung
            .models
            .iter()
            .zip(mf.effect_params.iter().zip(&pinned.effect_params))
            .filter(|(_, (a, b))| moved(a, b))
            .map(|(m, _)| m.kind())
            .collect();
        Ok(Some(NotSeparable {
            error_without: e_pin,
            ratio_without: e_pin / noise,
            removes,
            traded_with,
        }))
    }

    /// The model of the rung the ladder stopped on (its effects set up as `set`; `an` the
    /// analysis of its base) fitted on `fdata` from the last step's values: with the six
    /// base parameters free beside its effects ([`machine::fit_machine`], their 95 %
    /// half-widths), or, where the log cannot refit the base parameters, its effects alone
    /// on the rung's base (no half-widths). Without `halves`, no half-widths either.
    pub(super) fn machine_on(
        &self,
        an: &Analysis,
        fdata: &Prepared,
        set: &[ActiveEffect<'_>],
        halves: bool,
    ) -> Result<(MachineFit, [Option<f64>; 6]), AnalysisError> {
        let (rung, sr) = (&self.rung, &self.series);
        let w = Weights::new(fdata, 0, usize::MAX);
        if sr.fit_base {
            let mf = machine::fit_machine(
                fdata,
                &sr.file,
                set,
                &w,
                &rung.scales.with_paper(&rung.fit.base),
                prior_weight(rung.noise),
                MAX_ITER,
            )?;
            if !halves {
                return Ok((mf, [None; 6]));
            }
            let half = machine::machine_half_widths(fdata, &sr.file, set, &w, &mf)?;
            return Ok((mf, half));
        }
        let f = an.fit_spec(
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

/// True when an effect's values `a` and `b` differ by more than 0.5 % of the larger (a
/// value that carries what the pinned base parameter did).
fn moved(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > 0.005 * x.abs().max(y.abs()).max(1e-12))
}
