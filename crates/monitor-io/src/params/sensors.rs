//! The sensors' ranges and a log's plausibility limits for a machine on a supply: the
//! one place they are derived from the parameter file.

use super::ParamFile;
use monitor_core::MotorParameters;
use nalgebra::Complex;

/// The sensors' measurement ranges for a machine on a supply: the simulator's default ADC
/// ranges ([`monitor_sim::SensorSpec`]), and what the plausibility limits of a log are built
/// from ([`ParamFile::log_limits`]). The one place these ranges are derived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorRanges {
    /// Voltage range +/- [V]: 1.2 x the phase peak sqrt(2/3) V_ll rounded up to 50 V
    /// (400 V for the 2.2 kW reference motor, 250 V for the 3 hp one).
    pub v_range_v: f64,
    /// Current range +/- [A]: 2 x the locked-rotor peak current rounded up to 5 A (a
    /// direct-on-line start, whose first peaks exceed the steady locked-rotor peak, does
    /// not clip).
    pub i_range_a: f64,
}

impl SensorRanges {
    /// The ranges for motor `m` on a supply of `v_ll_rms` [V, line-to-line RMS] at `f_hz`
    /// [Hz] (a scenario may run the motor on another supply than the parameter file's).
    pub fn new(m: &MotorParameters, v_ll_rms: f64, f_hz: f64) -> Self {
        let vpk = v_ll_rms * (2.0f64 / 3.0).sqrt();
        let v = (1.2 * vpk / 50.0).ceil() * 50.0;
        let i_locked = locked_rotor_current_rms_a(m, v_ll_rms, f_hz);
        let i = (2.0 * 2f64.sqrt() * i_locked / 5.0).ceil() * 5.0;
        SensorRanges {
            v_range_v: v,
            i_range_a: i,
        }
    }
}

/// Stator phase current RMS [A] of the T-equivalent circuit with the rotor locked (slip
/// 1): `I = V / (Zs + Zm || Zr)` with `V = V_ll / sqrt 3`, `Zs = Rs + j we Lls`,
/// `Zm = j we Lm`, `Zr = Rr + j we Llr`, `we = 2 pi f` (the simulator's analytic steady
/// state at slip 1, `monitor_sim::steady_state_at`, to the last bit; a test checks it).
pub fn locked_rotor_current_rms_a(m: &MotorParameters, v_ll_rms: f64, f_hz: f64) -> f64 {
    let we = 2.0 * std::f64::consts::PI * f_hz;
    let model = m.model::<f64>();
    let v = Complex::new(v_ll_rms / 3f64.sqrt(), 0.0);
    let zs = Complex::new(m.rs_ohm, we * model.lls_h());
    let zm = Complex::new(0.0, we * m.lm_h);
    let zr = Complex::new(m.rr_ohm, we * model.llr_h());
    let zp = zm * zr / (zm + zr);
    (v / (zs + zp)).norm()
}

/// The largest believable readings in a log of a machine: beyond them a cell is bad (the
/// data-quality stage, `crate::log::quality::CellLimits`) and the replay's monitor flags
/// the sensor (`monitor_replay::monitor_config_for_log`). In the core's `f32`, as the
/// monitor's `SensorLimits`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogLimits {
    /// Largest |phase voltage| [V]: twice the voltage range ([`SensorRanges`]), since a
    /// log does not say its ADC ranges.
    pub v_max_v: f32,
    /// Largest |phase current| [A]: twice the current range.
    pub i_max_a: f32,
    /// Largest |mechanical speed| [rad/s]: 2 x 2 pi f (at least twice the synchronous
    /// speed for any number of poles; the core's default `max_speed_rad_s`).
    pub wm_max_rad_s: f32,
}

impl ParamFile {
    /// The sensor ranges of this machine on its own supply ([`SensorRanges::new`]).
    pub fn sensor_ranges(&self) -> SensorRanges {
        SensorRanges::new(&self.motor, self.supply.v_ll_rms, self.supply.f_hz)
    }

    /// The plausibility limits of a log of this machine ([`LogLimits`]).
    pub fn log_limits(&self) -> LogLimits {
        let r = self.sensor_ranges();
        LogLimits {
            v_max_v: 2.0 * r.v_range_v as f32,
            i_max_a: 2.0 * r.i_range_a as f32,
            wm_max_rad_s: 2.0 * std::f32::consts::TAU * self.supply.f_hz as f32,
        }
    }
}
