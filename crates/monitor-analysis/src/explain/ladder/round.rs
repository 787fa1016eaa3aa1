//! One round of the ladder: the candidates, each fitted nested from the model of the step
//! before, and the choice of the one kept (the test of [`super::STEP_MIN`]).

use super::split::weights_for;
use super::PAIR_FROM;
use crate::effects::{self, EffectModel};
use crate::explain::PARAM_PENALTY;
use crate::fit::machine::MachineScales;
use crate::fit::{self, ActiveEffect, BaseSpec, FitResult};
use crate::metrics::{self, Weights};
use crate::prep::Prepared;
use crate::simplified_model::{BaseParams, MachineConstants};
use crate::{align, base_newly_out_of_range, transients, Analysis, AnalysisError};
use monitor_core::EffectKind;
use monitor_io::params::ParamFile;

/// Where a round's candidates of several effects start their fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Starts {
    /// From where the model stood and from the nominal base parameters, the lower training
    /// cost kept: the singles' round (an effect with what it needs first, the full-order
    /// machine).
    AlsoNominal,
    /// From where the model stood only: the pairs' round. The second start doubled the
    /// round's time and decided nothing measured: on the 52 logs of the test matrix no pair
    /// was kept (22 pair rounds), and on the nine `effect_*` scenarios the one pair kept
    /// (flux dynamics and a load torque, the windage scenario's second step) is kept with
    /// the same fitted values to 1e-12 without it (docs/model-vs-measurement.md, "Time").
    NestedOnly,
}

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
}

/// The model of a ladder step: its effects, their set-ups on the fit series, and the fit.
pub(super) struct Rung<'a> {
    /// The base parameters of the model, as factors on the user's file (the analysis the
    /// rung's fit is relative to is the file with them, [`Analysis::recentred`]).
    pub(super) scales: MachineScales,
    pub(super) kinds: Vec<EffectKind>,
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
}

/// A candidate fitted in one round.
#[derive(Clone)]
pub(super) struct Fitted<'a> {
    pub(super) models: Vec<&'a dyn EffectModel>,
    pub(super) fit: FitResult,
    pub(super) n_parameters: usize,
    pub(super) heldback_fit_series: f64,
    pub(super) implausible: Vec<String>,
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
    pub(super) fn added(&self, before: usize) -> Vec<EffectKind> {
        self.models.iter().skip(before).map(|m| m.kind()).collect()
    }
}

