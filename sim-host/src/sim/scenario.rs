//! The scenario file: what to simulate (supply, load, faults, effects, sensors, timing).
//!
//! See the module documentation of [`crate::sim`] for the TOML format.

use super::SimError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A whole scenario: timing, supply, load, faults, physical effects and sensors.
///
/// Built from TOML ([`Scenario::load`], [`Scenario::from_toml_str`]) or in code
/// ([`Scenario::steady`], [`Scenario::reference_2p2kw`]) and then edited through the public
/// fields. Unknown keys are an error everywhere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Simulated time [s], > 0. Rows are produced at `t = k / sample_rate_hz` for
    /// `k = 0 .. round(duration_s * sample_rate_hz)` (end excluded).
    pub duration_s: f64,
    /// Output sample rate [Hz], > 0.
    pub sample_rate_hz: f64,
    /// Seed of the sensor-noise generator (ChaCha8); the same seed gives the same rows.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Largest integrator step [s] (fixed-step RK4, an integer number of steps per output
    /// sample). Default [`DEFAULT_MAX_STEP_S`] = 100 us: max current error about 1e-5 A on
    /// the 2.2 kW reference start against a 100x finer run.
    #[serde(default)]
    pub max_step_s: Option<f64>,
    /// Supply: overrides of the parameter file's supply and steps. Default: the file's supply.
    #[serde(default)]
    pub supply: SupplySpec,
    /// Mechanical load. Default: the paper's viscous load `Bl * omega` with the file's Bl.
    #[serde(default)]
    pub load: LoadSpec,
    /// Faults switched on at given times.
    #[serde(default)]
    pub faults: Vec<FaultSpec>,
    /// Physical effects (on for the whole run unless the effect has its own `at_s`).
    #[serde(default)]
    pub effects: Vec<Effect>,
    /// Sensor chain (ADC, errors, noise, encoder). Default: [`SensorSpec::default`].
    #[serde(default)]
    pub sensors: SensorSpec,
}

/// Default largest integrator step [s].
pub const DEFAULT_MAX_STEP_S: f64 = 1.0e-4;

fn default_seed() -> u64 {
    1
}

/// Supply section: a stiff three-phase source.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplySpec {
    /// Line-to-line RMS voltage [V] at t = 0 (default: the parameter file's `v_ll_rms`).
    #[serde(default)]
    pub v_ll_rms: Option<f64>,
    /// Frequency [Hz] at t = 0 (default: the parameter file's `f_hz`).
    #[serde(default)]
    pub f_hz: Option<f64>,
    /// Steps, applied at the first output sample at or after `t_s`, phase-continuous.
    #[serde(default)]
    pub steps: Vec<SupplyStep>,
}

/// One supply step. Either or both of `v_scale` and `f_hz`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupplyStep {
    /// Time of the step [s].
    pub t_s: f64,
    /// New voltage as a multiple of the initial voltage (1.05 = +5 %), > 0.
    #[serde(default)]
    pub v_scale: Option<f64>,
    /// New frequency [Hz], > 0.
    #[serde(default)]
    pub f_hz: Option<f64>,
}

/// How the load torque depends on speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadKind {
    /// The paper's load: T_L = Bl * omega_m [N m] (Bl on the shaft, omega_m mechanical).
    #[default]
    Viscous,
    /// A prescribed torque T_L(t) [N m], independent of speed (positive opposes motoring).
    Torque,
}

/// Load section.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// `"viscous"` (default) or `"torque"`.
    #[serde(default)]
    pub kind: LoadKind,
    /// Initial load torque [N m] for `kind = "torque"` (default 0).
    #[serde(default)]
    pub torque_nm: Option<f64>,
    /// Load coefficient Bl [N m s/rad] for `kind = "viscous"` (default: the parameter file's).
    #[serde(default)]
    pub bl_nms: Option<f64>,
    /// Load steps at the first output sample at or after `t_s`.
    #[serde(default)]
    pub steps: Vec<LoadStep>,
}

