//! What the effects contribute to the model equations.

use super::super::prep::{Prepared, C64};
use super::InputNoise;

/// Per-sample contributions of the effects to the model equations. Neutral values
/// (no effect) are 1 for factors, 0 for additive terms, `None` for the dynamics.
#[derive(Debug, Clone, Default)]
pub struct EffectTerms {
    /// Multiplies Rs and Rr (winding temperature); empty = 1.
    pub r_factor: Vec<f64>,
    /// Multiplies the rotor resistance term of Ra only (`rotor_asymmetry`); empty = 1.
    pub rr_factor: Vec<f64>,
    /// Extra drive of the normalised rotor flux phi = psi_r/Lm [A] (`rotor_asymmetry`: the
    /// d-q element of an unequal rotor resistance): phi follows i_f + drive through the
    /// rotor time constant (the fitted one with `flux_dynamics`, else the nominal Lr/Rr,
    /// as a deviation added to the quasi-static flux); empty = 0.
    pub phi_drive: Vec<f64>,
    /// The flux's periodic response to `phi_drive` at the first sample [A] (added to the
    /// initial phi: a flux started without it rings for a rotor time constant).
    pub phi_drive_start: f64,
    /// Multiplies Lm (saturation); empty = 1.
    pub lm_factor: Vec<f64>,
    /// Extra load torque on the shaft [N m] (speed independent); empty = 0.
    pub load_nm: Vec<f64>,
    /// Predicted negative-sequence current, stationary frame [A]; empty = 0 (the reduced
    /// model's `supply_unbalance`; the full-order model uses `v_neg_gain` instead).
    pub i_neg: Vec<C64>,
    /// `supply_unbalance` in the full-order model: the measured negative-sequence voltage
    /// times this gain drives the machine beside the positive sequence, so that the
    /// negative-sequence current follows from the machine itself (its slip through a start,
    /// the 2f torque and speed ripple it makes); the gain is the reduced model's relative
    /// admittance `y` (`None`: the positive sequence alone).
    pub v_neg_gain: Option<C64>,
    /// `phase_asymmetry`: an unequal stator winding (`None`: symmetric).
    pub winding: Option<WindingAsymmetry>,
    /// `rotor_asymmetry` in the full-order model: (delta, phi) of an unequal rotor cage,
    /// rotor phase a's resistance Rr (1 + delta), `phi` twice its angle at the log's start
    /// against the analysis frame (the reduced model uses `rr_factor` and `phi_drive`).
    pub rotor_asym: Option<(f64, f64)>,
    /// `saturation` in the full-order model: (psi_sat [Wb], exponent n) of
    /// Lm = Lm0 / (1 + (|psi_m| / psi_sat)^n), psi_m the model's own magnetising flux (the
    /// reduced model uses `lm_factor`, computed from the measured i_f).
    pub sat: Option<(f64, f64)>,
    /// Core-loss conductance 1/Rfe [S].
    pub g_fe_s: f64,
    /// Coulomb friction torque [N m] (tanh(w_m / 1 rad/s) shape).
    pub coulomb_nm: f64,
    /// Windage coefficient [N m s^2/rad^2]: torque k w_m |w_m|.
    pub windage_nms2: f64,
    /// Rotor time constant Lr/Rr [s] when `flux_dynamics` is on.
    pub tau_r_s: Option<f64>,
    /// La [H] when `current_dynamics` is on.
    pub la_h: Option<f64>,
    /// `d_axis_dynamics`: I_ds predicted by the d-axis stator equation ([`simulate`] runs
    /// the full-order form).
    pub d_axis: bool,
    /// `cross_coupling_dynamics`: q-axis rotor flux and the slip coupling ([`simulate`]
    /// runs the full-order form).
    pub cross_coupling: bool,
    /// Extra white noise on the inputs (for the noise floor; `None` in every fit).
    pub input_noise: Option<InputNoise>,
}

/// An unequal stator winding (`phase_asymmetry`) in the two forms of the model.
///
/// Reduced model: the steady-state description `i_neg = c conj(i_pos)` (`c` from the
/// measured positive-sequence current). Full-order model: the simulator's winding (see
/// `crate::sim`'s machine: a fraction mu of phase k's turns shorted, stator turns matrix
/// T = I - (2/3) mu u_k u_k^T). In the winding's MMF variables i' = T i the machine is the
/// symmetric one driven by T^-1 v with the stator resistance Rs T^-1, and the terminal
/// current is T^-1 i'. T^-1 = I + k u_k u_k^T, k = (2/3) mu / (1 - (2/3) mu), acts on a
/// complex vector z as `A z = (1 + |e|) z + e conj(z)`, e = (k/2) e^{j 2 th_k}:
/// ```text
///   L_sigma di'/dt = A v - Rs A i' - dpsi_R/dt,   i_terminal = A i'
/// ```
/// To first order in e, in steady state at slip s the terminal current's negative sequence
/// is `c conj(i_pos)` with `c = e conj((Z1 + Z2 - Rs) / Z2)` (Z1, Z2 the positive- and
/// negative-sequence impedances): the effect fits `c` in both forms and converts it with
/// that factor at the log's mean operating point, so that the fitted value means the same.
#[derive(Debug, Clone, Copy)]
pub struct WindingAsymmetry {
    /// The steady-state ratio i_neg / conj(i_pos) [-].
    pub c: C64,
    /// The full-order operator's coefficient `e` [-].
    pub e: C64,
}

impl WindingAsymmetry {
    /// The operator `A z = (1 + |e|) z + e conj(z)` (T^-1 of the stator turns matrix).
    #[inline(always)]
    pub(super) fn apply(&self, z: C64) -> C64 {
        z * (1.0 + self.e.norm()) + self.e * z.conj()
    }

    /// The reduced model's negative-sequence current at sample `k` of `d`.
    #[inline(always)]
    fn i_neg(&self, d: &Prepared, k: usize) -> C64 {
        self.c * (d.i_ab[k] - d.i_neg[k]).conj()
    }
}

/// The reduced model's negative-sequence current of the effects at sample `k`.
#[inline(always)]
pub(super) fn reduced_i_neg(d: &Prepared, t: &EffectTerms, k: usize) -> C64 {
    let ineg = t.i_neg.get(k).copied().unwrap_or_default();
    match &t.winding {
        Some(w) => ineg + w.i_neg(d, k),
        None => ineg,
    }
}