impl Analysis {
    /// The model `models` fitted as `fit` on the fit series, measured on the working
    /// series: whole log, held-back part, and their noise floors.
    pub(super) fn measure_rung<'a>(
        &self,
        models: Vec<&'a dyn EffectModel>,
        fit: FitResult,
        sr: &LadderSeries,
        scales: MachineScales,
    ) -> Result<Rung<'a>, AnalysisError> {
        let (fd, m, held, held_fd) = (&sr.fd, sr.m, &sr.held[..], &sr.held_fd[..]);
        let d = &self.data;
        let active: Vec<ActiveEffect<'a>> = models
            .iter()
            .map(|e| {
                e.setup(d, self.setup_constants())
                    .map(|setup| ActiveEffect { effect: *e, setup })
                    .map_err(|source| AnalysisError::Effect {
                        effect: e.kind(),
                        source,
                    })
            })
            .collect::<Result<_, _>>()?;
        let f_full = align(&active, fit.clone());
        let (pred, renoised) = self.predict_and_renoised(d, &active, &f_full)?;
        let w = weights_for(d, held, usize::MAX);
        let noise = metrics::noise_floor(d, &w, Some((&pred, &renoised)));
        let heldback_noise = metrics::noise_floor_on(d, held, Some((&pred, &renoised)));
        let error = metrics::errors(d, &pred, None).normalized_rms_error;
        let heldback_error = metrics::errors(d, &pred, Some(held)).normalized_rms_error;
        let (hb_fd, hn_fd) = if m == 1 {
            (heldback_error, heldback_noise)
        } else {
            let fa = self.setup_list(fd, &models)?;
            let fit_a = align(&fa, fit.clone());
            let (p, r) = self.predict_and_renoised(fd, &fa, &fit_a)?;
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
        })
    }

    /// `models` set up on `d`.
    pub(super) fn setup_list<'a>(
        &self,
        d: &Prepared,
        models: &[&'a dyn EffectModel],
    ) -> Result<Vec<ActiveEffect<'a>>, AnalysisError> {
        models
            .iter()
            .map(|e| {
                e.needs()
                    .met_by(d)
                    .and_then(|()| e.setup(d, self.setup_constants()))
                    .map(|setup| ActiveEffect { effect: *e, setup })
                    .map_err(|source| AnalysisError::Effect {
                        effect: e.kind(),
                        source,
                    })
            })
            .collect()
    }

    /// Why effect `e` of `lib` cannot be fitted on this log (`None`: it can): a missing
    /// channel, a set-up the data refuse, a time constant the fit series cannot resolve.
    /// What an effect needs first is tried with it ([`Analysis::ladder_candidates`]), not a
    /// reason to skip it; a dynamics effect competes on any log (its held-back error
    /// decides), not only through a start or a supply step.
    fn ladder_cannot_fit(
        &self,
        lib: &[Box<dyn EffectModel>],
        e: &dyn EffectModel,
        sr: &LadderSeries,
    ) -> Option<String> {
        let all: Vec<EffectKind> = lib.iter().map(|x| x.kind()).collect();
        let resolvable = transients::Span {
            input_transient: true,
            ..sr.span
        };
        if let Some(t) = transients::not_proposed(e, resolvable, self.setup_constants(), &all) {
            return Some(t.spelled(&*self.words));
        }
        e.needs()
            .met_by(&self.data)
            .and_then(|()| e.setup(&sr.fd, self.setup_constants()).map(|_| ()))
            .err()
            .map(|s| s.to_string())
    }

    /// The round's candidates: each library effect not in the model, preceded by what it
    /// needs first and the model lacks, and the full-order machine at once
    /// ([`full_order`]); and the effects that cannot be fitted on this log, each as
    /// `name: why` ([`Analysis::ladder_cannot_fit`]).
    pub(super) fn ladder_candidates<'a>(
        &self,
        lib: &'a [Box<dyn EffectModel>],
        rung: &Rung<'_>,
        sr: &LadderSeries,
    ) -> (Vec<Vec<&'a dyn EffectModel>>, Vec<String>) {
        let fits = |e: &dyn EffectModel| self.ladder_cannot_fit(lib, e, sr).is_none();
        let mut out = Vec::new();
        let mut skipped = Vec::new();
        for e in lib.iter().map(|e| e.as_ref()) {
            if rung.kinds.contains(&e.kind()) {
                continue;
            }
            if let Some(why) = self.ladder_cannot_fit(lib, e, sr) {
                skipped.push(format!("{}: {why}", e.kind()));
                continue;
            }
            let missing: Vec<Option<&dyn EffectModel>> = e
                .requires()
                .iter()
                .filter(|r| !rung.kinds.contains(r))
                .map(|r| {
                    lib.iter()
                        .map(|x| x.as_ref())
                        .find(|x| x.kind() == *r && fits(*x))
                })
                .collect();
            let Some(mut set) = missing.into_iter().collect::<Option<Vec<_>>>() else {
                skipped.push(format!(
                    "{}: needs {} first, which cannot be fitted on this log",
                    e.kind(),
                    transients::names(e.requires())
                ));
                continue;
            };
            set.push(e);
            out.push(set);
        }
        let dynamics = full_order(lib, &rung.kinds, self.setup_constants(), &fits);
        if dynamics.len() >= 2 {
            out.push(dynamics);
        }
        (out, skipped)
    }

    /// One candidate `c` (effects to add, in order) fitted with the model of `rung`, from
    /// the `starts` given, the base parameters as `spec` says (for the candidate's effects,
    /// [`BaseSpec::for_effects`]), at most `max_iter` iterations; from a screening fit
    /// `from`'s values where given, else from where the model stood.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fit_candidate<'a>(
        &self,
        c: &[&'a dyn EffectModel],
        rung: &Rung<'a>,
        sr: &LadderSeries,
        spec: BaseSpec,
        starts: Starts,
        max_iter: usize,
        from: Option<&Fitted<'a>>,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let set = match from {
            Some(f) => self.nested_from(&f.models, &f.fit.effect_params, &[], &sr.fd),
            None => self.nested(c, rung, &sr.fd),
        };
        let Some(set) = set else {
            return Ok(None);
        };
        let start = from.map_or(rung.fit.base, |f| f.fit.base);
        let n_parameters = set
            .iter()
            .skip(rung.models.len())
            .map(|a| a.setup.len())
            .sum();
        let spec = spec.for_effects(&set);
        // Nested: from where the model stood. An effect with what it needs first (or the
        // full-order machine) can trade off against a base parameter (the B + Bl that
        // absorbed a start's acceleration): where the fit frees the base parameters it is
        // also fitted from the nominal ones, and the lower training cost wins, so the nested
        // fit's cost is never exceeded. The two fits are independent and share the cores.
        let frees_base = spec.free.iter().any(|f| *f);
        let f = if frees_base && c.len() > 1 && starts == Starts::AlsoNominal {
            let nominal = BaseParams::nominal(&self.constants);
            let (f, g) = rayon::join(
                || self.fit_spec_iter(&sr.fd, &set, &sr.wf, &start, spec, max_iter),
                || self.fit_spec_iter(&sr.fd, &set, &sr.wf, &nominal, spec, max_iter),
            );
            let (f, g) = (f?, g?);
            if g.report.cost < f.report.cost {
                g
            } else {
                f
            }
        } else {
            self.fit_spec_iter(&sr.fd, &set, &sr.wf, &start, spec, max_iter)?
        };
        let pred = fit::predict(&sr.fd, &self.constants, &set, &f)?;
        let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
        let why = self.implausible_step(&set, rung, &f, sr.m)?;
        Ok(Some(Fitted {
            models: set.iter().map(|a| a.effect).collect(),
            fit: f,
            n_parameters,
            heldback_fit_series: hb,
            implausible: why,
            base: None,
        }))
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
        &self,
        c: &[&'a dyn EffectModel],
        rung: &Rung<'a>,
        fd: &Prepared,
    ) -> Option<Vec<ActiveEffect<'a>>> {
        self.nested_from(&rung.models, &rung.fit.effect_params, c, fd)
    }

    /// [`Analysis::nested`] for the effects `models` with their values `values`.
    pub(super) fn nested_from<'a>(
        &self,
        models: &[&'a dyn EffectModel],
        values: &[Vec<f64>],
        c: &[&'a dyn EffectModel],
        fd: &Prepared,
    ) -> Option<Vec<ActiveEffect<'a>>> {
        let starts = values.iter().map(Some);
        let mut set = Vec::new();
        for (e, p) in models.iter().zip(starts).chain(c.iter().map(|e| (e, None))) {
            let mut setup = e.setup(fd, self.setup_constants()).ok()?;
            if let Some(p) = p {
                setup.start_only_from(p);
            }
            set.push(ActiveEffect { effect: *e, setup });
        }
        Some(set)
    }

    /// Why the step that adds the effects of `set` after the model of `rung`, fitted as
    /// `f`, is not plausible (empty: it is): an added effect's value outside its physical
    /// range, pinned at a bound of its fit, or contradicted by a measurement of the log
    /// ([`EffectModel::contradicted_by`]); a base parameter the fit takes out of range that
    /// the model's own fit had in range.
    pub(super) fn implausible_step(
        &self,
        set: &[ActiveEffect<'_>],
        rung: &Rung<'_>,
        f: &FitResult,
        m: usize,
    ) -> Result<Vec<String>, AnalysisError> {
        let d = &self.data;
        let mut why = Vec::new();
        for (i, a) in set.iter().enumerate().skip(rung.models.len()) {
            let p = f.effect_params.get(i).map_or(&[][..], Vec::as_slice);
            // The plausible ranges are those of the working series' set-up (a long log's
            // coarse copy may have fewer load segments: its own set-up then).
            let s_full = (m > 1)
                .then(|| a.effect.setup(d, self.setup_constants()).ok())
                .flatten();
            let setup = s_full
                .as_ref()
                .filter(|s| s.len() == p.len())
                .unwrap_or(&a.setup);
            let kind = a.effect.kind();
            why.extend(
                setup
                    .implausible(p)
                    .into_iter()
                    .map(|w| format!("{kind}: {w}")),
            );
            why.extend(pinned(kind, &a.setup, p));
            why.extend(a.effect.contradicted_by(d, &self.constants, p)?);
        }
        why.extend(base_newly_out_of_range(
            &self.constants,
            &rung.fit.base,
            &f.base,
            d,
        ));
        Ok(why)
    }
}