/// One load step: `torque_nm` (torque load) or `bl_scale` (viscous load).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadStep {
    /// Time of the step [s].
    pub t_s: f64,
    /// New load torque [N m] (torque load only).
    #[serde(default)]
    pub torque_nm: Option<f64>,
    /// New Bl as a multiple of the initial Bl (viscous load only), >= 0.
    #[serde(default)]
    pub bl_scale: Option<f64>,
}

/// Fault names (DESIGN.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// Stator resistance Rs x (1 + change).
    Rs,
    /// Rotor resistance Rr x (1 + change).
    Rr,
    /// Stator LEAKAGE inductance Lls x (1 + change); Ls = Lls + Lm follows (PSIM convention).
    /// For a Gamma-model machine (Lls = 0) the stator inductance Ls = Lm itself is scaled
    /// (Lm x (1 + change), the rotor leakage kept, so Lr = Llr + Lm follows).
    Ls,
    /// Rotor LEAKAGE inductance Llr x (1 + change); Lr = Llr + Lm follows. For a machine with
    /// Llr = 0, Lm is scaled instead (as for `ls`).
    Lr,
    /// Machine friction B x (1 + change).
    B,
    /// Load coefficient Bl x (1 + change); for a torque load, the load torque x (1 + change).
    Bl,
    /// Current sensor(s): `mode` gain / offset / disconnected / stuck.
    CurrentSensor,
    /// Voltage sensor(s): `mode` gain / offset / disconnected / stuck.
    VoltageSensor,
    /// Speed sensor: acts on `wm_rad_s` and on the encoder count.
    SpeedSensor,
}

impl FaultKind {
    /// True for the sensor faults.
    pub fn is_sensor(self) -> bool {
        matches!(
            self,
            FaultKind::CurrentSensor | FaultKind::VoltageSensor | FaultKind::SpeedSensor
        )
    }
}

/// What a sensor fault does to the reading x.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorFaultMode {
    /// Reads (1 + change) * x.
    Gain,
    /// Reads x + offset (offset in the channel's unit: V, A or rad/s).
    Offset,
    /// Reads 0 (the encoder stops counting).
    Disconnected,
    /// Holds the last reading before the fault (the encoder stops counting).
    Stuck,
}

/// A phase of the three-phase system.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Phase a (alpha axis).
    A,
    /// Phase b.
    B,
    /// Phase c.
    C,
}

impl Phase {
    /// 0, 1, 2 for a, b, c.
    pub fn index(self) -> usize {
        match self {
            Phase::A => 0,
            Phase::B => 1,
            Phase::C => 2,
        }
    }
}

/// One fault, switched on at the first output sample at or after `at_s` and kept on.
///
/// Parametric faults (`rs, rr, ls, lr, b, bl`) need `change` (relative, > -1; +0.5 = +50 %).
/// Sensor faults need `mode`; `gain` needs `change`, `offset` needs `offset`; `phase`
/// (voltage and current sensors only) restricts the fault to one phase (default: all three).
/// Several faults of the same kind compose multiplicatively.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// Which fault.
    pub kind: FaultKind,
    /// Switch-on time [s], >= 0.
    pub at_s: f64,
    /// Relative change (parametric faults, sensor gain).
    #[serde(default)]
    pub change: Option<f64>,
    /// Sensor fault mode.
    #[serde(default)]
    pub mode: Option<SensorFaultMode>,
    /// Sensor offset in the channel's unit [V, A or rad/s].
    #[serde(default)]
    pub offset: Option<f64>,
    /// Restrict a voltage/current sensor fault to one phase.
    #[serde(default)]
    pub phase: Option<Phase>,
}

impl FaultSpec {
    /// A parametric fault (`rs, rr, ls, lr, b, bl`) with relative `change` at `at_s`.
    pub fn parametric(kind: FaultKind, at_s: f64, change: f64) -> Self {
        FaultSpec {
            kind,
            at_s,
            change: Some(change),
            mode: None,
            offset: None,
            phase: None,
        }
    }
    /// A sensor gain fault: the reading is (1 + change) times the true value.
    pub fn sensor_gain(kind: FaultKind, at_s: f64, change: f64) -> Self {
        FaultSpec {
            mode: Some(SensorFaultMode::Gain),
            ..Self::parametric(kind, at_s, change)
        }
    }
}

