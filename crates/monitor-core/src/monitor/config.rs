//! The monitor's configuration: [`MonitorConfig`], its defaults and its validation.

use crate::angle::AngleSource;
use crate::encoder::EncoderConfig;
use crate::error::{ensure, ConfigCheck::*, ConfigError};
use crate::machine::MotorModel;
use crate::threshold::ThresholdConfig;
use core::f32::consts::TAU;

/// Which form of the residuals the lamps act on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ResidualForm {
    /// Eq. (37): derivative terms dropped (the paper's choice; false alarms in transients).
    #[default]
    Steady,
    /// Eq. (36): with filtered first and second derivatives.
    Full,
}

/// Plausibility limits for the sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorLimits {
    /// Largest believable |phase voltage| [V] (the measurement range), > 0.
    pub v_max: f32,
    /// Largest believable |phase current| [A] (the measurement range), > 0.
    pub i_max: f32,
    /// Largest believable |mechanical speed| [rad/s], > 0.
    pub max_speed_rad_s: f32,
    /// Mean |ia+ib+ic| over mean max(|ia|,|ib|,|ic|) above which a current sensor is
    /// declared faulty (3-wire machine: the sum is zero), 0 < x (default 0.25).
    pub current_sum_frac: f32,
    /// The same for the voltages; 0 disables the check (a machine with its neutral
    /// connected can have a zero-sequence voltage). Default 0.25.
    pub voltage_sum_frac: f32,
}

/// Everything the monitor needs. Build with [`MonitorConfig::new`], adjust fields, and
/// [`MonitorConfig::validate`] (also done by [`Monitor::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorConfig {
    /// Nominal machine parameters.
    pub motor: MotorModel,
    /// Frame angle source.
    pub angle_source: AngleSource,
    /// Residual form for the lamps.
    pub residual_form: ResidualForm,
    /// Sample rate [Hz], 100..=100 000.
    pub sample_rate_hz: f32,
    /// Timestamp tick rate [Hz], >= sample rate.
    pub tick_hz: f32,
    /// Nominal supply frequency [Hz], 1..=400.
    pub supply_hz: f32,
    /// Nominal peak phase voltage [V] (sqrt(2/3) V_ll,rms), > 0.
    pub v_phase_peak: f32,
    /// Encoder.
    pub encoder: EncoderConfig,
    /// Corner of the d-q filters [Hz], > 0 and < supply_hz / 2 (default 5 Hz).
    pub filter_hz: f32,
    /// Slow path every `decimation` samples, 1..=1000 and at least 6 blocks per supply
    /// period (default 25: 400 Hz at 10 kHz, fine up to 66 Hz supplies).
    pub decimation: u16,
    /// Thresholds and lamp timing.
    pub thresholds: ThresholdConfig,
    /// Sensor plausibility limits.
    pub limits: SensorLimits,
    /// Time after start (and after a sensor fault clears) before lamps are evaluated [s].
    pub settle_s: f32,
    /// Lamps are evaluated only while |V| > this fraction of `v_phase_peak` (default 0.3).
    pub min_voltage_frac: f32,
    /// SRF-PLL bandwidth [Hz] (default 20).
    pub pll_bw_hz: f32,
    /// Negative-sequence filter corner [Hz] (default 2).
    pub sequence_hz: f32,
    /// Smallest |I2|/|I1| for which a suspect phase is named (default
    /// [`crate::sequence::INHERENT_ASYMMETRY_RATIO`], 0.03: the monitor has no healthy
    /// baseline of the negative sequence and does not take the supply's part out, so below
    /// a healthy machine's own asymmetry the phase would be the machine's build).
    pub unbalance_min_ratio: f32,
    /// Residual floor as a fraction of the no-load term sums (default 0.02).
    pub floor_fraction: f32,
    /// Quasi-steady-state gate [1/s]: while any of Iqs, i_ds, Vqs, wr changes faster than
    /// this fraction of itself per second (filtered derivative), and for `gate_hold_s`
    /// after, commissioning does not learn and lamp timers hold. The steady-state residuals
    /// of eq. (37) describe the machine only in steady state (the paper: "false alarms in
    /// transients"). 0 disables the gate. Default 0.1 /s: above the derivative noise of the
    /// 5 Hz filters on 0.1 %-noise sensors (~0.03 /s), below a 5 % supply step's flux
    /// transient (~0.5 /s) and a 30 % load step's (~0.15 /s). A ripple moves the
    /// derivatives too (a broken rotor bar's `2 s f` torque ripple of a few % at 1-10 Hz:
    /// 0.2-3 /s), without moving the operating point: a closure longer than three hold
    /// times while the quantities' slow trend (two 0.5 Hz low-passes) has been steady for
    /// two is taken for a ripple, and the gate opens (1.5 s after a steady record starts,
    /// instead of the timeout's 5 s).
    pub steady_gate_per_s: f32,
    /// How long the gate stays closed after the last fast change [s] (default 0.5).
    pub gate_hold_s: f32,
    /// Longest the gate may stay closed [s] (default 5): an operating point that never
    /// settles is itself abnormal (for example a frame detuned by a sensor fault keeps the
    /// d-q quantities oscillating), so after this the lamps are evaluated regardless.
    pub gate_timeout_s: f32,
    /// Longest gap in the timestamps that is bridged [s] (default 0.1, >= 0): the frame's
    /// estimators advance over the missing time at their present frequency and the block
    /// that holds the gap is left out of the filters. A longer gap, a stalled or backward
    /// clock restarts the estimators and the settling time (see [`TimingEvents`]).
    pub max_bridged_gap_s: f32,
}

