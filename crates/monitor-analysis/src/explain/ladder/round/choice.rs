//! The choice of a round: the fitted candidates in order (the log's evidence between two
//! confusable ones, the whole machine's order before a part of it), the first that passes
//! the step's test ([`STEP_MIN`]) and lowers the whole-log error kept, the others refused
//! with why ([`Refusal`]), and the step's report.

use super::super::climb::Ladder;
use super::super::refusal::{Refusal, Tried};
use super::super::report::{BaseChange, LadderStep, RangedValue};
use super::super::rules::STEP_MIN;
use super::super::rung::{Fitted, Rung};
use crate::analysis::{Analysis, AnalysisError};
use crate::effects::{self, EffectModel};
use crate::simplified_model::MachineConstants;
use monitor_laws::EffectId;
use std::collections::BTreeMap;

/// The step a round keeps: the model after it and the step's report.
pub(super) type Kept<'a> = (Rung<'a>, LadderStep);

/// What a round's choice found: the step kept (if any) and the candidates not kept, with
/// why.
type Choice<'a> = (Option<Kept<'a>>, Vec<Tried>);

/// A candidate taken as a round's step, or why it is not kept.
enum Take<'a> {
    /// The model after the step and the step's report.
    Kept(Box<Kept<'a>>),
    /// Why not.
    Not(Refusal),
}

impl<'a> Ladder<'a> {
    /// The round's choice among `fitted` (fitted from `rung`, whose base `an` is the
    /// analysis of): the plausible candidates by their penalised held-back error, the
    /// first that passes the step's test and lowers the whole-log error; the others tried
    /// with why they were not kept.
    pub(super) fn choose(
        &self,
        an: &Analysis,
        mut fitted: Vec<Fitted<'a>>,
        rung: &Rung<'a>,
    ) -> Result<Choice<'a>, AnalysisError> {
        fitted.sort_by(|a, b| {
            a.implausible
                .is_empty()
                .cmp(&b.implausible.is_empty())
                .reverse()
                .then(a.score().total_cmp(&b.score()))
        });
        let before = rung.models.len();
        evidence_decides(an, &mut fitted, before);
        whole_machine_first(&mut fitted, rung, before, &an.constants);
        let mut tried = Vec::new();
        let mut kept = None;
        for c in fitted {
            let mut sig = significance(rung, &c);
            let refusal = if kept.is_some() {
                Some(Refusal::BetterKept)
            } else {
                match self.take(an, &c, rung, &mut sig)? {
                    Take::Kept(k) => {
                        kept = Some(*k);
                        None
                    }
                    Take::Not(why) => Some(why),
                }
            };
            if let Some(refusal) = refusal {
                tried.push(Tried {
                    base: c.base.is_some() && c.added(before).is_empty(),
                    added: c.added(before),
                    heldback_error: c.heldback_fit_series,
                    significance: sig,
                    refusal,
                });
            }
        }
        Ok((kept, tried))
    }

    /// Candidate `c` (its test statistic `sig`) taken as the step from `rung` (`an` the
    /// analysis of its base): the new rung and the step, or why it is not kept (diverged,
    /// not physical, below the test, or the whole-log error would rise).
    ///
    /// A candidate whose values the inputs' noise biases and SIMEX corrected
    /// ([`crate::fit::FitResult::corrected`]) is taken at the corrected values
    /// ([`Ladder::at_corrected`]) and judged beyond its own noise floor
    /// ([`beyond_own_floor`]), and `sig` becomes that statistic: its fitted values buy
    /// part of their lower error by passing less of the inputs' noise, which lowers its
    /// floor as much as its error.
    fn take(
        &self,
        an: &Analysis,
        c: &Fitted<'a>,
        rung: &Rung<'a>,
        sig: &mut f64,
    ) -> Result<Take<'a>, AnalysisError> {
        // The base rung's fit (and an effect's fitted with the six base parameters free)
        // is relative to the file recentred on its factors.
        let recentred;
        let on: &Analysis = match c.base {
            Some(s) => {
                recentred = an.rebased(s.apply(&self.series.file));
                &recentred
            }
            None => an,
        };
        let held = self.at_corrected(on, c)?;
        let c = held.as_ref().unwrap_or(c);
        let before_test = if held.is_some() { f64::INFINITY } else { *sig };
        if let Some(why) = refused(c, before_test) {
            return Ok(Take::Not(why));
        }
        let scales = c.base.unwrap_or(rung.scales);
        let next = self
            .series
            .measure(on, c.models.clone(), c.fit.clone(), scales)?;
        if !next.error.is_finite() || !next.heldback_error.is_finite() {
            return Ok(Take::Not(Refusal::DivergedOnWholeLog));
        }
        if held.is_some() {
            *sig = beyond_own_floor(rung, &next, c.n_parameters);
            if let Some(why) = refused(c, *sig) {
                return Ok(Take::Not(why));
            }
        }
        if next.error >= rung.error {
            return Ok(Take::Not(Refusal::WholeLogRises {
                from: rung.error,
                to: next.error,
            }));
        }
        let step = self.step_taken(on, c, rung, &next, *sig)?;
        Ok(Take::Kept(Box::new((next, step))))
    }

    /// The step from `rung` to `next` that candidate `c` (its statistic `sig`) makes, with
    /// the base changes it brought (`on` the analysis of `next`'s base): a base rung's
    /// step, or an effect's (fitted with the base parameters refitted beside it: their
    /// changes too, where any is named).
    fn step_taken(
        &self,
        on: &Analysis,
        c: &Fitted<'a>,
        rung: &Rung<'a>,
        next: &Rung<'a>,
        sig: f64,
    ) -> Result<LadderStep, AnalysisError> {
        let added = c.added(rung.models.len());
        if added.is_empty() {
            let changes = self.base_rung_changes(on, c)?;
            return Ok(base_step(changes, rung, next, sig));
        }
        let mut step = step_of(on, c, &added, rung, next, sig)?;
        if c.base.is_some() {
            let changes = self.base_rung_changes(on, c)?;
            if changes.iter().any(|x| x.changed) {
                step.base = changes;
            }
        }
        Ok(step)
    }
}