/// Main-flux saturation law parameters; see [`Effect::Saturation`].
fn d_sat_exp() -> f64 {
    6.0
}
fn d_sat_ratio() -> f64 {
    1.3
}
fn d_tau_s() -> f64 {
    3.0
}
fn d_alpha() -> f64 {
    0.00393
}
fn d_true() -> bool {
    true
}
fn d_iron_ratio() -> f64 {
    25.0
}
fn d_coulomb_w() -> f64 {
    1.0
}
fn d_unb() -> f64 {
    0.03
}
fn d_asym() -> f64 {
    0.05
}
fn d_phase_a() -> Phase {
    Phase::A
}

/// Physical effects (DESIGN.md §3 effect library), `[[effects]] name = "..."`.
///
/// Each variant lists its parameters (TOML keys) with units and defaults. The defaults make a
/// visible but realistic difference on the reference motors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "name", rename_all = "snake_case", deny_unknown_fields)]
pub enum Effect {
    /// Winding temperature rise dT [K] above the parameter file's temperature:
    /// Rs = Rs0 (1 + alpha dT), Rr = Rr0 (1 + alpha dT) (copper alpha = 0.00393 /K;
    /// 20 -> 90 C is +27 %). First-order thermal model, one lumped winding temperature:
    /// - prescribed (default): dT(t) = rise_k (1 - exp(-(t - at_s)/tau_s)) for t >= at_s;
    /// - loss-driven (when `r_th_k_per_w` is given): tau_s d(dT)/dt = r_th P_loss - dT,
    ///   P_loss = stator + rotor copper + iron losses [W].
    ///
    /// The default tau_s = 3 s is accelerated so that short runs show the drift; real
    /// machines have 10 - 60 min. Resistances are updated once per output sample.
    ThermalDrift {
        /// Final temperature rise [K] (prescribed mode), default 60.
        #[serde(default)]
        rise_k: Option<f64>,
        /// Thermal time constant [s], default 3.
        #[serde(default = "d_tau_s")]
        tau_s: f64,
        /// Start of heating [s], default 0.
        #[serde(default)]
        at_s: f64,
        /// Thermal resistance [K/W]; switches to the loss-driven mode.
        #[serde(default)]
        r_th_k_per_w: Option<f64>,
        /// Temperature coefficient of resistance [1/K], default 0.00393 (copper).
        #[serde(default = "d_alpha")]
        alpha_per_k: f64,
        /// Heat the rotor cage too (default true).
        #[serde(default = "d_true")]
        rotor: bool,
    },
    /// Main-flux saturation: Lm(psi_m) = Lm0 / (1 + (|psi_m| / psi_sat)^n), Lm0 = the
    /// parameter file's lm_h (unsaturated value), psi_m = Lm (i_s + i_r) the magnetising
    /// flux linkage [Wb, peak]. Leakages are unchanged, Ls = Lls + Lm and Lr = Llr + Lm follow.
    /// Solved exactly at every derivative evaluation (secant iteration on Lm).
    /// Default psi_sat = 1.3 x rated flux (V_phase,peak / omega_e) and n = 6: Lm is about
    /// 17 % below Lm0 at rated voltage, the no-load current correspondingly larger.
    Saturation {
        /// Saturation flux psi_sat [Wb peak]; default `psi_sat_ratio` x rated flux.
        #[serde(default)]
        psi_sat_wb: Option<f64>,
        /// psi_sat as a multiple of the rated flux when `psi_sat_wb` is not given, default 1.3.
        #[serde(default = "d_sat_ratio")]
        psi_sat_ratio: f64,
        /// Exponent n (> 0), default 6.
        #[serde(default = "d_sat_exp")]
        exponent: f64,
    },
    /// Core loss: a resistance Rfe [ohm] across the magnetising branch, placed at the
    /// air-gap side of Rs (before the stator leakage; exact for the Gamma model, Lls = 0,
    /// and an O(Lls/Lm) approximation otherwise). u = dpsi_s/dt, terminal current
    /// i = i_s + u / Rfe, iron loss P_fe = (3/2) |u|^2 / Rfe.
    /// Default Rfe = 25 x Xm (Xm = 2 pi f_n Lm): 3 % to 4 % of rated power.
    IronLoss {
        /// Core-loss resistance [ohm]; default `rfe_over_xm` x Xm.
        #[serde(default)]
        rfe_ohm: Option<f64>,
        /// Rfe / Xm when `rfe_ohm` is not given, default 25.
        #[serde(default = "d_iron_ratio")]
        rfe_over_xm: f64,
    },
    /// Coulomb (dry) friction: T = Tc tanh(omega_m / omega_0) [N m], smooth near standstill.
    /// Default Tc = 2 % of the rated torque estimate (Bl x synchronous mechanical speed, or
    /// the torque load's largest step), omega_0 = 1 rad/s.
    CoulombFriction {
        /// Friction torque Tc [N m].
        #[serde(default)]
        torque_nm: Option<f64>,
        /// Smoothing speed omega_0 [rad/s] (mechanical), default 1.
        #[serde(default = "d_coulomb_w")]
        omega0_rad_s: f64,
    },
    /// Windage / fan load: T = k omega_m |omega_m| [N m], k in N m s^2/rad^2.
    /// Default k: 5 % of the rated torque estimate at synchronous speed.
    Windage {
        /// Coefficient k [N m s^2 / rad^2].
        #[serde(default)]
        k_nms2: Option<f64>,
    },
    /// The load as a constant torque input instead of Bl omega (replaces a viscous load).
    /// Default torque = Bl x synchronous mechanical speed (the viscous load's value at
    /// synchronous speed), applied from standstill.
    LoadTorque {
        /// Constant load torque [N m].
        #[serde(default)]
        torque_nm: Option<f64>,
    },
    /// Negative-sequence supply voltage: v = V e^{j theta} + k V e^{-j theta + j phi}
    /// (alpha-beta, amplitude-invariant). Default k = 0.03 (3 % voltage unbalance), phi = 0.
    SupplyUnbalance {
        /// Negative-sequence fraction k (0..0.5).
        #[serde(default = "d_unb")]
        fraction: f64,
        /// Negative-sequence angle phi [deg].
        #[serde(default)]
        angle_deg: f64,
    },
    /// Shorted turns in one stator phase (inter-turn short), modelled as a fraction mu of
    /// that phase's turns taken out of the circuit: its resistance falls as (1 - mu), its
    /// self inductance as (1 - mu)^2 and its coupling to the rotor as (1 - mu). Star
    /// connection, isolated neutral: in alpha-beta the turns matrix is
    /// T = I - (2/3) mu u u^T, u = (cos th_k, sin th_k), th_k = 0, 2pi/3, 4pi/3 for a, b, c;
    /// R_s = Rs T, psi_s = T (symmetric machine flux of the MMF current T i_s). The current
    /// circulating in the shorted loop itself is not modelled. Default mu = 0.05 in phase a.
    /// Measured (3 hp, no load, mu = 0.1 in phase b): the faulty phase carries the largest
    /// current.
    PhaseAsymmetry {
        /// Faulty phase, default "a".
        #[serde(default = "d_phase_a")]
        phase: Phase,
        /// Fraction mu of the winding shorted (0..0.5), default 0.05.
        #[serde(default = "d_asym")]
        fraction: f64,
    },
    /// Rotor flux dynamics (Lr/Rr): always present in the full-order model; a no-op here.
    FluxDynamics {},
    /// Stator current dynamics (La dI/dt): always present in the full-order model; a no-op.
    CurrentDynamics {},
}

