//! The fits of a round's candidates, in three passes: every one screened, the finalists
//! fitted to convergence, the round's best refitted with every value of the model free.

use super::super::climb::Ladder;
use super::super::rules::{FINALISTS, SCREEN_ITER};
use super::super::rung::{implausible_step, nested, nested_from, Fitted, Rung};
use crate::analysis::{Analysis, AnalysisError, MAX_ITER};
use crate::effects::EffectModel;
use crate::fit::{self, BaseSpec};
use crate::metrics;
use crate::simplified_model::BaseParams;
use rayon::prelude::*;

/// One slot per candidate of the round: its latest fit, or none where it could not run.
type Slots<'a> = Vec<Option<Fitted<'a>>>;

/// Where a round's candidates of several effects start their last fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Starts {
    /// From where the model stood and from the nominal base parameters, the lower training
    /// cost kept: the singles (an effect with what it needs first, the full-order
    /// machine).
    AlsoNominal,
    /// From where the model stood only: the pairs. The second start doubled the round's
    /// time and decided nothing measured: on the 52 logs of the test matrix no pair was
    /// kept (22 pair rounds), and on the nine `effect_*` scenarios the one pair kept (flux
    /// dynamics and a load torque, the windage scenario's second step) is kept with the
    /// same fitted values to 1e-12 without it (docs/model-vs-measurement.md, "Time").
    NestedOnly,
}

/// One kind of a round's candidates (the singles, or the pairs) and how they are fitted.
#[derive(Clone, Copy)]
pub(super) struct RoundFits<'r, 'a> {
    /// The candidates (effects to add, in order).
    pub(super) cands: &'r [Vec<&'a dyn EffectModel>],
    /// The model they are added to.
    pub(super) rung: &'r Rung<'a>,
    /// The base parameters' freedom for the candidates' fits.
    pub(super) spec: BaseSpec,
    /// Where a best candidate of several effects starts its last fit.
    pub(super) starts: Starts,
    /// Whether the round's best is refitted with the six physical base parameters free.
    pub(super) machine: bool,
}

impl RoundFits<'_, '_> {
    /// The screening's base specification: the model's own values held, only the
    /// candidate's and the base parameters move.
    fn screen_spec(&self) -> BaseSpec {
        let mut screen = self.spec;
        screen.hold_first = self.rung.models.len();
        screen
    }

    /// Whether candidate `c` is confusable with an effect of the model (Coulomb friction
    /// beside a load torque: the same term where the speed never reverses): it can only
    /// show what it adds by trading values with it, so it is a finalist with every value
    /// free.
    fn trades(&self, c: &[&dyn EffectModel]) -> bool {
        c.iter().any(|e| {
            e.confused_with()
                .iter()
                .any(|x| self.rung.kinds.contains(&x.with))
        })
    }
}

impl<'a> Ladder<'a> {
    /// Every candidate of `round` added to the model of its rung (`an` the analysis of the
    /// rung's base), fitted on the fit series (in parallel), with its held-back error there
    /// and what makes it implausible. Three passes: every candidate screened
    /// ([`SCREEN_ITER`] iterations, from where the model stood, the model's own values
    /// held), then the [`FINALISTS`] best (plausible first, by their penalised held-back
    /// error, and the best of all) fitted to convergence from there, and the round's best
    /// of them refitted with every value of the model free (with `machine`, the six
    /// physical base parameters free beside them, [`Ladder::joint_machine`]); `starts` says
    /// whether that one, of several effects, is also fitted from the nominal base
    /// parameters ([`Starts`]). The held values cost no simulation per iteration: in a
    /// late round the model holds a dozen. `progress` is handed the share of the round
    /// done.
    pub(super) fn fit_round(
        &self,
        an: &Analysis,
        round: &RoundFits<'_, 'a>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Vec<Fitted<'a>>, AnalysisError> {
        let done = std::sync::atomic::AtomicUsize::new(0);
        let total = (round.cands.len() + FINALISTS).max(1);
        let tick = || {
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(k as f64 / total as f64);
        };
        let screened = self.screen_pass(an, round, &tick)?;
        let out = self.final_pass(an, round, screened, &tick)?;
        let out = self.joint_pass(an, round, out)?;
        Ok(out.into_iter().flatten().collect())
    }

