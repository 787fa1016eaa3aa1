//! The commissioning procedure of thread mode: the button starts (or cancels) a run, the
//! result is stored in flash, and a run that makes no progress is cancelled.
//!
//! The core owns the run (`monitor_core::commissioning`: start, progress in evaluated
//! blocks, cancel, the learned calibration, failure reasons). This procedure only
//! - turns a button press into a start request (or, during learning, a cancel),
//! - watches the run's progress in the status the sample task sends, and cancels the run
//!   when no evaluated block was learned for `stall_timeout_ms` (the motor stopped, or the
//!   operating point does not settle),
//! - stores the learned calibration when the core asks for it
//!   ([`RunStage::AwaitingStorage`]) and reports what the flash holds afterwards
//!   ([`crate::app::Command::CalibrationStored`]), so the core puts exactly the stored
//!   record into force,
//! - remembers why the last attempt failed, for the panel and the log.
//!
//! It holds no copy of the thresholds in force and no clock of its own for the learning:
//! the panel's "commissioned or not" comes from the core, whose thresholds always equal the
//! flash record (a test drives every path and checks the three agree).
//!
//! ```text
//!  Idle ──button──► Requested ──core reports a new run──► Following(run)
//!   ▲                  │ no new run within 1 s: Failed(NotStarted)     │ Learning: progress? else after the stall time: Cancel
//!   │                  ▼                                               │ AwaitingStorage: Store (again after 1 s if still waiting)
//!   └──────────────────┴──── Done / Failed(reason) / cancelled ◄───────┘
//! ```
//!
//! Pure logic (no hardware): the firmware and the host tests feed it the latest
//! [`CommissioningRun`] and button presses and carry out the returned [`Action`].

use crate::flash_record::CalibrationRecord;
use monitor_core::{Calibration, CommissioningFailure, CommissioningRun, RunStage};

/// Why the last commissioning attempt failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// The core did not start a run within [`CommissioningProcedure::START_TIMEOUT_MS`]
    /// (it refused the duration, or a run was still active).
    NotStarted,
    /// No evaluated block for the stall time: the procedure cancelled the run.
    Stalled,
    /// The core ended the run for this reason.
    Core(CommissioningFailure),
}

impl Failure {
    /// A short name for logs.
    pub fn name(self) -> &'static str {
        match self {
            Failure::NotStarted => "not-started",
            Failure::Stalled => "no-progress",
            Failure::Core(why) => why.name(),
        }
    }
}

/// How a run the procedure followed ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunEnd {
    /// Learned, stored, and in force.
    Commissioned {
        /// The run's id.
        run: u16,
    },
    /// Cancelled with the button: the thresholds in force before stay, nothing failed.
    CancelledByUser {
        /// The run's id.
        run: u16,
    },
    /// Failed; the thresholds the core reports are in force (the ones before the run, or
    /// what the flash held after a failed write).
    Failed {
        /// The run's id (`None` when no run was started).
        run: Option<u16>,
        /// Why.
        why: Failure,
    },
}

/// What the firmware has to do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Nothing.
    None,
    /// Ask the core to start a run of `duration_s` seconds of evaluated running, installed
    /// after storage ([`crate::app::Command::StartCommissioning`]).
    Start {
        /// Learning time, s.
        duration_s: f32,
    },
    /// Ask the core to cancel run `run` ([`crate::app::Command::CancelCommissioning`]).
    Cancel {
        /// The run's id.
        run: u16,
    },
    /// Store `record` (run `run`'s calibration) in flash, read it back and report the
    /// result to the core ([`crate::app::Command::CalibrationStored`]).
    Store {
        /// The run's id.
        run: u16,
        /// The calibration to store.
        record: CalibrationRecord,
    },
}

/// The result of feeding the procedure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningStep {
    /// What to do now.
    pub action: Action,
    /// A followed run (or a start request) ended at this step.
    pub ended: Option<RunEnd>,
}

impl CommissioningStep {
    const NOTHING: CommissioningStep = CommissioningStep {
        action: Action::None,
        ended: None,
    };

    fn act(action: Action) -> CommissioningStep {
        CommissioningStep {
            action,
            ended: None,
        }
    }
}

/// Who asked for a cancel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CancelReason {
    User,
    Stalled,
}

