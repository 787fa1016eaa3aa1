//! Commissioning: learning the healthy residual statistics, owned by the core from the
//! start of a run to its end.
//!
//! A run learns the mean and spread of the normalised residuals r1..r4 (Welford) over a
//! number of *evaluated blocks*: slow-path blocks in which the motor runs settled, with
//! voltage, without a sensor fault and quasi-steady (`MonitorOutput::quasi_steady`: the gate
//! open, or closed for longer than `MonitorConfig::gate_timeout_s`). Blocks that do not
//! qualify are not counted, so the run's progress ([`CommissioningRun::blocks_learned`])
//! stands still while the gate is closed; a supervisor that sees no progress for long can
//! [`cancel`](crate::Monitor::cancel_commissioning) the run. (A supervisor that cancels
//! after less than the gate's timeout refuses to learn on an operating point that never
//! settles.)
//!
//! ```text
//!            start ─► Learning ──(blocks_needed evaluated blocks)──► statistics valid? ──no─► Failed(InvalidStatistics)
//!                        │                                                 │ yes
//!   cancel_commissioning │                      Install::OnCompletion ◄────┴────► Install::AfterStorage
//!                        ▼                             │                                   │
//!               Failed(Cancelled)           Done (calibration in force)        AwaitingStorage(calibration)
//!                                                                                          │ calibration_stored(stored)
//!                                                        Done ◄── stored == learned ───────┴─── otherwise ──► Failed(NotStored)
//!   set_calibration / clear_calibration during a run ─► Failed(Superseded)
//! ```
//!
//! With [`Install::AfterStorage`] (the firmware) the learned calibration goes into force
//! only once the caller has stored it and reports what the store holds
//! ([`Monitor::calibration_stored`](crate::Monitor::calibration_stored)); the thresholds in
//! force then always equal the stored record. While a run is learning or awaiting storage
//! the lamps stay off; the thresholds in force before the run stay in force until it ends.
//!
//! Every run has an id (a wrapping `u16` that changes at every start), so a late cancel or
//! a late storage report for an older run cannot touch a newer one, and a supervisor sees
//! each run's end as a state ([`RunStage`]) that stays until the next start rather than as
//! a one-sample event it might miss.

use crate::threshold::{Calibration, Welford};

/// When the calibration a run learned goes into force.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Install {
    /// As soon as the run has learned it (a host replay: nothing to store).
    #[default]
    OnCompletion,
    /// Only after [`Monitor::calibration_stored`](crate::Monitor::calibration_stored)
    /// reports that the store holds it (the firmware writes it to flash first).
    AfterStorage,
}

/// Why a run ended without putting its calibration into force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommissioningFailure {
    /// [`Monitor::cancel_commissioning`](crate::Monitor::cancel_commissioning) ended it
    /// while it was learning (a user, or a supervisor that saw no progress).
    Cancelled,
    /// A calibration was installed or cleared directly while the run was active.
    Superseded,
    /// The learned statistics are outside [`Calibration::is_valid`]'s range (|mean| <= 1,
    /// 0 <= spread <= 2): they could not be a healthy machine's.
    InvalidStatistics,
    /// The store did not hold the learned calibration after the write (a flash error or
    /// a failed read-back); the store's content went into force instead.
    NotStored,
}

impl CommissioningFailure {
    /// A short name for logs (`cancelled`, `superseded`, `invalid-statistics`, `not-stored`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Cancelled => "cancelled",
            Self::Superseded => "superseded",
            Self::InvalidStatistics => "invalid-statistics",
            Self::NotStored => "not-stored",
        }
    }
}

/// Where a commissioning run stands.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum RunStage {
    /// No run since the monitor was built.
    #[default]
    Idle,
    /// Learning: [`CommissioningRun::blocks_learned`] counts the evaluated blocks.
    Learning,
    /// Learned (with [`Install::AfterStorage`]); waiting for
    /// [`Monitor::calibration_stored`](crate::Monitor::calibration_stored). The payload is
    /// the calibration to store.
    AwaitingStorage(Calibration),
    /// Ended: the learned calibration is in force.
    Done,
    /// Ended without the learned calibration in force; the reason.
    Failed(CommissioningFailure),
}

