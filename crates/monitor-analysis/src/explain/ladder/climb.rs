//! The ladder as a type of its own ([`Ladder`]): what it climbs with (the user's analysis,
//! the effect library, the fit series and its held-back split), where it stands (the
//! rung, the analysis of that rung's base parameters, the steps so far, what the last
//! round found), and the climb, round by round ([`Ladder::round`] says the rung order),
//! until it stops ([`StopReason`]).

use super::refusal::Tried;
use super::refusal::{StopReason, WhatIsLeft};
use super::report::{LadderProgress, LadderReport, LadderStart, LadderStep};
use super::rung::{LadderSeries, Rung};
use crate::analysis::{Analysis, AnalysisError, Options};
use crate::effects::EffectModel;
use crate::explain::Skipped;
use crate::fit::machine::MachineScales;
use crate::simplified_model::BaseParams;
use monitor_laws::EffectId;

/// The ladder on one log: forward (and backward) selection over the effect library from
/// the configured model to the noise floor (the module `ladder`'s doc).
pub(super) struct Ladder<'a> {
    /// The analysis of the user's file: the log, the file's constants, its data quality.
    pub(super) file: &'a Analysis,
    /// The effects the rungs are drawn from ([`crate::effects::ladder_library`]).
    pub(super) library: &'a [Box<dyn EffectModel>],
    /// The series the fits run on, with the held-back split.
    pub(super) series: LadderSeries,
    /// The effects the user configured: the start, never dropped.
    pub(super) configured: Vec<EffectId>,
    /// Gets where the ladder is.
    pub(super) progress: &'a (dyn Fn(LadderProgress) + Sync),
    /// The rung the ladder stands on.
    pub(super) rung: Rung<'a>,
    /// The analysis of that rung's base parameters: the file recentred on them (`None`:
    /// the file's own).
    pub(super) rebased: Option<Analysis>,
    /// The steps climbed so far.
    pub(super) steps: Vec<LadderStep>,
    /// The last round's candidates not kept, best first.
    pub(super) last_round: Vec<Tried>,
    /// The effects the last round could not fit on this log, with why.
    pub(super) skipped: Vec<Skipped>,
}

impl<'a> Ladder<'a> {
    /// The ladder at its start on the log of `file`: the `configured` effects (resolved
    /// from `opts`) fitted on the fit series with the held-back mask `held`, measured.
    ///
    /// # Errors
    /// A configured effect whose needs the log does not meet.
    pub(super) fn start(
        file: &'a Analysis,
        library: &'a [Box<dyn EffectModel>],
        configured: &'a [Box<dyn EffectModel>],
        opts: &Options,
        held: Vec<bool>,
        progress: &'a (dyn Fn(LadderProgress) + Sync),
    ) -> Result<Self, AnalysisError> {
        let series = LadderSeries::of(file, held, opts.fit_base);
        let active = file.setup_all(&series.fd, configured)?;
        let nominal = BaseParams::nominal(&file.constants);
        let f0 = file.fit_set(&series.fd, &active, &series.wf, &nominal, opts.fit_base)?;
        let models: Vec<&dyn EffectModel> = configured.iter().map(|e| e.as_ref()).collect();
        let rung = series.measure(file, models, f0, MachineScales::of_file(&file.params))?;
        Ok(Ladder {
            file,
            library,
            series,
            configured: opts.effects.clone(),
            progress,
            rung,
            rebased: None,
            steps: Vec::new(),
            last_round: Vec::new(),
            skipped: Vec::new(),
        })
    }

    /// The analysis of the rung the ladder stands on (its base parameters).
    pub(super) fn standing(&self) -> &Analysis {
        self.rebased.as_ref().unwrap_or(self.file)
    }

    /// Where the model stood before the first step.
    pub(super) fn start_figures(&self) -> LadderStart {
        let r = &self.rung;
        LadderStart {
            effects: self.configured.clone(),
            error: r.error,
            heldback_error: r.heldback_error,
            noise_floor: r.noise,
            heldback_noise_floor: r.heldback_noise,
            ratio_to_floor: r.error / r.noise,
            error_over_time: r.over_time.clone(),
        }
    }

    /// Climbs from the rung the ladder stands on until the error is within the
    /// noise-floor band or nothing helps: each round ([`Ladder::round`]) keeps at most one
    /// step, and the step drops the earlier effects it explains better
    /// ([`Ladder::drop_stand_ins`]). Why it stopped.
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn climb(&mut self) -> Result<StopReason, AnalysisError> {
        loop {
            if let Some(reason) = at_floor(&self.rung) {
                return Ok(reason);
            }
            let base_after_base = self.base_changed_last();
            let round = self.round()?;
            self.skipped = round.skipped;
            self.last_round = round.tried;
            if round.exhausted {
                return Ok(StopReason::LibraryExhausted);
            }
            let Some((next, step)) = round.kept else {
                return Ok(self.nothing_helps(round.base_tried || base_after_base));
            };
            self.step_to(next, step)?;
        }
    }

