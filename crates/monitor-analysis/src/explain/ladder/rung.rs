//! What the ladder's rounds share: the series its fits run on with the held-back split, a
//! rung (the model of a step) measured there, a candidate fitted in a round, and why a
//! fitted step is not physical.

use super::refusal::WhyNotPhysical;
use super::rules::{FloorBand, LADDER_FIT_SAMPLES, LADDER_MAX_FIT_SAMPLES};
use super::split::{mask_on, weights_for};
use crate::analysis::{align, coarsen, Analysis, AnalysisError};
use crate::base_range::base_newly_out_of_range;
use crate::effects::{self, EffectModel};
use crate::explain::PARAM_PENALTY;
use crate::fit::machine::MachineScales;
use crate::fit::{ActiveEffect, FitResult};
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::transients;
use monitor_io::params::ParamFile;
use monitor_laws::EffectId;

/// The series a ladder's fits run on, with its held-back split.
pub(super) struct LadderSeries {
    /// The copy of the working series the fits run on.
    pub(super) fd: Prepared,
    /// Its coarsening factor (1: the working series itself).
    pub(super) m: usize,
    /// The held-back mask of the working series.
    pub(super) held: Vec<bool>,
    /// The held-back mask of the fit series.
    pub(super) held_fd: Vec<bool>,
    /// The fit's weights (training on the samples not held back).
    pub(super) wf: Weights,
    /// What the fit series offers a dynamics effect.
    pub(super) span: transients::Span,
    /// The user's parameter file: the base rung's factors are relative to it.
    pub(super) file: ParamFile,
    /// Whether the base parameters are refitted at all (the base rung and the final
    /// refit; `--no-fit-base` keeps the file's).
    pub(super) fit_base: bool,
    /// The log's noise-floor band (its length in supply periods, [`FloorBand::of_periods`]).
    pub(super) band: FloorBand,
}

/// The model of a ladder step: its effects, their set-ups on the fit series, and the fit.
pub(super) struct Rung<'a> {
    /// The base parameters of the model, as factors on the user's file (the analysis the
    /// rung's fit is relative to is the file with them, [`Analysis::recentred`]).
    pub(super) scales: MachineScales,
    pub(super) kinds: Vec<EffectId>,
    pub(super) models: Vec<&'a dyn EffectModel>,
    pub(super) fit: FitResult,
    /// Whole-log and held-back error and floors on the working series.
    pub(super) error: f64,
    pub(super) heldback_error: f64,
    pub(super) noise: f64,
    pub(super) heldback_noise: f64,
    /// The held-back error on the fit series (what candidates are ranked on).
    pub(super) heldback_fit_series: f64,
    pub(super) heldback_noise_fit_series: f64,
    /// The error over time on the working series ([`metrics::error_over_time`]).
    pub(super) over_time: Vec<(f64, f64)>,
    /// The log's noise-floor band (the series').
    pub(super) band: FloorBand,
}

impl Rung<'_> {
    /// The share of the error beyond the noise floor `noise` a change from `e_base` to
    /// `e_with` removes, within this log's band ([`FloorBand::explained`]).
    pub(super) fn explained(&self, e_base: f64, e_with: f64, noise: f64) -> f64 {
        self.band.explained(e_base, e_with, noise)
    }
}

/// A candidate fitted in one round.
#[derive(Clone)]
pub(super) struct Fitted<'a> {
    pub(super) models: Vec<&'a dyn EffectModel>,
    pub(super) fit: FitResult,
    pub(super) n_parameters: usize,
    pub(super) heldback_fit_series: f64,
    /// Why the step is not physical (empty: it is).
    pub(super) implausible: Vec<WhyNotPhysical>,
    /// For the base rung: the refitted base parameters (its `fit` is relative to the file
    /// with them); `None` for an effect candidate.
    pub(super) base: Option<MachineScales>,
}

impl Fitted<'_> {
    /// The held-back error on the fit series, each parameter costing [`PARAM_PENALTY`].
    pub(super) fn score(&self) -> f64 {
        self.heldback_fit_series * (1.0 + PARAM_PENALTY * self.n_parameters as f64)
    }
    /// The effects the candidate adds to a model of `before` effects.
    pub(super) fn added(&self, before: usize) -> Vec<EffectId> {
        self.models.iter().skip(before).map(|m| m.kind()).collect()
    }
}

