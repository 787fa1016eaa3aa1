//! The simplified model of "Fault Diagnosis of Induction Motor Using D-Q Simplified Model
//! and Parity Equations" (Energies 2022, 15(22), 8372; eqs. 23-29), driven by measured
//! inputs, with effects: the model `compare` and `explain` test against a log. (The
//! simulator's full-order machine is `monitor_sim`'s; the core evaluates the same simplified
//! model's residuals.)
//!
//! Base model (rotor-flux frame; the models and their sources: `docs/design.md`), per
//! working sample:
//! ```text
//!   Psi   = Ls i_f                        (i_f = measured positive-sequence I_ds, smoothed)
//!   I_qs  = (V_qs - Psi omega_r) / Ra     (eq. 23/28 with La dI_qs/dt dropped: see below)
//!   J dw_m/dt = Kf I_qs - (B + Bl) w_m,   Kf = (3/2) Np (Lm^2/Lr) i_f,  omega_r = Np w_m  (eq. 29)
//! ```
//! The La dI_qs/dt term of eq. (28) is the library effect `current_dynamics`, and the
//! assumption psi_r = Lm i_f is lifted by `flux_dynamics`: the full-order machine always has
//! both, but the steady-state parity equations (37) drop both, and on steady data neither
//! matters; treating them as effects lets `explain` name them when transients dominate.
//!
//! With all four dynamics effects in, the model is the full-order machine driven by the
//! measured voltages and runs in the stationary frame (`stationary`): the
//! analysis frame then only projects its outputs. There the effects that change the
//! machine act as the simulator injects them (`monitor_sim`'s machine), not through their
//! steady-state descriptions: the heated cage's rotor time constant (`thermal_drift`),
//! Lm on the model's own magnetising flux (`SatMachine`, `saturation`), the unequal
//! stator winding ([`WindingAsymmetryTerm`], `phase_asymmetry`) and rotor cage
//! (`CageAsymmetry`, `rotor_asymmetry`).
//!
//! The forms: `reduced` (the paper's model with the effects' steady-state terms; the
//! mechanical equation semi-implicit, so the step is stable at any working rate),
//! `full_order` (the full-order form in the analysis frame, with the dynamics effects
//! that are in) and `stationary` (all four in).
//!
//! Effects enter through one interface, [`ModelTerms`]: physical channels (resistance and
//! magnetising-inductance scales per sample, the magnetising law and the core loss, extra
//! shaft torques, the negative sequence, unequal windings, which states are dynamic) that
//! each effect writes and the model reads; the model does not name effects.

mod full_order;
mod reduced;
mod stationary;
mod terms;

pub use terms::{
    CageAsymmetry, Dynamics, LmShape, Magnetising, MagnetisingLaw, ModelTerms,
    NegativeSequenceTerm, Resistance, RotorCage, SampleTorque, SaturationLaw, Shaft, SpeedTorque,
    WindingAsymmetryTerm,
};

use super::prep::{Prepared, C64};
use monitor_io::params::ParamFile;

/// The machine constants the simplified model and the effects need: the parameter file's
/// nominal values and what [`monitor_core::MotorModel`] derives from them (Ra, La, the
/// leakages), plus a rated-torque scale. Built by [`MachineConstants::from_params`].
#[derive(Debug, Clone, Copy)]
pub struct MachineConstants {
    /// Rs [ohm].
    pub rs_ohm: f64,
    /// Rr referred to the stator [ohm].
    pub rr_ohm: f64,
    /// Rotor resistance term of Ra: (Ls/Lr) Rr [ohm].
    pub rr_a_ohm: f64,
    /// Ra = Rs + (Ls/Lr) Rr [ohm].
    pub ra_ohm: f64,
    /// Stator leakage Lls [H].
    pub lls_h: f64,
    /// Rotor leakage Llr [H].
    pub llr_h: f64,
    /// Lm [H].
    pub lm_h: f64,
    /// Ls [H].
    pub ls_h: f64,
    /// Lr [H].
    pub lr_h: f64,
    /// La = sigma Ls [H].
    pub la_h: f64,
    /// Pole pairs.
    pub np: f64,
    /// J [kg m^2].
    pub j_kgm2: f64,
    /// B + Bl [N m s/rad] (shaft).
    pub btot_nms: f64,
    /// Rated torque estimate [N m]: Kf at nominal flux times the current at 3 % slip, or
    /// at least Bl times synchronous speed. Used for scales only.
    pub torque_scale_nm: f64,
    /// The core's model of the machine (f32), for the computations the analysis shares
    /// with the monitor (the faulty-phase method).
    pub core_model: monitor_core::MotorModel,
    /// The parameter file's peak phase voltage [V].
    pub v_phase_peak: f64,
    /// The parameter file's supply frequency [Hz] (a no-load test's table is taken at it).
    pub f_hz: f64,
    /// Which magnetising inductance `lm_h` is (the file's `lm_at`): a saturation law takes
    /// its unsaturated Lm0 from it ([`monitor_io::params::lm0_over_file`]).
    pub lm_point: monitor_core::LmPoint,
    /// The rated point's magnetising flux [Wb, peak]
    /// ([`monitor_io::params::rated_magnetising_flux_wb`]).
    pub psi_m_rated_wb: f64,
}