/// When the first two plausible single candidates of `fitted` (in the round's order) are
/// effects that declare each other confusable and score within the declared factor, the
/// log's evidence (read on `an`) decides, as in `explain`'s ranking: a first one it
/// contradicts goes second unless it contradicts the other too (a constant load torque and
/// Coulomb friction are one equation at a speed that never reverses).
fn evidence_decides<'a>(an: &Analysis, fitted: &mut [Fitted<'a>], before: usize) {
    let (Some(a), Some(b)) = (fitted.first(), fitted.get(1)) else {
        return;
    };
    if !a.implausible.is_empty() || !b.implausible.is_empty() {
        return;
    }
    let single = |c: &Fitted<'a>| -> Option<&'a dyn EffectModel> {
        (c.models.len() == before + 1)
            .then(|| c.models.get(before).copied())
            .flatten()
    };
    let (Some(ea), Some(eb)) = (single(a), single(b)) else {
        return;
    };
    let Some(conf) = ea.confused_with().iter().find(|c| c.with == eb.kind()) else {
        return;
    };
    if b.score() > conf.within * a.score() {
        return;
    }
    let unbalance = an.unbalance();
    let says = |c: &Fitted<'a>, e: &dyn EffectModel| {
        let fitted = c.fit.reported().last().map(Vec::as_slice).unwrap_or(&[]);
        e.evidence(&effects::EffectEvidence {
            voltage_unbalance: unbalance.voltage_negative_sequence_ratio,
            winding_suspected: unbalance.suspect_phase.is_some(),
            torque_scale_nm: an.constants.torque_scale_nm,
            fitted,
        })
    };
    if says(a, ea) == Some(false) && says(b, eb) != Some(false) {
        fitted.swap(0, 1);
    }
}

/// The ladder step that took the model from `rung` to `next` by adding `c` (`on` the
/// analysis of `next`'s base): the added effects' values with their physical ranges, and
/// each effect's values in its own words.
fn step_of(
    on: &Analysis,
    c: &Fitted<'_>,
    added: &[EffectId],
    rung: &Rung<'_>,
    next: &Rung<'_>,
    sig: f64,
) -> Result<LadderStep, AnalysisError> {
    let d = &on.data;
    let before = rung.models.len();
    let mut fitted = BTreeMap::new();
    let mut described = Vec::new();
    for (i, e) in c.models.iter().enumerate().skip(before) {
        let p = c.fit.reported().get(i).map_or(&[][..], Vec::as_slice);
        let Ok(setup) = e.setup(d, on.setup_constants()) else {
            continue;
        };
        // A long log's coarse copy may have fewer load segments than the working series.
        if setup.len() != p.len() {
            continue;
        }
        for (q, v) in setup.params.iter().zip(p) {
            let key = if added.len() > 1 {
                format!("{}.{}", e.kind(), q.name)
            } else {
                q.name.clone()
            };
            fitted.insert(
                key,
                RangedValue {
                    value: *v,
                    unit: q.unit().to_string(),
                    low: q.plausible.lo,
                    high: q.plausible.hi,
                },
            );
        }
        described.push(setup.describe(p, d, &on.constants)?);
    }
    Ok(LadderStep {
        effect: added.last().copied(),
        added: added.to_vec(),
        fitted,
        described,
        ..step_between(rung, next, sig)
    })
}

/// The ladder step of a base rung: the changes `changes` took the model from `rung` to
/// `next` (test statistic `sig`).
fn base_step(changes: Vec<BaseChange>, rung: &Rung<'_>, next: &Rung<'_>, sig: f64) -> LadderStep {
    let mut fitted = BTreeMap::new();
    for c in changes.iter().filter(|c| c.changed) {
        let (lo, hi) = c.interval.map_or((f64::NAN, f64::NAN), |[lo, hi]| (lo, hi));
        fitted.insert(
            c.base.name().to_string(),
            RangedValue {
                value: c.change,
                unit: "relative change".into(),
                low: lo,
                high: hi,
            },
        );
    }
    LadderStep {
        base: changes,
        fitted,
        ..step_between(rung, next, sig)
    }
}

