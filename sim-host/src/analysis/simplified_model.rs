//! The paper's simplified model (eqs. 23-29), driven by measured inputs, with effects: the
//! model `compare` and `explain` test against a log. (The simulator's full-order machine
//! is `crate::sim`'s; the core evaluates the same simplified model's residuals.)
//!
//! Base model (rotor-flux frame, DESIGN.md §2), per working sample:
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
//! measured voltages and runs in the stationary frame (`simulate_stationary`): the
//! analysis frame then only projects its outputs. There the effects that change the
//! machine act as the simulator injects them (`crate::sim`'s machine), not through their
//! steady-state descriptions: the heated cage's rotor time constant (`thermal_drift`),
//! Lm on the model's own magnetising flux (`SatMachine`, `saturation`), the unequal
//! stator winding ([`WindingAsymmetry`], `phase_asymmetry`) and rotor cage
//! (`CageAsymmetry`, `rotor_asymmetry`).
//!
//! The mechanical equation is integrated semi-implicitly (the speed dependence of the
//! quasi-static torque is taken at the new speed), so the step is stable at any working rate.
//! Effects enter through [`EffectTerms`]: per-sample series computed from the measured inputs
//! (resistance factor, magnetising-inductance factor, extra load torque, negative-sequence
//! current) and a speed-dependent extra torque evaluated inside the loop.

