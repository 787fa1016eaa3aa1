//! The scenario file: what to simulate (supply, load, faults, effects, sensors, timing).
//!
//! See the module documentation of [`crate::sim`] for the TOML format.

use super::{FaultSpec, SensorSpec, SimError};
use monitor_core::{EffectKind, Phase};
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
    pub effects: Vec<EffectSpec>,
    /// Sensor chain (ADC, errors, noise, encoder). Default: [`SensorSpec::default`].
    #[serde(default)]
    pub sensors: SensorSpec,
}

/// Default largest integrator step [s].
pub const DEFAULT_MAX_STEP_S: f64 = 1.0e-4;

/// Output sample rates a scenario may ask for [Hz]: 1 Hz ..= 1 MHz. The monitor reads logs
/// of 1 kHz to 50 kHz; the simulator writes outside that band too (slow rates for long
/// thermal runs, fast ones for other tools); above 1 MHz there is nothing left to resolve
/// (the model has no PWM switching) and a second of output would be about 100 MB.
pub const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (1.0, 1.0e6);

/// Smallest `max_step_s` [s]: 0.1 us. Fixed-step RK4 at the default 100 us is already
/// accurate to about 1e-5 A on the reference start (a 100x finer run is the accuracy
/// reference, 1 us); a step a thousand times finer than that adds only rounding error
/// and makes a 10 s run take 1e8 steps.
pub const MIN_STEP_S: f64 = 1.0e-7;

/// What a scenario costs before it runs ([`Scenario::workload`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Workload {
    /// Output rows: round(duration_s * sample_rate_hz).
    pub rows: u64,
    /// RK4 steps per output row: ceil(sample period / max_step_s), >= 1.
    pub steps_per_row: u64,
    /// Integrator steps of the whole run: rows * steps_per_row (as f64: it may be huge).
    pub steps: f64,
}

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

