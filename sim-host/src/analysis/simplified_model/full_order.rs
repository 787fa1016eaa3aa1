//! The full-order form in the analysis frame (`d_axis_dynamics` or
//! `cross_coupling_dynamics` in the model).

use super::reduced::initial_state;
use super::terms::reduced_i_neg;
use super::{BaseParams, EffectTerms, MachineConstants, Prediction};
use crate::analysis::prep::{Prepared, C64};

/// The machine of the full-order form at one sample (inverse-Gamma equivalent of the
/// T-equivalent circuit: the rotor leakage moved to the stator side, which the terminals
/// cannot tell apart): R = Rs + Rr', L_sigma, L_M = Lm^2/Lr, a = Rr'/L_M = 1/tau_r.
#[derive(Debug, Clone, Copy)]
pub(super) struct FullMachine {
    pub(super) rs: f64,
    pub(super) rr: f64,
    pub(super) l_sigma: f64,
    pub(super) a: f64,
    pub(super) l_m: f64,
}

/// The full-order state: stator current (frame), rotor flux psi_R = (Lm/Lr) psi_r, speed.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FullState {
    pub(super) id: f64,
    pub(super) iq: f64,
    pub(super) pd: f64,
    pub(super) pq: f64,
    pub(super) wm: f64,
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
    pub(super) fn at(
        n: &MachineConstants,
        b: &BaseParams,
        t: &EffectTerms,
        k: usize,
    ) -> FullMachine {
        Self::at_lm(n, b, t, k, t.lm_factor.get(k).copied().unwrap_or(1.0))
    }

    /// [`FullMachine::at`] with the magnetising inductance `mf` x Lm (1: unsaturated, what
    /// the stationary-frame model's own saturation starts from).
    pub(super) fn at_lm(
        n: &MachineConstants,
        b: &BaseParams,
        t: &EffectTerms,
        k: usize,
        mf: f64,
    ) -> Self {
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
pub(super) fn full_initial_state(
    d: &Prepared,
    n: &MachineConstants,
    m0: &FullMachine,
) -> FullState {
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
pub(super) fn simulate_full(
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
