//! One round of the ladder, as one idea: its candidates, the rung order
//! ([`Ladder::round`]: the base rung first, then the single effects, then pairs), the fits
//! of each kind of candidate ([`fits`]: screened, the finalists in full, the best refitted
//! with every value free), and the choice of the step kept ([`choice`]).
//!
//! The base rung comes first (the six base parameters refitted, [`crate::fit::machine`]);
//! when it does not pass the step's test, the effects are fitted on the base it refitted
//! (where its values are physical), each judged against that base, so that no effect is
//! credited with what the file's own errors explain and none stands in for them (a warm
//! stator's Rs, the rotor resistance a locked-rotor test read at line frequency, the
//! viscous load a user's file leaves out).

mod choice;
mod fits;

use super::climb::Ladder;
use super::refusal::Tried;
use super::report::LadderProgress;
use super::rules::{PAIRS_ABOVE, PAIR_FROM};
use super::rung::{Fitted, Rung};
use crate::analysis::{Analysis, AnalysisError};
use crate::effects::EffectModel;
use crate::explain::{SkipReason, Skipped};
use crate::fit::BaseSpec;
use crate::simplified_model::MachineConstants;
use crate::transients;
use choice::Kept;
use fits::{RoundFits, Starts};
use monitor_laws::EffectId;

/// What a round found.
pub(super) struct RoundOutcome<'a> {
    /// The step kept, if one passed.
    pub(super) kept: Option<Kept<'a>>,
    /// The candidates not kept, with why.
    pub(super) tried: Vec<Tried>,
    /// The effects that cannot be fitted on this log, with why.
    pub(super) skipped: Vec<Skipped>,
    /// Whether the base rung was a candidate of the round.
    pub(super) base_tried: bool,
    /// No candidate at all was left (the whole library is in the model).
    pub(super) exhausted: bool,
}

impl RoundOutcome<'_> {
    /// A round's outcome before its choice: the effects it could not fit (`skipped`),
    /// whether the base rung is a candidate, whether no effect is (`no_effects`).
    fn new(skipped: Vec<Skipped>, base_tried: bool, no_effects: bool) -> Self {
        RoundOutcome {
            kept: None,
            tried: Vec::new(),
            skipped,
            base_tried,
            exhausted: no_effects && !base_tried,
        }
    }
}