impl MachineConstants {
    /// The saturation law's unsaturated Lm0 over `lm_h` for a law with `psi_sat_wb` and
    /// exponent `n` ([`monitor_io::params::lm0_over_file`]: 1 for a file that holds the
    /// unsaturated value).
    pub fn lm0_over_file(&self, psi_sat_wb: f64, n: f64) -> f64 {
        match self.lm_point {
            monitor_core::LmPoint::Unsaturated => 1.0,
            monitor_core::LmPoint::Rated => {
                1.0 + (self.psi_m_rated_wb / psi_sat_wb.max(1e-9)).powf(n)
            }
        }
    }
}

impl MachineConstants {
    /// Derives the constants from a parameter file.
    pub fn from_params(p: &ParamFile) -> Self {
        let m = p.motor.model::<f64>();
        let np = m.np();
        let ws = p.supply.omega_rad_s();
        let i_f = p.supply.v_phase_peak() / (ws * m.ls_h);
        let kf = m.kf_per_if() * i_f;
        // Current at 3 % slip: slip frequency = (Rr/Lr) iq/if.
        let iq = 0.03 * ws * m.lr_h / m.rr_ohm * i_f;
        let t_rated = (kf * iq).max(m.bl_nms * ws / np).max(1e-3);
        MachineConstants {
            rs_ohm: m.rs_ohm,
            rr_ohm: m.rr_ohm,
            rr_a_ohm: m.rr_referred_ohm(),
            ra_ohm: m.ra_ohm(),
            lls_h: m.lls_h(),
            llr_h: m.llr_h(),
            lm_h: m.lm_h,
            ls_h: m.ls_h,
            lr_h: m.lr_h,
            la_h: m.la_h(),
            np,
            j_kgm2: m.j_kgm2,
            btot_nms: m.b_nms + m.bl_nms,
            torque_scale_nm: t_rated,
            core_model: p.motor.model(),
            v_phase_peak: p.supply.v_phase_peak(),
            f_hz: p.supply.f_hz,
            lm_point: p.motor.lm_point(),
            psi_m_rated_wb: monitor_io::params::rated_magnetising_flux_wb(&p.motor, &p.supply),
        }
    }
}

/// The base parameters the data identify, refitted with every effect set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseParams {
    /// Ra relative to nominal (1 = nominal).
    pub ra_scale: f64,
    /// Ls (the Psi = Ls i_f coefficient) relative to nominal.
    pub ls_scale: f64,
    /// B + Bl [N m s/rad] (shaft).
    pub btot_nms: f64,
    /// Inertia J relative to nominal.
    pub j_scale: f64,
}

impl BaseParams {
    /// The nominal values.
    pub fn nominal(n: &MachineConstants) -> Self {
        BaseParams {
            ra_scale: 1.0,
            ls_scale: 1.0,
            btot_nms: n.btot_nms,
            j_scale: 1.0,
        }
    }
}

/// One of the four base parameters the data identify (the JSON keys of `compare`'s
/// `base_parameters`, `identifiability.base` and `explain`'s `base_refit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum BaseParameter {
    /// Ra = Rs + (Ls/Lr) Rr [ohm].
    #[serde(rename = "ra_ohm")]
    Ra,
    /// Ls, the Psi = Ls i_f coefficient [H].
    #[serde(rename = "ls_h")]
    Ls,
    /// B + Bl, the shaft's viscous coefficient [N m s/rad].
    #[serde(rename = "b_plus_bl_nms")]
    BPlusBl,
    /// J, the inertia [kg m^2].
    #[serde(rename = "j_kgm2")]
    J,
}

impl BaseParameter {
    /// The four, in the order of the fit's parameter vector ([`BaseParams`]' fields).
    pub const ALL: [BaseParameter; 4] = [
        BaseParameter::Ra,
        BaseParameter::Ls,
        BaseParameter::BPlusBl,
        BaseParameter::J,
    ];

    /// The JSON key (`ra_ohm`, `ls_h`, `b_plus_bl_nms`, `j_kgm2`).
    pub fn key(self) -> &'static str {
        match self {
            BaseParameter::Ra => "ra_ohm",
            BaseParameter::Ls => "ls_h",
            BaseParameter::BPlusBl => "b_plus_bl_nms",
            BaseParameter::J => "j_kgm2",
        }
    }

    /// The unit.
    pub fn unit(self) -> &'static str {
        match self {
            BaseParameter::Ra => "ohm",
            BaseParameter::Ls => "H",
            BaseParameter::BPlusBl => "N m s/rad",
            BaseParameter::J => "kg m^2",
        }
    }
}

impl std::fmt::Display for BaseParameter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

/// The shaft's constants of a run: J [kg m^2] and B + Bl [N m s/rad] of the base
/// parameters, held physical (J at least 1e-9, B + Bl at least 0).
#[derive(Debug, Clone, Copy)]
struct ModelMechanics {
    j: f64,
    btot: f64,
}

