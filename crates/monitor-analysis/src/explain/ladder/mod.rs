//! `explain --ladder`: forward selection over the effect library, from the configured model
//! to the noise floor. Open this file first: it says how a climb goes and where each part
//! lives; the entry ([`Analysis::ladder`]) is at its end.
//!
//! # How a climb goes
//! 1. **The split** (`split.rs`): the log is cut into strata by its events (the start,
//!    supply or speed transients, load moves, steady stretches) and each stratum into
//!    alternating windows; half are held back, so that each kind of event is both fitted
//!    and judged (`rules.rs`, "The held-back split").
//! 2. **The start** (`climb.rs`'s `Ladder::start`): the effects the user configured, fitted
//!    on the fit series (a copy of the working series thinned no further than the
//!    machine's fastest dynamics allow, `rung.rs`'s `LadderSeries`), measured on the whole
//!    log and on the held-back part against their noise floors (a `rung.rs`'s `Rung`).
//! 3. **Rounds** (`round/`), one step at most each, in one order: the base rung (the six
//!    base parameters refitted, `base.rs`), then every library effect not in the model
//!    (with what it needs first, and the full-order machine at once), then, far from the
//!    floor, pairs. Every candidate is screened, the finalists fitted in full, the best
//!    refitted with every value free (`round/fits.rs`); the plausible candidate with the
//!    lowest held-back error that passes the step's test ([`STEP_MIN`]) and lowers
//!    the whole-log error is kept, the others refused with why ([`Refusal`]). A candidate
//!    whose values the inputs' noise biases is judged at its values corrected for it, the
//!    base refitted around them, against its own noise floor (`round/choice.rs`).
//! 4. **Both ways** (`stepwise.rs`): after a step, an earlier effect the model no longer
//!    needs is dropped (the step explains what it stood in for).
//! 5. **The stop** (`climb.rs`): within the log's noise-floor band ([`FLOOR_BAND`], narrower
//!    on a log longer than [`BAND_PERIODS`] supply periods: [`FloorBand`]) on the
//!    whole log and the held-back part, or when no plausible candidate passes, or when the
//!    library is exhausted ([`StopReason`]).
//! 6. **The end** (`end.rs`): the chosen model refitted on the whole log with the base
//!    parameters free; each base change read there is checked against the effects it may
//!    trade with, and where the error lives is located when it ends above the floor.
//!
//! The values a climb produces (`report.rs`: the report, its steps, the base changes; and
//! `refusal.rs`: why a candidate was not kept, why the ladder stopped) are types of their
//! own, which every part imports and none defines; the numbers the ladder decides by are
//! in `rules.rs`. The ladder decides by matching on these values; the sentences a crew
//! reads are spelled from them by `monitor-words`.

mod apart;
mod base;
mod climb;
mod end;
mod refusal;
mod report;
mod round;
mod rules;
mod rung;
mod split;
mod stepwise;
#[cfg(test)]
mod tests;

pub use base::base_changes;
pub use refusal::{Refusal, Stop, StopReason, Tried, WhatIsLeft, WhyNotPhysical};
pub use report::{
    Alike, AsOne, BaseChange, Dropped, FinalFit, InPlace, LadderProgress, LadderReport,
    LadderStart, LadderStep, LawShape, NotSeparable, RangedValue, SplitInfo, Stratum, TestRule,
    Unsteady,
};
pub use rules::{
    FloorBand, AS_ONE_WITHIN, BAND_EXCESS_MIN, BAND_PERIODS, BASE_CHANGE_MIN, EVENT_WINDOW_MAX_S,
    FINALISTS, FLOOR_BAND, IN_PLACE_OF_BASE, LADDER_FIT_SAMPLES, LADDER_MAX_FIT_SAMPLES,
    PAIRS_ABOVE, PAIR_FROM, SCREEN_ITER, SHAPE_TRADE_MAX, STEP_MIN, UNSTEADY_SHARE, WINDOW_MAX_S,
    WINDOW_MIN_PERIODS,
};
pub use rung::fit_thinning;
pub use split::stratified_heldback;

use crate::analysis::{resolve, Analysis, AnalysisError, Options};
use crate::explain::PARAM_PENALTY;
use climb::Ladder;

impl Analysis {
    /// `explain --ladder`: forward selection over the effect library from the configured
    /// model (module doc, "How a climb goes"; the climb is `climb.rs`'s `Ladder`).
    /// `progress` gets where the ladder is ([`LadderProgress`]).
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub fn ladder(
        &self,
        opts: &Options,
        progress: &(dyn Fn(LadderProgress) + Sync),
    ) -> Result<LadderReport, AnalysisError> {
        let (held, strata) = stratified_heldback(&self.data, &self.constants);
        let mut report = self.report_before(opts, &held, strata);
        if let Some(reason) = self.ladder_refused() {
            report.stop = reason.stop();
            report.stopped_reason = reason;
            return Ok(report);
        }
        let library = opts.laws.ladder_models();
        let configured = resolve(&opts.effects, &opts.laws);
        let mut ladder = Ladder::start(self, &library, &configured, opts, held, progress)?;
        report.start = ladder.start_figures();
        report.test_rule.floor_band = ladder.series.band.ratio;
        let reason = ladder.climb()?;
        ladder.report(reason, &mut report)?;
        Ok(report)
    }

    /// The ladder's report before its first step: the split (`held`, `strata`), the test,
    /// the data, no steps.
    fn report_before(&self, opts: &Options, held: &[bool], strata: Vec<Stratum>) -> LadderReport {
        LadderReport {
            base_changes: Vec::new(),
            final_fit: None,
            start: LadderStart {
                effects: opts.effects.clone(),
                error: f64::NAN,
                heldback_error: f64::NAN,
                noise_floor: f64::NAN,
                heldback_noise_floor: f64::NAN,
                ratio_to_floor: f64::NAN,
                error_over_time: Vec::new(),
            },
            ladder: Vec::new(),
            stop: Stop::NoModel,
            stopped_reason: StopReason::NoVoltages,
            final_effects: opts.effects.clone(),
            last_round: Vec::new(),
            skipped_reasons: Vec::new(),
            split: SplitInfo {
                heldback_share: held.iter().filter(|h| **h).count() as f64
                    / self.data.len().max(1) as f64,
                strata,
            },
            test_rule: TestRule {
                step_min: STEP_MIN,
                param_penalty: PARAM_PENALTY,
                floor_band: FLOOR_BAND,
            },
            data: self.info(),
            data_quality: self.quality.clone(),
            leftover: None,
        }
    }

    /// Why the ladder cannot start on this log, if it cannot: no voltages (the model cannot
    /// run), or a log the data-quality stage does not trust.
    fn ladder_refused(&self) -> Option<StopReason> {
        if !self.data.channels.voltages {
            return Some(StopReason::NoVoltages);
        }
        (!self.quality.trusted_but_for_the_supply).then_some(StopReason::Untrusted)
    }
}