use super::prep::{self, Prepared, C64};
use crate::params::ParamFile;

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
    fn apply(&self, z: C64) -> C64 {
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
fn reduced_i_neg(d: &Prepared, t: &EffectTerms, k: usize) -> C64 {
    let ineg = t.i_neg.get(k).copied().unwrap_or_default();
    match &t.winding {
        Some(w) => ineg + w.i_neg(d, k),
        None => ineg,
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
}

impl Prediction {
    /// Empty series with room for `len` samples.
    fn with_capacity(len: usize) -> Self {
        Prediction {
            iq: Vec::with_capacity(len),
            omega_r: Vec::with_capacity(len),
            i_ab: Vec::with_capacity(len),
        }
    }
}

/// Runs the model over the prepared data.
///
/// Initial state from the measurement at the first sample: w_m = measured speed (0 without
/// a speed column), I_qs = measured, the normalised rotor flux phi = i_f.
pub fn simulate(d: &Prepared, n: &MachineConstants, b: &BaseParams, t: &EffectTerms) -> Prediction {
    simulate_with(d, n, b, t, |k| C64::new(d.theta[k].cos(), d.theta[k].sin()))
}

/// The frame rotation `e^{j theta_k}` of every sample of `d` (what [`simulate_rot`] takes).
pub fn rotations(d: &Prepared) -> Vec<C64> {
    d.theta
        .iter()
        .map(|th| {
            let (s, c) = th.sin_cos();
            C64::new(c, s)
        })
        .collect()
}

/// [`simulate`] with the frame rotations precomputed ([`rotations`] of the same data), for
/// the many simulations of a fit.
pub fn simulate_rot(
    d: &Prepared,
    rot: &[C64],
    n: &MachineConstants,
    b: &BaseParams,
    t: &EffectTerms,
) -> Prediction {
    if rot.len() != d.len() {
        return simulate(d, n, b, t);
    }
    simulate_with(d, n, b, t, |k| rot[k])
}

/// The model's inputs at one working sample: V_ds, V_qs, I_ds, i_f, positive-sequence I_qs.
#[derive(Debug, Clone, Copy)]
struct Inputs {
    vd: f64,
    vq: f64,
    id: f64,
    i_f: f64,
    iq_pos: f64,
}

/// The measured inputs, with [`InputNoise`] added when the terms ask for it.
struct InputSource<'a> {
    d: &'a Prepared,
    noise: Option<(InputNoise, rand_chacha::ChaCha8Rng, [f64; 4])>,
    /// Step of the four first-order passes that smooth the noise added to i_f.
    a_if: f64,
}

impl<'a> InputSource<'a> {
    fn new(d: &'a Prepared, t: &EffectTerms) -> Self {
        let noise = t.input_noise.map(|nz| {
            use rand::SeedableRng;
            (
                nz,
                rand_chacha::ChaCha8Rng::seed_from_u64(nz.seed),
                [0.0f64; 4],
            )
        });
        let a_if = 1.0 - (-2.0 * std::f64::consts::PI * super::prep::I_F_SMOOTH_HZ * d.dt_s).exp();
        InputSource { d, noise, a_if }
    }

    #[inline(always)]
    fn at(&mut self, k: usize) -> Inputs {
        let d = self.d;
        match self.noise.as_mut() {
            None => Inputs {
                vd: d.vd[k],
                vq: d.vq[k],
                id: d.id[k],
                i_f: d.i_f[k],
                iq_pos: d.iq_pos[k],
            },
            Some((nz, rng, lp)) => {
                use rand_distr::{Distribution, StandardNormal};
                let mut g = || -> f64 { StandardNormal.sample(&mut *rng) };
                let (nvd, nvq, nid, niq) = (g(), g(), g(), g());
                let nid = nz.sigma_i * nid;
                let a_if = self.a_if;
                lp[0] += a_if * (nid - lp[0]);
                lp[1] += a_if * (lp[0] - lp[1]);
                lp[2] += a_if * (lp[1] - lp[2]);
                lp[3] += a_if * (lp[2] - lp[3]);
                Inputs {
                    vd: d.vd[k] + nz.sigma_v * nvd,
                    vq: d.vq[k] + nz.sigma_v * nvq,
                    id: d.id[k] + nid,
                    i_f: d.i_f[k] + lp[3],
                    iq_pos: d.iq_pos[k] + nz.sigma_i * niq,
                }
            }
        }
    }
}

/// The machine behind the core-loss conductance (`iron_loss`) at one sample.
#[derive(Debug, Clone, Copy)]
struct CoreLoss {
    /// Flux-making current of the machine [A].
    i_f: f64,
    /// I_ds without the smoothing, for the flux dynamics [A].
    id_raw: f64,
    /// V_qs the machine behind Rs sees [V].
    vq: f64,
    /// Tilt of the voltage-model frame against the rotor flux [rad].
    eps: f64,
    /// I_ds of the machine in the rotor-flux frame [A].
    id_term: f64,
    /// q part of the core-loss current [A].
    i_fe_q: f64,
    /// The machine's own I_qs minus the terminal one (start of the current state) [A].
    iq_shift: f64,
}

/// Core loss (`iron_loss`, g = 1/Rfe across the magnetising branch, behind Rs): the
/// terminal current is the machine's i_s plus i_fe = g j w_s psi_s, psi_s =
/// Ls i_ds + j sigma Ls i_qs. Three consequences, all evaluated here:
/// (1) Rs carries i_fe too: the machine behind Rs sees V_qs - Rs i_fe,q;
/// (2) the flux is made by i_ds = measured - i_fe,d = measured + g w_s sigma Ls I_qs;
/// (3) the voltage-model frame of `prep` takes psi_r from the terminal current, so it
///     is turned by eps = (Lr/Lm) sigma Ls i_fe,q / psi_r = (Lr/Lm) sigma Ls g w_s Ls / Lm
///     against the true rotor flux (0.01 rad at Rfe = 8 Xm): inputs are turned back by
///     eps and outputs forward.
#[inline(always)]
fn core_loss(
    g: f64,
    ws: f64,
    n: &MachineConstants,
    ls: f64,
    lm: f64,
    rs: f64,
    x: Inputs,
) -> CoreLoss {
    let eps = n.lr_h / n.lm_h * n.la_h * g * ws * ls / lm;
    let back = C64::new(eps.cos(), -eps.sin());
    let v = C64::new(x.vd, x.vq) * back;
    let i = C64::new(x.id, x.iq_pos) * back;
    let i_fe_d = -g * ws * n.la_h * i.im;
    let shift = (i.re - x.id) - i_fe_d;
    let i_f = x.i_f + shift;
    let i_fe_q = g * ws * ls * i_f;
    CoreLoss {
        i_f,
        id_raw: x.id + shift,
        vq: v.im - rs * i_fe_q,
        eps,
        id_term: i.re,
        i_fe_q,
        iq_shift: (i.im - x.iq_pos) - i_fe_q,
    }
}

/// Initial speed [rad/s, mechanical] and I_qs [A]: means over the first 10 ms (a single
/// sample would start the model off by that sample's sensor noise, and the speed then
/// takes a mechanical time constant, about 0.3 s, to forget it).
fn initial_state(d: &Prepared, n: &MachineConstants) -> (f64, f64) {
    let len = d.len();
    let head = ((0.01 / d.dt_s).ceil() as usize).clamp(1, len);
    let wm = if d.omega_r.len() >= head {
        d.omega_r[..head].iter().sum::<f64>() / head as f64 / n.np
    } else {
        0.0
    };
    let iq = d.iq_pos[..head].iter().sum::<f64>() / head as f64;
    (wm, iq)
}

#[inline(always)]
fn simulate_with(
    d: &Prepared,
    n: &MachineConstants,
    b: &BaseParams,
    t: &EffectTerms,
    rot_at: impl Fn(usize) -> C64,
) -> Prediction {
    if t.d_axis && t.cross_coupling && t.la_h.is_some() && t.tau_r_s.is_some() {
        return simulate_stationary(d, n, b, t, rot_at);
    }
    if t.d_axis || t.cross_coupling {
        return simulate_full(d, n, b, t, rot_at);
    }
    let len = d.len();
    let mut out = Prediction::with_capacity(len);
    if len == 0 || d.vq.len() != len {
        return out;
    }
    let dt = d.dt_s;
    let j = (n.j_kgm2 * b.j_scale).max(1e-9);
    let btot = b.btot_nms.max(0.0);
    let rs0 = n.rs_ohm * b.ra_scale;
    let rr0 = n.rr_a_ohm * b.ra_scale;
    let (mut wm, mut iq_state) = initial_state(d, n);
    let mut phi = d.i_f[0];
    let i_f_ref = d.id.iter().fold(0.0f64, |a, &x| a.max(x.abs())).max(1e-6);
    let flux_decay = t.tau_r_s.map(|tau| (-dt / tau.max(1e-5)).exp());
    // The rotor flux's deviation driven by `phi_drive` when the flux is quasi-static.
    let drive_decay = (-dt * n.rr_ohm / n.lr_h).exp();
    phi += t.phi_drive_start;
    let mut phi_dev = t.phi_drive_start;
    let mut inputs = InputSource::new(d, t);
    for k in 0..len {
        let x = inputs.at(k);
        let rf = t.r_factor.get(k).copied().unwrap_or(1.0);
        let mf = t.lm_factor.get(k).copied().unwrap_or(1.0);
        let rs = rs0 * rf;
        let rr = rr0 * rf * t.rr_factor.get(k).copied().unwrap_or(1.0);
        let lm = n.lm_h * mf;
        let ls = b.ls_scale * (n.lls_h + lm);
        let lmr = lm * lm / (n.llr_h + lm);
        let cl = if t.g_fe_s != 0.0 {
            let cl = core_loss(t.g_fe_s, d.omega_s[k], n, ls, lm, rs, x);
            if k == 0 {
                // The states start from the machine's own currents, not the terminal ones.
                iq_state += cl.iq_shift;
                phi = cl.i_f + t.phi_drive_start;
            }
            cl
        } else {
            CoreLoss {
                i_f: x.i_f,
                id_raw: x.id,
                vq: x.vq,
                eps: 0.0,
                id_term: x.id,
                i_fe_q: 0.0,
                iq_shift: 0.0,
            }
        };
        // Flux: phi = psi_r / Lm [A].
        let drive = t.phi_drive.get(k).copied().unwrap_or(0.0);
        let (psi_p, rden, phi_t) = match flux_decay {
            Some(a) => {
                // The rotor flux follows the raw I_ds (its own lag filters the noise).
                let target = cl.id_raw + drive;
                phi = target + (phi - target) * a;
                // sigma Ls part with the raw I_ds (fast), the rotor part through phi.
                let psi_p = (ls - b.ls_scale * lmr) * cl.id_raw + b.ls_scale * lmr * phi;
                let phi_c = if phi.abs() < 0.05 * i_f_ref {
                    0.05 * i_f_ref * if phi < 0.0 { -1.0 } else { 1.0 }
                } else {
                    phi
                };
                let rden = rs + rr * psi_p / (ls * phi_c);
                (psi_p, rden.clamp(0.2 * (rs + rr), 50.0 * (rs + rr)), phi)
            }
            None if t.phi_drive.is_empty() => (ls * cl.i_f, rs + rr, cl.i_f),
            None => {
                phi_dev = drive + (phi_dev - drive) * drive_decay;
                let phi = cl.i_f + phi_dev;
                let psi_p = ls * cl.i_f + b.ls_scale * lmr * phi_dev;
                let phi_c = if phi.abs() < 1e-6 { 1e-6 } else { phi };
                (psi_p, rs + rr * psi_p / (ls * phi_c), phi)
            }
        };
        let kt = 1.5 * n.np * lmr * phi_t; // Te = kt * iq  [N m/A]
        let extra = |w: f64| {
            // (No tanh when there is no dry friction: 0 x tanh(w) is 0.)
            let coulomb = if t.coulomb_nm != 0.0 {
                t.coulomb_nm * (w / 1.0).tanh()
            } else {
                0.0
            };
            coulomb + t.windage_nms2 * w * w.abs() + t.load_nm.get(k).copied().unwrap_or(0.0)
        };
        let vq = cl.vq;
        let iq;
        match t.la_h {
            Some(la) => {
                let iq_ss = (vq - psi_p * n.np * wm) / rden;
                let a = (-dt * rden / la.max(1e-6)).exp();
                iq_state = iq_ss + (iq_state - iq_ss) * a;
                iq = iq_state;
                let te = kt * iq;
                wm = (j * wm + dt * (te - extra(wm))) / (j + dt * btot);
            }
            None => {
                // Te = kt (vq - psi_p Np wm)/rden, linear in wm: implicit.
                let a = kt * vq / rden;
                let bb = kt * psi_p * n.np / rden;
                wm = (j * wm + dt * (a - extra(wm))) / (j + dt * (bb + btot));
                iq = (vq - psi_p * n.np * wm) / rden;
            }
        }
        let rot = rot_at(k);
        let ineg = reduced_i_neg(d, t, k);
        // Back to the analysis frame (measured d current, predicted q current).
        let i_dq = if cl.eps != 0.0 {
            let i_true = C64::new(cl.id_term, iq + cl.i_fe_q);
            let fwd = C64::new(cl.eps.cos(), cl.eps.sin());
            C64::new(d.id[k], (i_true * fwd).im)
        } else {
            // The measured I_ds (not a re-noised one: the error never sees its noise).
            C64::new(d.id[k], iq)
        };
        let i_ab = i_dq * rot + ineg;
        out.iq.push(i_dq.im + (ineg * rot.conj()).im);
        out.omega_r.push(n.np * wm);
        out.i_ab.push(i_ab);
    }
    out
}

/// The machine of the full-order form at one sample (inverse-Gamma equivalent of the
/// T-equivalent circuit: the rotor leakage moved to the stator side, which the terminals
/// cannot tell apart): R = Rs + Rr', L_sigma, L_M = Lm^2/Lr, a = Rr'/L_M = 1/tau_r.
#[derive(Debug, Clone, Copy)]
struct FullMachine {
    rs: f64,
    rr: f64,
    l_sigma: f64,
    a: f64,
    l_m: f64,
}

/// The full-order state: stator current (frame), rotor flux psi_R = (Lm/Lr) psi_r, speed.
#[derive(Debug, Clone, Copy, Default)]
struct FullState {
    id: f64,
    iq: f64,
    pd: f64,
    pq: f64,
    wm: f64,
}

/// The switches of the full-order form: which dynamics effects are in the model.
#[derive(Debug, Clone, Copy)]
struct Switches {
    /// `current_dynamics`: L_sigma dI_qs/dt (else the q equation is algebraic).
    iq: bool,
    /// `d_axis_dynamics`: the d-axis equation (else I_ds is the measured one).
    id: bool,
    /// `flux_dynamics`: the rotor-flux equations (else psi_Rd = L_M i_f).
    flux: bool,
    /// `cross_coupling_dynamics`: psi_Rq (else 0); a state only with `flux` and `id`,
    /// quasi-static otherwise.
    cross: bool,
}

impl FullMachine {
    /// The inputs' part of the state that is algebraic under the switches, then the
    /// derivative. `v` = (V_ds, V_qs), `id_in`/`if_in` the measured I_ds and i_f, `wk` the
    /// frame speed [rad/s], `np` pole pairs.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn deriv(
        &self,
        sw: Switches,
        x: &FullState,
        v: (f64, f64),
        id_in: f64,
        if_in: f64,
        wk: f64,
        np: f64,
    ) -> (FullState, FullState) {
        let mut x = *x;
        let wr = np * x.wm;
        let r = self.rs + self.rr;
        if !sw.id {
            x.id = id_in;
        }
        if !sw.flux {
            x.pd = self.l_m * if sw.id { x.id } else { if_in };
        }
        if !sw.cross {
            x.pq = 0.0;
        } else if !(sw.flux && sw.id) {
            // Quasi-static q flux: a dynamic psi_Rq against a measured (not predicted) I_ds
            // is not a consistent machine (it oscillates and grows on real frames).
            x.pq = (self.rr * x.iq - (wk - wr) * x.pd) / self.a.max(1e-9);
        }
        if !sw.iq {
            x.iq = (v.1 - wk * self.l_sigma * x.id + self.a * x.pq - wr * x.pd) / r;
        }
        let inv_ls = 1.0 / self.l_sigma.max(1e-9);
        let did = if sw.id {
            (v.0 - r * x.id + wk * self.l_sigma * x.iq + self.a * x.pd + wr * x.pq) * inv_ls
        } else {
            0.0
        };
        let diq = if sw.iq {
            (v.1 - r * x.iq - wk * self.l_sigma * x.id + self.a * x.pq - wr * x.pd) * inv_ls
        } else {
            0.0
        };
        let (dpd, dpq) = if sw.flux {
            let slip = wk - wr;
            let dpd =
                self.rr * x.id - self.a * x.pd + if sw.cross && sw.id { slip * x.pq } else { 0.0 };
            let dpq = if sw.cross && sw.id {
                self.rr * x.iq - self.a * x.pq - slip * x.pd
            } else {
                0.0
            };
            (dpd, dpq)
        } else {
            (0.0, 0.0)
        };
        (
            x,
            FullState {
                id: did,
                iq: diq,
                pd: dpd,
                pq: dpq,
                wm: 0.0,
            },
        )
    }
}