impl ModelMechanics {
    fn new(n: &MachineConstants, b: &BaseParams) -> Self {
        ModelMechanics {
            j: (n.j_kgm2 * b.j_scale).max(1e-9),
            btot: b.btot_nms.max(0.0),
        }
    }
}

/// White Gaussian noise added to the model's inputs, to measure how much of the inputs'
/// sensor noise reaches the outputs (see `metrics::noise_floor`).
#[derive(Debug, Clone, Copy)]
pub struct InputNoise {
    /// Seed of the generator (the result is reproducible).
    pub seed: u64,
    /// Standard deviation added to V_ds and V_qs [V].
    pub sigma_v: f64,
    /// Standard deviation added to I_ds and I_qs [A]; i_f gets it through the same 10 Hz
    /// smoothing magnitude response as `prep` applies (four first-order passes).
    pub sigma_i: f64,
}

/// Model outputs over the working series.
#[derive(Debug, Clone, Default)]
pub struct Prediction {
    /// Predicted I_qs [A] (all sequences, including core-loss current).
    pub iq: Vec<f64>,
    /// Predicted omega_r [rad/s] (electrical).
    pub omega_r: Vec<f64>,
    /// Predicted current vector, stationary frame [A].
    pub i_ab: Vec<C64>,
    /// True when the model predicts I_ds itself (the stator current is a state: the
    /// stationary-frame full-order machine, or `d_axis_dynamics` in the analysis frame);
    /// false when the predicted current vector takes the measured I_ds (the reduced
    /// model): then only the q-axis sensor noise shows in the phase currents' error
    /// (`metrics::noise_floor`).
    pub predicts_d_axis: bool,
}

impl Prediction {
    /// Empty series with room for `len` samples.
    fn with_capacity(len: usize) -> Self {
        Prediction {
            iq: Vec::with_capacity(len),
            omega_r: Vec::with_capacity(len),
            i_ab: Vec::with_capacity(len),
            predicts_d_axis: false,
        }
    }
}

/// Runs the model over the prepared data: the form the dynamics channel asks for
/// ([`Dynamics`]).
///
/// Initial state from the measurement at the first sample: w_m = measured speed (0 without
/// a speed column), I_qs = measured, the normalised rotor flux phi = i_f.
pub fn simulate(d: &Prepared, n: &MachineConstants, b: &BaseParams, t: &ModelTerms) -> Prediction {
    simulate_with(d, n, b, t, |k| C64::new(d.theta[k].cos(), d.theta[k].sin()))
}

/// What every run of the model on one working series shares, computed once for the many
/// simulations of a fit: the frame rotation `e^{j theta_k}` of every sample, and the
/// stationary-frame model's voltage input (its phase steps, the block mean's gains and the
/// supply steps), built at the first full-order run.
pub struct Rotations {
    /// `e^{j theta_k}` per working sample.
    rot: Vec<C64>,
    /// The full-order model's voltage input without input noise (built on first use).
    stat: std::sync::OnceLock<stationary::StatVoltage>,
}

/// The frame rotations of every sample of `d` (what [`simulate_rot`] takes).
pub fn rotations(d: &Prepared) -> Rotations {
    let rot = d
        .theta
        .iter()
        .map(|th| {
            let (s, c) = th.sin_cos();
            C64::new(c, s)
        })
        .collect();
    Rotations {
        rot,
        stat: std::sync::OnceLock::new(),
    }
}

/// [`simulate`] with the frame rotations precomputed ([`rotations`] of the same data), for
/// the many simulations of a fit: the same prediction, without recomputing what depends on
/// the series alone.
pub fn simulate_rot(
    d: &Prepared,
    rot: &Rotations,
    n: &MachineConstants,
    b: &BaseParams,
    t: &ModelTerms,
) -> Prediction {
    if rot.rot.len() != d.len() {
        return simulate(d, n, b, t);
    }
    let rot_at = |k: usize| rot.rot[k];
    if t.dynamics.is_full_order() && t.input_noise.is_none() {
        let volt = rot
            .stat
            .get_or_init(|| stationary::StatVoltage::new(d, &rot_at, None));
        let run = ModelRun { d, n, b, t };
        return stationary::simulate_stationary_with(run, rot_at, volt);
    }
    simulate_with(d, n, b, t, rot_at)
}

/// The form of the model the dynamics channel asks for, `rot_at(k)` the frame rotation.
#[inline(always)]
fn simulate_with(
    d: &Prepared,
    n: &MachineConstants,
    b: &BaseParams,
    t: &ModelTerms,
    rot_at: impl Fn(usize) -> C64,
) -> Prediction {
    let run = ModelRun { d, n, b, t };
    if t.dynamics.is_full_order() {
        stationary::simulate_stationary(run, rot_at)
    } else if t.dynamics.needs_full_form() {
        full_order::simulate_full(run, rot_at)
    } else {
        reduced::simulate_reduced(run, rot_at)
    }
}

/// One run of the model: the working series, the machine's constants, the base
/// parameters and the effects' terms.
#[derive(Clone, Copy)]
struct ModelRun<'a> {
    d: &'a Prepared,
    n: &'a MachineConstants,
    b: &'a BaseParams,
    t: &'a ModelTerms,
}
