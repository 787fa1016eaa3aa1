//! One round of the ladder, in its order: the base rung first (the six base parameters
//! refitted, [`crate::fit::machine`]); when it does not pass the step's test, the effects
//! are fitted on the base it refitted (where its values are physical), each judged against
//! that base, so that no effect is credited with what the file's own errors explain and
//! none stands in for them (a warm stator's Rs, the rotor resistance a locked-rotor test
//! read at line frequency, the viscous load a user's file leaves out).

use super::choice::Kept;
use super::passes::Round;
use super::round::{pairs_of, Fitted, LadderSeries, Rung, Starts};
use super::{LadderStep, Tried, PAIRS_ABOVE};
use crate::effects::EffectModel;
use crate::explain::explained_fraction;
use crate::fit::BaseSpec;
use crate::{Analysis, AnalysisError};

/// What a round found.
pub(super) struct RoundOutcome<'a> {
    /// The step kept, if one passed.
    pub(super) kept: Option<Kept<'a>>,
    /// The candidates not kept, with why.
    pub(super) tried: Vec<Tried>,
    /// The effects that cannot be fitted on this log, each as `name: why`.
    pub(super) skipped: Vec<String>,
    /// Whether the base rung was a candidate of the round.
    pub(super) base_tried: bool,
    /// No candidate at all was left (the whole library is in the model).
    pub(super) exhausted: bool,
}

impl Analysis {
    /// The round from `rung` (`self` the analysis of its model): the base rung when
    /// `with_base` (and the base parameters are refitted at all), then, if it is not kept,
    /// the library's effects (then pairs, when no single one passes) on the base it
    /// refitted. `progress` gets the round's fraction done.
    pub(super) fn round<'a>(
        &self,
        lib: &'a [Box<dyn EffectModel>],
        rung: &Rung<'a>,
        sr: &LadderSeries,
        with_base: bool,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<RoundOutcome<'a>, AnalysisError> {
        let (cands, skipped) = self.ladder_candidates(lib, rung, sr);
        progress(0.0);
        // The base parameters are read through a model that can follow the log: on a log
        // with a start or a supply step, once the machine's dynamics are in (a base refitted
        // through the paper's steady model takes the transients it cannot follow for Rs,
        // Lm and J, and every effect fitted on it inherits that).
        let order_done = !sr.span.input_transient
            || !cands
                .iter()
                .any(|c| c.iter().all(|e| is_dynamics(*e, self)));
        let base = if sr.fit_base && with_base && order_done {
            self.base_candidate(rung, sr)?
        } else {
            None
        };
        let mut out = RoundOutcome {
            kept: None,
            tried: Vec::new(),
            skipped,
            base_tried: base.is_some(),
            exhausted: cands.is_empty() && base.is_none(),
        };
        let judge = self.base_first(base, rung, sr, &mut out)?;
        if out.kept.is_some() || cands.is_empty() {
            return Ok(out);
        }
        // The effects, fitted from where the model stood; once the machine's order is in,
        // the round's best are refitted with the six base parameters free beside them, and
        // each is judged against the base refitted alone (where that is physical): no
        // effect is credited with what the file's own errors explain, and none stands in
        // for them.
        let round = Round {
            cands: &cands,
            rung,
            sr,
            spec: BaseSpec::paper(sr.fit_base),
            starts: Starts::AlsoNominal,
            machine: sr.fit_base && order_done,
        };
        let from: &Rung<'a> = judge.as_ref().unwrap_or(rung);
        let kept = self.effects_round(&round, from, &mut out.tried, progress)?;
        out.kept = match (kept, &judge) {
            (Some((next, step)), Some(_)) => {
                let step = restated(step, rung, &next);
                Some((next, step))
            }
            (k, _) => k,
        };
        progress(1.0);
        Ok(out)
    }

    /// The base rung `base` of the round, if any, tried first: kept in `out` when it passes
    /// the step's test on its own; else, where its values are plausible, the model the
    /// round's effects are judged against ([`Analysis::judge_of`]).
    fn base_first<'a>(
        &self,
        base: Option<Fitted<'a>>,
        rung: &Rung<'a>,
        sr: &LadderSeries,
        out: &mut RoundOutcome<'a>,
    ) -> Result<Option<Rung<'a>>, AnalysisError> {
        let Some(b) = base else {
            return Ok(None);
        };
        let plausible = b.implausible.is_empty();
        let (kept, tried) = self.choose(vec![b.clone()], rung, sr)?;
        out.tried.extend(tried);
        if kept.is_some() {
            out.kept = kept;
            return Ok(None);
        }
        if plausible {
            return self.judge_of(&b, sr).map(Some);
        }
        Ok(None)
    }

    /// The effects of `round`, each judged against `from`: the singles, then, when none
    /// passes and the model is still far from its floor ([`PAIRS_ABOVE`]), the pairs of
    /// the singles that lowered the training error most. The candidates not kept go to
    /// `tried`; `progress` gets the round's fraction done.
    fn effects_round<'a>(
        &self,
        round: &Round<'_, 'a>,
        from: &Rung<'a>,
        tried: &mut Vec<Tried>,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<Option<Kept<'a>>, AnalysisError> {
        let (rung, sr) = (round.rung, round.sr);
        let fitted = self.fit_round(round, &|f| progress(0.1 + 0.6 * f))?;
        let pairs = pairs_of(&fitted, rung.models.len());
        let (kept, t) = self.choose(fitted, from, sr)?;
        tried.extend(t);
        let far = rung.heldback_error > PAIRS_ABOVE * rung.heldback_noise;
        if kept.is_some() || pairs.is_empty() || !far {
            return Ok(kept);
        }
        // No single effect passes: two that need each other (a load torque and the cross
        // coupling of a start, two hidden effects at once) are tried together.
        let of_pairs = Round {
            cands: &pairs,
            starts: Starts::NestedOnly,
            ..*round
        };
        let fitted = self.fit_round(&of_pairs, &|f| progress(0.7 + 0.3 * f))?;
        let (kept, t) = self.choose(fitted, from, sr)?;
        tried.extend(t);
        Ok(kept)
    }

    /// The base rung `b` (not kept) as the model the round's effects are judged against:
    /// its rung on the file recentred on its base parameters.
    fn judge_of<'a>(&self, b: &Fitted<'a>, sr: &LadderSeries) -> Result<Rung<'a>, AnalysisError> {
        let scales = b
            .base
            .unwrap_or_else(|| crate::fit::machine::MachineScales::of_file(&sr.file));
        self.rebased(scales.apply(&sr.file)).measure_rung(
            b.models.clone(),
            b.fit.clone(),
            sr,
            scales,
        )
    }
}

/// The step `step`, judged against the base refitted alone, restated against the model
/// `rung` the round started from: the shares explained from `rung` to `next`.
fn restated(mut step: LadderStep, rung: &Rung<'_>, next: &Rung<'_>) -> LadderStep {
    step.explained = explained_fraction(rung.error, next.error, next.noise);
    step.heldback_explained = explained_fraction(
        rung.heldback_error,
        next.heldback_error,
        next.heldback_noise,
    );
    step
}
/// An effect of the machine's order (one with a time constant, or one that needs one first).
fn is_dynamics(e: &dyn EffectModel, an: &Analysis) -> bool {
    e.time_constant_s(an.setup_constants()).is_some() || !e.requires().is_empty()
}
