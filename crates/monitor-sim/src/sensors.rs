//! The sensor chain: transducer faults, gain/offset errors, white noise, ADC, encoder.

use super::faults::{FaultSpec, SensorFaultMode};
use super::scenario::{d_true, invalid, not_negative, positive};
use super::thermometer::{TemperatureSpec, Thermometer};
use super::{SimError, Truth};
use monitor_core::{FaultTarget, SensorChannel};
use monitor_io::log::{Channels, Row};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Transducer fault state of one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ChanFault {
    None,
    Gain(f64),
    Offset(f64),
    Zero,
    Stuck,
}

impl ChanFault {
    fn from_spec(f: &FaultSpec) -> Self {
        match f.mode {
            Some(SensorFaultMode::Gain) => ChanFault::Gain(1.0 + f.change.unwrap_or(0.0)),
            Some(SensorFaultMode::Offset) => ChanFault::Offset(f.offset.unwrap_or(0.0)),
            Some(SensorFaultMode::Disconnected) => ChanFault::Zero,
            Some(SensorFaultMode::Stuck) => ChanFault::Stuck,
            None => ChanFault::None,
        }
    }
}

/// One ADC channel's static chain.
#[derive(Debug, Clone, Copy)]
struct Adc {
    gain: f64,
    offset: f64,
    sigma: f64,
    lsb: f64,
    code_min: f64,
    code_max: f64,
    quantise: bool,
}

impl Adc {
    #[inline(always)]
    fn read(&self, x: f64, rng: &mut ChaCha8Rng) -> f64 {
        let mut y = self.gain * x + self.offset;
        if self.sigma > 0.0 {
            let n: f64 = StandardNormal.sample(rng);
            y += self.sigma * n;
        }
        if self.quantise {
            (y / self.lsb).round().clamp(self.code_min, self.code_max) * self.lsb
        } else {
            y
        }
    }
}

/// The resolved sensor chain with its state (faults, held values, encoder).
pub(crate) struct Sensors {
    v_adc: Adc,
    i_adc: Adc,
    w_sigma: f64,
    rng: ChaCha8Rng,
    counts_per_rad: f64,
    v_fault: [ChanFault; 3],
    i_fault: [ChanFault; 3],
    w_fault: ChanFault,
    v_last: [f64; 3],
    i_last: [f64; 3],
    w_last: f64,
    theta_prev: f64,
    theta_sensed: f64,
    voltages: bool,
    speed: bool,
    encoder: bool,
    thermometer: Option<Thermometer>,
    /// Ranges in effect [V], [A] (for the summary).
    pub v_range_v: f64,
    pub i_range_a: f64,
    pub noise_v: f64,
    pub noise_i: f64,
}

impl Sensors {
    pub fn new(spec: &SensorSpec, v_range_v: f64, i_range_a: f64, seed: u64) -> Self {
        let half = f64::from(1u32 << (spec.adc_bits - 1));
        let noise_v = spec.noise_v.unwrap_or(5e-4 * v_range_v);
        let noise_i = spec.noise_i.unwrap_or(5e-4 * i_range_a);
        let mk = |range: f64, gain_err: f64, offset: f64, sigma: f64| Adc {
            gain: if spec.ideal { 1.0 } else { 1.0 + gain_err },
            offset: if spec.ideal { 0.0 } else { offset },
            sigma: if spec.ideal { 0.0 } else { sigma },
            lsb: range / half,
            code_min: -half,
            code_max: half - 1.0,
            quantise: !spec.ideal,
        };
        Sensors {
            v_adc: mk(v_range_v, spec.v_gain_error, spec.v_offset_v, noise_v),
            i_adc: mk(i_range_a, spec.i_gain_error, spec.i_offset_a, noise_i),
            w_sigma: if spec.ideal { 0.0 } else { spec.noise_w_rad_s },
            rng: ChaCha8Rng::seed_from_u64(seed),
            counts_per_rad: 4.0 * f64::from(spec.encoder_lines) / (2.0 * std::f64::consts::PI),
            v_fault: [ChanFault::None; 3],
            i_fault: [ChanFault::None; 3],
            w_fault: ChanFault::None,
            v_last: [0.0; 3],
            i_last: [0.0; 3],
            w_last: 0.0,
            theta_prev: 0.0,
            theta_sensed: 0.0,
            voltages: spec.voltages,
            speed: spec.speed,
            encoder: spec.encoder,
            thermometer: spec.temperature.as_ref().map(|t| Thermometer::new(t, seed)),
            v_range_v,
            i_range_a,
            noise_v: if spec.ideal { 0.0 } else { noise_v },
            noise_i: if spec.ideal { 0.0 } else { noise_i },
        }
    }