impl LadderSeries {
    /// The model `models` fitted as `fit` on the fit series, measured on the working
    /// series of `an` (the analysis of the rung's base parameters): whole log, held-back
    /// part, and their noise floors.
    pub(super) fn measure<'a>(
        &self,
        an: &Analysis,
        models: Vec<&'a dyn EffectModel>,
        fit: FitResult,
        scales: MachineScales,
    ) -> Result<Rung<'a>, AnalysisError> {
        let (fd, m, held, held_fd) = (&self.fd, self.m, &self.held[..], &self.held_fd[..]);
        let d = &an.data;
        let active: Vec<ActiveEffect<'a>> = models
            .iter()
            .map(|e| {
                e.setup(d, an.setup_constants())
                    .map(|setup| ActiveEffect { effect: *e, setup })
                    .map_err(|source| AnalysisError::Effect {
                        effect: e.kind(),
                        source,
                    })
            })
            .collect::<Result<_, _>>()?;
        let f_full = align(&active, fit.clone());
        let (pred, renoised) = an.predict_and_renoised(d, &active, &f_full)?;
        let w = weights_for(d, held, usize::MAX);
        let noise = metrics::noise_floor(d, &w, Some((&pred, &renoised)));
        let heldback_noise = metrics::noise_floor_on(d, held, Some((&pred, &renoised)));
        let error = metrics::errors(d, &pred, None).normalized_rms_error;
        let heldback_error = metrics::errors(d, &pred, Some(held)).normalized_rms_error;
        let over_time = metrics::error_over_time(d, &pred, &w.inv_rms);
        let (hb_fd, hn_fd) = if m == 1 {
            (heldback_error, heldback_noise)
        } else {
            let fa = setup_list(an, fd, &models)?;
            let fit_a = align(&fa, fit.clone());
            let (p, r) = an.predict_and_renoised(fd, &fa, &fit_a)?;
            (
                metrics::errors(fd, &p, Some(held_fd)).normalized_rms_error,
                metrics::noise_floor_on(fd, held_fd, Some((&p, &r))),
            )
        };
        Ok(Rung {
            scales,
            kinds: models.iter().map(|e| e.kind()).collect(),
            models,
            fit,
            error,
            heldback_error,
            noise,
            heldback_noise,
            heldback_fit_series: hb_fd,
            heldback_noise_fit_series: hn_fd,
            over_time,
            band: self.band,
        })
    }
}

/// `models` set up on `d` with the set-up constants of `an`.
pub(super) fn setup_list<'a>(
    an: &Analysis,
    d: &Prepared,
    models: &[&'a dyn EffectModel],
) -> Result<Vec<ActiveEffect<'a>>, AnalysisError> {
    models
        .iter()
        .map(|e| {
            e.needs()
                .met_by(d)
                .and_then(|()| e.setup(d, an.setup_constants()))
                .map(|setup| ActiveEffect { effect: *e, setup })
                .map_err(|source| AnalysisError::Effect {
                    effect: e.kind(),
                    source,
                })
        })
        .collect()
}

/// The model of `rung` set up on `fd`, each effect starting from its fitted values and
/// from nowhere else, with the candidate's effects `c` added last (from their own
/// starts, [`crate::effects::FitSetup::alt_init`] included); `None` when a set-up refuses
/// the series. An effect of the model had its other starts tried in the step that added
/// it, and the fit of that step chose its valley: started there again, in a model
/// fitted around it, it ended far above the nested fit on every log measured (the
/// broken-bar example's last round: 40 iterations each, 30x the cost) and took more than
/// half the ladder's time (docs/model-vs-measurement.md, "Time").
pub(super) fn nested<'a>(
    an: &Analysis,
    c: &[&'a dyn EffectModel],
    rung: &Rung<'a>,
    fd: &Prepared,
) -> Option<Vec<ActiveEffect<'a>>> {
    nested_from(an, &rung.models, &rung.fit.effect_params, c, fd)
}

/// [`nested`] for the effects `models` with their values `values`.
pub(super) fn nested_from<'a>(
    an: &Analysis,
    models: &[&'a dyn EffectModel],
    values: &[Vec<f64>],
    c: &[&'a dyn EffectModel],
    fd: &Prepared,
) -> Option<Vec<ActiveEffect<'a>>> {
    let starts = values.iter().map(Some);
    let mut set = Vec::new();
    for (e, p) in models.iter().zip(starts).chain(c.iter().map(|e| (e, None))) {
        let mut setup = e.setup(fd, an.setup_constants()).ok()?;
        if let Some(p) = p {
            setup.start_only_from(p);
        }
        set.push(ActiveEffect { effect: *e, setup });
    }
    Some(set)
}