/// The step from `rung` to `next` (test statistic `sig`) with its errors, floors and
/// shares explained, and nothing added, changed or dropped yet.
fn step_between(rung: &Rung<'_>, next: &Rung<'_>, sig: f64) -> LadderStep {
    LadderStep {
        effect: None,
        added: Vec::new(),
        base: Vec::new(),
        dropped: Vec::new(),
        dropped_because: Vec::new(),
        fitted: BTreeMap::new(),
        described: Vec::new(),
        error: next.error,
        heldback_error: next.heldback_error,
        noise_floor: next.noise,
        heldback_noise_floor: next.heldback_noise,
        ratio_to_floor: next.error / next.noise,
        heldback_ratio_to_floor: next.heldback_error / next.heldback_noise,
        significance: sig,
        explained: rung.explained(rung.error, next.error, next.noise),
        heldback_explained: rung.explained(
            rung.heldback_error,
            next.heldback_error,
            next.heldback_noise,
        ),
        error_over_time: next.over_time.clone(),
    }
}

/// The step's test statistic for candidate `c` on the model of `rung`: the share of the
/// held-back error beyond the noise floor it removes, its held-back error first raised by
/// [`crate::explain::PARAM_PENALTY`] per parameter.
fn significance(rung: &Rung<'_>, c: &Fitted<'_>) -> f64 {
    rung.explained(
        rung.heldback_fit_series,
        c.score(),
        rung.heldback_noise_fit_series,
    )
}

/// The step's test for a candidate judged at its corrected values: the share of `rung`'s
/// held-back error beyond its own floor that `next` (the candidate measured, with
/// `n_parameters` more parameters) leaves beyond *its* own floor, `1 - x_with / x_rung`
/// with `x = sqrt(E² - N²)`, the candidate's held-back error first raised by the band's
/// penalty per parameter ([`super::super::rules::FloorBand::penalty`]); 0 where the rung's
/// excess is within the band. On the 3 hp machine's 40 s log warming by 50 K, the drift at
/// its injected values (base refitted) ends 0.99x its own floor, which is 6 % below the
/// model's without the drift: the warmer windings pass less of the voltages' noise.
fn beyond_own_floor(rung: &Rung<'_>, next: &Rung<'_>, n_parameters: usize) -> f64 {
    let x = |e: f64, n: f64| (e * e - n * n).max(0.0).sqrt();
    let xb = x(rung.heldback_error, rung.heldback_noise);
    if !(xb > 0.0 && xb >= rung.band.excess * rung.heldback_noise) {
        return 0.0;
    }
    let with = next.heldback_error * (1.0 + rung.band.penalty * n_parameters as f64);
    (1.0 - x(with, next.heldback_noise) / xb).clamp(0.0, 1.0)
}

/// When the round's first plausible candidate adds dynamics effects only (a part of the
/// full-order machine: the stator's d axis alone through a start) and a plausible candidate
/// adding more of the machine's dynamics, and nothing else, passes the step's test too,
/// that one goes first: the rest of the machine's order is needed as well, and a step that
/// takes it at once leaves no partial model for the next rounds' effects to be fitted on.
fn whole_machine_first(
    fitted: &mut [Fitted<'_>],
    rung: &Rung<'_>,
    before: usize,
    n: &MachineConstants,
) {
    let dynamics_only = |c: &Fitted<'_>| {
        c.models
            .iter()
            .skip(before)
            .all(|m| m.time_constant_s(n).is_some() || !m.requires().is_empty())
    };
    let Some(first) = fitted.first() else {
        return;
    };
    if !first.implausible.is_empty() || !dynamics_only(first) || first.base.is_some() {
        return;
    }
    let k = first.models.len();
    let whole = fitted.iter().position(|c| {
        c.implausible.is_empty()
            && c.base.is_none()
            && c.models.len() > k
            && dynamics_only(c)
            && significance(rung, c) >= STEP_MIN
    });
    if let Some(i) = whole {
        fitted[..=i].rotate_right(1);
    }
}

/// Why candidate `c` (its test statistic `sig`) cannot be a step whatever the whole log
/// says: its model diverged on the held-back windows, its values are not physical, or it
/// removes less than the test's [`STEP_MIN`] of the held-back error beyond the floor.
fn refused(c: &Fitted<'_>, sig: f64) -> Option<Refusal> {
    if !(c.heldback_fit_series.is_finite() && c.heldback_fit_series > 0.0) {
        return Some(Refusal::Diverged);
    }
    if !c.implausible.is_empty() {
        return Some(Refusal::NotPhysical {
            why: c.implausible.clone(),
        });
    }
    if sig < STEP_MIN {
        return Some(Refusal::BelowTest {
            share: sig,
            asks: STEP_MIN,
        });
    }
    None
}
