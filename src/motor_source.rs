//! The machine the firmware monitors: the motor record in flash
//! (`monitor_core::motor_record`, written by `sim-host board-record`) or, when the page
//! holds no valid record, the built-in default ([`crate::app::DEFAULT_MACHINE`] with the
//! board's front end). Host-testable: the firmware reads the page at
//! [`board::MOTOR_RECORD_FLASH_OFFSET`] and hands the bytes to [`select`].

use crate::acquisition::{self, LinearRange, LinearRanges};
use crate::app::{AppError, SamplePath, DEFAULT_MACHINE};
use crate::board::{self, ChannelScale, FrontEnd};
use crate::sampling::TICK_HZ;
use monitor_core::isolation::Isolator;
use monitor_core::motor_record::{MotorRecord, RecordError};
use monitor_core::{ConfigError, MonitorConfig};

/// Where the machine in force came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MachineSource {
    /// A valid motor record in flash.
    Flash,
    /// The built-in default, because the record was rejected for this reason
    /// ([`RecordError::Erased`]: the page is erased, no record was ever written).
    Default(RecordError),
}

impl MachineSource {
    /// One line for the boot log: "motor record from flash" or
    /// "built-in default motor (record: <reason>)".
    pub fn describe(&self) -> &'static str {
        match self {
            MachineSource::Flash => "motor record from flash",
            MachineSource::Default(RecordError::Erased) => "built-in default motor (no record)",
            MachineSource::Default(RecordError::Magic) => {
                "built-in default motor (no motor record on its page)"
            }
            MachineSource::Default(RecordError::Version(_)) => {
                "built-in default motor (record of another version)"
            }
            MachineSource::Default(RecordError::Crc) => "built-in default motor (record CRC bad)",
            MachineSource::Default(RecordError::Truncated | RecordError::Length) => {
                "built-in default motor (record truncated)"
            }
            MachineSource::Default(RecordError::Invalid) => {
                "built-in default motor (record values rejected)"
            }
            // `RecordError` is non-exhaustive: a check added to the record module later.
            MachineSource::Default(_) => "built-in default motor (record rejected)",
        }
    }

    /// True when the built-in default is in force.
    pub fn is_default(&self) -> bool {
        matches!(self, MachineSource::Default(_))
    }
}

/// The built-in default as a record: [`DEFAULT_MACHINE`], the board's full scales
/// ([`board::CURRENT_FULL_SCALE_A`], [`board::VOLTAGE_FULL_SCALE_V`]), zero at mid-scale
/// ([`board::MID_SCALE_CODE`]) and [`board::ENCODER_LINES`] lines counting up, with the
/// internal pull-ups on.
pub fn default_record() -> MotorRecord {
    MotorRecord {
        motor: DEFAULT_MACHINE.motor,
        supply: DEFAULT_MACHINE.supply,
        current_full_scale_a: board::CURRENT_FULL_SCALE_A,
        voltage_full_scale_v: board::VOLTAGE_FULL_SCALE_V,
        current_offset_counts: [board::MID_SCALE_CODE; 3],
        voltage_offset_counts: [board::MID_SCALE_CODE; 3],
        encoder_lines: board::ENCODER_LINES as u16,
        encoder_reversed: false,
        encoder_pull_up: true,
    }
}

/// The record stored in `page` (the bytes read from the motor-record flash page) if it is
/// valid, otherwise [`default_record`], with where it came from.
pub fn select(page: &[u8]) -> (MotorRecord, MachineSource) {
    match MotorRecord::parse(page) {
        Ok(rec) => (rec, MachineSource::Flash),
        Err(e) => (default_record(), MachineSource::Default(e)),
    }
}

/// The core configuration for `rec` at `sample_rate_hz`: its machine on its supply, 1 MHz
/// timestamps, a 16-bit x4 encoder counter with `4 x encoder_lines` counts per revolution,
/// and sensor limits beyond any reading of the front end ([`board::LIMIT_OVER_FULL_SCALE`]
/// times the full scales: a reading at its edge is a clip). For [`default_record`] this is
/// [`crate::app::board_monitor_config`] (a test checks it).
pub fn monitor_config(rec: &MotorRecord, sample_rate_hz: u32) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(
        rec.motor.model(),
        rec.supply.f_hz as f32,
        rec.supply.v_ll_rms as f32,
        sample_rate_hz as f32,
    );
    cfg.tick_hz = TICK_HZ as f32;
    cfg.encoder.counter_bits = 16;
    cfg.encoder.counts_per_rev = 4 * u32::from(rec.encoder_lines);
    cfg.limits.v_max = board::LIMIT_OVER_FULL_SCALE * rec.voltage_full_scale_v;
    cfg.limits.i_max = board::LIMIT_OVER_FULL_SCALE * rec.current_full_scale_a;
    cfg
}

/// The front end for `rec`: `per_lsb = 2 x full scale / 4095` and each channel's offset.
/// For [`default_record`] this is [`FrontEnd::DEFAULT`].
pub fn front_end(rec: &MotorRecord) -> FrontEnd {
    let max = f32::from(board::ADC_MAX_CODE);
    let scale = |offset_code: f32, full_scale: f32| ChannelScale {
        offset_code,
        per_lsb: 2.0 * full_scale / max,
    };
    let [va, vb, vc] = rec.voltage_offset_counts;
    let [ia, ib, ic] = rec.current_offset_counts;
    let (v, i) = (rec.voltage_full_scale_v, rec.current_full_scale_a);
    FrontEnd {
        voltage: [scale(va, v), scale(vb, v), scale(vc, v)],
        current: [scale(ia, i), scale(ib, i), scale(ic, i)],
    }
}

