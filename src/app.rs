//! The firmware's application logic, hardware-free: what runs per sample and what the
//! slow (thread-mode) side does with the results.
//!
//! - [`SamplePath`] runs in the high-priority sample task: [`RawFrame`] -> [`Sample`] ->
//!   [`Monitor::update`], applies [`Command`]s between samples, and reports when the core
//!   finished learning. Bounded work, no panics, no allocation.
//! - [`Supervisor`] runs in thread mode: the commissioning state machine and the mapping
//!   of the latest [`MonitorOutput`] to the [`panel`](crate::panel).
//!
//! The host tests (`tests/sil.rs`) drive exactly these two types with simulated data.

use crate::board::{self, FrontEnd};
use crate::commissioning::{Action, Commissioning, Event};
use crate::flash_record::CalibrationRecord;
use crate::panel::{Mode, PanelInput};
use crate::sampling::{RawFrame, SampleBuilder, SamplingError, TICK_HZ};
use monitor_core::{
    Commissioning as CoreCommissioning, ConfigError, Monitor, MonitorConfig, MonitorOutput,
    MotorModel,
};

/// Supply frequency of the default drive, Hz.
pub const SUPPLY_HZ: f32 = 50.0;
/// Line-to-line RMS supply voltage of the default drive, V.
pub const SUPPLY_V_LL_RMS: f32 = 400.0;

/// The motor the firmware monitors by default: DESIGN.md's "2.2 kW" reference machine
/// (400 V, 50 Hz, 4 poles, Gamma model: Rs 3.7 ohm, Rr 2.5 ohm, Ls = Lm = 0.245 H,
/// Lr 0.268 H, J 0.015 kg m^2, B 0.005 N m s/rad, Bl 0.0975 N m s/rad so that Bl*omega is
/// the rated 14.6 N m near rated speed). Edit here for another machine.
pub const DEFAULT_MOTOR: MotorModel = MotorModel {
    rs_ohm: 3.7,
    rr_ohm: 2.5,
    ls_h: 0.245,
    lr_h: 0.268,
    lm_h: 0.245,
    pole_pairs: 2,
    j_kgm2: 0.015,
    b_nms: 0.005,
    bl_nms: 0.0975,
};

/// Core configuration for the board: [`DEFAULT_MOTOR`] on 400 V / 50 Hz, sampled at
/// `sample_rate_hz`, 1 MHz timestamps, a 16-bit x4 encoder counter with
/// [`board::ENCODER_COUNTS_PER_REV`] counts per revolution, and sensor limits equal to the
/// front end's full scale (a reading beyond it cannot be real).
pub fn monitor_config(sample_rate_hz: u32) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(
        DEFAULT_MOTOR,
        SUPPLY_HZ,
        SUPPLY_V_LL_RMS,
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
    builder: SampleBuilder,
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
            builder: SampleBuilder::new(front_end, sample_rate_hz).map_err(AppError::Sampling)?,
            learning: Learning::Idle,
        })
    }

    /// The default board setup at `sample_rate_hz`.
    ///
    /// # Errors
    /// As [`SamplePath::new`].
    pub fn for_board(sample_rate_hz: u32) -> Result<Self, AppError> {
        Self::new(
            monitor_config(sample_rate_hz),
            FrontEnd::DEFAULT,
            sample_rate_hz,
        )
    }

    /// Apply a command.
    ///
    /// # Errors
    /// [`ConfigError::Calibration`] when a stored calibration is out of the core's range
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

    /// The sample builder (for timestamp resynchronisation after lost samples).
    pub fn sampler_mut(&mut self) -> &mut SampleBuilder {
        &mut self.builder
    }

    /// The sample builder.
    pub fn sampler(&self) -> &SampleBuilder {
        &self.builder
    }

    /// The core monitor.
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// Process one trigger's readings.
    #[inline]
    pub fn on_frame(&mut self, raw: &RawFrame) -> SampleResult {
        let sample = self.builder.build(raw);
        let output = *self.monitor.update(&sample);
        let mut learned = None;
        let mut learning_failed = false;
        let core_learning = matches!(output.commissioning, CoreCommissioning::Learning(_));
        if self.learning == Learning::Requested && core_learning {
            self.learning = Learning::Running;
        } else if self.learning == Learning::Running && !core_learning {
            self.learning = Learning::Idle;
            match (output.commissioning, self.monitor.calibration()) {
                (CoreCommissioning::Commissioned, Some(cal)) => learned = Some(cal.into()),
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

/// Thread-mode side: commissioning and the panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Supervisor {
    commissioning: Commissioning,
}

impl Supervisor {
    /// A supervisor whose commissioning runs learn for `duration_s` seconds.
    pub fn new(duration_s: f32) -> Self {
        Self {
            commissioning: Commissioning::new(duration_s),
        }
    }

    /// The commissioning state machine.
    pub fn commissioning(&self) -> &Commissioning {
        &self.commissioning
    }

    /// Feed a commissioning event; returns what to do.
    pub fn handle(&mut self, event: Event, now_ms: u32) -> Action {
        self.commissioning.handle(event, now_ms)
    }

    /// Panel inputs for the latest core output.
    pub fn panel_input(&self, out: &MonitorOutput) -> PanelInput {
        let mode: Mode = self.commissioning.panel_mode();
        PanelInput {
            mode,
            residual_lamps: out.lamps,
            fault_detected: out.fault_detected,
            input_invalid: out.sensor_fault.any() && !out.lamps.iter().any(|l| *l),
            top_candidate: out.top().map(|(f, _)| f.index() as u8),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn board_config_is_valid() {
        assert!(monitor_config(board::DEFAULT_SAMPLE_RATE_HZ)
            .validate()
            .is_ok());
        assert!(SamplePath::for_board(board::DEFAULT_SAMPLE_RATE_HZ).is_ok());
    }
}