impl<'a> Ladder<'a> {
    /// One round from the rung the ladder stands on, in the ladder's order (decided here
    /// and nowhere else):
    /// 1. **the base rung**: the six base parameters refitted
    ///    ([`Ladder::base_candidate`]), when the base parameters are refitted at all, the
    ///    last step did not change them already, and, on a log with a start or a supply
    ///    step, the machine's dynamics are in (a base refitted through the paper's steady
    ///    model takes the transients it cannot follow for Rs, Lm and J, and every effect
    ///    fitted on it inherits that); kept when it passes the step's test on its own;
    /// 2. **the single effects**: each library effect not in the model, with what it needs
    ///    first, and the full-order machine at once ([`Ladder::candidates`]), fitted from
    ///    where the model stood ([`Ladder::fit_round`]) and each judged against the base
    ///    the base rung refitted where its values are physical ([`Ladder::choose`]);
    /// 3. **the pairs** of the singles that lowered the training cost most
    ///    ([`pairs_of`]), when no single passes and the held-back error is still above
    ///    [`PAIRS_ABOVE`] times its floor.
    ///
    /// The step reports what it explains from the rung the round started from.
    pub(super) fn round(&self) -> Result<RoundOutcome<'a>, AnalysisError> {
        let (an, rung) = (self.standing(), &self.rung);
        let kept = self.steps.len();
        let progress = |fraction: f64| {
            (self.progress)(LadderProgress::Round {
                round: kept + 1,
                kept,
                fraction,
            })
        };
        let (cands, skipped) = self.candidates(an);
        progress(0.0);
        // 1. The base rung.
        let order_done = !self.series.span.input_transient
            || !cands.iter().any(|c| c.iter().all(|e| is_dynamics(*e, an)));
        let base = if self.series.fit_base && !self.base_changed_last() && order_done {
            self.base_candidate(an, rung)?
        } else {
            None
        };
        let mut out = RoundOutcome::new(skipped, base.is_some(), cands.is_empty());
        let judge = self.base_first(an, base, rung, &mut out)?;
        if out.kept.is_some() || cands.is_empty() {
            return Ok(out);
        }
        // 2. The single effects (the full-order machine among them), from where the model
        // stood; once the machine's order is in, the round's best refitted with the six
        // base parameters free beside them.
        let from: &Rung<'a> = judge.as_ref().unwrap_or(rung);
        let singles = RoundFits {
            cands: &cands,
            rung,
            spec: BaseSpec::paper(self.series.fit_base),
            starts: Starts::AlsoNominal,
            machine: self.series.fit_base && order_done,
        };
        let fitted = self.fit_round(an, &singles, &|f| progress(0.1 + 0.6 * f))?;
        let pairs = pairs_of(&fitted, rung.models.len());
        let (mut kept, tried) = self.choose(an, fitted, from)?;
        out.tried.extend(tried);
        // 3. The pairs: two effects that need each other (a load torque and the cross
        // coupling of a start, two hidden effects at once), far from the floor.
        let far = rung.heldback_error > PAIRS_ABOVE * rung.heldback_noise;
        if kept.is_none() && !pairs.is_empty() && far {
            let of_pairs = RoundFits {
                cands: &pairs,
                starts: Starts::NestedOnly,
                ..singles
            };
            let fitted = self.fit_round(an, &of_pairs, &|f| progress(0.7 + 0.3 * f))?;
            let (k, tried) = self.choose(an, fitted, from)?;
            out.tried.extend(tried);
            kept = k;
        }
        out.kept = kept.map(|k| restated(k, rung, judge.is_some()));
        progress(1.0);
        Ok(out)
    }

    /// The base rung `base` of the round, if any, tried first (`an` the analysis of
    /// `rung`'s base): kept in `out` when it passes the step's test on its own; else, where
    /// its values are plausible, the model the round's effects are judged against (its
    /// rung on the file recentred on its base parameters).
    fn base_first(
        &self,
        an: &Analysis,
        base: Option<Fitted<'a>>,
        rung: &Rung<'a>,
        out: &mut RoundOutcome<'a>,
    ) -> Result<Option<Rung<'a>>, AnalysisError> {
        let Some(b) = base else {
            return Ok(None);
        };
        let plausible = b.implausible.is_empty();
        let (kept, tried) = self.choose(an, vec![b.clone()], rung)?;
        out.tried.extend(tried);
        if kept.is_some() {
            out.kept = kept;
            return Ok(None);
        }
        if !plausible {
            return Ok(None);
        }
        let file = &self.series.file;
        let scales = b
            .base
            .unwrap_or_else(|| crate::fit::machine::MachineScales::of_file(file));
        self.series
            .measure(&an.rebased(scales.apply(file)), b.models, b.fit, scales)
            .map(Some)
    }

    /// Why effect `e` of the library cannot be fitted on this log (`None`: it can; `an`
    /// the analysis of the rung's base): a missing channel, a set-up the data refuse, a
    /// time constant the fit series cannot resolve. What an effect needs first is tried
    /// with it ([`Ladder::candidates`]), not a reason to skip it; a dynamics effect
    /// competes on any log (its held-back error decides), not only through a start or a
    /// supply step.
    fn cannot_fit(&self, an: &Analysis, e: &dyn EffectModel) -> Option<SkipReason> {
        let all: Vec<EffectId> = self.library.iter().map(|x| x.kind()).collect();
        let resolvable = transients::Span {
            input_transient: true,
            ..self.series.span
        };
        if let Some(why) = transients::not_proposed(e, resolvable, an.setup_constants(), &all) {
            return Some(SkipReason::NotProposed { why });
        }
        e.needs()
            .met_by(&an.data)
            .and_then(|()| e.setup(&self.series.fd, an.setup_constants()).map(|_| ()))
            .err()
            .map(|why| SkipReason::Setup { why })
    }

    /// The round's candidates: each library effect not in the model, preceded by what it
    /// needs first and the model lacks, and the full-order machine at once
    /// ([`full_order`]); and the effects that cannot be fitted on this log, with why
    /// ([`Ladder::cannot_fit`]).
    fn candidates(&self, an: &Analysis) -> (Vec<Vec<&'a dyn EffectModel>>, Vec<Skipped>) {
        let (lib, have) = (self.library, &self.rung.kinds);
        let fits = |e: &dyn EffectModel| self.cannot_fit(an, e).is_none();
        let mut out = Vec::new();
        let mut skipped = Vec::new();
        for e in lib.iter().map(|e| e.as_ref()) {
            if have.contains(&e.kind()) {
                continue;
            }
            if let Some(because) = self.cannot_fit(an, e) {
                // One effect of two laws (the drift's windings apart and together) is
                // skipped once.
                if skipped.iter().any(|s: &Skipped| s.effect == e.kind()) {
                    continue;
                }
                skipped.push(Skipped {
                    effect: e.kind(),
                    because,
                });
                continue;
            }
            let missing: Vec<Option<&dyn EffectModel>> = e
                .requires()
                .iter()
                .filter(|r| !have.contains(r))
                .map(|r| {
                    lib.iter()
                        .map(|x| x.as_ref())
                        .find(|x| x.kind() == *r && fits(*x))
                })
                .collect();
            let Some(mut set) = missing.into_iter().collect::<Option<Vec<_>>>() else {
                skipped.push(Skipped {
                    effect: e.kind(),
                    because: SkipReason::NeedsFirst {
                        effects: e.requires().to_vec(),
                    },
                });
                continue;
            };
            set.push(e);
            out.push(set);
        }
        let dynamics = full_order(lib, have, an.setup_constants(), &fits);
        if dynamics.len() >= 2 {
            out.push(dynamics);
        }
        (out, skipped)
    }
}