impl FullMachine {
    /// The machine at sample `k` with the base parameters `b` and the effects' terms `t`.
    fn at(n: &MachineConstants, b: &BaseParams, t: &EffectTerms, k: usize) -> FullMachine {
        Self::at_lm(n, b, t, k, t.lm_factor.get(k).copied().unwrap_or(1.0))
    }

    /// [`FullMachine::at`] with the magnetising inductance `mf` x Lm (1: unsaturated, what
    /// the stationary-frame model's own saturation starts from).
    fn at_lm(n: &MachineConstants, b: &BaseParams, t: &EffectTerms, k: usize, mf: f64) -> Self {
        let rf = t.r_factor.get(k).copied().unwrap_or(1.0);
        let lm = n.lm_h * mf;
        let lr = n.llr_h + lm;
        let ls = b.ls_scale * (n.lls_h + lm);
        let l_sigma = t
            .la_h
            .unwrap_or(b.ls_scale * (n.lls_h + lm - lm * lm / lr))
            .clamp(1e-3 * ls, 0.9 * ls);
        let l_m = ls - l_sigma;
        // The winding temperature (`thermal_drift`) heats the cage too: the fitted rotor time
        // constant is the cold one, and a = Rr/Lr follows the resistance factor.
        let a = match t.tau_r_s {
            Some(tau) => rf / tau.max(1e-5),
            None => n.rr_ohm * b.ra_scale * rf / lr,
        };
        FullMachine {
            rs: n.rs_ohm * b.ra_scale * rf,
            rr: a * l_m,
            l_sigma,
            a,
            l_m,
        }
    }
}