/// The values of `p` pinned at a bound of their fit in `setup` (effect `kind`), each in
/// words: no minimum the log shows, the solver pushed it as far as it was let (a fit of the
/// model's numerical residue). A bound at 0 does not count (no effect at all: the step's
/// test refuses that).
fn pinned(kind: EffectKind, setup: &effects::FitSetup, p: &[f64]) -> Vec<String> {
    let at = |v: f64, b: f64| b.is_finite() && b != 0.0 && (v - b).abs() <= 1e-3 * b.abs();
    setup
        .params
        .iter()
        .zip(p)
        .filter(|(q, v)| at(**v, q.lo) || at(**v, q.hi))
        .map(|(q, v)| {
            format!(
                "{kind}: {} = {} {} is at the bound of its fit ({}..{}), not a value the log shows",
                q.name,
                effects::sig(*v),
                q.unit(),
                effects::sig(q.lo),
                effects::sig(q.hi)
            )
        })
        .collect()
}

/// The full-order machine at once: every dynamics effect of `lib` not in the model `have`
/// that `fits` the log (those with a time constant, and what needs one of them). A start or
/// a step can need all of them before any one fits with values a machine has: one alone
/// takes its time constant out of range to follow the others' part.
fn full_order<'a>(
    lib: &'a [Box<dyn EffectModel>],
    have: &[EffectKind],
    n: &MachineConstants,
    fits: &dyn Fn(&dyn EffectModel) -> bool,
) -> Vec<&'a dyn EffectModel> {
    let timed = |k: EffectKind| {
        lib.iter()
            .any(|e| e.kind() == k && e.time_constant_s(n).is_some())
    };
    lib.iter()
        .map(|e| e.as_ref())
        .filter(|e| !have.contains(&e.kind()) && fits(*e))
        .filter(|e| e.time_constant_s(n).is_some() || e.requires().iter().any(|r| timed(*r)))
        .collect()
}