/// Main-flux saturation law parameters; see [`EffectSpec::Saturation`].
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
pub(super) fn d_true() -> bool {
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

/// A physical effect to inject, with its parameters: `[[effects]] name = "..."`, the name
/// an [`EffectKind`] (the effect library of `docs/design.md`).
///
/// Each variant lists its parameters (TOML keys) with units and defaults. The defaults make a
/// visible but realistic difference on the reference motors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "name", rename_all = "snake_case", deny_unknown_fields)]
pub enum EffectSpec {
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
    /// Shorted turns in one stator phase (inter-turn short) as they are (Tallam, Habetler,
    /// Harley, IEEE Trans. Ind. Appl. 38(3), 2002): a fraction mu of that phase's turns
    /// shorted through a fault resistance r_f. The shorted turns stay in the winding; the
    /// loop carries the fault current i_f, `(mu Lls/3) di_f/dt = u_k . v_s - R_f i_f`,
    /// `R_f = Rs (1 - 2mu/3) + r_f/mu`, and the terminals draw (2/3) mu i_f u_k on top of the
    /// healthy machine's current (star connection, isolated neutral; `sim::machine` docs).
    /// The negative-sequence current is `I2/I1 = (mu/3) (Z1/Z_f) a^k`. Default mu = 0.05 in
    /// phase a through r_f = Rs/10 (a low-resistance short, as insulation breakdown makes:
    /// the loop draws a few times the rated current). A bolted short (`r_f = 0`) of a few
    /// per cent of the turns draws a loop current of V/Rs, tens of times the rated current.
    PhaseAsymmetry {
        /// Faulty phase, default "a".
        #[serde(default = "d_phase_a")]
        phase: Phase,
        /// Fraction mu of the winding shorted (0..0.5), default 0.05.
        #[serde(default = "d_asym")]
        fraction: f64,
        /// Fault resistance r_f of the short [ohm], >= 0; default a tenth of the phase's
        /// resistance Rs.
        #[serde(default)]
        fault_resistance_ohm: Option<f64>,
    },
    /// Rotor cage asymmetry (broken rotor bars): rotor phase a's resistance is
    /// Rr (1 + delta), the others Rr. In the rotor's own alpha-beta frame (amplitude-invariant
    /// Clarke, isolated neutral) the rotor resistance is the matrix
    /// R_r = Rr I + (2/3) Rr delta e_a e_a^T; in the stator frame it turns with the rotor,
    /// R_r(theta) = Rr I + (2/3) Rr delta u u^T, u = (cos Np theta_m, sin Np theta_m), and the
    /// rotor voltage equation becomes dpsi_r/dt = -R_r(theta) i_r + J omega_r psi_r. The
    /// extra rotor loss is (3/2) i_r^T R_r i_r - (3/2) Rr |i_r|^2.
    ///
    /// Give `delta` (relative resistance asymmetry, 0..10), or `broken_bars` n with `bars`
    /// N: delta = 3n / (N - 3n) (the usual approximation for n adjacent broken bars of an
    /// N-bar cage, Kliman et al., IEEE Trans. Energy Convers. 3(4), 1988; Bellini et al.,
    /// IEEE Trans. Ind. Appl. 37(5), 2001; it ignores the inter-bar currents and the
    /// end-ring redistribution). Default delta = 0.1 (about one broken bar of 28).
    RotorAsymmetry {
        /// Relative rotor phase resistance asymmetry delta [-] (0..10).
        #[serde(default)]
        delta: Option<f64>,
        /// Number of adjacent broken bars n (with `bars`; instead of `delta`).
        #[serde(default)]
        broken_bars: Option<f64>,
        /// Rotor bar count N (with `broken_bars`).
        #[serde(default)]
        bars: Option<f64>,
    },
    /// Rotor flux dynamics (Lr/Rr): always present in the full-order model; a no-op here.
    FluxDynamics {},
    /// Stator current dynamics (La dI/dt): always present in the full-order model; a no-op.
    CurrentDynamics {},
    /// d-axis stator dynamics: always present in the full-order model; a no-op.
    DAxisDynamics {},
    /// Cross-coupling and q-axis rotor flux: always present in the full-order model; a no-op.
    CrossCouplingDynamics {},
}

impl EffectSpec {
    /// Which effect.
    pub fn kind(&self) -> EffectKind {
        match self {
            EffectSpec::ThermalDrift { .. } => EffectKind::ThermalDrift,
            EffectSpec::Saturation { .. } => EffectKind::Saturation,
            EffectSpec::IronLoss { .. } => EffectKind::IronLoss,
            EffectSpec::CoulombFriction { .. } => EffectKind::CoulombFriction,
            EffectSpec::Windage { .. } => EffectKind::Windage,
            EffectSpec::LoadTorque { .. } => EffectKind::LoadTorque,
            EffectSpec::SupplyUnbalance { .. } => EffectKind::SupplyUnbalance,
            EffectSpec::PhaseAsymmetry { .. } => EffectKind::PhaseAsymmetry,
            EffectSpec::FluxDynamics {} => EffectKind::FluxDynamics,
            EffectSpec::CurrentDynamics {} => EffectKind::CurrentDynamics,
            EffectSpec::RotorAsymmetry { .. } => EffectKind::RotorAsymmetry,
            EffectSpec::DAxisDynamics {} => EffectKind::DAxisDynamics,
            EffectSpec::CrossCouplingDynamics {} => EffectKind::CrossCouplingDynamics,
        }
    }

    /// The effect with every parameter at its default (as `name = "<kind>"` alone in a
    /// scenario file gives it).
    pub fn with_defaults(kind: EffectKind) -> EffectSpec {
        match kind {
            EffectKind::ThermalDrift => EffectSpec::ThermalDrift {
                rise_k: None,
                tau_s: d_tau_s(),
                at_s: 0.0,
                r_th_k_per_w: None,
                alpha_per_k: d_alpha(),
                rotor: d_true(),
            },
            EffectKind::Saturation => EffectSpec::Saturation {
                psi_sat_wb: None,
                psi_sat_ratio: d_sat_ratio(),
                exponent: d_sat_exp(),
            },
            EffectKind::IronLoss => EffectSpec::IronLoss {
                rfe_ohm: None,
                rfe_over_xm: d_iron_ratio(),
            },
            EffectKind::CoulombFriction => EffectSpec::CoulombFriction {
                torque_nm: None,
                omega0_rad_s: d_coulomb_w(),
            },
            EffectKind::Windage => EffectSpec::Windage { k_nms2: None },
            EffectKind::LoadTorque => EffectSpec::LoadTorque { torque_nm: None },
            EffectKind::SupplyUnbalance => EffectSpec::SupplyUnbalance {
                fraction: d_unb(),
                angle_deg: 0.0,
            },
            EffectKind::PhaseAsymmetry => EffectSpec::PhaseAsymmetry {
                phase: d_phase_a(),
                fraction: d_asym(),
                fault_resistance_ohm: None,
            },
            EffectKind::FluxDynamics => EffectSpec::FluxDynamics {},
            EffectKind::CurrentDynamics => EffectSpec::CurrentDynamics {},
            EffectKind::RotorAsymmetry => EffectSpec::RotorAsymmetry {
                delta: None,
                broken_bars: None,
                bars: None,
            },
            EffectKind::DAxisDynamics => EffectSpec::DAxisDynamics {},
            EffectKind::CrossCouplingDynamics => EffectSpec::CrossCouplingDynamics {},
        }
    }

    /// Checks the parameters' ranges.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key (`effects.<name>.<parameter>`).
    pub fn validate(&self) -> Result<(), SimError> {
        let k = |p: &str| format!("effects.{}.{p}", self.kind().name());
        let fraction = |key: &str, f: f64| {
            if f.is_finite() && (0.0..=0.5).contains(&f) {
                Ok(())
            } else {
                invalid(key, format!("must be in 0..0.5, got {f}"))
            }
        };
        match self {
            EffectSpec::ThermalDrift {
                rise_k,
                tau_s,
                at_s,
                r_th_k_per_w,
                alpha_per_k,
                ..
            } => {
                if let Some(r) = rise_k {
                    if !r.is_finite() || *r < -200.0 {
                        return invalid(&k("rise_k"), format!("must be finite, >= -200, got {r}"));
                    }
                }
                if rise_k.is_some() && r_th_k_per_w.is_some() {
                    return invalid(&k("rise_k"), "give rise_k or r_th_k_per_w, not both".into());
                }
                positive(&k("tau_s"), *tau_s)?;
                not_negative(&k("at_s"), *at_s)?;
                if let Some(r) = r_th_k_per_w {
                    not_negative(&k("r_th_k_per_w"), *r)?;
                }
                not_negative(&k("alpha_per_k"), *alpha_per_k)
            }
            EffectSpec::Saturation {
                psi_sat_wb,
                psi_sat_ratio,
                exponent,
            } => {
                if let Some(p) = psi_sat_wb {
                    positive(&k("psi_sat_wb"), *p)?;
                }
                positive(&k("psi_sat_ratio"), *psi_sat_ratio)?;
                positive(&k("exponent"), *exponent)
            }
            EffectSpec::IronLoss {
                rfe_ohm,
                rfe_over_xm,
            } => {
                if let Some(r) = rfe_ohm {
                    positive(&k("rfe_ohm"), *r)?;
                }
                positive(&k("rfe_over_xm"), *rfe_over_xm)
            }
            EffectSpec::CoulombFriction {
                torque_nm,
                omega0_rad_s,
            } => {
                if let Some(t) = torque_nm {
                    not_negative(&k("torque_nm"), *t)?;
                }
                positive(&k("omega0_rad_s"), *omega0_rad_s)
            }
            EffectSpec::Windage { k_nms2 } => match k_nms2 {
                Some(v) => not_negative(&k("k_nms2"), *v),
                None => Ok(()),
            },
            EffectSpec::LoadTorque { torque_nm } => match torque_nm {
                Some(t) if !t.is_finite() => {
                    invalid(&k("torque_nm"), format!("must be finite, got {t}"))
                }
                _ => Ok(()),
            },
            EffectSpec::SupplyUnbalance {
                fraction: f,
                angle_deg,
            } => {
                fraction(&k("fraction"), *f)?;
                if angle_deg.is_finite() {
                    Ok(())
                } else {
                    invalid(&k("angle_deg"), "must be finite".into())
                }
            }
            EffectSpec::PhaseAsymmetry {
                fraction: f,
                fault_resistance_ohm: rf,
                ..
            } => {
                fraction(&k("fraction"), *f)?;
                rf.map_or(Ok(()), |r| not_negative(&k("fault_resistance_ohm"), r))
            }
            EffectSpec::FluxDynamics {}
            | EffectSpec::CurrentDynamics {}
            | EffectSpec::DAxisDynamics {}
            | EffectSpec::CrossCouplingDynamics {} => Ok(()),
            EffectSpec::RotorAsymmetry { .. } => self.rotor_delta().map(|_| ()),
        }
    }

    /// The rotor resistance asymmetry delta of a `rotor_asymmetry` effect (0 for any
    /// other effect): `delta`, or 3n/(N - 3n) from `broken_bars` n and `bars` N.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key when a value is out of range or the keys do not
    /// go together.
    pub fn rotor_delta(&self) -> Result<f64, SimError> {
        let EffectSpec::RotorAsymmetry {
            delta,
            broken_bars,
            bars,
        } = *self
        else {
            return Ok(0.0);
        };
        let k = |p: &str| format!("effects.rotor_asymmetry.{p}");
        let bad = |key: &str, message: String| -> Result<f64, SimError> {
            Err(SimError::Invalid {
                key: key.to_string(),
                message,
            })
        };
        match (delta, broken_bars, bars) {
            (Some(_), Some(_), _) => bad(&k("delta"), "give delta or broken_bars, not both".into()),
            (Some(d), None, _) if d.is_finite() && (0.0..=10.0).contains(&d) => Ok(d),
            (Some(d), None, _) => bad(&k("delta"), format!("must be in 0..10, got {d}")),
            (None, Some(n), Some(nb)) => {
                if !(nb.is_finite() && nb >= 6.0) {
                    return bad(&k("bars"), format!("must be at least 6, got {nb}"));
                }
                if !(n.is_finite() && n >= 0.0 && 3.0 * n < nb) {
                    return bad(
                        &k("broken_bars"),
                        format!("must be in 0..{} (N/3) for {nb} bars, got {n}", nb / 3.0),
                    );
                }
                let d = super::machine::delta_of_broken_bars(n, nb);
                if d <= 10.0 {
                    Ok(d)
                } else {
                    bad(&k("broken_bars"), format!("gives delta = {d} > 10"))
                }
            }
            (None, Some(_), None) => bad(&k("bars"), "broken_bars needs the bar count bars".into()),
            (None, None, _) => Ok(d_rotor_delta()),
        }
    }
}

fn d_rotor_delta() -> f64 {
    0.1
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

    /// The reference scenario for the 2.2 kW machine: direct-on-line from
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
    /// [`SimError::Toml`] (syntax, unknown or missing key, with the line and column) or
    /// [`SimError::Invalid`] (a value out of range, naming the key).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SimError> {
        let s: Scenario = toml::from_str(text).map_err(|e| SimError::Toml {
            path: origin.to_string(),
            message: crate::params::toml_error_message(text, &e),
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

    /// The run's size: output rows and integrator steps (the integer number of RK4 steps
    /// per output sample is the smallest that keeps the step at or below `max_step_s`).
    /// Meaningful for a scenario that passed [`Scenario::validate`].
    pub fn workload(&self) -> Workload {
        let rows = (self.duration_s * self.sample_rate_hz).round();
        let period = 1.0 / self.sample_rate_hz;
        let hmax = self.max_step_s.unwrap_or(DEFAULT_MAX_STEP_S);
        // The 1e-12 keeps a step that divides the period exactly from rounding up.
        let steps_per_row = ((period / hmax) * (1.0 - 1e-12)).ceil().max(1.0);
        Workload {
            rows: rows as u64,
            steps_per_row: steps_per_row as u64,
            steps: rows * steps_per_row,
        }
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
        positive("duration_s", self.duration_s)?;
        let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
        if !(self.sample_rate_hz.is_finite() && (lo..=hi).contains(&self.sample_rate_hz)) {
            return invalid(
                "sample_rate_hz",
                format!("must be in {lo}..={hi} Hz, got {}", self.sample_rate_hz),
            );
        }
        if self.duration_s * self.sample_rate_hz > 1.0e10 {
            return invalid("duration_s", "more than 1e10 samples".into());
        }
        if let Some(h) = self.max_step_s {
            // The sample period with a little slack, so that 1/rate written out is accepted.
            let period = 1.0 / self.sample_rate_hz;
            if !(h.is_finite() && h >= MIN_STEP_S && h <= period * (1.0 + 1e-9)) {
                return invalid(
                    "max_step_s",
                    format!(
                        "must be in {MIN_STEP_S:e}..={period:e} s (the sample period), got {h:e}"
                    ),
                );
            }
        }
        self.supply.validate()?;
        self.load.validate()?;
        for f in &self.faults {
            f.validate()?;
        }
        for e in &self.effects {
            e.validate()?;
        }
        self.sensors.validate()
    }
}

impl SupplySpec {
    /// Checks the supply overrides and steps.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        if let Some(v) = self.v_ll_rms {
            positive("supply.v_ll_rms", v)?;
        }
        if let Some(f) = self.f_hz {
            positive("supply.f_hz", f)?;
        }
        for st in &self.steps {
            not_negative("supply.steps.t_s", st.t_s)?;
            if st.v_scale.is_none() && st.f_hz.is_none() {
                return invalid("supply.steps", "a step needs v_scale or f_hz".into());
            }
            if let Some(v) = st.v_scale {
                positive("supply.steps.v_scale", v)?;
            }
            if let Some(f) = st.f_hz {
                positive("supply.steps.f_hz", f)?;
            }
        }
        Ok(())
    }
}

impl LoadSpec {
    /// Checks that the load's values and steps fit its kind.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), SimError> {
        match self.kind {
            LoadKind::Viscous => {
                if self.torque_nm.is_some() {
                    return invalid("load.torque_nm", "only for kind = \"torque\"".into());
                }
                if let Some(b) = self.bl_nms {
                    not_negative("load.bl_nms", b)?;
                }
            }
            LoadKind::Torque => {
                if self.bl_nms.is_some() {
                    return invalid("load.bl_nms", "only for kind = \"viscous\"".into());
                }
                if let Some(t) = self.torque_nm {
                    if !t.is_finite() {
                        return invalid("load.torque_nm", format!("must be finite, got {t}"));
                    }
                }
            }
        }
        for st in &self.steps {
            not_negative("load.steps.t_s", st.t_s)?;
            match (self.kind, st.torque_nm, st.bl_scale) {
                (LoadKind::Torque, Some(t), None) if t.is_finite() => {}
                (LoadKind::Viscous, None, Some(b)) => not_negative("load.steps.bl_scale", b)?,
                (LoadKind::Torque, _, _) => {
                    return invalid(
                        "load.steps",
                        "a torque load's step needs a finite torque_nm (and no bl_scale)".into(),
                    )
                }
                (LoadKind::Viscous, _, _) => {
                    return invalid(
                        "load.steps",
                        "a viscous load's step needs bl_scale (and no torque_nm)".into(),
                    )
                }
            }
        }
        Ok(())
    }
}