/// The slow path's target rate [Hz]: 400 Hz, 25 samples at 10 kHz (module docs).
pub const TARGET_BLOCK_RATE_HZ: f32 = 400.0;

/// The decimation (samples per block) for a sample rate and supply: the nearest whole
/// number of samples to [`TARGET_BLOCK_RATE_HZ`], 1..=1000, lowered until the block rate is
/// at least 6 blocks per supply period (so the negative sequence's 2f ripple stays below a
/// third of the block rate). 25 at 10 kHz, 2 at 1 kHz (60 Hz) or 3 (50 Hz), 125 at 50 kHz.
pub fn decimation_for(sample_rate_hz: f32, supply_hz: f32) -> u16 {
    let mut d = crate::math::minf(
        crate::math::maxf(sample_rate_hz / TARGET_BLOCK_RATE_HZ + 0.5, 1.0),
        1000.0,
    ) as u16;
    while d > 1 && sample_rate_hz / f32::from(d) < 6.0 * supply_hz {
        d -= 1;
    }
    d.max(1)
}

impl MonitorConfig {
    /// Defaults for a motor on a supply of `supply_hz` and `v_ll_rms`, sampled at
    /// `sample_rate_hz`, with microsecond timestamps and a 32-bit encoder counter: the
    /// workspace's one function that derives the configuration (the firmware's and the
    /// host's replay adjust only the sensor ranges, the encoder and the clock).
    ///
    /// Every rate-dependent setting follows from the sample rate and the supply frequency:
    /// - `decimation` from [`decimation_for`]: the slow path runs at about 400 Hz whatever
    ///   the rate, and at least 6 times per supply period;
    /// - the d-q filters (5 Hz) and the sequence filters (2 Hz) then satisfy
    ///   `2 pi fc / block rate <= 0.2` from 1 kHz on;
    /// - the SRF-PLL bandwidth is 20 Hz, or `sample_rate_hz / 50` when lower (its
    ///   discrete loop keeps `wn dt <= 0.13`);
    /// - times (settling, gate, debounce, commissioning, encoder windows) are in seconds.
    ///
    /// The one physical limit is 8 samples per supply period ([`MonitorConfig::validate`]
    /// refuses a lower rate, naming `sample_rate_hz`): 400 Hz for 50 Hz, 480 Hz for 60 Hz.
    /// Tested from 1 kHz to 50 kHz on both reference motors.
    pub fn new(motor: MotorModel, supply_hz: f32, v_ll_rms: f32, sample_rate_hz: f32) -> Self {
        let v_phase_peak = v_ll_rms * 0.816_496_6;
        MonitorConfig {
            motor,
            angle_source: AngleSource::RotorFluxCurrentModel,
            residual_form: ResidualForm::Steady,
            sample_rate_hz,
            tick_hz: 1_000_000.0,
            supply_hz,
            v_phase_peak,
            encoder: EncoderConfig::default(),
            filter_hz: 5.0,
            decimation: decimation_for(sample_rate_hz, supply_hz),
            thresholds: ThresholdConfig::default(),
            limits: SensorLimits {
                v_max: 2.0 * v_phase_peak,
                i_max: 1000.0,
                max_speed_rad_s: 2.0 * TAU * supply_hz,
                current_sum_frac: 0.25,
                voltage_sum_frac: 0.25,
            },
            settle_s: 1.0,
            min_voltage_frac: 0.3,
            pll_bw_hz: crate::math::minf(20.0, sample_rate_hz / 50.0),
            sequence_hz: 2.0,
            unbalance_min_ratio: crate::sequence::INHERENT_ASYMMETRY_RATIO,
            floor_fraction: 0.02,
            steady_gate_per_s: 0.1,
            gate_hold_s: 0.5,
            gate_timeout_s: 5.0,
            max_bridged_gap_s: 0.1,
        }
    }