    /// The first pass: every candidate fitted [`SCREEN_ITER`] iterations with the model's
    /// own values held.
    fn screen_pass(
        &self,
        an: &Analysis,
        round: &RoundFits<'_, 'a>,
        tick: &(dyn Fn() + Sync),
    ) -> Result<Slots<'a>, AnalysisError> {
        let screen = round.screen_spec();
        round
            .cands
            .par_iter()
            .map(|c| {
                let r = self.fit_candidate(
                    an,
                    c,
                    round.rung,
                    screen,
                    Starts::NestedOnly,
                    SCREEN_ITER,
                    None,
                );
                tick();
                r
            })
            .collect()
    }

    /// The second pass: the finalists ([`finalists`], and every candidate that trades
    /// values with an effect of the model) fitted to convergence from their screening.
    fn final_pass(
        &self,
        an: &Analysis,
        round: &RoundFits<'_, 'a>,
        screened: Slots<'a>,
        tick: &(dyn Fn() + Sync),
    ) -> Result<Slots<'a>, AnalysisError> {
        let screen = round.screen_spec();
        let mut chosen = finalists(&screened);
        for (i, c) in round.cands.iter().enumerate() {
            if round.trades(c) && screened[i].is_some() && !chosen.contains(&i) {
                chosen.push(i);
            }
        }
        let full: Vec<(usize, Option<Fitted<'a>>)> = chosen
            .par_iter()
            .map(|&i| {
                let c = &round.cands[i];
                let spec = if round.trades(c) { round.spec } else { screen };
                let r = self.fit_candidate(
                    an,
                    c,
                    round.rung,
                    spec,
                    Starts::NestedOnly,
                    MAX_ITER,
                    screened[i].as_ref(),
                );
                tick();
                r.map(|f| (i, f))
            })
            .collect::<Result<_, _>>()?;
        // A finalist whose full fit could not run leaves the round.
        let mut out = screened;
        for (i, f) in full {
            if let Some(slot) = out.get_mut(i) {
                *slot = f;
            }
        }
        Ok(out)
    }

    /// The third pass: the round's best plausible candidate (what the step would keep) and
    /// the best by held-back error alone (a fit that held the model's values may have
    /// ended at a bound its own values' freedom leaves), refitted with every value of the
    /// model free: with the six base parameters beside them where the round's `machine`
    /// says so, else from the round's `starts`.
    fn joint_pass(
        &self,
        an: &Analysis,
        round: &RoundFits<'_, 'a>,
        out: Slots<'a>,
    ) -> Result<Slots<'a>, AnalysisError> {
        let joint: Vec<(usize, Option<Fitted<'a>>)> = best_two(&out)
            .par_iter()
            .map(|&i| {
                let r = match (round.machine, out[i].as_ref()) {
                    (true, Some(f)) => self.joint_machine(an, f, round.rung).map(Some),
                    _ => self.fit_candidate(
                        an,
                        &round.cands[i],
                        round.rung,
                        round.spec,
                        round.starts,
                        MAX_ITER,
                        out[i].as_ref(),
                    ),
                };
                r.map(|f| (i, f))
            })
            .collect::<Result<_, _>>()?;
        Ok(replace(out, joint))
    }

    /// One candidate `c` (effects to add, in order) fitted with the model of `rung` (`an`
    /// the analysis of its base), from the `starts` given, the base parameters as `spec`
    /// says (for the candidate's effects, [`BaseSpec::for_effects`]), at most `max_iter`
    /// iterations; from a screening fit `from`'s values where given, else from where the
    /// model stood.
    #[allow(clippy::too_many_arguments)]
    fn fit_candidate(
        &self,
        an: &Analysis,
        c: &[&'a dyn EffectModel],
        rung: &Rung<'a>,
        spec: BaseSpec,
        starts: Starts,
        max_iter: usize,
        from: Option<&Fitted<'a>>,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let sr = &self.series;
        let set = match from {
            Some(f) => nested_from(an, &f.models, &f.fit.effect_params, &[], &sr.fd),
            None => nested(an, c, rung, &sr.fd),
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
            let nominal = BaseParams::nominal(&an.constants);
            let (f, g) = rayon::join(
                || an.fit_spec_iter(&sr.fd, &set, &sr.wf, &start, spec, max_iter),
                || an.fit_spec_iter(&sr.fd, &set, &sr.wf, &nominal, spec, max_iter),
            );
            let (f, g) = (f?, g?);
            if g.report.cost < f.report.cost {
                g
            } else {
                f
            }
        } else {
            an.fit_spec_iter(&sr.fd, &set, &sr.wf, &start, spec, max_iter)?
        };
        let pred = fit::predict(&sr.fd, &an.constants, &set, &f)?;
        let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
        let why = implausible_step(an, &set, rung, &f, sr.m)?;
        Ok(Some(Fitted {
            models: set.iter().map(|a| a.effect).collect(),
            fit: f,
            n_parameters,
            heldback_fit_series: hb,
            implausible: why,
            base: None,
        }))
    }
}

