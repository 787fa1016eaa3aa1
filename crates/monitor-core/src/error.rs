//! The one error of the core: a configuration it cannot run with, found when it is built.
//!
//! [`ConfigError`] is one byte: which check failed ([`ConfigCheck`]). Its field's path, the
//! requirement and the group ([`ConfigErrorKind`]) are looked up from the check, so the
//! firmware, which never prints them, carries none of the text.

/// Which part of the configuration is wrong (the group of a [`ConfigCheck`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConfigErrorKind {
    /// A motor parameter is not positive/finite, or Lm^2 >= Ls Lr.
    MotorParameter,
    /// Sample or tick rate out of range, or below 8x the supply frequency.
    SampleRate,
    /// Supply frequency or voltage out of range.
    Supply,
    /// A filter corner is not positive or too high for the supply or sample rate.
    Filter,
    /// Decimation outside 1..=1000, or fewer than 6 blocks per supply period.
    Decimation,
    /// Encoder settings impossible (zero counts, counter width, windows, max speed).
    Encoder,
    /// Sensor limits or timing not positive/finite.
    Limits,
    /// Threshold settings out of range.
    Threshold,
    /// A stored calibration holds non-finite or out-of-range values.
    Calibration,
    /// An isolation baseline ([`crate::isolation::Baseline`]) holds non-finite values.
    Baseline,
}

/// Every check of the configuration: a field and what it must satisfy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
#[allow(missing_docs)] // Each variant's field and requirement are in `path` and `requirement`.
pub enum ConfigCheck {
    MotorRs,
    MotorRr,
    MotorLs,
    MotorLr,
    MotorLm,
    MotorJ,
    MotorB,
    MotorBl,
    MotorPoles,
    MotorLsBelowLm,
    MotorLrBelowLm,
    MotorNoLeakage,
    SupplyVoltage,
    SupplyFrequency,
    SampleRate,
    TickRate,
    SupplyHz,
    PhasePeakVoltage,
    SampleRateVsSupply,
    Decimation,
    BlocksPerPeriod,
    FilterCorner,
    SequenceCorner,
    FilterCornerHz,
    FilterSamplePeriod,
    FilterStability,
    PllBandwidth,
    EncoderCounts,
    EncoderCounterBits,
    EncoderMinWindow,
    EncoderTimeout,
    EncoderMaxStep,
    VoltageLimit,
    CurrentLimit,
    SpeedLimit,
    CurrentSumFraction,
    VoltageSumFraction,
    SettleTime,
    MinVoltageFraction,
    UnbalanceMinRatio,
    FloorFraction,
    SteadyGate,
    GateHold,
    GateTimeout,
    MaxBridgedGap,
    ThresholdFixed,
    ThresholdMinBand,
    ThresholdKSigma,
    ThresholdDebounce,
    ThresholdRelease,
    ThresholdHysteresis,
    Calibration,
    IsolationSupplyHz,
    IsolationTorqueBase,
    BaselineMean,
    BaselineSpread,
}

