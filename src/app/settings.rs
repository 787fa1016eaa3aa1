//! The firmware's settings ([`Settings`]): what a user may change without touching the code
//! paths (the firmware's `SETTINGS`, checked at compile time with [`Settings::validate`]).

use crate::board;
use crate::commissioning::CommissioningProcedure;
use crate::sampling::TICK_HZ;

/// The firmware's settings: what a user may change without touching the code paths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Sample (trigger) rate of the six channels, Hz: must divide the 1 MHz timestamp clock
    /// and be a multiple of 100 (the status rate), and the core must accept it (at least
    /// 8x the supply frequency, see `MonitorConfig`). Default 10 kHz.
    pub sample_rate_hz: u32,
    /// Seconds of evaluated running one commissioning run learns, > 0. Default 10 s.
    pub commissioning_duration_s: f32,
    /// A commissioning run that learns no evaluated block for this long is cancelled, ms.
    /// Default 3 s ([`CommissioningProcedure::DEFAULT_STALL_TIMEOUT_MS`]).
    pub commissioning_stall_ms: u32,
}

impl Settings {
    /// The defaults: 10 kHz, 10 s of learning, 3 s stall time.
    pub const DEFAULT: Settings = Settings {
        sample_rate_hz: board::DEFAULT_SAMPLE_RATE_HZ,
        commissioning_duration_s: CommissioningProcedure::DEFAULT_DURATION_S,
        commissioning_stall_ms: CommissioningProcedure::DEFAULT_STALL_TIMEOUT_MS,
    };

    /// Samples between two status hand-overs to thread mode: `sample_rate_hz / 100`, so
    /// the status comes at 100 Hz (at least every sample).
    pub const fn status_every(&self) -> u32 {
        let n = self.sample_rate_hz / 100;
        if n == 0 {
            1
        } else {
            n
        }
    }

    /// Checks the ranges of the fields (a `const fn`: the firmware checks its settings at
    /// compile time). Whether the core accepts the sample rate for the machine (at least
    /// 8 times the supply frequency, enough slow-path blocks per period) is checked when
    /// the sample path is built ([`SamplePath::for_board`](super::SamplePath::for_board)).
    ///
    /// # Errors
    /// [`SettingsError`] naming the first field out of range.
    pub const fn validate(&self) -> Result<(), SettingsError> {
        let rate = self.sample_rate_hz;
        if rate == 0 || !rate.is_multiple_of(100) || !TICK_HZ.is_multiple_of(rate) {
            return Err(SettingsError::SampleRate);
        }
        let d = self.commissioning_duration_s;
        if !(d > 0.0 && d < f32::INFINITY) {
            return Err(SettingsError::CommissioningDuration);
        }
        if self.commissioning_stall_ms == 0 {
            return Err(SettingsError::CommissioningStall);
        }
        Ok(())
    }
}

/// A [`Settings`] field out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// `sample_rate_hz` is 0, not a multiple of 100, or does not divide the 1 MHz
    /// timestamp clock.
    SampleRate,
    /// `commissioning_duration_s` is not finite and positive.
    CommissioningDuration,
    /// `commissioning_stall_ms` is 0.
    CommissioningStall,
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}