    /// Whether the last step changed the base parameters (a base rung, or an effect with
    /// the base refitted beside it): the next round does not try the base rung again.
    pub(super) fn base_changed_last(&self) -> bool {
        self.steps.last().is_some_and(|s| !s.base.is_empty())
    }

    /// The ladder steps onto `next` by `step`: the model relative to its own base
    /// parameters, without the earlier effects the step explains better.
    fn step_to(&mut self, next: Rung<'a>, step: LadderStep) -> Result<(), AnalysisError> {
        let moved = next.scales != self.rung.scales;
        let next_an = moved.then(|| self.file.rebased(next.scales.apply(&self.series.file)));
        let an = next_an.as_ref().unwrap_or(self.standing());
        let (next, mut step) = self.drop_stand_ins(an, next, step, &self.rung)?;
        step.error_over_time = next.over_time.clone();
        self.steps.push(step);
        self.rung = next;
        if moved {
            self.rebased = next_an;
        }
        Ok(())
    }

    /// Why no candidate helps ([`StopReason::NothingHelps`]): the candidate that came
    /// closest, and what is left. "Beyond the effect library" only when the base rung was a
    /// candidate of the last round (`base_tried`: the effects were tried on a refitted
    /// base) and every effect of the library could be fitted; otherwise what was not tried.
    fn nothing_helps(&self, base_tried: bool) -> StopReason {
        let tried = &self.last_round;
        // The plausible candidate that came closest to passing (else the first tried).
        let closest = tried
            .iter()
            .filter(|t| !t.refusal.fit_failed())
            .max_by(|a, b| a.significance.total_cmp(&b.significance));
        let left = if base_tried && self.skipped.is_empty() {
            WhatIsLeft::BeyondLibrary
        } else if !self.skipped.is_empty() {
            WhatIsLeft::NotTried {
                effects: self.skipped.iter().map(|s| s.effect).collect(),
            }
        } else {
            WhatIsLeft::OnTheFileBase
        };
        let r = &self.rung;
        StopReason::NothingHelps {
            error: r.error,
            noise_floor: r.noise,
            heldback_error: r.heldback_error,
            heldback_noise_floor: r.heldback_noise,
            best: closest.or(tried.first()).cloned(),
            left,
        }
    }

    /// The report of the ladder that stopped for `reason` (its start and split already in
    /// `report`): the steps, the stop, the last round, and the chosen model refitted on the
    /// whole log ([`Ladder::final_fit`]) with the base changes read there.
    ///
    /// # Errors
    /// A model that cannot be set up on the log.
    pub(super) fn report(
        self,
        reason: StopReason,
        report: &mut LadderReport,
    ) -> Result<(), AnalysisError> {
        let kept = self.steps.len();
        (self.progress)(LadderProgress::FinalFit {
            kept,
            fraction: 0.0,
        });
        let fin = self.final_fit(report.start.error)?;
        (self.progress)(LadderProgress::FinalFit {
            kept,
            fraction: 1.0,
        });
        let (fin, leftover) = fin.map_or((None, None), |(f, l)| (Some(f), l));
        if let Some(f) = &fin {
            report.base_changes = f.base.iter().filter(|c| c.changed).cloned().collect();
        }
        // Where the error lives, when the ladder stops above the floor (or the chosen
        // model, refitted on the whole log, ends above it).
        let at_floor = matches!(reason, StopReason::NoiseFloor { .. });
        report.leftover = leftover.filter(|l| !(at_floor && l.at_floor));
        report.final_fit = fin;
        report.stop = reason.stop();
        report.stopped_reason = reason;
        report.final_effects = self.rung.kinds;
        report.ladder = self.steps;
        report.last_round = self.last_round;
        report.skipped_reasons = self.skipped;
        Ok(())
    }
}

/// Why the ladder stops at `rung` for the noise floor, if it does: both the whole-log and
/// the held-back error within the log's band of their floors ([`super::rules::FLOOR_BAND`] on a log of
/// up to [`super::rules::BAND_PERIODS`] supply periods, narrower beyond:
/// [`super::rules::FloorBand`]).
fn at_floor(rung: &Rung<'_>) -> Option<StopReason> {
    let r = rung.error / rung.noise;
    let rh = rung.heldback_error / rung.heldback_noise;
    let band = rung.band.ratio;
    (r <= band && rh <= band).then_some(StopReason::NoiseFloor {
        error: rung.error,
        noise_floor: rung.noise,
        heldback_error: rung.heldback_error,
        heldback_noise_floor: rung.heldback_noise,
        band,
    })
}