impl ConfigCheck {
    /// The field's path in [`crate::MonitorConfig`] or in the parameter file.
    pub fn path(self) -> &'static str {
        use ConfigCheck::*;
        match self {
            MotorRs => "motor.rs_ohm",
            MotorRr => "motor.rr_ohm",
            MotorLs | MotorLsBelowLm => "motor.ls_h",
            MotorLr | MotorLrBelowLm => "motor.lr_h",
            MotorLm | MotorNoLeakage => "motor.lm_h",
            MotorJ => "motor.j_kgm2",
            MotorB => "motor.b_nms",
            MotorBl => "motor.bl_nms",
            MotorPoles => "motor.poles",
            SupplyVoltage => "supply.v_ll_rms",
            SupplyFrequency => "supply.f_hz",
            SampleRate | SampleRateVsSupply => "sample_rate_hz",
            TickRate => "tick_hz",
            SupplyHz => "supply_hz",
            PhasePeakVoltage => "v_phase_peak",
            Decimation | BlocksPerPeriod => "decimation",
            FilterCorner => "filter_hz",
            SequenceCorner => "sequence_hz",
            FilterCornerHz | FilterStability => "filter.fc_hz",
            FilterSamplePeriod => "filter.dt_s",
            PllBandwidth => "pll_bw_hz",
            EncoderCounts => "encoder.counts_per_rev",
            EncoderCounterBits => "encoder.counter_bits",
            EncoderMinWindow => "encoder.min_window_s",
            EncoderTimeout => "encoder.timeout_s",
            EncoderMaxStep | SpeedLimit => "limits.max_speed_rad_s",
            VoltageLimit => "limits.v_max",
            CurrentLimit => "limits.i_max",
            CurrentSumFraction => "limits.current_sum_frac",
            VoltageSumFraction => "limits.voltage_sum_frac",
            SettleTime => "settle_s",
            MinVoltageFraction => "min_voltage_frac",
            UnbalanceMinRatio => "unbalance_min_ratio",
            FloorFraction => "floor_fraction",
            SteadyGate => "steady_gate_per_s",
            GateHold => "gate_hold_s",
            GateTimeout => "gate_timeout_s",
            MaxBridgedGap => "max_bridged_gap_s",
            ThresholdFixed => "thresholds.fixed",
            ThresholdMinBand => "thresholds.min_band",
            ThresholdKSigma => "thresholds.k_sigma",
            ThresholdDebounce => "thresholds.debounce_s",
            ThresholdRelease => "thresholds.release_s",
            ThresholdHysteresis => "thresholds.hysteresis",
            Calibration => "calibration",
            IsolationSupplyHz => "supply_hz",
            IsolationTorqueBase => "v_phase_peak",
            BaselineMean => "baseline.mean",
            BaselineSpread => "baseline.spread",
        }
    }

    /// What the field must satisfy, the phrase after "must".
    pub fn requirement(self) -> &'static str {
        use ConfigCheck::*;
        match self {
            MotorRs | MotorRr | MotorLs | MotorLr | MotorLm | MotorJ | PhasePeakVoltage
            | PllBandwidth | EncoderMinWindow | VoltageLimit | CurrentLimit | SpeedLimit
            | CurrentSumFraction | FloorFraction | ThresholdKSigma | IsolationSupplyHz => {
                "be positive and finite"
            }
            MotorB | MotorBl | VoltageSumFraction | SettleTime | UnbalanceMinRatio
            | SteadyGate | GateHold | MaxBridgedGap | ThresholdDebounce | ThresholdRelease => {
                "be >= 0"
            }
            MotorPoles => "be even and 2..=254",
            MotorLsBelowLm | MotorLrBelowLm => {
                "be >= motor.lm_h (self = leakage + magnetising)"
            }
            MotorNoLeakage => {
                "give Lm^2 < Ls*Lr with sigma = 1 - Lm^2/(Ls Lr) > 1e-4: give at least one leakage inductance"
            }
            SupplyVoltage | SupplyFrequency => "be a positive number",
            SampleRate => "be 100 Hz..100 kHz",
            TickRate => "be at least sample_rate_hz",
            SupplyHz => "be 1..400 Hz",
            SampleRateVsSupply => "be at least 8x supply_hz",
            Decimation => "be 1..=1000",
            BlocksPerPeriod => {
                "leave at least 6 blocks per supply period (sample_rate_hz / decimation >= 6 supply_hz)"
            }
            FilterCorner | SequenceCorner => {
                "be positive, below supply_hz/2 and at most 0.2/(2 pi) of the block rate sample_rate_hz/decimation"
            }
            FilterCornerHz | FilterSamplePeriod => "be finite and positive",
            FilterStability => {
                "keep 2 pi fc_hz dt_s below 0.5 (the state-variable filter's Euler step is unstable beyond)"
            }
            EncoderCounts => "be at least 1",
            EncoderCounterBits => "be 8..=32",
            EncoderTimeout => "be longer than encoder.min_window_s",
            EncoderMaxStep => "move the encoder by less than half its counter range per sample",
            MinVoltageFraction => "be in [0, 1)",
            GateTimeout => "be finite and longer than gate_hold_s",
            ThresholdFixed | ThresholdMinBand | ThresholdHysteresis => "be in (0, 1]",
            Calibration => "hold finite means in [-1, 1] and spreads in [0, 2]",
            IsolationTorqueBase => {
                "give a positive, finite torque base 3/2 Np Lm^2/Lr i_mag^2, i_mag = v_phase_peak / (2 pi supply_hz Ls)"
            }
            BaselineMean | BaselineSpread => "be finite",
        }
    }

    /// The group the check belongs to.
    pub fn kind(self) -> ConfigErrorKind {
        use ConfigCheck::*;
        use ConfigErrorKind as K;
        match self {
            MotorRs | MotorRr | MotorLs | MotorLr | MotorLm | MotorJ | MotorB | MotorBl
            | MotorPoles | MotorLsBelowLm | MotorLrBelowLm | MotorNoLeakage => K::MotorParameter,
            SupplyVoltage | SupplyFrequency | SupplyHz | PhasePeakVoltage | IsolationSupplyHz
            | IsolationTorqueBase => K::Supply,
            SampleRate | TickRate | SampleRateVsSupply => K::SampleRate,
            Decimation | BlocksPerPeriod => K::Decimation,
            FilterCorner | SequenceCorner | PllBandwidth => K::Filter,
            FilterCornerHz | FilterSamplePeriod | FilterStability => K::Filter,
            EncoderCounts | EncoderCounterBits | EncoderMinWindow | EncoderTimeout
            | EncoderMaxStep => K::Encoder,
            VoltageLimit | CurrentLimit | SpeedLimit | CurrentSumFraction | VoltageSumFraction
            | SettleTime | MinVoltageFraction | UnbalanceMinRatio | FloorFraction | SteadyGate
            | GateHold | GateTimeout | MaxBridgedGap => K::Limits,
            ThresholdFixed | ThresholdMinBand | ThresholdKSigma | ThresholdDebounce
            | ThresholdRelease | ThresholdHysteresis => K::Threshold,
            Calibration => K::Calibration,
            BaselineMean | BaselineSpread => K::Baseline,
        }
    }
}