/// What the procedure is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tracking {
    Idle,
    /// A start was requested at `since_ms`; the core's latest run was `previous_run`.
    Requested {
        previous_run: u16,
        since_ms: u32,
    },
    /// Following run `run`.
    Following {
        run: u16,
        started_ms: u32,
        /// Progress last seen, and when it last changed.
        blocks: u32,
        progress_ms: u32,
        /// A cancel sent: why and when.
        cancel: Option<(CancelReason, u32)>,
        /// When the calibration was last handed over for storage.
        stored_ms: Option<u32>,
    },
}

/// The procedure (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningProcedure {
    duration_s: f32,
    stall_timeout_ms: u32,
    tracking: Tracking,
    last_failure: Option<Failure>,
}

impl CommissioningProcedure {
    /// Default learning time, s: 10 s of evaluated running = 4000 slow-path blocks.
    pub const DEFAULT_DURATION_S: f32 = 10.0;
    /// Default stall time, ms: a run that learns no evaluated block for 3 s is cancelled.
    /// Longer than a load or supply step keeps the quasi-steady gate closed (its hold is
    /// 0.5 s), shorter than the gate's 5 s timeout, after which the core would learn on an
    /// operating point that does not settle.
    pub const DEFAULT_STALL_TIMEOUT_MS: u32 = 3_000;
    /// Time the core has to start a requested run, ms.
    pub const START_TIMEOUT_MS: u32 = 1_000;
    /// A press within this time after a start does not cancel the run (a bouncing or
    /// doubled press), ms.
    pub const CANCEL_GUARD_MS: u32 = 1_000;
    /// A cancel or a storage report the core has not acted on is repeated after this, ms.
    pub const RETRY_MS: u32 = 1_000;

    /// A procedure that asks for runs of `duration_s` seconds of evaluated running and
    /// cancels a run after `stall_timeout_ms` without progress. (The core refuses a
    /// non-finite or non-positive duration: the attempt then fails with
    /// [`Failure::NotStarted`].)
    pub fn new(duration_s: f32, stall_timeout_ms: u32) -> Self {
        Self {
            duration_s,
            stall_timeout_ms,
            tracking: Tracking::Idle,
            last_failure: None,
        }
    }

    /// Learning duration asked for, s.
    pub fn duration_s(&self) -> f32 {
        self.duration_s
    }

    /// Why the last attempt failed (`None` after a success, a cancel with the button, or
    /// a new start).
    pub fn last_failure(&self) -> Option<Failure> {
        self.last_failure
    }

    /// True from a start request until the run has ended.
    pub fn busy(&self) -> bool {
        self.tracking != Tracking::Idle
    }

    /// The button was pressed at `now_ms`: start a run, or cancel the one that is learning.
    /// `run` is the core's latest run as last reported.
    pub fn button(&mut self, run: &CommissioningRun, now_ms: u32) -> Action {
        match &mut self.tracking {
            Tracking::Idle => {
                self.tracking = Tracking::Requested {
                    previous_run: run.id,
                    since_ms: now_ms,
                };
                self.last_failure = None;
                Action::Start {
                    duration_s: self.duration_s,
                }
            }
            Tracking::Following {
                run: id,
                started_ms,
                cancel,
                stored_ms: None,
                ..
            } if cancel.is_none() && now_ms.wrapping_sub(*started_ms) >= Self::CANCEL_GUARD_MS => {
                *cancel = Some((CancelReason::User, now_ms));
                Action::Cancel { run: *id }
            }
            _ => Action::None,
        }
    }

    /// The latest status reported `run` at `now_ms` (call it every panel period).
    pub fn on_status(&mut self, run: &CommissioningRun, now_ms: u32) -> CommissioningStep {
        match self.tracking {
            Tracking::Idle if run.stage.is_active() => {
                // A run the procedure did not ask for (none should exist): follow it.
                self.follow(run, now_ms);
                self.following(run, now_ms)
            }
            Tracking::Idle => CommissioningStep::NOTHING,
            Tracking::Requested {
                previous_run,
                since_ms,
            } => {
                if run.id != previous_run {
                    self.follow(run, now_ms);
                    self.following(run, now_ms)
                } else if now_ms.wrapping_sub(since_ms) > Self::START_TIMEOUT_MS {
                    self.end(RunEnd::Failed {
                        run: None,
                        why: Failure::NotStarted,
                    })
                } else {
                    CommissioningStep::NOTHING
                }
            }
            Tracking::Following { run: id, .. } if id != run.id => {
                // A newer run replaced the one followed (it cannot end any more).
                self.follow(run, now_ms);
                self.following(run, now_ms)
            }
            Tracking::Following { .. } => self.following(run, now_ms),
        }
    }

