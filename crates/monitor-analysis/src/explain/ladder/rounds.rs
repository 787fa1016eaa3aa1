//! One round of the ladder, in its order: the base rung first (the six base parameters
//! refitted, [`crate::fit::machine`]); when it does not pass the step's test, the effects
//! are fitted on the base it refitted (where its values are physical), each judged against
//! that base, so that no effect is credited with what the file's own errors explain and
//! none stands in for them (a warm stator's Rs, the rotor resistance a locked-rotor test
//! read at line frequency, the viscous load a user's file leaves out).

use super::base::BaseChange;
use super::choice::{base_step, Kept};
use super::round::{pairs_of, Fitted, LadderSeries, Rung, Starts};
use super::{LadderStep, Tried};
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
        let t0 = std::time::Instant::now();
        let base = if sr.fit_base && with_base {
            self.base_candidate(rung, sr)?
        } else {
            None
        };
        if std::env::var("LADDER_DEBUG").is_ok() {
            eprintln!("  base candidate {:.2} s", t0.elapsed().as_secs_f64());
        }
        let mut out = RoundOutcome {
            kept: None,
            tried: Vec::new(),
            skipped,
            base_tried: base.is_some(),
            exhausted: cands.is_empty() && base.is_none(),
        };
        // The base rung first: kept when it passes the step's test on its own.
        let mut on_base = None;
        if let Some(b) = base {
            let plausible = b.implausible.is_empty();
            let (kept, tried) = self.choose(vec![b.clone()], rung, sr)?;
            out.tried.extend(tried);
            if kept.is_some() {
                out.kept = kept;
                return Ok(out);
            }
            if plausible {
                on_base = Some(self.on_base(&b, sr)?);
            }
        }
        if cands.is_empty() {
            return Ok(out);
        }
        // The effects, on the refitted base where it is physical.
        let (an, from): (&Analysis, &Rung<'a>) = match &on_base {
            Some((an, r, _)) => (an, r),
            None => (self, rung),
        };
        let spec = BaseSpec::paper(sr.fit_base);
        let fitted = an.fit_round(&cands, from, sr, spec, Starts::AlsoNominal, &|f| {
            progress(0.1 + 0.6 * f)
        })?;
        if std::env::var("LADDER_DEBUG").is_ok() {
            eprintln!("  singles {:.2} s", t0.elapsed().as_secs_f64());
        }
        let pairs = pairs_of(&fitted, from.models.len());
        let (mut kept, tried) = an.choose(fitted, from, sr)?;
        out.tried.extend(tried);
        if kept.is_none() && !pairs.is_empty() {
            // No single effect passes: two that need each other (a load torque and the
            // cross coupling of a start, two hidden effects at once) are tried together.
            let fitted = an.fit_round(&pairs, from, sr, spec, Starts::NestedOnly, &|f| {
                progress(0.7 + 0.3 * f)
            })?;
            let (k2, t2) = an.choose(fitted, from, sr)?;
            kept = k2;
            out.tried.extend(t2);
        }
        out.kept = match (kept, on_base) {
            (Some((next, step)), Some((_, _, changes))) => {
                let step = with_base_of(step, changes, rung, &next);
                Some((next, step))
            }
            (k, _) => k,
        };
        progress(1.0);
        Ok(out)
    }

    /// The base rung `b` (not kept) as the model the effects are fitted on: the analysis of
    /// its base, its rung, and its changes against the file.
    fn on_base<'a>(
        &self,
        b: &Fitted<'a>,
        sr: &LadderSeries,
    ) -> Result<(Analysis, Rung<'a>, Vec<BaseChange>), AnalysisError> {
        let scales = b
            .base
            .unwrap_or_else(|| crate::fit::machine::MachineScales::of_file(&sr.file));
        let an = self.rebased(scales.apply(&sr.file));
        let r = an.measure_rung(b.models.clone(), b.fit.clone(), sr, scales)?;
        let changes = an.base_rung_changes(b, sr)?;
        Ok((an, r, changes))
    }
}

/// The step `step` of an effect fitted on a refitted base (with its `changes` against the
/// file), restated against the model `rung` the round started from: the base changes it
/// brings, and the shares explained from `rung` to `next`.
fn with_base_of(
    mut step: LadderStep,
    changes: Vec<BaseChange>,
    rung: &Rung<'_>,
    next: &Rung<'_>,
) -> LadderStep {
    let named: Vec<&BaseChange> = changes.iter().filter(|c| c.changed).collect();
    if !named.is_empty() {
        let b = base_step(changes.clone(), rung, next, step.significance);
        step.summary = format!("{}; on the refitted base: {}", step.summary, b.summary);
        step.base = changes;
    }
    step.explained = explained_fraction(rung.error, next.error, next.noise);
    step.heldback_explained = explained_fraction(
        rung.heldback_error,
        next.heldback_error,
        next.heldback_noise,
    );
    step
}
