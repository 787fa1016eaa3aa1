//! The firmware's application logic, hardware-free: what runs per sample and what the
//! slow (thread-mode) side does with the results.
//!
//! - [`SamplePath`] runs in the high-priority sample task: [`RawFrame`] -> [`Sample`] ->
//!   [`Monitor::update`], applies [`Command`]s between samples, and reports when the core
//!   finished learning. Bounded work, no panics, no allocation.
//! - Thread mode runs the commissioning procedure
//!   ([`CommissioningProcedure`](crate::commissioning::CommissioningProcedure)) and maps
//!   the latest [`MonitorOutput`] to the panel ([`PanelInput::from_output`]).
//!
//! The host tests (`tests/sil.rs`) drive exactly these types with simulated data.
//!
//! [`Sample`]: monitor_core::Sample
//! [`MonitorOutput`]: monitor_core::MonitorOutput
//! [`PanelInput::from_output`]: crate::panel::PanelInput::from_output

use crate::board::{self, FrontEnd};
use crate::flash_record::CalibrationRecord;
use crate::sampling::{AdcSampler, RawFrame, SamplingError, TICK_HZ};
use monitor_core::{
    CommissioningState, ConfigError, Monitor, MonitorConfig, MonitorOutput, MotorModel,
    ReferenceMachine,
};

/// The machine the firmware monitors by default: DESIGN.md's "2.2 kW" reference machine
/// (`monitor_core::reference::MOTOR_2P2KW`: 400 V, 50 Hz, 4 poles, Gamma model, Bl for the
/// rated 14.6 N m near rated speed). Edit here for another machine.
pub const DEFAULT_MACHINE: ReferenceMachine = monitor_core::reference::MOTOR_2P2KW;

/// The default machine in the core's precision.
pub fn default_motor() -> MotorModel {
    DEFAULT_MACHINE.motor.model()
}

/// Core configuration for the board: [`DEFAULT_MACHINE`] on its rated supply, sampled at
/// `sample_rate_hz`, 1 MHz timestamps, a 16-bit x4 encoder counter with
/// [`board::ENCODER_COUNTS_PER_REV`] counts per revolution, and sensor limits equal to the
/// front end's full scale (a reading beyond it cannot be real). (The host's configuration
/// for replaying a log is `sim_host::replay::monitor_config_for_log`.)
pub fn board_monitor_config(sample_rate_hz: u32) -> MonitorConfig {
    let supply = DEFAULT_MACHINE.supply;
    let mut cfg = MonitorConfig::new(
        default_motor(),
        supply.f_hz as f32,
        supply.v_ll_rms as f32,
        sample_rate_hz as f32,
    );
    cfg.tick_hz = TICK_HZ as f32;
    cfg.encoder.counter_bits = 16;
    cfg.encoder.counts_per_rev = board::ENCODER_COUNTS_PER_REV;
    cfg.limits.v_max = board::VOLTAGE_FULL_SCALE_V;
    cfg.limits.i_max = board::CURRENT_FULL_SCALE_A;
    cfg
}

/// Why the application could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AppError {
    /// The core rejected the configuration.
    Config(ConfigError),
    /// The sample rate does not fit the timestamp clock.
    Sampling(SamplingError),
}

/// Requests from thread mode to the sample task (applied between two samples).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Start learning the healthy thresholds for `duration_s` seconds.
    StartCommissioning {
        /// Learning time, s (> 0).
        duration_s: f32,
    },
    /// Install a calibration read from flash.
    SetCalibration(CalibrationRecord),
}

/// Result of one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleResult {
    /// The core's output after this sample.
    pub output: MonitorOutput,
    /// `Some` exactly once, on the sample where learning finished: the learned values.
    pub learned: Option<CalibrationRecord>,
    /// `true` exactly once if learning ended without a calibration.
    pub learning_failed: bool,
}

/// The per-sample path: scaling, the core, commands.
#[derive(Clone, Debug)]
pub struct SamplePath {
    monitor: Monitor,
    sampler: AdcSampler,
    learning: Learning,
}

/// Where a requested learning run stands, as seen from the outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Learning {
    /// Not learning.
    Idle,
    /// Requested; the core reports `Learning` from its next slow-path run on.
    Requested,
    /// The core reported `Learning`; its end is the result.
    Running,
}

impl SamplePath {
    /// Build from a core configuration, the board's front end and the sample rate.
    ///
    /// # Errors
    /// [`AppError`] if the core or the sampler rejects the settings.
    pub fn new(
        cfg: MonitorConfig,
        front_end: FrontEnd,
        sample_rate_hz: u32,
    ) -> Result<Self, AppError> {
        Ok(Self {
            monitor: Monitor::new(cfg).map_err(AppError::Config)?,
            sampler: AdcSampler::new(front_end, sample_rate_hz).map_err(AppError::Sampling)?,
            learning: Learning::Idle,
        })
    }

    /// The default board setup at `sample_rate_hz`.
    ///
    /// # Errors
    /// As [`SamplePath::new`].
    pub fn for_board(sample_rate_hz: u32) -> Result<Self, AppError> {
        Self::new(
            board_monitor_config(sample_rate_hz),
            FrontEnd::DEFAULT,
            sample_rate_hz,
        )
    }

    /// Apply a command.
    ///
    /// # Errors
    /// [`monitor_core::ConfigErrorKind::Calibration`] when a stored calibration is out of the core's range
    /// (the monitor keeps its previous thresholds).
    pub fn command(&mut self, cmd: Command) -> Result<(), ConfigError> {
        match cmd {
            Command::StartCommissioning { duration_s } => {
                self.monitor.start_commissioning(duration_s);
                self.learning = Learning::Requested;
                Ok(())
            }
            Command::SetCalibration(rec) => self.monitor.set_calibration(rec.into()),
        }
    }

    /// The ADC sampler (for timestamp resynchronisation after lost samples).
    pub fn sampler_mut(&mut self) -> &mut AdcSampler {
        &mut self.sampler
    }

    /// The ADC sampler.
    pub fn sampler(&self) -> &AdcSampler {
        &self.sampler
    }

    /// The core monitor.
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// Process one trigger's readings.
    #[inline]
    pub fn on_frame(&mut self, raw: &RawFrame) -> SampleResult {
        let sample = self.sampler.build(raw);
        let output = *self.monitor.update(&sample);
        let mut learned = None;
        let mut learning_failed = false;
        let core_learning = matches!(output.commissioning, CommissioningState::Learning(_));
        if self.learning == Learning::Requested && core_learning {
            self.learning = Learning::Running;
        } else if self.learning == Learning::Running && !core_learning {
            self.learning = Learning::Idle;
            match (output.commissioning, self.monitor.calibration()) {
                (CommissioningState::Commissioned, Some(cal)) => learned = Some(cal.into()),
                _ => learning_failed = true,
            }
        }
        SampleResult {
            output,
            learned,
            learning_failed,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn board_config_is_valid() {
        assert!(board_monitor_config(board::DEFAULT_SAMPLE_RATE_HZ)
            .validate()
            .is_ok());
        assert!(SamplePath::for_board(board::DEFAULT_SAMPLE_RATE_HZ).is_ok());
    }
}