    fn follow(&mut self, run: &CommissioningRun, now_ms: u32) {
        self.tracking = Tracking::Following {
            run: run.id,
            started_ms: now_ms,
            blocks: run.blocks_learned,
            progress_ms: now_ms,
            cancel: None,
            stored_ms: None,
        };
    }

    /// One step of following the run: what the run's stage at `now_ms` asks for.
    fn following(&mut self, run: &CommissioningRun, now_ms: u32) -> CommissioningStep {
        let Tracking::Following {
            run: id, cancel, ..
        } = self.tracking
        else {
            return CommissioningStep::NOTHING;
        };
        match run.stage {
            RunStage::Learning => self.learning(run.blocks_learned, now_ms),
            RunStage::AwaitingStorage(cal) => self.awaiting_storage(cal, now_ms),
            RunStage::Done => self.end(RunEnd::Commissioned { run: id }),
            RunStage::Failed(why) => self.end(failed_end(id, why, cancel)),
            RunStage::Idle => {
                self.tracking = Tracking::Idle;
                CommissioningStep::NOTHING
            }
        }
    }

    /// The followed run is learning and has learned `blocks_learned` evaluated blocks at
    /// `now_ms`: progress restarts the stall time; without progress for the stall time, a
    /// cancel (repeated after [`Self::RETRY_MS`] while the core has not acted on it).
    fn learning(&mut self, blocks_learned: u32, now_ms: u32) -> CommissioningStep {
        let stall_timeout_ms = self.stall_timeout_ms;
        let Tracking::Following {
            run: id,
            blocks,
            progress_ms,
            cancel,
            ..
        } = &mut self.tracking
        else {
            return CommissioningStep::NOTHING;
        };
        if blocks_learned != *blocks {
            *blocks = blocks_learned;
            *progress_ms = now_ms;
            return CommissioningStep::NOTHING;
        }
        let since = |t: u32| now_ms.wrapping_sub(t);
        let due = match *cancel {
            None => since(*progress_ms) >= stall_timeout_ms,
            Some((_, sent_ms)) => since(sent_ms) >= Self::RETRY_MS,
        };
        if !due {
            return CommissioningStep::NOTHING;
        }
        let reason = cancel.map_or(CancelReason::Stalled, |(r, _)| r);
        *cancel = Some((reason, now_ms));
        CommissioningStep::act(Action::Cancel { run: *id })
    }

    /// The followed run waits for its calibration `cal` to be stored at `now_ms`:
    /// hands it over, again after [`Self::RETRY_MS`] while the core still waits.
    fn awaiting_storage(&mut self, cal: Calibration, now_ms: u32) -> CommissioningStep {
        let Tracking::Following {
            run: id, stored_ms, ..
        } = &mut self.tracking
        else {
            return CommissioningStep::NOTHING;
        };
        if stored_ms.is_some_and(|t| now_ms.wrapping_sub(t) < Self::RETRY_MS) {
            return CommissioningStep::NOTHING;
        }
        *stored_ms = Some(now_ms);
        CommissioningStep::act(Action::Store {
            run: *id,
            record: cal.into(),
        })
    }

    fn end(&mut self, end: RunEnd) -> CommissioningStep {
        self.tracking = Tracking::Idle;
        self.last_failure = match end {
            RunEnd::Failed { why, .. } => Some(why),
            RunEnd::Commissioned { .. } | RunEnd::CancelledByUser { .. } => None,
        };
        CommissioningStep {
            action: Action::None,
            ended: Some(end),
        }
    }
}

/// How followed run `id` ended when the core reports it failed for `why`, given the cancel
/// the procedure sent (if any): a cancel is the user's, or the stall's, or (none sent) the
/// core's own reason.
fn failed_end(id: u16, why: CommissioningFailure, cancel: Option<(CancelReason, u32)>) -> RunEnd {
    match (why, cancel) {
        (CommissioningFailure::Cancelled, Some((CancelReason::User, _))) => {
            RunEnd::CancelledByUser { run: id }
        }
        (CommissioningFailure::Cancelled, Some((CancelReason::Stalled, _))) => RunEnd::Failed {
            run: Some(id),
            why: Failure::Stalled,
        },
        (why, _) => RunEnd::Failed {
            run: Some(id),
            why: Failure::Core(why),
        },
    }
}

#[cfg(test)]
mod tests;