/// The full-order state at the first sample: a log that starts de-energised (a start
/// from standstill: the first current still small against the start's peak, the speed
/// near zero) starts from the first sample's current and no flux; otherwise from the
/// means over the first 10 ms, the flux in its steady state.
fn full_initial_state(d: &Prepared, n: &MachineConstants, m0: &FullMachine) -> FullState {
    let len = d.len();
    let (wm0, iq0) = initial_state(d, n);
    let head = ((0.01 / d.dt_s).ceil() as usize).clamp(1, len);
    let id0 = d.id[..head].iter().sum::<f64>() / head as f64;
    let i_peak = d
        .i_ab
        .iter()
        .take(len.min(head * 20))
        .fold(0.0f64, |a, x| a.max(x.norm()));
    let w_sync = d.omega_s.iter().fold(0.0f64, |a, w| a.max(w.abs())) / n.np;
    let dead = d.i_ab[0].norm() < 0.3 * i_peak && wm0.abs() < 0.05 * w_sync;
    if dead {
        FullState {
            id: d.id[0],
            iq: d.iq_pos[0],
            wm: d.omega_r.first().map_or(0.0, |w| w / n.np),
            ..Default::default()
        }
    } else {
        FullState {
            id: id0,
            iq: iq0,
            pd: m0.l_m * id0,
            pq: 0.0,
            wm: wm0,
        }
    }
}

/// The full-order form of the model (`d_axis_dynamics` or `cross_coupling_dynamics` in
/// it), in the analysis frame turning at omega_k = d theta/dt, inverse-Gamma form:
/// ```text
///   L_sigma dI_ds/dt = V_ds - R I_ds + omega_k L_sigma I_qs + a psi_Rd + omega_r psi_Rq
///   L_sigma dI_qs/dt = V_qs - R I_qs - omega_k L_sigma I_ds + a psi_Rq - omega_r psi_Rd
///   dpsi_Rd/dt = Rr' I_ds - a psi_Rd + (omega_k - omega_r) psi_Rq
///   dpsi_Rq/dt = Rr' I_qs - a psi_Rq - (omega_k - omega_r) psi_Rd
///   J dw_m/dt = (3/2) Np (psi_Rd I_qs - psi_Rq I_ds) - (B + Bl) w_m - T_extra(w_m)
/// ```
/// R = Rs + Rr', Rr' = (Lm/Lr)^2 Rr, L_M = Lm^2/Lr, a = Rr'/L_M = Rr/Lr. Each dynamics
/// effect not in the model replaces its part by the paper's simplification ([`Switches`]).
/// The refitted Ra scales Rs and Rr, Ls scales L_M and L_sigma; `current_dynamics`'
/// La sets L_sigma (L_M = Ls - La), `flux_dynamics`' tau_r sets a. Integration: classic
/// RK4 per working sample, inputs linear between samples (L_sigma/R is about 7 samples at
/// 2 kHz, RK4's error is below 1e-6 of a step). Iron loss adds g j omega_k psi_s to the
/// output current (no feedback: 1 % of the current at Rfe = 8 Xm).
fn simulate_full(
    d: &Prepared,
    n: &MachineConstants,
    b: &BaseParams,
    t: &EffectTerms,
    rot_at: impl Fn(usize) -> C64,
) -> Prediction {
    let len = d.len();
    let mut out = Prediction::with_capacity(len);
    if len == 0 || d.vq.len() != len {
        return out;
    }
    let sw = Switches {
        iq: t.la_h.is_some(),
        id: t.d_axis,
        flux: t.tau_r_s.is_some(),
        cross: t.cross_coupling,
    };
    let dt = d.dt_s;
    let j = (n.j_kgm2 * b.j_scale).max(1e-9);
    let btot = b.btot_nms.max(0.0);
    let machine_at = |k: usize| FullMachine::at(n, b, t, k);
    // Frame speed in the equations: the angle's increment over the step, kept within 5 %
    // (+ 20 rad/s) of the smoothed omega_s (the increments jump where the flux estimate
    // starts at a start); after each step the state is turned by what the frame turned
    // beyond that, so the frame the model runs in is exactly the measurements' frame.
    let wk_at = |k: usize| -> f64 {
        let ws = d.omega_s[k];
        if k + 1 < len {
            let lim = 0.05 * ws.abs() + 20.0;
            ((d.theta[k + 1] - d.theta[k]) / dt).clamp(ws - lim, ws + lim)
        } else {
            ws
        }
    };
    let mut x = full_initial_state(d, n, &machine_at(0));
    let extra = |k: usize, w: f64| {
        let coulomb = if t.coulomb_nm != 0.0 {
            t.coulomb_nm * w.tanh()
        } else {
            0.0
        };
        coulomb + t.windage_nms2 * w * w.abs() + t.load_nm.get(k).copied().unwrap_or(0.0)
    };
    let np = n.np;
    for k in 0..len {
        let m = machine_at(k);
        let wk = wk_at(k);
        let input = |s: f64| -> ((f64, f64), f64, f64) {
            let k1 = (k + 1).min(len - 1);
            let lerp = |a: &[f64]| a[k] + s * (a[k1] - a[k]);
            ((lerp(&d.vd), lerp(&d.vq)), lerp(&d.id), lerp(&d.i_f))
        };
        // Output at sample k (the algebraic parts resolved).
        let (v0, id0, if0) = input(0.0);
        let (xa, _) = m.deriv(sw, &x, v0, id0, if0, wk, np);
        let rot = rot_at(k);
        let ineg = reduced_i_neg(d, t, k);
        let mut i_dq = C64::new(if sw.id { xa.id } else { d.id[k] }, xa.iq);
        if t.g_fe_s != 0.0 {
            let psd = m.l_sigma * xa.id + xa.pd;
            let psq = m.l_sigma * xa.iq + xa.pq;
            i_dq += C64::new(-psq, psd) * (t.g_fe_s * wk);
        }
        out.iq.push(i_dq.im + (ineg * rot.conj()).im);
        out.omega_r.push(np * xa.wm);
        out.i_ab.push(i_dq * rot + ineg);
        if k + 1 == len {
            break;
        }
        // RK4 over [k, k+1] for the electrical states; the speed with the torque.
        let f = |st: &FullState, s: f64| -> FullState {
            let (v, idm, ifm) = input(s);
            let (xa, mut dx) = m.deriv(sw, st, v, idm, ifm, wk, np);
            let te = 1.5 * np * (xa.pd * xa.iq - xa.pq * xa.id);
            dx.wm = (te - btot * xa.wm - extra(k, xa.wm)) / j;
            dx
        };
        let add = |a: &FullState, b: &FullState, h: f64| FullState {
            id: a.id + h * b.id,
            iq: a.iq + h * b.iq,
            pd: a.pd + h * b.pd,
            pq: a.pq + h * b.pq,
            wm: a.wm + h * b.wm,
        };
        let k1 = f(&x, 0.0);
        let k2 = f(&add(&x, &k1, 0.5 * dt), 0.5);
        let k3 = f(&add(&x, &k2, 0.5 * dt), 0.5);
        let k4 = f(&add(&x, &k3, dt), 1.0);
        let sum = FullState {
            id: k1.id + 2.0 * (k2.id + k3.id) + k4.id,
            iq: k1.iq + 2.0 * (k2.iq + k3.iq) + k4.iq,
            pd: k1.pd + 2.0 * (k2.pd + k3.pd) + k4.pd,
            pq: k1.pq + 2.0 * (k2.pq + k3.pq) + k4.pq,
            wm: k1.wm + 2.0 * (k2.wm + k3.wm) + k4.wm,
        };
        x = add(&x, &sum, dt / 6.0);
        let corr = (d.theta[k + 1] - d.theta[k]) - wk * dt;
        if corr != 0.0 {
            let r = C64::from_polar(1.0, -corr);
            let i = C64::new(x.id, x.iq) * r;
            let p = C64::new(x.pd, x.pq) * r;
            (x.id, x.iq, x.pd, x.pq) = (i.re, i.im, p.re, p.im);
        }
        if !(x.id.is_finite() && x.iq.is_finite() && x.pd.is_finite() && x.wm.is_finite()) {
            // A diverging trial of the fit: stop; the residuals of the missing samples are
            // large (the fit treats a short prediction as a bad one).
            break;
        }
    }
    out
}