/// `Err(SimError::Invalid)` for `key`.
pub(super) fn invalid(key: &str, message: String) -> Result<(), SimError> {
    Err(SimError::Invalid {
        key: key.to_string(),
        message,
    })
}

/// Checks `v` is positive and finite.
pub(super) fn positive(key: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        invalid(key, format!("must be a positive number, got {v}"))
    }
}

/// Checks `v` is finite and >= 0.
pub(super) fn not_negative(key: &str, v: f64) -> Result<(), SimError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        invalid(key, format!("must be >= 0, got {v}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Scenario, String> {
        Scenario::from_toml_str(text, "s.toml").map_err(|e| e.to_string())
    }

    #[test]
    fn sample_rate_and_step_outside_their_ranges_are_refused_with_the_range() {
        for ok in ["1.0", "1e6", "10000.0"] {
            parse(&format!("duration_s = 1.0\nsample_rate_hz = {ok}\n")).unwrap();
        }
        for bad in ["0.5", "2e6", "1e9", "inf", "nan"] {
            let e = parse(&format!("duration_s = 1.0\nsample_rate_hz = {bad}\n")).unwrap_err();
            assert!(
                e.contains("sample_rate_hz") && e.contains("1..=1000000 Hz"),
                "{e}"
            );
        }
        let with_step = |h: &str| {
            parse(&format!(
                "duration_s = 1.0\nsample_rate_hz = 1e4\nmax_step_s = {h}\n"
            ))
        };
        // The floor and the sample period itself are in range.
        for ok in ["1e-7", "1e-4", "0.0001", "3e-5"] {
            with_step(ok).unwrap();
        }
        for bad in ["1e-12", "5e-8", "2e-4", "0.0", "-1e-5"] {
            let e = with_step(bad).unwrap_err();
            assert!(
                e.contains("max_step_s") && e.contains("1e-7..=1e-4 s"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn workload_counts_rows_and_integrator_steps() {
        let w = |text: &str| parse(text).unwrap().workload();
        // 2 s at 10 kHz, the default 100 us step: one step a row.
        let a = w("duration_s = 2.0\nsample_rate_hz = 1e4\n");
        assert_eq!((a.rows, a.steps_per_row, a.steps), (20_000, 1, 20_000.0));
        // A 10 us step: ten a row. A 30 us step: ceil(100/30) = 4 a row (25 us).
        let b = w("duration_s = 2.0\nsample_rate_hz = 1e4\nmax_step_s = 1e-5\n");
        assert_eq!((b.rows, b.steps_per_row, b.steps), (20_000, 10, 200_000.0));
        let c = w("duration_s = 2.0\nsample_rate_hz = 1e4\nmax_step_s = 3e-5\n");
        assert_eq!(c.steps_per_row, 4);
        // 1 kHz with the default step: ten a row.
        let d = w("duration_s = 1.0\nsample_rate_hz = 1000.0\n");
        assert_eq!((d.rows, d.steps_per_row), (1000, 10));
    }

    #[test]
    fn toml_errors_give_line_and_column() {
        let e = parse("duration_s = 1.0\nsample_rate_hz = 1e4\nseed = = 2\n").unwrap_err();
        // "seed = = 2": the second '=' is the 8th character of line 3.
        assert!(e.contains("s.toml: line 3, column 8: "), "{e}");
    }

    #[test]
    fn every_effect_kind_parses_with_defaults() {
        for kind in EffectKind::ALL {
            let text = format!("name = \"{}\"", kind.name());
            let parsed: EffectSpec = toml::from_str(&text).unwrap();
            assert_eq!(parsed, EffectSpec::with_defaults(kind));
            assert_eq!(parsed.kind(), kind);
        }
    }
}