impl Effect {
    /// The effect's name as in DESIGN.md (`thermal_drift`, `saturation`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Effect::ThermalDrift { .. } => "thermal_drift",
            Effect::Saturation { .. } => "saturation",
            Effect::IronLoss { .. } => "iron_loss",
            Effect::CoulombFriction { .. } => "coulomb_friction",
            Effect::Windage { .. } => "windage",
            Effect::LoadTorque { .. } => "load_torque",
            Effect::SupplyUnbalance { .. } => "supply_unbalance",
            Effect::PhaseAsymmetry { .. } => "phase_asymmetry",
            Effect::FluxDynamics {} => "flux_dynamics",
            Effect::CurrentDynamics {} => "current_dynamics",
        }
    }

    /// The effect with all its parameters at their defaults, by DESIGN.md name.
    ///
    /// # Errors
    /// [`SimError::Invalid`] for an unknown name.
    pub fn by_name(name: &str) -> Result<Effect, SimError> {
        let text = format!("name = \"{name}\"");
        toml::from_str::<Effect>(&text).map_err(|e| SimError::Invalid {
            key: "effects.name".into(),
            message: crate::params::one_line(e.message()),
        })
    }

    /// All effect names of DESIGN.md's library.
    pub const NAMES: [&'static str; 10] = [
        "thermal_drift",
        "saturation",
        "iron_loss",
        "coulomb_friction",
        "windage",
        "load_torque",
        "supply_unbalance",
        "phase_asymmetry",
        "flux_dynamics",
        "current_dynamics",
    ];
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
    /// Voltage full scale +/- [V]. Default: 1.25 x the supply's phase peak, rounded up to
    /// a multiple of 50 V (400 V for the 2.2 kW motor, 250 V for the 3 hp motor).
    #[serde(default)]
    pub v_range_v: Option<f64>,
    /// Current full scale +/- [A]. Default: 1.25 x the analytic locked-rotor peak current,
    /// rounded up to a multiple of 5 A (no clipping on a direct-on-line start).
    #[serde(default)]
    pub i_range_a: Option<f64>,
    /// Voltage noise [V rms]; default 0.1 % of the range.
    #[serde(default)]
    pub noise_v: Option<f64>,
    /// Current noise [A rms]; default 0.1 % of the range.
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