/// The state of the stationary-frame full-order model: stator current, rotor flux
/// psi_R (both alpha + j beta), mechanical speed.
#[derive(Debug, Clone, Copy)]
struct StatState {
    i: C64,
    psi: C64,
    wm: f64,
}

/// An unequal rotor cage in the stationary-frame model over one working sample: rotor
/// phase a's resistance Rr (1 + delta). As in the simulator (`crate::sim`'s machine), the
/// rotor resistance matrix in the stator frame is Rr (I + D), D = (2/3) delta u u^T, u along
/// rotor phase a at the electrical angle theta_a = Np theta_m + phi/2; on a complex vector
/// `D z = (delta/3) (z + e^{j 2 theta_a} conj(z))`. In the inverse-Gamma form (psi_R =
/// (Lm/Lr) psi_r, Rr' = (Lm/Lr)^2 Rr, a = Rr/Lr) the rotor equation
/// `dpsi_r/dt = -R_r i_r + j omega_r psi_r` becomes
/// `dpsi_R/dt = (I + D) (Rr' i - a psi_R) + j omega_r psi_R`.
#[derive(Debug, Clone, Copy)]
struct CageAsymmetry {
    /// delta / 3.
    d3: f64,
    /// e^{j 2 theta_a} at the sample's start.
    u0: C64,
    /// d(2 theta_a)/dt over the sample [rad/s] (twice the measured electrical speed).
    w2: f64,
}

/// One working sample's machine and shaft for [`simulate_stationary`].
struct StatMachine<'a, F: Fn(f64) -> f64> {
    m: FullMachine,
    np: f64,
    j: f64,
    btot: f64,
    /// Extra shaft torque at a speed [N m].
    extra: &'a F,
    /// `phase_asymmetry` (the terminal current is `A i'`, see [`WindingAsymmetry`]).
    wind: Option<WindingAsymmetry>,
    /// `rotor_asymmetry`.
    cage: Option<CageAsymmetry>,
    /// `saturation`: the states are the fluxes of the T-equivalent circuit.
    sat: Option<SatMachine<'a>>,
}

/// The saturated machine (`saturation` in the full-order model) as the simulator
/// integrates it (`crate::sim`'s machine): T-equivalent circuit, states psi_s and psi_r
/// (stationary frame; in [`StatState`] `i` holds psi_s and `psi` holds psi_r), currents
/// from the fluxes with Lm = Lm0 / (1 + (|psi_m| / psi_sat)^n):
/// ```text
///   dpsi_s/dt = v - Rs i_s,   dpsi_r/dt = -Rr i_r + j omega_r psi_r
///   psi_m = (psi_s/Lls + psi_r/Llr) / (1/Lm + 1/Lls + 1/Llr)
///   i_s = (psi_s - psi_m)/Lls,   i_r = (psi_r - psi_m)/Llr
///   T_e = (3/2) Np Im(psi_r conj(i_r))
/// ```
/// The circuit comes from the fitted unsaturated inverse-Gamma machine ([`FullMachine`]:
/// Rs, L_sigma, L_M, a): the leakages are the nominal ones scaled by L_sigma / nominal
/// L_sigma, Lm0 = Ls - Lls, Rr = a Lr (the inverse-Gamma L_sigma of that circuit is within
/// (Llr/Lr)^2, 0.2 %, of the fitted one). Given psi_s and psi_r, y = 1/Lm solves
/// `y = (1/Lm0) (1 + (W / (psi_sat (y + G)))^n)`, W = |psi_s/Lls + psi_r/Llr|,
/// G = 1/Lls + 1/Llr, by Newton's method from the last solve (f is increasing in y).
/// The winding (`phase_asymmetry`) and the cage (`rotor_asymmetry`) act as in
/// [`WindingAsymmetry`] and [`CageAsymmetry`], on the fluxes' equations.
#[derive(Clone, Copy)]
struct SatMachine<'a> {
    inv_lls: f64,
    inv_llr: f64,
    inv_lm0: f64,
    rr: f64,
    psi_sat: f64,
    nexp: f64,
    /// The last solve's 1/Lm (0: none yet).
    guess: &'a std::cell::Cell<f64>,
}

impl<'a> SatMachine<'a> {
    fn new(
        n: &MachineConstants,
        m: &FullMachine,
        (psi_sat, nexp): (f64, f64),
        guess: &'a std::cell::Cell<f64>,
    ) -> Self {
        let sigma_n = n.lls_h + n.lm_h * n.llr_h / (n.llr_h + n.lm_h);
        let scale = m.l_sigma / sigma_n.max(1e-12);
        let (lls, llr) = (n.lls_h * scale, n.llr_h * scale);
        let lm0 = (m.l_sigma + m.l_m - lls).max(1e-6);
        SatMachine {
            inv_lls: 1.0 / lls.max(1e-9),
            inv_llr: 1.0 / llr.max(1e-9),
            inv_lm0: 1.0 / lm0,
            rr: m.a * (llr + lm0),
            psi_sat: psi_sat.max(1e-9),
            nexp,
            guess,
        }
    }