/// The sample path for `rec` at `sample_rate_hz`: [`monitor_config`] and [`front_end`].
/// For [`default_record`] this is [`SamplePath::for_board`].
///
/// # Errors
/// As [`SamplePath::new`] (a record that [`select`] accepted passed the core's checks of
/// its machine; the sample rate is the firmware's setting).
pub fn sample_path(rec: &MotorRecord, sample_rate_hz: u32) -> Result<SamplePath, AppError> {
    SamplePath::new(
        monitor_config(rec, sample_rate_hz),
        front_end(rec),
        sample_rate_hz,
    )
}

/// How the encoder timer is set up for a record: counts per revolution (4 x lines),
/// the count direction, the input filter and the pull-ups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncoderSetup {
    /// Quadrature counts per revolution, `4 x encoder_lines` (the core's
    /// `EncoderConfig::counts_per_rev`, [`monitor_config`]).
    pub counts_per_rev: u32,
    /// Invert input A's polarity (`TIMx_CCER.CC1P`), so that the counter counts up when the
    /// motor turns forward with an encoder that counts down: the record's
    /// `encoder_reversed`, applied in the timer at no cost per sample.
    pub invert_a: bool,
    /// The inputs' filter `ICxF` ([`board::encoder_input_filter`] at twice the supply's
    /// synchronous speed).
    pub input_filter: u8,
    /// Internal pull-ups on A and B (about 40 kohm), the record's `encoder_pull_up`:
    /// open-collector encoders need a pull-up, push-pull ones are not disturbed by it, and
    /// an unplugged encoder reads a steady high instead of noise; off for a board with
    /// pull-ups (or a line receiver) of its own.
    pub pull_up: bool,
    /// The largest step of the count between two latched counts (two triggers) that the
    /// maximum speed allows [counts]: twice the synchronous speed, the input filter's
    /// speed too ([`acquisition::max_step_per_trigger`]); a larger step is a glitch,
    /// rejected by [`acquisition::EncoderCheck`].
    pub max_step_per_trigger: u16,
}

/// The encoder setup for `rec` at `sample_rate_hz` (the latch's triggers at
/// [`acquisition::trigger_rate_hz`] of it) ([`EncoderSetup`]).
pub fn encoder_setup(rec: &MotorRecord, sample_rate_hz: u32) -> EncoderSetup {
    let pole_pairs = (rec.motor.poles / 2).max(1) as f32;
    let max_rev_per_s = 2.0 * rec.supply.f_hz as f32 / pole_pairs;
    let counts_per_rev = 4 * u32::from(rec.encoder_lines);
    EncoderSetup {
        max_step_per_trigger: acquisition::max_step_per_trigger(
            counts_per_rev,
            max_rev_per_s,
            acquisition::trigger_rate_hz(sample_rate_hz),
        ),
        counts_per_rev,
        invert_a: rec.encoder_reversed,
        input_filter: board::encoder_input_filter(
            rec.encoder_lines,
            max_rev_per_s,
            board::ENCODER_TIMER_HZ,
        ),
        pull_up: rec.encoder_pull_up,
    }
}

/// The fault isolator for `rec`'s machine on its supply (for [`default_record`],
/// [`crate::app::board_isolator`]).
///
/// # Errors
/// The core's [`ConfigError`] if it rejects the machine or the supply.
pub fn isolator(rec: &MotorRecord) -> Result<Isolator, ConfigError> {
    Isolator::new(
        rec.motor.model(),
        rec.supply.v_phase_peak() as f32,
        rec.supply.f_hz as f32,
    )
}

/// The front end's linear limit for `rec`, per channel: the record's full scale on either
/// side of the channel's zero (`offset +- full_scale / per_lsb` = `offset +- 2047.5` codes,
/// [`front_end`]), narrowed by the isolated amplifier's output headroom
/// ([`board::AMPLIFIER_HEADROOM_CODES`]: its output stage is linear only that far from its
/// supply), within the ADC's rails. The clip levels are the amplifier's, fixed in volts: a
/// start-up offset trim does not move them. For the built-in default (zero at mid-scale):
/// 62..=4033, a conversion at or below 62 or at or above 4033 clipped.
pub fn linear_ranges(rec: &MotorRecord) -> LinearRanges {
    let half_span = f32::from(board::ADC_MAX_CODE) / 2.0;
    let headroom = board::AMPLIFIER_HEADROOM_CODES;
    let top = f32::from(board::ADC_MAX_CODE);
    let range = |offset: f32| {
        let low = (offset - half_span).max(0.0) + headroom;
        let high = (offset + half_span).min(top) - headroom;
        LinearRange {
            // Rounded to the nearest code (no `f32::round` on the board: + 0.5, truncated;
            // `max`/`min`, not `f32::clamp`, whose assertion formats floats: 10 KiB of
            // flash).
            low: (low.max(0.0).min(top) + 0.5) as u16,
            high: (high.max(0.0).min(top) + 0.5) as u16,
        }
    };
    LinearRanges {
        voltage: rec.voltage_offset_counts.map(range),
        current: rec.current_offset_counts.map(range),
    }
}