impl Scenario {
    /// A healthy run of `duration_s` at `sample_rate_hz`: the parameter file's supply, the
    /// paper's viscous load, no faults or effects, ideal sensors, seed 1. Starts from
    /// standstill (direct-on-line).
    pub fn steady(duration_s: f64, sample_rate_hz: f64) -> Self {
        Scenario {
            duration_s,
            sample_rate_hz,
            seed: 1,
            max_step_s: None,
            supply: SupplySpec::default(),
            load: LoadSpec::default(),
            faults: Vec::new(),
            effects: Vec::new(),
            sensors: SensorSpec::ideal(),
        }
    }

    /// DESIGN.md §4 reference scenario for the 2.2 kW machine: direct-on-line from
    /// standstill, 14.6 N m constant load torque from 2.5 s, 10 s at 10 kHz, ideal sensors.
    pub fn reference_2p2kw() -> Self {
        Scenario {
            load: LoadSpec {
                kind: LoadKind::Torque,
                torque_nm: Some(0.0),
                bl_nms: None,
                steps: vec![LoadStep {
                    t_s: 2.5,
                    torque_nm: Some(14.6),
                    bl_scale: None,
                }],
            },
            ..Scenario::steady(10.0, 10_000.0)
        }
    }

    /// Parses scenario TOML; `origin` names the source in messages.
    ///
    /// # Errors
    /// [`SimError::Toml`] (syntax, unknown or missing key, with the line) or
    /// [`SimError::Invalid`] (a value out of range, naming the key).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SimError> {
        let s: Scenario = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|sp| text[..sp.start.min(text.len())].matches('\n').count() + 1);
            let at = line.map(|l| format!("line {l}: ")).unwrap_or_default();
            SimError::Toml {
                path: origin.to_string(),
                message: format!("{at}{}", crate::params::one_line(e.message())),
            }
        })?;
        s.validate()?;
        Ok(s)
    }

    /// Reads and checks a scenario file.
    ///
    /// # Errors
    /// [`SimError::Io`] if unreadable, otherwise as [`Scenario::from_toml_str`].
    pub fn load(path: &Path) -> Result<Self, SimError> {
        let text = std::fs::read_to_string(path).map_err(|source| SimError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Serialises to TOML.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// Checks ranges that do not need the motor parameters (those are checked by
    /// [`crate::sim::simulate`]).
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |key: &str, message: String| {
            Err(SimError::Invalid {
                key: key.to_string(),
                message,
            })
        };
        let pos = |key: &str, v: f64| -> Result<(), SimError> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                bad(key, format!("must be a positive number, got {v}"))
            }
        };
        let nonneg = |key: &str, v: f64| -> Result<(), SimError> {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                bad(key, format!("must be >= 0, got {v}"))
            }
        };
        pos("duration_s", self.duration_s)?;
        pos("sample_rate_hz", self.sample_rate_hz)?;
        if self.duration_s * self.sample_rate_hz > 1.0e10 {
            return bad("duration_s", "more than 1e10 samples".into());
        }
        if let Some(h) = self.max_step_s {
            pos("max_step_s", h)?;
        }
        if let Some(v) = self.supply.v_ll_rms {
            pos("supply.v_ll_rms", v)?;
        }
        if let Some(f) = self.supply.f_hz {
            pos("supply.f_hz", f)?;
        }
        for st in &self.supply.steps {
            nonneg("supply.steps.t_s", st.t_s)?;
            if st.v_scale.is_none() && st.f_hz.is_none() {
                return bad("supply.steps", "a step needs v_scale or f_hz".into());
            }
            if let Some(v) = st.v_scale {
                pos("supply.steps.v_scale", v)?;
            }
            if let Some(f) = st.f_hz {
                pos("supply.steps.f_hz", f)?;
            }
        }
        match self.load.kind {
            LoadKind::Viscous => {
                if self.load.torque_nm.is_some() {
                    return bad("load.torque_nm", "only for kind = \"torque\"".into());
                }
                if let Some(b) = self.load.bl_nms {
                    nonneg("load.bl_nms", b)?;
                }
            }
            LoadKind::Torque => {
                if self.load.bl_nms.is_some() {
                    return bad("load.bl_nms", "only for kind = \"viscous\"".into());
                }
                if let Some(t) = self.load.torque_nm {
                    if !t.is_finite() {
                        return bad("load.torque_nm", format!("must be finite, got {t}"));
                    }
                }
            }
        }
        for st in &self.load.steps {
            nonneg("load.steps.t_s", st.t_s)?;
            match (self.load.kind, st.torque_nm, st.bl_scale) {
                (LoadKind::Torque, Some(t), None) if t.is_finite() => {}
                (LoadKind::Viscous, None, Some(b)) => nonneg("load.steps.bl_scale", b)?,
                (LoadKind::Torque, _, _) => {
                    return bad(
                        "load.steps",
                        "a torque load's step needs a finite torque_nm (and no bl_scale)".into(),
                    )
                }
                (LoadKind::Viscous, _, _) => {
                    return bad(
                        "load.steps",
                        "a viscous load's step needs bl_scale (and no torque_nm)".into(),
                    )
                }
            }
        }
        for f in &self.faults {
            nonneg("faults.at_s", f.at_s)?;
            if f.kind.is_sensor() {
                let Some(mode) = f.mode else {
                    return bad(
                        "faults.mode",
                        "a sensor fault needs mode = gain|offset|disconnected|stuck".into(),
                    );
                };
                match mode {
                    SensorFaultMode::Gain => match f.change {
                        Some(c) if c.is_finite() => {}
                        _ => return bad("faults.change", "mode = \"gain\" needs change".into()),
                    },
                    SensorFaultMode::Offset => match f.offset {
                        Some(o) if o.is_finite() => {}
                        _ => return bad("faults.offset", "mode = \"offset\" needs offset".into()),
                    },
                    _ => {}
                }
                if f.phase.is_some() && f.kind == FaultKind::SpeedSensor {
                    return bad("faults.phase", "the speed sensor has no phases".into());
                }
            } else {
                if f.mode.is_some() || f.offset.is_some() || f.phase.is_some() {
                    return bad(
                        "faults.mode",
                        "mode/offset/phase are for sensor faults only".into(),
                    );
                }
                match f.change {
                    Some(c) if c.is_finite() && c > -1.0 => {}
                    Some(c) => return bad("faults.change", format!("must be > -1, got {c}")),
                    None => return bad("faults.change", "a parametric fault needs change".into()),
                }
            }
        }
        for e in &self.effects {
            let k = |p: &str| format!("effects.{}.{p}", e.name());
            match e {
                Effect::ThermalDrift {
                    rise_k,
                    tau_s,
                    at_s,
                    r_th_k_per_w,
                    alpha_per_k,
                    ..
                } => {
                    if let Some(r) = rise_k {
                        if !r.is_finite() || *r < -200.0 {
                            return bad(&k("rise_k"), format!("must be finite, >= -200, got {r}"));
                        }
                    }
                    if rise_k.is_some() && r_th_k_per_w.is_some() {
                        return bad(&k("rise_k"), "give rise_k or r_th_k_per_w, not both".into());
                    }
                    pos(&k("tau_s"), *tau_s)?;
                    nonneg(&k("at_s"), *at_s)?;
                    if let Some(r) = r_th_k_per_w {
                        nonneg(&k("r_th_k_per_w"), *r)?;
                    }
                    nonneg(&k("alpha_per_k"), *alpha_per_k)?;
                }
                Effect::Saturation {
                    psi_sat_wb,
                    psi_sat_ratio,
                    exponent,
                } => {
                    if let Some(p) = psi_sat_wb {
                        pos(&k("psi_sat_wb"), *p)?;
                    }
                    pos(&k("psi_sat_ratio"), *psi_sat_ratio)?;
                    pos(&k("exponent"), *exponent)?;
                }
                Effect::IronLoss {
                    rfe_ohm,
                    rfe_over_xm,
                } => {
                    if let Some(r) = rfe_ohm {
                        pos(&k("rfe_ohm"), *r)?;
                    }
                    pos(&k("rfe_over_xm"), *rfe_over_xm)?;
                }
                Effect::CoulombFriction {
                    torque_nm,
                    omega0_rad_s,
                } => {
                    if let Some(t) = torque_nm {
                        nonneg(&k("torque_nm"), *t)?;
                    }
                    pos(&k("omega0_rad_s"), *omega0_rad_s)?;
                }
                Effect::Windage { k_nms2 } => {
                    if let Some(v) = k_nms2 {
                        nonneg(&k("k_nms2"), *v)?;
                    }
                }
                Effect::LoadTorque { torque_nm } => {
                    if let Some(t) = torque_nm {
                        if !t.is_finite() {
                            return bad(&k("torque_nm"), format!("must be finite, got {t}"));
                        }
                    }
                }
                Effect::SupplyUnbalance {
                    fraction,
                    angle_deg,
                } => {
                    if !(fraction.is_finite() && (0.0..=0.5).contains(fraction)) {
                        return bad(&k("fraction"), format!("must be in 0..0.5, got {fraction}"));
                    }
                    if !angle_deg.is_finite() {
                        return bad(&k("angle_deg"), "must be finite".into());
                    }
                }
                Effect::PhaseAsymmetry { fraction, .. } => {
                    if !(fraction.is_finite() && (0.0..=0.5).contains(fraction)) {
                        return bad(&k("fraction"), format!("must be in 0..0.5, got {fraction}"));
                    }
                }
                Effect::FluxDynamics {} | Effect::CurrentDynamics {} => {}
            }
        }
        let s = &self.sensors;
        if !(2..=24).contains(&s.adc_bits) {
            return bad(
                "sensors.adc_bits",
                format!("must be 2..=24, got {}", s.adc_bits),
            );
        }
        for (key, v) in [
            ("sensors.v_range_v", s.v_range_v),
            ("sensors.i_range_a", s.i_range_a),
        ] {
            if let Some(v) = v {
                pos(key, v)?;
            }
        }
        for (key, v) in [
            ("sensors.noise_v", s.noise_v),
            ("sensors.noise_i", s.noise_i),
        ] {
            if let Some(v) = v {
                nonneg(key, v)?;
            }
        }
        nonneg("sensors.noise_w_rad_s", s.noise_w_rad_s)?;
        for (key, v) in [
            ("sensors.v_gain_error", s.v_gain_error),
            ("sensors.v_offset_v", s.v_offset_v),
            ("sensors.i_gain_error", s.i_gain_error),
            ("sensors.i_offset_a", s.i_offset_a),
        ] {
            if !v.is_finite() {
                return bad(key, format!("must be finite, got {v}"));
            }
        }
        if s.encoder_lines == 0 {
            return bad("sensors.encoder_lines", "must be >= 1".into());
        }
        Ok(())
    }
}