    /// Rejects a configuration that cannot work (see each field's range).
    ///
    /// # Errors
    /// The first [`ConfigError`] found, naming its field (e.g. `sample_rate_hz`,
    /// `limits.i_max`, `motor.rs_ohm`).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.motor.validate()?;
        self.validate_rates()?;
        self.validate_filters()?;
        self.validate_encoder()?;
        self.validate_limits()?;
        self.thresholds.validate()
    }

    fn validate_rates(&self) -> Result<(), ConfigError> {
        ensure(
            positive(self.sample_rate_hz) && (100.0..=100_000.0).contains(&self.sample_rate_hz),
            SampleRate,
        )?;
        ensure(
            positive(self.tick_hz) && self.tick_hz >= self.sample_rate_hz,
            TickRate,
        )?;
        ensure(
            positive(self.supply_hz) && (1.0..=400.0).contains(&self.supply_hz),
            SupplyHz,
        )?;
        ensure(positive(self.v_phase_peak), PhasePeakVoltage)?;
        ensure(
            self.supply_hz * 8.0 <= self.sample_rate_hz,
            SampleRateVsSupply,
        )?;
        ensure((1..=1000).contains(&self.decimation), Decimation)?;
        // The block average feeds filters that must see the 2f ripple (negative sequence)
        // well below their Nyquist frequency: at least 6 blocks per supply period (slow
        // rate >= 6 f, so 2f <= 1/3 of it).
        ensure(
            self.sample_rate_hz / f32::from(self.decimation) >= 6.0 * self.supply_hz,
            BlocksPerPeriod,
        )
    }

    fn validate_filters(&self) -> Result<(), ConfigError> {
        // The d-q filters run once per block of `decimation` samples.
        let slow_dt = f32::from(self.decimation.max(1)) / self.sample_rate_hz;
        let corner_ok =
            |fc: f32| positive(fc) && fc < self.supply_hz * 0.5 && TAU * fc * slow_dt <= 0.2;
        ensure(corner_ok(self.filter_hz), FilterCorner)?;
        ensure(corner_ok(self.sequence_hz), SequenceCorner)?;
        ensure(positive(self.pll_bw_hz), PllBandwidth)
    }

    fn validate_encoder(&self) -> Result<(), ConfigError> {
        let e = &self.encoder;
        ensure(e.counts_per_rev > 0, EncoderCounts)?;
        ensure((8..=32).contains(&e.counter_bits), EncoderCounterBits)?;
        ensure(positive(e.min_window_s), EncoderMinWindow)?;
        ensure(e.timeout_s > e.min_window_s, EncoderTimeout)?;
        // Counts per sample at max speed must stay below half the counter range.
        let max_counts =
            self.limits.max_speed_rad_s / TAU * e.counts_per_rev as f32 / self.sample_rate_hz;
        let half = if e.counter_bits >= 32 {
            2.1e9
        } else {
            (1u32 << (e.counter_bits - 1)) as f32
        };
        ensure(max_counts < half, EncoderMaxStep)
    }

    fn validate_limits(&self) -> Result<(), ConfigError> {
        let l = &self.limits;
        let at_least_0 = |x: f32| x.is_finite() && x >= 0.0;
        for (ok, check) in [
            (positive(l.v_max), VoltageLimit),
            (positive(l.i_max), CurrentLimit),
            (positive(l.max_speed_rad_s), SpeedLimit),
            (positive(l.current_sum_frac), CurrentSumFraction),
            (at_least_0(l.voltage_sum_frac), VoltageSumFraction),
            (at_least_0(self.settle_s), SettleTime),
            (
                self.min_voltage_frac.is_finite() && (0.0..1.0).contains(&self.min_voltage_frac),
                MinVoltageFraction,
            ),
            (at_least_0(self.unbalance_min_ratio), UnbalanceMinRatio),
            (positive(self.floor_fraction), FloorFraction),
            (at_least_0(self.steady_gate_per_s), SteadyGate),
            (at_least_0(self.gate_hold_s), GateHold),
            (
                self.gate_timeout_s.is_finite() && self.gate_timeout_s > self.gate_hold_s,
                GateTimeout,
            ),
            (at_least_0(self.max_bridged_gap_s), MaxBridgedGap),
        ] {
            ensure(ok, check)?;
        }
        Ok(())
    }
}

/// Positive and finite.
fn positive(x: f32) -> bool {
    x.is_finite() && x > 0.0
}