    /// Switches a sensor fault on (on the sensor the core's fault list names for it,
    /// [`monitor_core::Fault::target`]).
    pub fn apply_fault(&mut self, f: &FaultSpec) {
        let cf = ChanFault::from_spec(f);
        let FaultTarget::Sensor(channel) = f.kind.target() else {
            return;
        };
        let target = match channel {
            SensorChannel::Current => &mut self.i_fault,
            SensorChannel::Voltage => &mut self.v_fault,
            SensorChannel::Speed => {
                self.w_fault = cf;
                return;
            }
        };
        match f.phase {
            Some(p) => target[p.index()] = cf,
            None => *target = [cf; 3],
        }
    }

    /// Sensor readings of the true state `tr`; `dt_s` is the time since the previous call.
    pub fn measure(&mut self, tr: &Truth, dt_s: f64) -> Row {
        let mut v = [0.0; 3];
        if self.voltages {
            for (k, out) in v.iter_mut().enumerate() {
                *out = Self::chan(
                    self.v_fault[k],
                    tr.v_abc[k],
                    &mut self.v_last[k],
                    &self.v_adc,
                    &mut self.rng,
                );
            }
        }
        let mut i = [0.0; 3];
        for (k, out) in i.iter_mut().enumerate() {
            *out = Self::chan(
                self.i_fault[k],
                tr.i_abc[k],
                &mut self.i_last[k],
                &self.i_adc,
                &mut self.rng,
            );
        }
        let wm = self.speed.then(|| self.read_speed(tr));
        let enc = self.read_encoder(tr, dt_s);
        Row {
            t_s: tr.t_s,
            v_abc: if self.voltages { Some(v) } else { None },
            i_abc: i,
            wm_rad_s: wm,
            enc_count: enc,
            t_winding_c: self
                .thermometer
                .as_mut()
                .map(|th| th.read(tr.t_s, tr.temperature_rise_k, dt_s)),
        }
    }

    /// The speed sensor's reading of `tr` (its fault, then its noise unless stuck).
    fn read_speed(&mut self, tr: &Truth) -> f64 {
        let x = match self.w_fault {
            ChanFault::None => tr.wm_rad_s,
            ChanFault::Gain(g) => g * tr.wm_rad_s,
            ChanFault::Offset(o) => tr.wm_rad_s + o,
            ChanFault::Zero => 0.0,
            ChanFault::Stuck => self.w_last,
        };
        let y = if self.w_sigma > 0.0 && self.w_fault != ChanFault::Stuck {
            let n: f64 = StandardNormal.sample(&mut self.rng);
            x + self.w_sigma * n
        } else {
            x
        };
        self.w_last = y;
        y
    }

    /// The encoder's count at `tr` (`None` without an encoder): the sensed angle follows
    /// the true one through the speed sensor's fault (`dt_s` since the last call).
    fn read_encoder(&mut self, tr: &Truth, dt_s: f64) -> Option<i64> {
        let dth = tr.theta_m_rad - self.theta_prev;
        self.theta_prev = tr.theta_m_rad;
        match self.w_fault {
            ChanFault::None => self.theta_sensed += dth,
            ChanFault::Gain(g) => self.theta_sensed += g * dth,
            ChanFault::Offset(o) => self.theta_sensed += dth + o * dt_s,
            ChanFault::Zero | ChanFault::Stuck => {}
        }
        self.encoder
            .then(|| (self.theta_sensed * self.counts_per_rad).floor() as i64)
    }

    #[inline(always)]
    fn chan(f: ChanFault, x: f64, last: &mut f64, adc: &Adc, rng: &mut ChaCha8Rng) -> f64 {
        let y = match f {
            ChanFault::None => adc.read(x, rng),
            ChanFault::Gain(g) => adc.read(g * x, rng),
            ChanFault::Offset(o) => adc.read(x + o, rng),
            ChanFault::Zero => adc.read(0.0, rng),
            ChanFault::Stuck => *last,
        };
        *last = y;
        y
    }
}

impl SensorSpec {
    /// The CSV channels these sensors produce.
    pub fn channels(&self) -> Channels {
        Channels {
            voltages: self.voltages,
            speed: self.speed,
            encoder: self.encoder,
            temperature: self.temperature.is_some(),
        }
    }
}