/// The pairs a round tries when no single candidate passes: every two of the [`PAIR_FROM`]
/// single-effect candidates of `fitted` (plausible or not, not diverged) (fits of one round, the model's own `before` effects
/// first in each) that lowered the training cost most, each pair's effects in the order
/// fitted. A held-back error can rise with one effect of a pair and fall with both: with a
/// start's cross coupling but no load torque, the fit uses the coupling to follow the
/// acceleration a missing load explains.
pub(super) fn pairs_of<'a>(fitted: &[Fitted<'a>], before: usize) -> Vec<Vec<&'a dyn EffectModel>> {
    // Implausible fits too: one effect alone may take its values out of range to carry its
    // partner's part.
    let mut by_cost: Vec<&Fitted<'a>> = fitted
        .iter()
        .filter(|c| {
            c.models.len() == before + 1
                && c.heldback_fit_series.is_finite()
                && c.heldback_fit_series > 0.0
        })
        .collect();
    by_cost.sort_by(|a, b| a.fit.report.cost.total_cmp(&b.fit.report.cost));
    let top: Vec<Vec<&'a dyn EffectModel>> = by_cost
        .iter()
        .take(PAIR_FROM)
        .map(|c| c.models.iter().skip(before).copied().collect())
        .collect();
    let mut out = Vec::new();
    for i in 0..top.len() {
        for j in (i + 1)..top.len() {
            let mut set = top[i].clone();
            for e in &top[j] {
                if !set.iter().any(|x| x.kind() == e.kind()) {
                    set.push(*e);
                }
            }
            out.push(set);
        }
    }
    out
}
