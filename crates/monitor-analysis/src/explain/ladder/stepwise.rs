//! Stepwise selection both ways: after a step, an effect an earlier step added is dropped
//! when the model without it loses less than the step's test asks ([`STEP_MIN`]): the later
//! step explains what it stood in for (iron loss taken for a fan's drag before windage was
//! in the model). Forward selection alone never undoes a step (Efroymson's stepwise
//! regression, 1960, removes a term whose partial test fails after each addition; the test
//! here is the ladder's own, on the held-back windows).

use super::climb::Ladder;
use super::report::{Dropped, LadderStep};
use super::rules::STEP_MIN;
use super::rung::{nested_from, Rung};
use crate::analysis::{Analysis, AnalysisError};
use crate::effects::EffectModel;
use crate::explain::PARAM_PENALTY;
use crate::fit::{self, BaseSpec, FitResult};
use crate::metrics;
use monitor_laws::EffectId;

/// An effect of the model that may be dropped: added by an earlier step (not configured by
/// the user, not added by this step), a steady-state effect (the dynamics effects are the
/// machine's order, not a stand-in), and nothing else in the model needs it.
fn droppable(
    models: &[&dyn EffectModel],
    i: usize,
    step: &LadderStep,
    configured: &[EffectId],
    an: &Analysis,
) -> bool {
    let Some(e) = models.get(i) else {
        return false;
    };
    let k = e.kind();
    !configured.contains(&k)
        && !step.added.contains(&k)
        && e.time_constant_s(&an.constants).is_none()
        && e.requires().is_empty()
        && !models.iter().any(|m| m.requires().contains(&k))
}

/// The model of `next` without its effect `i`, refitted nested (from its values, the base
/// as the step left it), on the fit series: the fit and its held-back error there.
struct Without<'a> {
    i: usize,
    models: Vec<&'a dyn EffectModel>,
    fit: FitResult,
    /// The dropped effect's share of the held-back error beyond the floor (the step's
    /// statistic for putting it back).
    significance: f64,
}

impl<'a> Ladder<'a> {
    /// Drops, one at a time, the earlier effects of `next` (the model after `step`, taken
    /// from `before`; `an` the analysis of `next`'s base) that the model no longer needs:
    /// refitted without it, the model loses less than [`STEP_MIN`] of its held-back error
    /// beyond the floor (each of the effect's parameters costing [`PARAM_PENALTY`]), and
    /// the whole-log error stays below `before`'s (the step as a whole still lowers it).
    /// The step records what it dropped and why.
    pub(super) fn drop_stand_ins(
        &self,
        an: &Analysis,
        mut next: Rung<'a>,
        mut step: LadderStep,
        before: &Rung<'a>,
    ) -> Result<(Rung<'a>, LadderStep), AnalysisError> {
        loop {
            let idx: Vec<usize> = (0..next.models.len())
                .filter(|&i| droppable(&next.models, i, &step, &self.configured, an))
                .collect();
            if idx.is_empty() {
                break;
            }
            let Some(w) = self.least_needed(an, &next, idx)? else {
                break;
            };
            if w.significance >= STEP_MIN {
                break;
            }
            let gone = next.kinds[w.i];
            let rung = self.series.measure(an, w.models, w.fit, next.scales)?;
            if !(rung.error < before.error && rung.error.is_finite()) {
                break;
            }
            step.dropped.push(gone);
            step.dropped_because.push(Dropped {
                effect: gone,
                loses: w.significance,
                asks: STEP_MIN,
            });
            step.error = rung.error;
            step.heldback_error = rung.heldback_error;
            step.noise_floor = rung.noise;
            step.heldback_noise_floor = rung.heldback_noise;
            step.ratio_to_floor = rung.error / rung.noise;
            step.heldback_ratio_to_floor = rung.heldback_error / rung.heldback_noise;
            step.explained = rung.explained(before.error, rung.error, rung.noise);
            step.heldback_explained = rung.explained(
                before.heldback_error,
                rung.heldback_error,
                rung.heldback_noise,
            );
            next = rung;
        }
        Ok((next, step))
    }

    /// Of `next`'s effects at `idx`, the one whose removal costs the least held-back
    /// error, refitted without it (`None` when no refit could run).
    fn least_needed(
        &self,
        an: &Analysis,
        next: &Rung<'a>,
        idx: Vec<usize>,
    ) -> Result<Option<Without<'a>>, AnalysisError> {
        let mut best: Option<Without<'a>> = None;
        for i in idx {
            let Some(w) = self.without(an, next, i)? else {
                continue;
            };
            if best
                .as_ref()
                .is_none_or(|b| w.significance < b.significance)
            {
                best = Some(w);
            }
        }
        Ok(best)
    }

    /// `next`'s model without its effect `i`, refitted nested on the fit series (`None`
    /// when a set-up refuses the series).
    fn without(
        &self,
        an: &Analysis,
        next: &Rung<'a>,
        i: usize,
    ) -> Result<Option<Without<'a>>, AnalysisError> {
        let sr = &self.series;
        let models: Vec<&'a dyn EffectModel> = next
            .models
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, m)| *m)
            .collect();
        let values: Vec<Vec<f64>> = next
            .fit
            .effect_params
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, p)| p.clone())
            .collect();
        let Some(set) = nested_from(an, &models, &values, &[], &sr.fd) else {
            return Ok(None);
        };
        let spec = BaseSpec::paper(sr.fit_base).for_effects(&set);
        let f = an.fit_spec(&sr.fd, &set, &sr.wf, &next.fit.base, spec)?;
        let pred = fit::predict(&sr.fd, &an.constants, &set, &f)?;
        let hb = metrics::errors(&sr.fd, &pred, Some(&sr.held_fd)).normalized_rms_error;
        if !hb.is_finite() {
            return Ok(None);
        }
        let k = next.fit.effect_params.get(i).map_or(0, Vec::len);
        let with = next.heldback_fit_series * (1.0 + PARAM_PENALTY * k as f64);
        Ok(Some(Without {
            i,
            models,
            fit: f,
            significance: next.explained(hb, with, next.heldback_noise_fit_series),
        }))
    }
}