impl RunStage {
    /// True while the run is learning or waiting for storage (lamps are held off).
    pub fn is_active(&self) -> bool {
        matches!(self, RunStage::Learning | RunStage::AwaitingStorage(_))
    }
}

/// The latest commissioning run: its id, stage and progress.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CommissioningRun {
    /// Run id: 0 before the first start, then changed (wrapping `+1`) by every start.
    pub id: u16,
    /// Where the run stands.
    pub stage: RunStage,
    /// Evaluated blocks learned so far (0..=`blocks_needed`); stands still while no block
    /// qualifies (gate closed, no voltage, settling, sensor fault).
    pub blocks_learned: u32,
    /// Evaluated blocks the run needs: `duration_s` times the slow-path rate
    /// (`sample_rate_hz / decimation`), at least 1.
    pub blocks_needed: u32,
}

impl CommissioningRun {
    /// Fraction of the needed blocks learned, in [0, 1] (0 when no run was started).
    pub fn fraction_done(&self) -> f32 {
        if self.blocks_needed == 0 {
            return 0.0;
        }
        crate::math::minf(self.blocks_learned as f32 / self.blocks_needed as f32, 1.0)
    }
}

/// Why a run could not be started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommissioningError {
    /// The duration is not finite and positive, or needs more than `u32::MAX` blocks.
    Duration,
    /// A run is still learning or awaiting storage (cancel it first).
    Busy,
    /// A storage report names a run that is not the latest one.
    StaleRun,
}

impl core::fmt::Display for CommissioningError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Duration => "commissioning duration must be finite and positive",
            Self::Busy => "a commissioning run is still active",
            Self::StaleRun => "the report names an older commissioning run",
        })
    }
}

/// The run state machine inside [`crate::Monitor`] (the thresholds themselves live in the
/// lamp logic; this decides when they change).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Learner {
    run: CommissioningRun,
    install: Install,
    welford: Welford,
}

impl Learner {
    /// The latest run.
    #[inline(always)]
    pub(crate) fn run(&self) -> CommissioningRun {
        self.run
    }

    /// True while learning or awaiting storage.
    #[inline(always)]
    pub(crate) fn is_active(&self) -> bool {
        self.run.stage.is_active()
    }

    /// True while learning.
    #[inline(always)]
    pub(crate) fn is_learning(&self) -> bool {
        self.run.stage == RunStage::Learning
    }

    /// Starts a run of `duration_s` seconds of evaluated running at `slow_hz` blocks per
    /// second; returns the new run's id.
    pub(crate) fn start(
        &mut self,
        duration_s: f32,
        slow_hz: f32,
        install: Install,
    ) -> Result<u16, CommissioningError> {
        if self.is_active() {
            return Err(CommissioningError::Busy);
        }
        let blocks = duration_s * slow_hz;
        if !(duration_s.is_finite() && duration_s > 0.0 && blocks < 4.0e9) {
            return Err(CommissioningError::Duration);
        }
        let id = self.run.id.wrapping_add(1);
        self.run = CommissioningRun {
            id,
            stage: RunStage::Learning,
            blocks_learned: 0,
            blocks_needed: (blocks as u32).max(1),
        };
        self.install = install;
        self.welford = Welford::default();
        Ok(id)
    }

    /// Learns one evaluated block's normalised residuals. Returns the calibration to put
    /// into force now (the run completed with [`Install::OnCompletion`] and valid
    /// statistics), else `None`.
    #[inline(always)]
    pub(crate) fn learn(&mut self, rn: [f32; 4]) -> Option<Calibration> {
        self.welford.push(rn);
        self.run.blocks_learned = self.run.blocks_learned.saturating_add(1);
        if self.run.blocks_learned < self.run.blocks_needed {
            return None;
        }
        self.complete()
    }

    /// Ends run `id` now with the blocks learned so far, if it is learning and has learned
    /// at least `min_blocks` (>= 1): the run completes as if those had been asked for.
    /// Returns whether it ended, and the calibration to put into force now, as
    /// [`Learner::learn`].
    pub(crate) fn finish(&mut self, id: u16, min_blocks: u32) -> (bool, Option<Calibration>) {
        let enough = self.run.blocks_learned >= min_blocks.max(1);
        if id != self.run.id || !self.is_learning() || !enough {
            return (false, None);
        }
        self.run.blocks_needed = self.run.blocks_learned;
        (true, self.complete())
    }