/// The full-order machine at once: every dynamics effect of `lib` not in the model `have`
/// that `fits` the log (those with a time constant, and what needs one of them). A start or
/// a step can need all of them before any one fits with values a machine has: one alone
/// takes its time constant out of range to follow the others' part.
fn full_order<'a>(
    lib: &'a [Box<dyn EffectModel>],
    have: &[EffectId],
    n: &MachineConstants,
    fits: &dyn Fn(&dyn EffectModel) -> bool,
) -> Vec<&'a dyn EffectModel> {
    let timed = |k: EffectId| {
        lib.iter()
            .any(|e| e.kind() == k && e.time_constant_s(n).is_some())
    };
    lib.iter()
        .map(|e| e.as_ref())
        .filter(|e| !have.contains(&e.kind()) && fits(*e))
        .filter(|e| e.time_constant_s(n).is_some() || e.requires().iter().any(|r| timed(*r)))
        .collect()
}

/// The pairs a round tries when no single candidate passes: every two of the
/// [`PAIR_FROM`] single-effect candidates of `fitted` (plausible or not, not
/// diverged; fits of one round, the model's own `before` effects first in each) that
/// lowered the training cost most (one law of an effect, its best), each pair's effects in
/// the order fitted. A held-back
/// error can rise with one effect of a pair and fall with both: with a start's cross
/// coupling but no load torque, the fit uses the coupling to follow the acceleration a
/// missing load explains.
fn pairs_of<'a>(fitted: &[Fitted<'a>], before: usize) -> Vec<Vec<&'a dyn EffectModel>> {
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
    // One law of an effect with two (the drift's windings apart and together): its best.
    let mut seen: Vec<EffectId> = Vec::new();
    by_cost.retain(|c| {
        let k = c.models.get(before).map(|m| m.kind());
        let first = k.is_some_and(|k| !seen.contains(&k));
        seen.extend(k);
        first
    });
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

/// The step kept, `(next, step)`, restated against the model `rung` the round started
/// from where it was `judged` against the base refitted alone: the shares explained from
/// `rung` to `next`.
fn restated<'a>((next, mut step): Kept<'a>, rung: &Rung<'_>, judged: bool) -> Kept<'a> {
    if judged {
        step.explained = rung.explained(rung.error, next.error, next.noise);
        step.heldback_explained = rung.explained(
            rung.heldback_error,
            next.heldback_error,
            next.heldback_noise,
        );
    }
    (next, step)
}

/// An effect of the machine's order (one with a time constant, or one that needs one
/// first), on the set-up constants of `an`.
fn is_dynamics(e: &dyn EffectModel, an: &Analysis) -> bool {
    e.time_constant_s(an.setup_constants()).is_some() || !e.requires().is_empty()
}
