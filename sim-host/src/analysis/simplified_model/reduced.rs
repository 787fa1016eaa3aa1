//! The reduced model: the paper's simplified model with the effects' steady-state terms.

use super::full_order::simulate_full;
use super::stationary::simulate_stationary;
use super::terms::reduced_i_neg;
use super::{BaseParams, EffectTerms, InputNoise, MachineConstants, Prediction};
use crate::analysis::prep::{Prepared, C64};

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
        let a_if = 1.0
            - (-2.0 * std::f64::consts::PI * crate::analysis::prep::I_F_SMOOTH_HZ * d.dt_s).exp();
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
pub(super) fn initial_state(d: &Prepared, n: &MachineConstants) -> (f64, f64) {
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
pub(super) fn simulate_with(
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