    /// The linear model's state (i_s, psi_R) as fluxes (psi_s, psi_r) at Lm0.
    fn linear_to_fluxes(&self, m: &FullMachine, x: &StatState) -> StatState {
        let lr_over_lm = 1.0 + self.inv_lm0 / self.inv_llr;
        StatState {
            i: x.i * m.l_sigma + x.psi,
            psi: x.psi * lr_over_lm,
            wm: x.wm,
        }
    }

    /// Stator and rotor currents at the fluxes `ps`, `pr`.
    #[inline(always)]
    fn currents(&self, ps: C64, pr: C64) -> (C64, C64) {
        let w = ps * self.inv_lls + pr * self.inv_llr;
        let g = self.inv_lls + self.inv_llr;
        let big_w = w.norm() / self.psi_sat;
        let mut y = self.guess.get().max(self.inv_lm0);
        for _ in 0..30 {
            let r = (big_w / (y + g)).powf(self.nexp);
            let f = y - self.inv_lm0 * (1.0 + r);
            let fp = 1.0 + self.inv_lm0 * self.nexp * r / (y + g);
            let ny = (y - f / fp).max(self.inv_lm0);
            let done = (ny - y).abs() <= 1e-12 * ny;
            y = ny;
            if done {
                break;
            }
        }
        self.guess.set(y);
        let psi_m = w / (y + g);
        ((ps - psi_m) * self.inv_lls, (pr - psi_m) * self.inv_llr)
    }
}

impl<F: Fn(f64) -> f64> StatMachine<'_, F> {
    /// The derivative at time `tau` into the working sample [s] (the rotor's angle).
    #[inline(always)]
    fn deriv(&self, x: &StatState, v: C64, tau: f64) -> StatState {
        if let Some(sat) = &self.sat {
            return self.deriv_sat(sat, x, v, tau);
        }
        let m = &self.m;
        let wr = self.np * x.wm;
        // Rotor: q = Rr' i - a psi_R, dpsi_R/dt = (I + D) q + j omega_r psi_R.
        let mut q = x.i * m.rr - x.psi * m.a;
        if let Some(c) = &self.cage {
            let u = c.u0 * C64::from_polar(1.0, c.w2 * tau);
            q += (q + u * q.conj()) * c.d3;
        }
        let dpsi = q + C64::new(0.0, wr) * x.psi;
        let te = 1.5 * self.np * (x.psi.conj() * x.i).im;
        // Stator: L_sigma di/dt = v - Rs i - dpsi_R/dt (with the winding: A v - Rs A i).
        let (v, ri) = match &self.wind {
            Some(w) => (w.apply(v), w.apply(x.i) * m.rs),
            None => (v, x.i * m.rs),
        };
        StatState {
            i: (v - ri - dpsi) / m.l_sigma.max(1e-9),
            psi: dpsi,
            wm: (te - self.btot * x.wm - (self.extra)(x.wm)) / self.j,
        }
    }

    /// [`StatMachine::deriv`] of the saturated machine ([`SatMachine`]).
    #[inline(always)]
    fn deriv_sat(&self, sat: &SatMachine, x: &StatState, v: C64, tau: f64) -> StatState {
        let (i_s, i_r) = sat.currents(x.i, x.psi);
        let wr = self.np * x.wm;
        let mut ri = i_r * sat.rr;
        if let Some(c) = &self.cage {
            let u = c.u0 * C64::from_polar(1.0, c.w2 * tau);
            ri += (ri + u * ri.conj()) * c.d3;
        }
        let te = 1.5 * self.np * (x.psi * i_r.conj()).im;
        let u_s = match &self.wind {
            Some(w) => w.apply(v - i_s * self.m.rs),
            None => v - i_s * self.m.rs,
        };
        StatState {
            i: u_s,
            psi: C64::new(0.0, wr) * x.psi - ri,
            wm: (te - self.btot * x.wm - (self.extra)(x.wm)) / self.j,
        }
    }

    /// The winding's current of the state (i' with an unequal winding): `x.i`, or from the
    /// fluxes of the saturated machine.
    #[inline(always)]
    fn current(&self, x: &StatState) -> C64 {
        match &self.sat {
            Some(sat) => sat.currents(x.i, x.psi).0,
            None => x.i,
        }
    }

    /// The stator flux psi_s of the state.
    #[inline(always)]
    fn stator_flux(&self, x: &StatState) -> C64 {
        match &self.sat {
            Some(_) => x.i,
            None => x.i * self.m.l_sigma + x.psi,
        }
    }

    /// The terminal current of the state (the winding's `A i'`).
    #[inline(always)]
    fn terminal(&self, x: &StatState) -> C64 {
        let i = self.current(x);
        match &self.wind {
            Some(w) => w.apply(i),
            None => i,
        }
    }

    /// Classic RK4 over `h` from `t0` into the sample, with the input at the start,
    /// middle and end.
    fn rk4(&self, x: &StatState, h: f64, v: [C64; 3], t0: f64) -> StatState {
        let add = |a: &StatState, b: &StatState, s: f64| StatState {
            i: a.i + b.i * s,
            psi: a.psi + b.psi * s,
            wm: a.wm + b.wm * s,
        };
        let k1 = self.deriv(x, v[0], t0);
        let k2 = self.deriv(&add(x, &k1, 0.5 * h), v[1], t0 + 0.5 * h);
        let k3 = self.deriv(&add(x, &k2, 0.5 * h), v[1], t0 + 0.5 * h);
        let k4 = self.deriv(&add(x, &k3, h), v[2], t0 + h);
        StatState {
            i: x.i + (k1.i + (k2.i + k3.i) * 2.0 + k4.i) * (h / 6.0),
            psi: x.psi + (k1.psi + (k2.psi + k3.psi) * 2.0 + k4.psi) * (h / 6.0),
            wm: x.wm + (k1.wm + 2.0 * (k2.wm + k3.wm) + k4.wm) * (h / 6.0),
        }
    }

    /// One working sample `dt` across a supply step at the fraction `phi` of it: the old
    /// voltage `v0` turning at `w[0]` before, the new `v1` turning at `w[1]` after. Each
    /// voltage is `[positive sequence, negative sequence]`; the negative sequence turns the
    /// other way.
    fn across_step(
        &self,
        x: &StatState,
        dt: f64,
        phi: f64,
        v0: [C64; 2],
        v1: [C64; 2],
        w: [f64; 2],
    ) -> StatState {
        let (ha, hb) = (phi * dt, (1.0 - phi) * dt);
        // `v` turned by `r` (the negative sequence by its conjugate).
        let turned = |v: [C64; 2], r: C64| v[0] * r + v[1] * r.conj();
        let mut y = *x;
        if ha > 0.0 {
            let r = |t: f64| C64::from_polar(1.0, w[0] * t);
            let at = |t: f64| turned(v0, r(t));
            y = self.rk4(&y, ha, [at(0.0), at(0.5 * ha), at(ha)], 0.0);
        }
        if hb > 0.0 {
            let r = |t: f64| C64::from_polar(1.0, -w[1] * t);
            let at = |t: f64| turned(v1, r(t));
            y = self.rk4(&y, hb, [at(hb), at(0.5 * hb), at(0.0)], ha);
        }
        y
    }
}