/// Why the step that adds the effects of `set` after the model of `rung`, fitted as `f`
/// on a fit series coarsened by `m`, is not physical on the log of `an` (empty: it is): an
/// added effect's value outside its physical range, pinned at a bound of its fit, or
/// contradicted by a measurement of the log ([`EffectModel::contradicted_by`]); a base
/// parameter the fit takes out of range that the model's own fit had in range.
pub(super) fn implausible_step(
    an: &Analysis,
    set: &[ActiveEffect<'_>],
    rung: &Rung<'_>,
    f: &FitResult,
    m: usize,
) -> Result<Vec<WhyNotPhysical>, AnalysisError> {
    let d = &an.data;
    let mut why = Vec::new();
    for (i, a) in set.iter().enumerate().skip(rung.models.len()) {
        let p = f.reported().get(i).map_or(&[][..], Vec::as_slice);
        // The plausible ranges are those of the working series' set-up (a long log's
        // coarse copy may have fewer load segments: its own set-up then).
        let s_full = (m > 1)
            .then(|| a.effect.setup(d, an.setup_constants()).ok())
            .flatten();
        let setup = s_full
            .as_ref()
            .filter(|s| s.len() == p.len())
            .unwrap_or(&a.setup);
        let effect = a.effect.kind();
        why.extend(
            setup
                .implausible(p)
                .into_iter()
                .map(|why| WhyNotPhysical::Effect { effect, why }),
        );
        why.extend(pinned(effect, &a.setup, p));
        why.extend(
            a.effect
                .contradicted_by(d, &an.constants, p)?
                .map(|why| WhyNotPhysical::Contradicted { effect, why }),
        );
    }
    why.extend(
        base_newly_out_of_range(&an.constants, &rung.fit.base, &f.base, d)
            .into_iter()
            .map(|why| WhyNotPhysical::Base { why }),
    );
    Ok(why)
}

/// The values of `p` pinned at a bound of their fit in `setup` (effect `effect`): no
/// minimum the log shows, the solver pushed it as far as it was let (a fit of the model's
/// numerical residue). A bound at 0 does not count (no effect at all: the step's test
/// refuses that).
fn pinned(effect: EffectId, setup: &effects::FitSetup, p: &[f64]) -> Vec<WhyNotPhysical> {
    let at = |v: f64, b: f64| b.is_finite() && b != 0.0 && (v - b).abs() <= 1e-3 * b.abs();
    setup
        .params
        .iter()
        .zip(p)
        .filter(|(q, v)| at(**v, q.lo) || at(**v, q.hi))
        .map(|(q, v)| WhyNotPhysical::AtBound {
            effect,
            parameter: q.name.clone(),
            value: *v,
            unit: q.unit().to_string(),
            low: q.lo,
            high: q.hi,
        })
        .collect()
}

impl LadderSeries {
    /// The series the ladder's fits run on for the log of `an`: a copy of at most
    /// [`LADDER_FIT_SAMPLES`] samples (a round fits every candidate, and a ladder has
    /// several rounds), thinned no further than the machine's fastest dynamics allow
    /// ([`fit_thinning`]), with the held-back mask `held` of the working series carried
    /// over; `fit_base`: whether the base parameters are refitted at all.
    pub(super) fn of(an: &Analysis, held: Vec<bool>, fit_base: bool) -> Self {
        let m = fit_thinning(
            an.data.len(),
            an.data.dt_s,
            fastest_dynamics_s(&an.constants),
        );
        let fd = coarsen(&an.data, m);
        let held_fd = if m == 1 {
            held.clone()
        } else {
            mask_on(&fd, &an.data, &held)
        };
        LadderSeries {
            wf: weights_for(&fd, &held_fd, LADDER_FIT_SAMPLES),
            span: transients::Span::of(&fd, &an.constants),
            file: an.params,
            fit_base,
            band: FloorBand::of_periods(supply_periods(&an.data)),
            fd,
            m,
            held,
            held_fd,
        }
    }
}

/// The supply periods of the working series `d`: its supply angle over 2 pi, from the
/// measured supply frequency of each sample (non-finite samples count nothing).
fn supply_periods(d: &Prepared) -> f64 {
    let angle: f64 = d
        .omega_s
        .iter()
        .filter(|w| w.is_finite())
        .map(|w| w.abs() * d.dt_s)
        .sum();
    angle / std::f64::consts::TAU
}

/// The fastest time constant of the library's dynamics effects on machine `n` [s] (the
/// stator's transient sigma Ls / Ra: a few ms).
fn fastest_dynamics_s(n: &crate::simplified_model::MachineConstants) -> f64 {
    effects::library()
        .iter()
        .filter_map(|e| e.time_constant_s(n))
        .filter(|t| t.is_finite() && *t > 0.0)
        .fold(f64::INFINITY, f64::min)
}

/// The thinning factor of the fit copy of a working series of `len` samples at `dt_s`: the
/// factor that brings it to [`LADDER_FIT_SAMPLES`], but never so coarse that the fastest
/// dynamics time constant `tau_s` has fewer than 3 samples (the rule of
/// [`crate::transients::not_proposed`]) while the copy stays within
/// [`LADDER_MAX_FIT_SAMPLES`]: a 24 s log at 2 kHz is fitted at 1 kHz (24 000 samples)
/// where a factor of 3 (667 Hz) left a 3.6 ms stator transient unresolved and every
/// dynamics effect refused.
pub fn fit_thinning(len: usize, dt_s: f64, tau_s: f64) -> usize {
    let budget = len.div_ceil(LADDER_FIT_SAMPLES).max(1);
    let resolving = if tau_s.is_finite() && dt_s > 0.0 {
        ((tau_s / (3.0 * dt_s)).floor() as usize).max(1)
    } else {
        budget
    };
    if budget <= resolving {
        budget
    } else {
        resolving.max(len.div_ceil(LADDER_MAX_FIT_SAMPLES).max(1))
    }
}
