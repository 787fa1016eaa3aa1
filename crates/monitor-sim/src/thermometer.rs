//! The winding-temperature channel (`t_winding_c`): a slow probe (a thermocouple or PT100
//! in the winding or on the stator frame) read by a sample-and-hold.
//!
//! reading(t) = hold( probe(t) + offset + noise ), probe' = (T_winding - probe) / tau,
//! T_winding = start + dT (the `thermal_drift` effect's rise; 0 without it).
//!
//! The probe's first-order lag `tau_s` stands for its thermal contact (a thermocouple
//! embedded in an end winding: seconds; a frame sensor: minutes), the hold for the data
//! acquisition's slow channel (a new sample every `hold_s`; a temperature module of a DAQ
//! samples at 1-10 Hz), the offset for a probe that reads another point than the hottest
//! spot (the frame, cooler by a constant). The noise has its own random stream (seeded from
//! the scenario's seed), so a log with the channel has the same other columns as one
//! without it.

use super::scenario::{invalid, not_negative};
use super::SimError;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The temperature channel of the scenario's sensors (`[sensors.temperature]`): written as
/// `t_winding_c` [degC] when present. Faults of the channel itself (`stuck_at_s`,
/// `lost_at_s`) are for testing what the isolation does with a channel that lies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureSpec {
    /// The winding's temperature at the start of the run (before any `thermal_drift` rise)
    /// [degC], -40..250; default 20.
    #[serde(default = "d_start_c")]
    pub start_c: f64,
    /// A constant the probe reads beside the winding's temperature [K] (a frame sensor
    /// reads the winding's rise through a cooler point: e.g. -15); default 0.
    #[serde(default)]
    pub offset_k: f64,
    /// White noise of a sample [K rms], >= 0; default 0.1.
    #[serde(default = "d_noise_k")]
    pub noise_k: f64,
    /// The probe's thermal time constant [s], >= 0 (0: no lag); default 2.
    #[serde(default = "d_tau_s")]
    pub tau_s: f64,
    /// Sample-and-hold period of the channel [s], >= 0 (0: every row); default 1.
    #[serde(default = "d_hold_s")]
    pub hold_s: f64,
    /// From this time the reading stays what it was (a probe or module that stopped) [s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stuck_at_s: Option<f64>,
    /// From this time the channel reads NaN (a broken thermocouple) [s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lost_at_s: Option<f64>,
}

fn d_start_c() -> f64 {
    20.0
}
fn d_noise_k() -> f64 {
    0.1
}
fn d_tau_s() -> f64 {
    2.0
}
fn d_hold_s() -> f64 {
    1.0
}

impl Default for TemperatureSpec {
    fn default() -> Self {
        TemperatureSpec {
            start_c: d_start_c(),
            offset_k: 0.0,
            noise_k: d_noise_k(),
            tau_s: d_tau_s(),
            hold_s: d_hold_s(),
            stuck_at_s: None,
            lost_at_s: None,
        }
    }
}

impl TemperatureSpec {
    /// Checks the channel's values.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key (`sensors.temperature.*`).
    pub fn validate(&self) -> Result<(), SimError> {
        if !(-40.0..=250.0).contains(&self.start_c) {
            return invalid(
                "sensors.temperature.start_c",
                format!("must be -40..250 degC, got {}", self.start_c),
            );
        }
        if !self.offset_k.is_finite() {
            return invalid(
                "sensors.temperature.offset_k",
                format!("must be finite, got {}", self.offset_k),
            );
        }
        not_negative("sensors.temperature.noise_k", self.noise_k)?;
        not_negative("sensors.temperature.tau_s", self.tau_s)?;
        not_negative("sensors.temperature.hold_s", self.hold_s)?;
        for (key, v) in [
            ("sensors.temperature.stuck_at_s", self.stuck_at_s),
            ("sensors.temperature.lost_at_s", self.lost_at_s),
        ] {
            if let Some(v) = v {
                not_negative(key, v)?;
            }
        }
        Ok(())
    }
}

/// The channel's state: the probe's temperature, the held reading and when the next sample
/// is taken.
pub(crate) struct Thermometer {
    spec: TemperatureSpec,
    rng: ChaCha8Rng,
    /// The probe's temperature [degC] (`None` before the first row).
    probe_c: Option<f64>,
    held_c: f64,
    next_sample_s: f64,
}

impl Thermometer {
    /// The channel of `spec`; its noise drawn from a stream of its own for `seed`.
    pub fn new(spec: &TemperatureSpec, seed: u64) -> Self {
        Thermometer {
            spec: spec.clone(),
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x7E3A_11C0_D5E1_2B47),
            probe_c: None,
            held_c: f64::NAN,
            next_sample_s: f64::NEG_INFINITY,
        }
    }

    /// The reading at time `t_s` of a winding `rise_k` above its start, `dt_s` after the
    /// previous row [degC].
    pub fn read(&mut self, t_s: f64, rise_k: f64, dt_s: f64) -> f64 {
        let s = &self.spec;
        let winding = s.start_c + rise_k;
        let probe = match self.probe_c {
            Some(p) if s.tau_s > 0.0 => winding + (p - winding) * (-dt_s / s.tau_s).exp(),
            _ => winding,
        };
        self.probe_c = Some(probe);
        if s.lost_at_s.is_some_and(|at| t_s >= at) {
            return f64::NAN;
        }
        let stuck = s.stuck_at_s.is_some_and(|at| t_s >= at) && self.held_c.is_finite();
        if !stuck && t_s >= self.next_sample_s {
            let n: f64 = if s.noise_k > 0.0 {
                StandardNormal.sample(&mut self.rng)
            } else {
                0.0
            };
            self.held_c = probe + s.offset_k + s.noise_k * n;
            self.next_sample_s = if self.next_sample_s.is_finite() {
                self.next_sample_s + s.hold_s
            } else {
                t_s + s.hold_s
            };
        }
        self.held_c
    }
}
