//! The commissioning API of [`Monitor`]: starting, cancelling and ending runs, and the
//! calibration in force (the learning itself is in [`crate::commissioning`]).

use super::{CommissioningState, Monitor};
use crate::commissioning::{CommissioningError, CommissioningRun, Install};
use crate::error::{ConfigCheck, ConfigError};
use crate::threshold::Calibration;

impl Monitor {
    /// Starts a commissioning run that learns the healthy statistics over the next
    /// `duration_s` seconds of evaluated running (see [`crate::commissioning`]: time without
    /// voltage, settling, with a sensor fault or with the quasi-steady gate closed does not
    /// count) and puts them into force when done ([`Install::OnCompletion`]). Lamps stay
    /// off while learning; [`MonitorOutput::commissioning`] says `Learning` from the next
    /// slow-path block on. Returns the run's id.
    ///
    /// # Errors
    /// As [`Monitor::start_commissioning_with`].
    pub fn start_commissioning(&mut self, duration_s: f32) -> Result<u16, CommissioningError> {
        self.start_commissioning_with(duration_s, Install::OnCompletion)
    }

    /// Starts a commissioning run as [`Monitor::start_commissioning`], with the learned
    /// calibration put into force as `install` says. Returns the run's id.
    ///
    /// # Errors
    /// [`CommissioningError::Duration`] for a non-finite or non-positive `duration_s` (or
    /// one longer than `u32::MAX` blocks); [`CommissioningError::Busy`] while a run is
    /// learning or awaiting storage. Nothing changes then.
    pub fn start_commissioning_with(
        &mut self,
        duration_s: f32,
        install: Install,
    ) -> Result<u16, CommissioningError> {
        let id = self
            .learner
            .start(duration_s, self.derived.block_rate_hz, install)?;
        self.lamps.reset();
        self.revision = self.revision.wrapping_add(1);
        Ok(id)
    }

    /// Cancels run `run_id` if it is still learning: it ends
    /// [`Failed(Cancelled)`](crate::CommissioningFailure::Cancelled) and the thresholds in
    /// force before it stay. Returns false (and changes nothing) when that run is not
    /// learning: another run, or it has learned already (a run awaiting storage is ended
    /// by [`Monitor::calibration_stored`], so a late cancel cannot leave a stored record
    /// that the monitor does not use).
    pub fn cancel_commissioning(&mut self, run_id: u16) -> bool {
        self.revision = self.revision.wrapping_add(1);
        let cancelled = self.learner.cancel(run_id);
        if cancelled {
            self.refresh_commissioning_state();
        }
        cancelled
    }

    /// Ends run `run_id` now with what it has learned, if it is still learning and has
    /// learned at least `min_s` seconds of evaluated running: the run completes as if that
    /// much had been asked for (statistics checked, the calibration put into force or
    /// awaiting storage as its [`Install`] says). A window over real running, whose supply
    /// and load steps close the quasi-steady gate for a while, is learned so. Returns
    /// whether the run ended; false (nothing changes) for another run, a run not
    /// learning, or one that has learned less than `min_s`.
    pub fn finish_commissioning(&mut self, run_id: u16, min_s: f32) -> bool {
        let min_blocks = min_s * self.derived.block_rate_hz;
        let min_blocks = if min_blocks.is_finite() && min_blocks >= 1.0 {
            min_blocks.min(4.0e9) as u32
        } else {
            1
        };
        self.revision = self.revision.wrapping_add(1);
        let (ended, cal) = self.learner.finish(run_id, min_blocks);
        if let Some(cal) = cal {
            self.lamps.set_calibration(Some(cal));
        }
        if ended {
            self.refresh_commissioning_state();
        }
        ended
    }

    /// Reports what the calibration store holds after storing run `run_id`'s calibration
    /// (read back after the write; `None`: no usable record). The thresholds in force
    /// become exactly `stored` (`None`: the fixed thresholds), so the monitor and its store
    /// agree whatever happened. If that run was awaiting storage it ends
    /// [`Done`](crate::RunStage::Done) when `stored` is the calibration it learned, else
    /// [`Failed(NotStored)`](crate::CommissioningFailure::NotStored).
    ///
    /// # Errors
    /// [`ConfigErrorKind::Calibration`](crate::ConfigErrorKind::Calibration) when `stored`
    /// is out of range (the fixed thresholds are put in force, as for no record). A report
    /// for an older run changes no run but still puts `stored` into force.
    pub fn calibration_stored(
        &mut self,
        run_id: u16,
        stored: Option<Calibration>,
    ) -> Result<(), ConfigError> {
        let usable = stored.filter(Calibration::is_valid);
        // A stale report leaves the runs alone; the store's content is what counts.
        let _ = self.learner.stored(run_id, usable);
        self.lamps.set_calibration(usable);
        self.refresh_commissioning_state();
        match (stored, usable) {
            (Some(_), None) => Err(ConfigError::new(ConfigCheck::Calibration)),
            _ => Ok(()),
        }
    }

    /// The latest commissioning run: id, stage (learning, awaiting storage, done or failed
    /// with the reason) and progress in evaluated blocks.
    pub fn commissioning(&self) -> CommissioningRun {
        self.learner.run()
    }

    /// The calibration in use, if commissioned.
    pub fn calibration(&self) -> Option<Calibration> {
        self.lamps.calibration()
    }

    /// The threshold band of each normalised residual r1..r4 in force: (centre, half-width)
    /// (learned mean and `k_sigma` spread once commissioned, else 0 and the fixed
    /// threshold); a residual outside its band lights its lamp after the debounce.
    pub fn threshold_bands(&self) -> [(f32, f32); 4] {
        [0, 1, 2, 3].map(|k| self.lamps.band(k))
    }

    /// Installs a stored calibration (at boot: the record read from flash). A run that is
    /// still active ends [`Failed(Superseded)`](crate::CommissioningFailure::Superseded).
    ///
    /// # Errors
    /// [`crate::ConfigErrorKind::Calibration`] when a value is not finite or out of range; the monitor
    /// then keeps its previous thresholds (and an active run goes on).
    pub fn set_calibration(&mut self, cal: Calibration) -> Result<(), ConfigError> {
        if !cal.is_valid() {
            return Err(ConfigError::new(ConfigCheck::Calibration));
        }
        self.learner.supersede();
        self.lamps.set_calibration(Some(cal));
        self.refresh_commissioning_state();
        Ok(())
    }

    /// Forgets the calibration (back to fixed thresholds); an active run ends
    /// [`Failed(Superseded)`](crate::CommissioningFailure::Superseded).
    pub fn clear_calibration(&mut self) {
        self.learner.supersede();
        self.lamps.set_calibration(None);
        self.refresh_commissioning_state();
    }

    /// `out.commissioning` from the run and the thresholds in force (after a change).
    pub(super) fn refresh_commissioning_state(&mut self) {
        self.revision = self.revision.wrapping_add(1);
        let run = self.learner.run();
        self.out.commissioning = if run.stage.is_active() {
            CommissioningState::Learning(run.fraction_done())
        } else if self.lamps.calibration().is_some() {
            CommissioningState::Commissioned
        } else {
            CommissioningState::NotCommissioned
        };
    }
}