    /// The run has learned its blocks: checks the statistics and ends it.
    #[cold]
    fn complete(&mut self) -> Option<Calibration> {
        let cal = self.welford.calibration();
        if !cal.is_valid() {
            self.run.stage = RunStage::Failed(CommissioningFailure::InvalidStatistics);
            return None;
        }
        match self.install {
            Install::OnCompletion => {
                self.run.stage = RunStage::Done;
                Some(cal)
            }
            Install::AfterStorage => {
                self.run.stage = RunStage::AwaitingStorage(cal);
                None
            }
        }
    }

    /// Cancels run `id` if it is learning; true if it was.
    pub(crate) fn cancel(&mut self, id: u16) -> bool {
        if id == self.run.id && self.is_learning() {
            self.run.stage = RunStage::Failed(CommissioningFailure::Cancelled);
            true
        } else {
            false
        }
    }

    /// Ends an active run because the thresholds were set directly.
    pub(crate) fn supersede(&mut self) {
        if self.is_active() {
            self.run.stage = RunStage::Failed(CommissioningFailure::Superseded);
        }
    }

    /// The store now holds `stored` after storing run `id`'s calibration: ends the run
    /// (Done when `stored` is what it learned, else Failed(NotStored)).
    ///
    /// # Errors
    /// [`CommissioningError::StaleRun`] when `id` is not the latest run (nothing changes
    /// in the run; the caller still puts `stored` into force).
    pub(crate) fn stored(
        &mut self,
        id: u16,
        stored: Option<Calibration>,
    ) -> Result<(), CommissioningError> {
        if id != self.run.id {
            return Err(CommissioningError::StaleRun);
        }
        if let RunStage::AwaitingStorage(cal) = self.run.stage {
            self.run.stage = if stored == Some(cal) {
                RunStage::Done
            } else {
                RunStage::Failed(CommissioningFailure::NotStored)
            };
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// The calibration a run awaiting storage holds; asserts the run is awaiting storage.
    fn awaiting_storage(stage: RunStage) -> Calibration {
        assert!(matches!(stage, RunStage::AwaitingStorage(_)), "{stage:?}");
        match stage {
            RunStage::AwaitingStorage(cal) => cal,
            _ => Calibration::default(),
        }
    }

    use super::*;

    fn learned(l: &mut Learner, blocks: u32) -> Option<Calibration> {
        let mut out = None;
        for k in 0..blocks {
            let x = 0.001 * (k % 3) as f32;
            out = out.or(l.learn([x, -x, 0.0, x]));
        }
        out
    }

    #[test]
    fn a_run_finished_early_needs_its_minimum_and_then_completes() {
        let mut l = Learner::default();
        let id = l.start(1.0, 400.0, Install::OnCompletion).unwrap_or(0);
        assert!(learned(&mut l, 99).is_none());
        // 99 blocks learned: not enough for a minimum of 100; another run's id changes
        // nothing either.
        assert_eq!(l.finish(id, 100), (false, None));
        assert_eq!(l.finish(id.wrapping_add(1), 10), (false, None));
        assert_eq!(l.run().stage, RunStage::Learning);
        assert!(learned(&mut l, 1).is_none());
        let (ended, cal) = l.finish(id, 100);
        assert!(ended);
        assert_eq!(l.run().stage, RunStage::Done);
        assert_eq!(l.run().blocks_needed, 100);
        // The calibration of the 100 blocks learned: mean of 0, 0.001, 0.002 repeated.
        let cal = cal.unwrap_or_default();
        assert!((cal.mean[0] - 0.00099).abs() < 2e-5, "{cal:?}");
        // A run no longer learning is not finished again.
        assert_eq!(l.finish(id, 1), (false, None));
    }

    #[test]
    fn a_run_completes_after_its_blocks_and_installs_per_its_mode() {
        let mut l = Learner::default();
        assert_eq!(l.run().stage, RunStage::Idle);
        assert_eq!(l.start(0.1, 400.0, Install::OnCompletion), Ok(1));
        assert_eq!(l.run().blocks_needed, 40);
        assert!(learned(&mut l, 39).is_none());
        assert_eq!(l.run().stage, RunStage::Learning);
        assert!((l.run().fraction_done() - 39.0 / 40.0).abs() < 1e-6);
        assert!(learned(&mut l, 1).is_some());
        assert_eq!(l.run().stage, RunStage::Done);

        assert_eq!(l.start(0.1, 400.0, Install::AfterStorage), Ok(2));
        assert!(learned(&mut l, 40).is_none());
        let cal = awaiting_storage(l.run().stage);
        assert_eq!(
            l.start(1.0, 400.0, Install::AfterStorage),
            Err(CommissioningError::Busy)
        );
        assert!(!l.cancel(2), "only a learning run can be cancelled");
        assert_eq!(l.stored(1, Some(cal)), Err(CommissioningError::StaleRun));
        assert_eq!(l.stored(2, Some(cal)), Ok(()));
        assert_eq!(l.run().stage, RunStage::Done);
    }

    #[test]
    fn cancel_bad_storage_and_bad_durations_end_or_refuse_a_run() {
        let mut l = Learner::default();
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 1.0e9] {
            assert_eq!(
                l.start(bad, 400.0, Install::OnCompletion),
                Err(CommissioningError::Duration),
                "{bad}"
            );
        }
        let id = l.start(1.0, 400.0, Install::AfterStorage).unwrap(); // ok: test
        assert!(!l.cancel(id.wrapping_add(1)), "a cancel for another run");
        assert!(l.cancel(id));
        assert_eq!(
            l.run().stage,
            RunStage::Failed(CommissioningFailure::Cancelled)
        );
        let id = l.start(0.01, 400.0, Install::AfterStorage).unwrap(); // ok: test
        learned(&mut l, 4);
        assert!(matches!(l.run().stage, RunStage::AwaitingStorage(_)));
        assert_eq!(l.stored(id, None), Ok(()));
        assert_eq!(
            l.run().stage,
            RunStage::Failed(CommissioningFailure::NotStored)
        );
        // Statistics no healthy machine gives (|mean| > 1) are refused.
        l.start(0.01, 400.0, Install::OnCompletion).unwrap(); // ok: test
        let mut installed = None;
        for _ in 0..4 {
            installed = installed.or(l.learn([3.0, 0.0, 0.0, 0.0]));
        }
        assert!(installed.is_none());
        assert_eq!(
            l.run().stage,
            RunStage::Failed(CommissioningFailure::InvalidStatistics)
        );
        l.start(1.0, 400.0, Install::OnCompletion).unwrap(); // ok: test
        l.supersede();
        assert_eq!(
            l.run().stage,
            RunStage::Failed(CommissioningFailure::Superseded)
        );
    }

    /// The monitor's side: a balanced 60 Hz supply and current on the 3 hp machine, the
    /// voltage amplitude swinging +-20 % at 0.5 Hz while `swinging` (the quasi-steady
    /// gate stays closed).
    mod monitor {
        use super::awaiting_storage;
        use crate::commissioning::*;
        use crate::{CommissioningState, Monitor, MonitorConfig, Sample};
        use core::f32::consts::TAU;

        fn sample(k: u32, swinging: bool) -> Sample {
            let t = k as f32 * 1e-4;
            let scale = if swinging {
                1.0 + 0.2 * (TAU * 0.5 * t).sin()
            } else {
                1.0
            };
            crate::testing::steady_sample(k, 179.6 * scale)
        }

        fn monitor() -> Monitor {
            let mut cfg = MonitorConfig::new(crate::testing::motor_3hp(), 60.0, 220.0, 10_000.0);
            cfg.limits.i_max = 200.0;
            Monitor::new(cfg).unwrap() // ok: test
        }

        #[test]
        fn a_stored_run_changes_the_thresholds_only_when_the_store_holds_them() {
            let mut m = monitor();
            let id = m
                .start_commissioning_with(0.5, Install::AfterStorage)
                .unwrap(); // ok: test
            assert_eq!(m.commissioning().blocks_needed, 200);
            let mut k = 0;
            while m.commissioning().stage == RunStage::Learning && k < 40_000 {
                let o = *m.update(&sample(k, false));
                assert_eq!(o.lamps, [false; 4]);
                assert!(!o.evaluating);
                k += 1;
            }
            // 1 s of settling, then 0.5 s of learning.
            assert!((14_900..15_200).contains(&k), "learned after {k} samples");
            let cal = awaiting_storage(m.commissioning().stage);
            assert_eq!(m.calibration(), None, "in force before it is stored");
            assert_eq!(m.output().commissioning, CommissioningState::Learning(1.0));
            assert!(
                !m.cancel_commissioning(id),
                "learned runs are not cancelled"
            );
            // The store failed: it holds nothing, and neither does the monitor.
            assert!(m.calibration_stored(id, None).is_ok());
            assert_eq!(
                m.commissioning().stage,
                RunStage::Failed(CommissioningFailure::NotStored)
            );
            assert_eq!(m.calibration(), None);
            assert_eq!(
                m.output().commissioning,
                CommissioningState::NotCommissioned
            );
            // Again, stored this time.
            let id = m
                .start_commissioning_with(0.5, Install::AfterStorage)
                .unwrap(); // ok: test
            for _ in 0..6_000 {
                m.update(&sample(k, false));
                k += 1;
            }
            let cal2 = awaiting_storage(m.commissioning().stage);
            assert!(cal2.is_valid() && cal != Calibration::default());
            assert!(m.calibration_stored(id, Some(cal2)).is_ok());
            assert_eq!(m.commissioning().stage, RunStage::Done);
            assert_eq!(m.calibration(), Some(cal2));
            assert_eq!(m.output().commissioning, CommissioningState::Commissioned);
            // Lamps are evaluated again.
            for _ in 0..100 {
                m.update(&sample(k, false));
                k += 1;
            }
            assert!(m.output().evaluating);
        }

        #[test]
        fn no_progress_while_the_gate_is_closed_then_a_cancel_keeps_the_old_thresholds() {
            let mut m = monitor();
            let old = Calibration {
                mean: [0.0; 4],
                spread: [0.01; 4],
            };
            m.set_calibration(old).unwrap(); // ok: test
            let id = m
                .start_commissioning_with(0.5, Install::AfterStorage)
                .unwrap(); // ok: test

            // 1 s of settling, then 3 s of a swinging supply (the gate's timeout is 5 s).
            let mut closed = 0;
            for k in 0..40_000 {
                if !m.update(&sample(k, true)).quasi_steady {
                    closed += 1;
                }
            }
            assert!(
                closed > 35_000,
                "the swing closes the gate ({closed} samples)"
            );
            assert_eq!(m.commissioning().blocks_learned, 0);
            assert_eq!(m.commissioning().stage, RunStage::Learning);
            assert_eq!(m.output().commissioning, CommissioningState::Learning(0.0));
            assert!(!m.cancel_commissioning(id.wrapping_add(1)));
            assert!(m.cancel_commissioning(id));
            assert_eq!(
                m.commissioning().stage,
                RunStage::Failed(CommissioningFailure::Cancelled)
            );
            assert_eq!(m.calibration(), Some(old));
            assert_eq!(m.output().commissioning, CommissioningState::Commissioned);
            assert!(!m.cancel_commissioning(id), "cancelled once");
        }

        #[test]
        fn a_host_run_installs_on_completion_and_set_calibration_supersedes_a_run() {
            let mut m = monitor();
            assert_eq!(
                m.start_commissioning(0.0),
                Err(CommissioningError::Duration)
            );
            let id = m.start_commissioning(0.2).unwrap(); // ok: test
            assert_eq!(m.start_commissioning(0.2), Err(CommissioningError::Busy));
            for k in 0..13_000 {
                m.update(&sample(k, false));
            }
            assert_eq!(m.commissioning().stage, RunStage::Done);
            assert_eq!(m.commissioning().id, id);
            assert!(m.calibration().is_some());
            let id2 = m.start_commissioning(1.0).unwrap(); // ok: test
            assert_ne!(id2, id);
            let cal = Calibration {
                mean: [0.0; 4],
                spread: [0.02; 4],
            };
            m.set_calibration(cal).unwrap(); // ok: test
            assert_eq!(
                m.commissioning().stage,
                RunStage::Failed(CommissioningFailure::Superseded)
            );
            assert_eq!(m.calibration(), Some(cal));
            // A storage report puts the store's content into force, even a stale one, and
            // an out-of-range record counts as none.
            let bad = Calibration {
                mean: [4.0; 4],
                spread: [0.0; 4],
            };
            assert!(m.calibration_stored(id, Some(bad)).is_err());
            assert_eq!(m.calibration(), None);
        }
    }
}