/// A configuration the monitor cannot run with: which check failed. Its field's path
/// ([`ConfigError::field`], e.g. `motor.rs_ohm`, `limits.i_max`), the requirement and the
/// group ([`ConfigError::kind`]) name the problem; `Display` gives "`field` must
/// `requirement`".
///
/// ```
/// use monitor_core::{reference, ConfigErrorKind, MonitorConfig};
/// let mut cfg = MonitorConfig::new(reference::MOTOR_3HP.motor.model(), 60.0, 220.0, 10_000.0);
/// cfg.limits.i_max = -1.0;
/// let e = cfg.validate().unwrap_err(); // ok: doc example
/// assert_eq!((e.kind(), e.field()), (ConfigErrorKind::Limits, "limits.i_max"));
/// assert_eq!(e.to_string(), "limits.i_max must be positive and finite");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigError {
    /// The check that failed.
    pub check: ConfigCheck,
}

impl ConfigError {
    /// The error of a failed check.
    pub const fn new(check: ConfigCheck) -> Self {
        ConfigError { check }
    }
    /// The group.
    pub fn kind(&self) -> ConfigErrorKind {
        self.check.kind()
    }
    /// The offending field, as a dotted path.
    pub fn field(&self) -> &'static str {
        self.check.path()
    }
    /// What the field must satisfy, the phrase after "must".
    pub fn requirement(&self) -> &'static str {
        self.check.requirement()
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} must {}", self.field(), self.requirement())
    }
}

impl core::error::Error for ConfigError {}

/// `Ok(())` when `ok`, else the error of `check`.
#[inline]
pub(crate) fn ensure(ok: bool, check: ConfigCheck) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError::new(check))
    }
}