/// Sensor chain: transducer (gain and offset error), white Gaussian noise, ADC quantisation
/// with clamping to the range; the encoder gives cumulative counts, 4 x lines per rev.
///
/// reading = clamp(round(((1 + gain_error) x + offset + noise) / lsb) lsb), lsb = range /
/// 2^(bits-1). Speed `wm_rad_s` is not quantised (it stands for a computed speed); add
/// `noise_w_rad_s` for a noisy one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Ideal sensors: no ADC, no noise, no gain/offset errors (the true values). Sensor
    /// faults still apply.
    #[serde(default)]
    pub ideal: bool,
    /// ADC resolution [bits], 2..=24, default 12.
    #[serde(default = "d_bits")]
    pub adc_bits: u32,
    /// Voltage full scale +/- [V]. Default: the machine's voltage range on the scenario's
    /// supply ([`monitor_io::params::SensorRanges`]: 1.2 x the phase peak, rounded up to a
    /// multiple of 50 V; 400 V for the 2.2 kW motor, 250 V for the 3 hp motor).
    #[serde(default)]
    pub v_range_v: Option<f64>,
    /// Current full scale +/- [A]. Default: the machine's current range
    /// ([`monitor_io::params::SensorRanges`]: 2 x the analytic locked-rotor peak current, rounded
    /// up to a multiple of 5 A; no clipping on a direct-on-line start).
    #[serde(default)]
    pub i_range_a: Option<f64>,
    /// Voltage noise [V rms]; default 0.05 % of the range.
    #[serde(default)]
    pub noise_v: Option<f64>,
    /// Current noise [A rms]; default 0.05 % of the range.
    #[serde(default)]
    pub noise_i: Option<f64>,
    /// Speed noise [rad/s rms], default 0.
    #[serde(default)]
    pub noise_w_rad_s: f64,
    /// Relative gain error of the voltage channels (all three), default 0.
    #[serde(default)]
    pub v_gain_error: f64,
    /// Offset of the voltage channels [V], default 0.
    #[serde(default)]
    pub v_offset_v: f64,
    /// Relative gain error of the current channels, default 0.
    #[serde(default)]
    pub i_gain_error: f64,
    /// Offset of the current channels [A], default 0.
    #[serde(default)]
    pub i_offset_a: f64,
    /// Encoder lines per revolution (counts per rev = 4 x lines), default 1024.
    #[serde(default = "d_lines")]
    pub encoder_lines: u32,
    /// Write the voltage columns (default true).
    #[serde(default = "d_true")]
    pub voltages: bool,
    /// Write the `wm_rad_s` column (default true).
    #[serde(default = "d_true")]
    pub speed: bool,
    /// Write the `enc_count` column (default true).
    #[serde(default = "d_true")]
    pub encoder: bool,
    /// The winding-temperature channel `t_winding_c` (`[sensors.temperature]`), written
    /// only when given (default none: the log has no temperature column).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<TemperatureSpec>,
}

fn d_bits() -> u32 {
    12
}
fn d_lines() -> u32 {
    1024
}

impl Default for SensorSpec {
    fn default() -> Self {
        SensorSpec {
            ideal: false,
            adc_bits: 12,
            v_range_v: None,
            i_range_a: None,
            noise_v: None,
            noise_i: None,
            noise_w_rad_s: 0.0,
            v_gain_error: 0.0,
            v_offset_v: 0.0,
            i_gain_error: 0.0,
            i_offset_a: 0.0,
            encoder_lines: 1024,
            voltages: true,
            speed: true,
            encoder: true,
            temperature: None,
        }
    }
}

impl SensorSpec {
    /// Ideal sensors: readings are the true phase voltages, currents and speed (the
    /// encoder still counts whole counts). All channels on.
    pub fn ideal() -> Self {
        SensorSpec {
            ideal: true,
            ..SensorSpec::default()
        }
    }
}

impl SensorSpec {
    /// Checks the sensor chain's ranges.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        if !(2..=24).contains(&self.adc_bits) {
            return invalid(
                "sensors.adc_bits",
                format!("must be 2..=24, got {}", self.adc_bits),
            );
        }
        for (key, v) in [
            ("sensors.v_range_v", self.v_range_v),
            ("sensors.i_range_a", self.i_range_a),
        ] {
            if let Some(v) = v {
                positive(key, v)?;
            }
        }
        for (key, v) in [
            ("sensors.noise_v", self.noise_v),
            ("sensors.noise_i", self.noise_i),
        ] {
            if let Some(v) = v {
                not_negative(key, v)?;
            }
        }
        not_negative("sensors.noise_w_rad_s", self.noise_w_rad_s)?;
        for (key, v) in [
            ("sensors.v_gain_error", self.v_gain_error),
            ("sensors.v_offset_v", self.v_offset_v),
            ("sensors.i_gain_error", self.i_gain_error),
            ("sensors.i_offset_a", self.i_offset_a),
        ] {
            if !v.is_finite() {
                return invalid(key, format!("must be finite, got {v}"));
            }
        }
        if self.encoder_lines == 0 {
            return invalid("sensors.encoder_lines", "must be >= 1".into());
        }
        if let Some(t) = &self.temperature {
            t.validate()?;
        }
        Ok(())
    }
}