/// `slots` with each refit of `new` in its candidate's slot (a refit that could not run
/// leaves the fit before it in place).
fn replace<'a>(mut slots: Slots<'a>, new: Vec<(usize, Option<Fitted<'a>>)>) -> Slots<'a> {
    for (i, f) in new {
        if let (Some(f), Some(slot)) = (f, slots.get_mut(i)) {
            *slot = Some(f);
        }
    }
    slots
}

/// The indices of the best plausible candidate and of the best by penalised held-back
/// error alone (one index when they are the same).
fn best_two(out: &[Option<Fitted<'_>>]) -> Vec<usize> {
    let score = |i: &usize| out[*i].as_ref().map_or(f64::INFINITY, Fitted::score);
    let ran = || {
        (0..out.len()).filter(|&i| {
            out[i]
                .as_ref()
                .is_some_and(|f| f.heldback_fit_series.is_finite())
        })
    };
    let best_plausible = ran()
        .filter(|&i| out[i].as_ref().is_some_and(|f| f.implausible.is_empty()))
        .min_by(|a, b| score(a).total_cmp(&score(b)));
    let best_any = ran().min_by(|a, b| score(a).total_cmp(&score(b)));
    let mut joint_of: Vec<usize> = best_plausible.into_iter().collect();
    if let Some(b) = best_any.filter(|b| !joint_of.contains(b)) {
        joint_of.push(b);
    }
    joint_of
}

/// The screened candidates fitted in full ([`Ladder::fit_round`]): the first
/// [`FINALISTS`] in the round's order (plausible first, then by penalised held-back
/// error), and the best by that error alone (a screening fit not yet plausible may end
/// plausible).
fn finalists(screened: &[Option<Fitted<'_>>]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..screened.len())
        .filter(|&i| {
            screened[i]
                .as_ref()
                .is_some_and(|f| f.heldback_fit_series.is_finite())
        })
        .collect();
    let score = |i: usize| screened[i].as_ref().map_or(f64::INFINITY, Fitted::score);
    let plausible = |i: usize| {
        screened[i]
            .as_ref()
            .is_some_and(|f| f.implausible.is_empty())
    };
    order.sort_by(|&a, &b| {
        plausible(b)
            .cmp(&plausible(a))
            .then(score(a).total_cmp(&score(b)))
    });
    let mut out: Vec<usize> = order.iter().copied().take(FINALISTS).collect();
    if let Some(best) = order
        .iter()
        .copied()
        .min_by(|&a, &b| score(a).total_cmp(&score(b)))
    {
        if !out.contains(&best) {
            out.push(best);
        }
    }
    // The full-order machine (the candidate with the most effects) too: the partial
    // dynamics a screening ranks first are followed by the rest anyway.
    if let Some(most) = order
        .iter()
        .copied()
        .filter(|&i| screened[i].as_ref().is_some_and(|f| f.models.len() >= 2))
        .max_by_key(|&i| screened[i].as_ref().map_or(0, |f| f.models.len()))
    {
        if !out.contains(&most) {
            out.push(most);
        }
    }
    out
}

impl<'a> Ladder<'a> {
    /// Candidate `c` at its values corrected for the inputs' noise (SIMEX,
    /// [`crate::fit::FitResult::corrected`]), every effect held there and the base
    /// parameters refitted around them (`an` the analysis `c`'s fit is relative to);
    /// `None` for a candidate without corrected values. The corrected values alone,
    /// beside a base and other effects fitted with the biased ones, are not a model of
    /// the log: on the 3 hp machine's 40 s log warming by 50 K the drift at 36 and 56 K
    /// with its fit's base ended at a held-back error of 0.0196, above the model without
    /// it (0.0176), and 0.0162 with the base refitted.
    pub(super) fn at_corrected(
        &self,
        an: &Analysis,
        c: &Fitted<'a>,
    ) -> Result<Option<Fitted<'a>>, AnalysisError> {
        let Some(values) = c.fit.corrected.as_ref() else {
            return Ok(None);
        };
        let sr = &self.series;
        let Some(set) = nested_from(an, &c.models, values, &[], &sr.fd) else {
            return Ok(None);
        };
        let mut f = if sr.fit_base {
            let mut spec = BaseSpec::paper(true).for_effects(&set);
            spec.hold_first = set.len();
            an.fit_spec(&sr.fd, &set, &sr.wf, &c.fit.base, spec)?
        } else {
            c.fit.clone()
        };
        f.effect_params.clone_from(values);
        f.corrected = Some(values.clone());
        let pred = fit::predict(&sr.fd, &an.constants, &set, &f)?;
        let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
        Ok(Some(Fitted {
            fit: f,
            heldback_fit_series: hb,
            ..c.clone()
        }))
    }
}