/// The median of a series (0 when empty).
fn median(x: &[f64]) -> f64 {
    let mut v: Vec<f64> = x.iter().copied().filter(|a| a.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

/// The voltage's phase step over a working sample [rad] (0 when either is zero).
fn phase_step(a: C64, b: C64) -> f64 {
    if a.norm() * b.norm() > 0.0 {
        (b * a.conj()).arg()
    } else {
        0.0
    }
}

/// The full-order machine (all four dynamics effects in the model) in the stationary
/// frame, complex form (`i`, `psi_R` = alpha + j beta):
/// ```text
///   L_sigma di/dt = v - R i + (a - j omega_r) psi_R
///   dpsi_R/dt     = Rr' i - (a - j omega_r) psi_R
///   J dw_m/dt     = (3/2) Np Im(conj(psi_R) i) - (B + Bl) w_m - T_extra(w_m)
/// ```
/// with the symbols of [`simulate_full`]. Nothing of the machine's dynamics depends on
/// the analysis frame: the frame only projects the outputs (I_qs) as it projects the
/// measurement. (Run in the frame, the model reads the inputs in a frame whose angle
/// comes from the voltage-model flux estimate, which through a start turns by up to
/// 0.3 rad per working sample against the rotor flux.) The input voltage between two
/// working samples follows the rotation, `v(s) = (1-s) v_k e^{j w s dt} + s v_k+1
/// e^{-j w (1-s) dt}`, `w` the voltage's own phase step: exact for a steady rotating
/// vector (a straight line between the samples cuts the circle's chord: 0.3 % at 50 Hz
/// and 2 kHz). Classic RK4 per working sample. Iron loss adds `g j omega_s psi_s` to the
/// output current.
///
/// A supply step (the voltage leaves its rotation by more than
/// [`prep::SUPPLY_STEP_REL`]) is placed where the current says it is: where in the
/// sampling interval it fell changes the interval's volt-seconds by up to `dV dt / 2`
/// (2 % of the current for 0.2 s on the reference motors at 2 kHz), so the interval is
/// integrated with the step at its start and at its end (the old vector turning on
/// before it, the new one after), and the fraction that brings the current at the next
/// sample nearest the measured one (less the model's error at this sample) is used.
///
/// Measured on effect-free simulated logs with a start, a V/f step and a dip, ideal
/// sensors, true parameters (2.2 kW, 11 kW; 2, 5, 10 kHz): `normalized_rms_error`
/// 0.0003-0.0007 (on the simulator's own rows at the log rate, point samples: below 1e-5).
fn simulate_stationary(
    d: &Prepared,
    n: &MachineConstants,
    b: &BaseParams,
    t: &EffectTerms,
    rot_at: impl Fn(usize) -> C64,
) -> Prediction {
    let len = d.len();
    let mut out = Prediction::with_capacity(len);
    if len == 0 || d.vq.len() != len {
        return out;
    }
    let dt = d.dt_s;
    let StatVoltage {
        v_mean,
        ph,
        gains,
        dev,
        step_thr,
    } = StatVoltage::new(d, &rot_at);
    let gain = |k: usize| gains[k];
    // The voltage before the block mean.
    let v_at = |k: usize| v_mean[k] / gains[k];
    let i_meas = |k: usize| d.i_ab[k] - d.i_neg[k];
    // With `saturation` the machine saturates with its own flux ([`SatMachine`]), not with
    // the reduced model's factor from the measured i_f.
    let machine_at = |k: usize| match t.sat {
        Some(_) => FullMachine::at_lm(n, b, t, k, 1.0),
        None => FullMachine::at(n, b, t, k),
    };
    let x0 = full_initial_state(d, n, &machine_at(0));
    let r0 = rot_at(0);
    let mut x = StatState {
        i: C64::new(x0.id, x0.iq) * r0,
        psi: C64::new(x0.pd, x0.pq) * r0,
        wm: x0.wm,
    };
    let mut v_cur = v_at(0);
    let mut v_next = v_at(1.min(len - 1));
    let mut cage = CageAngle::new(d, t);
    let lm_guess = std::cell::Cell::new(0.0);
    for k in 0..len {
        let extra = |w: f64| {
            let coulomb = if t.coulomb_nm != 0.0 {
                t.coulomb_nm * w.tanh()
            } else {
                0.0
            };
            coulomb + t.windage_nms2 * w * w.abs() + t.load_nm.get(k).copied().unwrap_or(0.0)
        };
        let sm = StatMachine {
            m: machine_at(k),
            np: n.np,
            j: (n.j_kgm2 * b.j_scale).max(1e-9),
            btot: b.btot_nms.max(0.0),
            extra: &extra,
            wind: t.winding,
            cage: cage.at(d, k),
            sat: None,
        };
        let sm = match t.sat {
            Some(law) => {
                let sat = SatMachine::new(n, &sm.m, law, &lm_guess);
                if k == 0 {
                    x = sat.linear_to_fluxes(&sm.m, &x);
                }
                StatMachine {
                    sat: Some(sat),
                    ..sm
                }
            }
            None => sm,
        };
        let rot = rot_at(k);
        // With `v_neg_gain` the negative sequence is in the machine's own current.
        let ineg = match t.v_neg_gain {
            Some(_) => C64::default(),
            None => t.i_neg.get(k).copied().unwrap_or_default(),
        };
        let mut i_out = sm.terminal(&x);
        if t.g_fe_s != 0.0 {
            let psi_s = sm.stator_flux(&x);
            i_out += C64::new(0.0, t.g_fe_s * d.omega_s[k]) * psi_s;
        }
        let i_ab = i_out * gain(k) + ineg;
        out.iq.push((i_ab * rot.conj()).im);
        out.omega_r.push(n.np * x.wm);
        out.i_ab.push(i_ab);
        if k + 1 == len {
            break;
        }
        let v_after = v_at((k + 2).min(len - 1));
        // The negative sequence (`supply_unbalance`), rotating the other way.
        let (vn0, vn1) = match t.v_neg_gain {
            Some(g) => {
                let at = |j: usize| d.v_neg.get(j).copied().unwrap_or_default();
                (g * at(k), g * at(k + 1))
            }
            None => (C64::default(), C64::default()),
        };
        let (v0, v1) = (v_cur + vn0, v_next + vn1);
        x = if dev[k] > step_thr {
            let w = [ph[k - 1] / dt, ph[k + 1] / dt];
            let (s0, s1) = ([v_cur, vn0], [v_next, vn1]);
            let early = sm.across_step(&x, dt, 0.0, s0, s1, w);
            let late = sm.across_step(&x, dt, 1.0, s0, s1, w);
            // The measured currents before the block mean, as the model's.
            let target = i_meas(k + 1) / gain(k + 1) - (i_meas(k) / gain(k) - sm.terminal(&x));
            let (early_i, late_i) = (sm.terminal(&early), sm.terminal(&late));
            let span = late_i - early_i;
            let phi = if span.norm_sqr() > 0.0 {
                ((target - early_i) * span.conj()).re / span.norm_sqr()
            } else {
                0.5
            };
            sm.across_step(&x, dt, phi.clamp(0.0, 1.0), s0, s1, w)
        } else {
            let half = C64::from_polar(1.0, 0.5 * ph[k]);
            let vm = (v_cur * half + v_next * half.conj()) * 0.5
                + (vn0 * half.conj() + vn1 * half) * 0.5;
            sm.rk4(&x, dt, [v0, vm, v1], 0.0)
        };
        // The measured (positive-sequence) voltages move on; `y V_neg` is added per sample
        // above (carrying `v1` over counted it twice at each sample's start).
        (v_cur, v_next) = (v_next, v_after);
        if !(x.i.re.is_finite() && x.i.im.is_finite() && x.psi.re.is_finite() && x.wm.is_finite()) {
            break;
        }
    }
    out
}

/// The stationary-frame model's voltage input, per working sample (see
/// [`simulate_stationary`]).
struct StatVoltage {
    /// Positive-sequence voltage, stationary frame, after the block mean [V].
    v_mean: Vec<C64>,
    /// The voltage's phase step over each working sample [rad].
    ph: Vec<f64>,
    /// The block mean's gain on the voltage's rotation.
    gains: Vec<f64>,
    /// How far the voltage leaves its rotation over each sample (relative).
    dev: Vec<f64>,
    /// `dev` above this is a supply step.
    step_thr: f64,
}

impl StatVoltage {
    fn new(d: &Prepared, rot_at: &impl Fn(usize) -> C64) -> Self {
        let len = d.len();
        let dt = d.dt_s;
        // A working sample is the mean of `factor` log rows: a vector turning at w comes out
        // of the block mean scaled by `gain(w)`, the input voltage and the measured current
        // alike. The machine is not linear in the voltage (the torque goes with its square:
        // 0.2 % less torque through a start at 10 kHz, 1 % of the start current), so the
        // model is driven by the voltage before the mean (v / gain) and its current is
        // compared after it (gain i).
        let factor = (d.log_rate_hz * dt).round().max(1.0);
        // Positive-sequence voltage (stationary frame, after the block mean) and the gain.
        let v_mean: Vec<C64> = (0..len)
            .map(|k| C64::new(d.vd[k], d.vq[k]) * rot_at(k))
            .collect();
        // The voltage's phase step over each working sample [rad].
        let ph: Vec<f64> = (0..len)
            .map(|k| {
                let a = k.min(len.saturating_sub(2));
                phase_step(v_mean[a], v_mean[(a + 1).min(len - 1)])
            })
            .collect();
        let gains: Vec<f64> = ph
            .iter()
            .map(|&p| block_gain(p / dt, dt / factor, factor))
            .collect();
        // The voltage before the block mean.
        let v_at = |k: usize| v_mean[k] / gains[k];
        // How far the voltage leaves its rotation over each working sample (relative); a
        // supply step is an outlier of it: above SUPPLY_STEP_REL and ten times the median
        // (harmonics in a real supply move the vector off its circle every sample).
        let dev: Vec<f64> = (0..len)
            .map(|k| {
                if k == 0 || k + 1 >= len {
                    return 0.0;
                }
                let (v0, v1) = (v_at(k), v_at(k + 1));
                (v1 - v0 * C64::from_polar(1.0, ph[k - 1])).norm()
                    / v0.norm().max(v1.norm()).max(1e-12)
            })
            .collect();
        let step_thr = prep::SUPPLY_STEP_REL.max(10.0 * median(&dev));
        StatVoltage {
            v_mean,
            ph,
            gains,
            dev,
            step_thr,
        }
    }
}

/// The angle 2 theta_a + phi of the faulty rotor phase for [`CageAsymmetry`] (`None`
/// without `rotor_asymmetry` or without a speed column): Np theta_m integrates the
/// measured electrical speed (trapezoid) from the analysis frame's angle at the first
/// sample, as the reduced model's `rotor_asymmetry` does, so that `phi` means the same.
struct CageAngle {
    /// (delta, phi) of the effect.
    p: Option<(f64, f64)>,
    /// 2 Np theta_m at the current sample [rad].
    th2: f64,
}

impl CageAngle {
    fn new(d: &Prepared, t: &EffectTerms) -> Self {
        let ok = d.omega_r.len() == d.len() && !d.is_empty();
        CageAngle {
            p: t.rotor_asym.filter(|_| ok),
            th2: d.theta.first().map_or(0.0, |t| 2.0 * t),
        }
    }

    /// The cage over working sample `k` (call for k = 0, 1, ... in turn).
    fn at(&mut self, d: &Prepared, k: usize) -> Option<CageAsymmetry> {
        let (delta, phi) = self.p?;
        if k > 0 {
            self.th2 += d.dt_s * (d.omega_r[k] + d.omega_r[k - 1]);
        }
        let k1 = (k + 1).min(d.len() - 1);
        Some(CageAsymmetry {
            d3: delta / 3.0,
            u0: C64::from_polar(1.0, self.th2 + phi),
            w2: d.omega_r[k] + d.omega_r[k1],
        })
    }
}

/// The discrete block mean's gain on a vector turning at `w` [rad/s]: the mean of
/// `factor` samples `h` apart, `sin(F w h / 2) / (F sin(w h / 2))`.
fn block_gain(w: f64, h: f64, factor: f64) -> f64 {
    let x = 0.5 * w * h;
    if x.abs() < 1e-9 {
        1.0
    } else {
        (factor * x).sin() / (factor * x.sin())
    }
}
