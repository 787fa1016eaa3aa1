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
use super::report::{BaseChange, FinalFit, LawShape, NotSeparable, Unsteady};
use super::rules::{PAIRS_ABOVE, SHAPE_TRADE_MAX, UNSTEADY_SHARE};
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
            for c in base.iter_mut().filter(|c| c.changed) {
                c.in_place = self.in_place(&an, &fdata, &mf, c.base, error, noise)?;
                c.changed = c.in_place.is_none();
            }
            if base.iter().any(|c| c.changed) {
                let halves = self.halves(&fdata, &set, &mf)?;
                for c in base.iter_mut().filter(|c| c.changed) {
                    c.unsteady = unsteady(c, &halves);
                    c.changed = c.unsteady.is_none();
                }
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
            far_from_floor: error / noise > PAIRS_ABOVE,
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
                corrected: mf.corrected.clone(),
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
    /// not the change's to carry, and a small true change removes little of it.) Except
    /// where the model ends far from its floor (above [`PAIRS_ABOVE`]), the refit without
    /// the change takes an effect's parameter to the end of its fit range ([`law_shape`])
    /// and its error stays within [`SHAPE_TRADE_MAX`] times the model's: the change then
    /// trades with that law's shape ([`LawShape`]), not a finding either.
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
        let pinned = self.refit_from(fdata, set, mf, &w, Some(key))?;
        let e_pin = self.on_whole_log(&rung.models, &pinned, false)?.error;
        let removes = if e_pin > noise {
            (e_pin - error) / (e_pin - noise)
        } else {
            0.0
        };
        let shape = if e_pin / noise > sr.band.ratio {
            if error / noise <= PAIRS_ABOVE || e_pin > SHAPE_TRADE_MAX * error {
                return Ok(None);
            }
            match law_shape(set, mf, &pinned) {
                Some(s) => Some(s),
                None => return Ok(None),
            }
        } else {
            None
        };
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
            shape,
        }))
    }

    /// The base changes of the chosen model (its effects set up as `set`, fitted as `mf` on
    /// `fdata`) read on each half of the series alone (by samples: the model still runs
    /// over the whole series, only the half's samples weigh), each with its 95 %
    /// half-widths on that half: the readings [`unsteady`] compares.
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    fn halves(
        &self,
        fdata: &Prepared,
        set: &[ActiveEffect<'_>],
        mf: &MachineFit,
    ) -> Result<[Vec<BaseChange>; 2], AnalysisError> {
        let sr = &self.series;
        let n = fdata.len();
        let half = |lo: usize, hi: usize| -> Result<Vec<BaseChange>, AnalysisError> {
            let mut w = Weights::new(fdata, 0, usize::MAX);
            for (k, t) in w.train.iter_mut().enumerate() {
                *t = (lo..hi).contains(&k);
            }
            let f = self.refit_from(fdata, set, mf, &w, None)?;
            let h = machine::machine_half_widths(fdata, &sr.file, set, &w, &f)?;
            Ok(base_changes(&f.scales, &sr.file, &h))
        };
        Ok([half(0, n / 2)?, half(n / 2, n)?])
    }

    /// The model of the effects `set` refitted as the final fit is, from the fit `mf`, on
    /// the training samples of `w`, with the base parameter `pin` (if any) held at the
    /// file's value ([`machine::fit_machine_pinned`]).
    ///
    /// # Errors
    /// An effect that refuses its set-up's values.
    pub(super) fn refit_from(
        &self,
        fdata: &Prepared,
        set: &[ActiveEffect<'_>],
        mf: &MachineFit,
        w: &Weights,
        pin: Option<BaseKey>,
    ) -> Result<MachineFit, AnalysisError> {
        let (rung, sr) = (&self.rung, &self.series);
        Ok(machine::fit_machine_pinned(
            fdata,
            &sr.file,
            set,
            w,
            &mf.scales,
            prior_weight(rung.noise),
            MAX_ITER,
            pin,
        )?)
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
            // Predicted with as the rungs were: at the values corrected for the inputs'
            // noise, where any were, the base refitted around them.
            let mf = machine::around_corrected(
                fdata,
                &sr.file,
                set,
                &w,
                mf,
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
            corrected: f.corrected,
        };
        Ok((mf, [None; 6]))
    }
}

/// The change `c` as [`Unsteady`] when its readings on the log's two halves (`halves`,
/// [`Ladder::halves`]) differ by more than both halves' 95 % intervals together and by more
/// than [`UNSTEADY_SHARE`] of the change itself; `None` when they agree, or when a half
/// does not determine it (no interval: that half cannot judge).
fn unsteady(c: &BaseChange, halves: &[Vec<BaseChange>; 2]) -> Option<Unsteady> {
    let [a, b] = [&halves[0], &halves[1]].map(|h| h.iter().find(|x| x.base == c.base));
    let (a, b) = (a?, b?);
    let ([alo, ahi], [blo, bhi]) = (a.interval?, b.interval?);
    let together = (0.5 * (ahi - alo)).hypot(0.5 * (bhi - blo));
    let apart = (a.change - b.change).abs();
    (apart > together && apart > UNSTEADY_SHARE * c.change.abs()).then_some(Unsteady {
        first: a.change,
        second: b.change,
    })
}

/// The first effect parameter of the model `set` that the refit `pinned` (a base
/// parameter held at the file's value) took to an end of its fit range while the fit `mf`
/// (with the change) kept it inside, by more than a thousandth of the range: the law's
/// shape ran out where the change was taken away ([`LawShape`]).
fn law_shape(set: &[ActiveEffect<'_>], mf: &MachineFit, pinned: &MachineFit) -> Option<LawShape> {
    set.iter()
        .zip(mf.effect_params.iter().zip(&pinned.effect_params))
        .find_map(|(a, (with, without))| {
            a.setup
                .params
                .iter()
                .zip(with.iter().zip(without))
                .find_map(|(p, (&w, &o))| {
                    let edge = 1e-3 * (p.hi - p.lo);
                    let bound = if o >= p.hi - edge {
                        p.hi
                    } else if o <= p.lo + edge {
                        p.lo
                    } else {
                        return None;
                    };
                    ((w - bound).abs() > edge).then(|| LawShape {
                        effect: a.effect.kind(),
                        parameter: p.name.clone(),
                        with_change: w,
                        bound,
                    })
                })
        })
}

/// True when an effect's values `a` and `b` differ by more than 0.5 % of the larger (a
/// value that carries what the pinned base parameter did).
fn moved(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > 0.005 * x.abs().max(y.abs()).max(1e-12))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A change of `key` read as `change` with the 95 % half-width `half`.
    fn read(key: BaseKey, change: f64, half: Option<f64>) -> BaseChange {
        BaseChange {
            base: key,
            change,
            interval: half.map(|h| [change - h, change + h]),
            file_value: 1.0,
            value: 1.0 + change,
            unit: "",
            identified: true,
            changed: true,
            not_separable: None,
            unsteady: None,
            in_place: None,
        }
    }

    /// The fan's inertia (-9 % on the whole log: -8 % on the half with the start, +9 % on
    /// the other, each known to 1-2 %) is unsteady; a warm stator's Rs (+19.8 % and
    /// +18.6 %, apart by more than their intervals but by a sixteenth of the change) is not;
    /// nor is a change a half cannot determine.
    #[test]
    fn a_change_that_moves_between_the_halves_is_unsteady() {
        let j = read(BaseKey::J, -0.09, Some(0.005));
        let halves = [
            vec![read(BaseKey::J, -0.08, Some(0.007))],
            vec![read(BaseKey::J, 0.09, Some(0.016))],
        ];
        let u = unsteady(&j, &halves).expect("the inertia moves between the halves");
        assert_eq!((u.first, u.second), (-0.08, 0.09));
        let rs = read(BaseKey::Rs, 0.19, Some(0.0004));
        let halves = [
            vec![read(BaseKey::Rs, 0.198, Some(0.0005))],
            vec![read(BaseKey::Rs, 0.186, Some(0.002))],
        ];
        assert!(unsteady(&rs, &halves).is_none());
        let halves = [
            vec![read(BaseKey::J, -0.08, None)],
            vec![read(BaseKey::J, 0.09, Some(0.016))],
        ];
        assert!(unsteady(&j, &halves).is_none());
        // Apart by less than the two intervals together: the halves agree.
        let halves = [
            vec![read(BaseKey::J, -0.08, Some(0.15))],
            vec![read(BaseKey::J, 0.05, Some(0.05))],
        ];
        assert!(unsteady(&j, &halves).is_none());
    }
}
