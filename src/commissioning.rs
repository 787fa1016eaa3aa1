//! Commissioning state machine: button -> learn healthy thresholds -> store in flash.
//!
//! Pure logic (no hardware, no core types): the firmware feeds it [`Event`]s and carries
//! out the returned [`Action`]. The same machine runs in the host tests.
//!
//! ```text
//!  boot ──RecordLoaded(ok)──► Commissioned ◄──────── SaveDone(ok) ──┐
//!    └───RecordLoaded(err)─► NotCommissioned                        │
//!  any idle state ──ButtonPressed──► Learning ──LearningDone(rec)──► Saving
//!                     (StartLearning)   │  (Save(rec))                  │
//!                                       └─LearningFailed / timeout─► Failed ◄─ SaveDone(err)
//! ```
//!
//! While learning or saving, button presses are ignored (debounce and no double start).
//! A failed commissioning never makes a half-learned record valid: the previous
//! thresholds (learned or default) stay in force in RAM and in flash.

use crate::flash_record::CalibrationRecord;
use crate::panel::Mode;

/// Where commissioning stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum State {
    /// No valid record: the core uses its default thresholds.
    NotCommissioned,
    /// The core is learning; started at `started_ms`.
    Learning {
        /// Time the learning started, ms (wrapping clock).
        started_ms: u32,
    },
    /// Learning finished; the record is being written.
    Saving,
    /// A valid record is in force.
    Commissioned,
    /// The last attempt failed; `why` says why.
    Failed {
        /// Reason of the failure.
        why: Failure,
    },
}

/// Why a commissioning attempt failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// The core rejected the start or produced no calibration.
    Learning,
    /// Learning did not finish within the expected time.
    Timeout,
    /// Writing or verifying the flash record failed.
    Storage,
}

/// Inputs of the state machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// Result of reading the record at boot (`true` = a valid record was applied).
    RecordLoaded(bool),
    /// The user button was pressed.
    ButtonPressed,
    /// The core finished learning with this calibration.
    LearningDone(CalibrationRecord),
    /// The core could not learn (or rejected the start).
    LearningFailed,
    /// Result of writing the record (`true` = written and read back equal).
    SaveDone(bool),
    /// Periodic tick (checks the timeout).
    Tick,
}

/// What the firmware has to do after an event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Nothing.
    None,
    /// Tell the core to start learning for `duration_s` seconds.
    StartLearning {
        /// Learning time, s.
        duration_s: f32,
    },
    /// Write this record to flash (then report [`Event::SaveDone`]).
    Save(CalibrationRecord),
}

/// The commissioning procedure: the button-learn-store state machine of thread mode (the
/// core's `monitor_core::CommissioningState` says whether the monitor itself is learning).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningProcedure {
    state: State,
    duration_s: f32,
}

impl CommissioningProcedure {
    /// Default learning time, s: 10 s at 10 kHz = 100 000 samples of healthy running.
    pub const DEFAULT_DURATION_S: f32 = 10.0;
    /// Extra time allowed beyond the learning duration before giving up, ms.
    pub const TIMEOUT_MARGIN_MS: u32 = 5_000;

    /// A machine in `NotCommissioned` that learns for `duration_s` seconds
    /// (non-finite or non-positive values fall back to [`Self::DEFAULT_DURATION_S`]).
    pub fn new(duration_s: f32) -> Self {
        let duration_s = if duration_s.is_finite() && duration_s > 0.0 {
            duration_s
        } else {
            Self::DEFAULT_DURATION_S
        };
        Self {
            state: State::NotCommissioned,
            duration_s,
        }
    }

    /// Current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// Learning duration, s.
    pub fn duration_s(&self) -> f32 {
        self.duration_s
    }

    /// Panel mode for this state.
    pub fn panel_mode(&self) -> Mode {
        match self.state {
            State::NotCommissioned => Mode::NotCommissioned,
            State::Learning { .. } | State::Saving => Mode::Commissioning,
            State::Commissioned => Mode::Commissioned,
            State::Failed { .. } => Mode::CommissioningFailed,
        }
    }

    /// Advance with `event` at time `now_ms`; returns what the firmware must do.
    pub fn handle(&mut self, event: Event, now_ms: u32) -> Action {
        match (self.state, event) {
            (_, Event::RecordLoaded(ok)) => {
                self.state = if ok {
                    State::Commissioned
                } else {
                    State::NotCommissioned
                };
                Action::None
            }
            (State::Learning { .. } | State::Saving, Event::ButtonPressed) => Action::None,
            (_, Event::ButtonPressed) => {
                self.state = State::Learning { started_ms: now_ms };
                Action::StartLearning {
                    duration_s: self.duration_s,
                }
            }
            (State::Learning { .. }, Event::LearningDone(rec)) => {
                self.state = State::Saving;
                Action::Save(rec)
            }
            (State::Learning { .. }, Event::LearningFailed) => {
                self.state = State::Failed {
                    why: Failure::Learning,
                };
                Action::None
            }
            (State::Learning { started_ms }, Event::Tick) => {
                let limit_ms = (self.duration_s * 1000.0) as u32 + Self::TIMEOUT_MARGIN_MS;
                if now_ms.wrapping_sub(started_ms) > limit_ms {
                    self.state = State::Failed {
                        why: Failure::Timeout,
                    };
                }
                Action::None
            }
            (State::Saving, Event::SaveDone(ok)) => {
                self.state = if ok {
                    State::Commissioned
                } else {
                    State::Failed {
                        why: Failure::Storage,
                    }
                };
                Action::None
            }
            // Stale or out-of-order events are ignored.
            _ => Action::None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec() -> CalibrationRecord {
        CalibrationRecord {
            mean: [0.0; 4],
            spread: [1.0; 4],
        }
    }

    #[test]
    fn happy_path() {
        let mut c = CommissioningProcedure::new(2.0);
        assert_eq!(c.handle(Event::RecordLoaded(false), 0), Action::None);
        assert_eq!(c.panel_mode(), Mode::NotCommissioned);
        assert_eq!(
            c.handle(Event::ButtonPressed, 10),
            Action::StartLearning { duration_s: 2.0 }
        );
        assert_eq!(c.handle(Event::ButtonPressed, 20), Action::None);
        assert_eq!(
            c.handle(Event::LearningDone(rec()), 2010),
            Action::Save(rec())
        );
        assert_eq!(c.panel_mode(), Mode::Commissioning);
        c.handle(Event::SaveDone(true), 2020);
        assert_eq!(c.state(), State::Commissioned);
    }

    #[test]
    fn timeout_and_storage_failure() {
        let mut c = CommissioningProcedure::new(1.0);
        c.handle(Event::ButtonPressed, u32::MAX - 100);
        c.handle(Event::Tick, 5000);
        assert!(matches!(c.state(), State::Learning { .. }));
        c.handle(Event::Tick, 6000);
        assert_eq!(
            c.state(),
            State::Failed {
                why: Failure::Timeout
            }
        );
        c.handle(Event::ButtonPressed, 7000);
        c.handle(Event::LearningDone(rec()), 8000);
        c.handle(Event::SaveDone(false), 8001);
        assert_eq!(c.panel_mode(), Mode::CommissioningFailed);
    }
}
