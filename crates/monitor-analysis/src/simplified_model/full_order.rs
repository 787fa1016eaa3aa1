//! The full-order form in the analysis frame (the stator d axis or the q-axis rotor flux
//! dynamic, [`super::Dynamics`]), and what it shares with the stationary-frame form: the
//! machine at a sample, the initial state, the run's set-up ([`FullRun`]).

use super::reduced::initial_state;
use super::{
    BaseParams, MachineConstants, MagnetisingLaw, ModelMechanics, ModelRun, ModelTerms, Prediction,
};
use crate::prep::{Prepared, C64};

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

/// The switches of the full-order form: which states are dynamic ([`super::Dynamics`]).
#[derive(Debug, Clone, Copy)]
struct Switches {
    /// L_sigma dI_qs/dt (else the q equation is algebraic).
    iq: bool,
    /// The d-axis equation (else I_ds is the measured one).
    id: bool,
    /// The rotor-flux equations (else psi_Rd = L_M i_f).
    flux: bool,
    /// psi_Rq (else 0); a state only with `flux` and `id`, quasi-static otherwise.
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
        let x = self.algebraic(sw, x, v.1, id_in, if_in, wk, np);
        let dx = self.derivative(sw, &x, v, wk, np * x.wm);
        (x, dx)
    }

    /// The state `x` with its parts that are algebraic under the switches `sw` put in: the
    /// measured I_ds, the flux of the current, a quasi-static q flux, the quasi-static
    /// I_qs of the q voltage `vq`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn algebraic(
        &self,
        sw: Switches,
        x: &FullState,
        vq: f64,
        id_in: f64,
        if_in: f64,
        wk: f64,
        np: f64,
    ) -> FullState {
        let mut x = *x;
        let wr = np * x.wm;
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
            x.iq =
                (vq - wk * self.l_sigma * x.id + self.a * x.pq - wr * x.pd) / (self.rs + self.rr);
        }
        x
    }

    /// The derivative of the dynamic states of `x` under the switches `sw` (the others'
    /// 0; the speed's is the caller's), `v` = (V_ds, V_qs), `wk` the frame speed and `wr`
    /// the electrical rotor speed [rad/s].
    #[inline(always)]
    fn derivative(
        &self,
        sw: Switches,
        x: &FullState,
        v: (f64, f64),
        wk: f64,
        wr: f64,
    ) -> FullState {
        let r = self.rs + self.rr;
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
        FullState {
            id: did,
            iq: diq,
            pd: dpd,
            pq: dpq,
            wm: 0.0,
        }
    }
}

impl FullMachine {
    /// The machine at sample `k` with the base parameters `b` and the effects' terms `t`.
    pub(super) fn at(
        n: &MachineConstants,
        b: &BaseParams,
        t: &ModelTerms,
        k: usize,
    ) -> FullMachine {
        Self::at_lm(
            n,
            b,
            t,
            k,
            t.magnetising.lm_scale.get(k).copied().unwrap_or(1.0),
        )
    }

    /// [`FullMachine::at`] with the magnetising inductance `mf` x Lm (1: unsaturated, what
    /// the stationary-frame model's own saturation starts from).
    pub(super) fn at_lm(
        n: &MachineConstants,
        b: &BaseParams,
        t: &ModelTerms,
        k: usize,
        mf: f64,
    ) -> Self {
        let rf = t.resistance.scale.get(k).copied().unwrap_or(1.0);
        let lm = n.lm_h * mf;
        let lr = n.llr_h + lm;
        let ls = b.ls_scale * (n.lls_h + lm);
        let l_sigma = t
            .dynamics
            .stator_current_la_h
            .unwrap_or(b.ls_scale * (n.lls_h + lm - lm * lm / lr))
            // max/min, not clamp: a trial point of the solver with a NaN or negative Ls
            // (its values diverged) gives a NaN here, which the fit counts as a failed point;
            // clamp would panic on the reversed bounds (seen on a 50 hp log's ladder).
            .max(1e-3 * ls)
            .min(0.9 * ls);
        let l_m = ls - l_sigma;
        // A winding temperature heats the cage too: the fitted rotor time constant is the
        // cold one, and a = Rr/Lr follows the resistance scale.
        let a = match t.dynamics.rotor_flux_tau_s {
            Some(tau) => rf / tau.max(1e-5),
            None => n.rr_ohm * b.ra_scale * rf / lr,
        };
        let sf = t.resistance.stator_scale.get(k).copied().unwrap_or(1.0);
        FullMachine {
            rs: n.rs_ohm * b.ra_scale * rf * sf,
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

/// What both full-order forms set up before their loop: the data, the shaft's constants,
/// the machine at each sample and the initial state. `None` when there is nothing to
/// simulate (no samples, or no voltages to drive the model).
pub(super) struct FullRun<'a> {
    pub(super) run: ModelRun<'a>,
    pub(super) mech: ModelMechanics,
    /// The initial state ([`full_initial_state`]).
    pub(super) x0: FullState,
    /// The machine's Lm starts unsaturated at every sample (the stationary model's own
    /// magnetising law acts on it) instead of following the channel's scale.
    unsaturated: bool,
}

impl<'a> FullRun<'a> {
    pub(super) fn new(run: ModelRun<'a>, unsaturated: bool) -> Option<Self> {
        let ModelRun { d, n, b, .. } = run;
        let len = d.len();
        if len == 0 || d.vq.len() != len {
            return None;
        }
        let mut full = FullRun {
            run,
            mech: ModelMechanics::new(n, b),
            x0: FullState::default(),
            unsaturated,
        };
        full.x0 = full_initial_state(d, n, &full.machine(0));
        Some(full)
    }

    /// The machine at sample `k`.
    pub(super) fn machine(&self, k: usize) -> FullMachine {
        let ModelRun { n, b, t, .. } = self.run;
        if self.unsaturated {
            let lm0 = t
                .magnetising
                .law
                .as_ref()
                .map_or(1.0, MagnetisingLaw::lm0_over_file);
            FullMachine::at_lm(n, b, t, k, lm0)
        } else {
            FullMachine::at(n, b, t, k)
        }
    }
}

/// The full-order form of the model (the stator d axis or the q-axis rotor flux dynamic),
/// in the analysis frame turning at omega_k = d theta/dt, inverse-Gamma form:
/// ```text
///   L_sigma dI_ds/dt = V_ds - R I_ds + omega_k L_sigma I_qs + a psi_Rd + omega_r psi_Rq
///   L_sigma dI_qs/dt = V_qs - R I_qs - omega_k L_sigma I_ds + a psi_Rq - omega_r psi_Rd
///   dpsi_Rd/dt = Rr' I_ds - a psi_Rd + (omega_k - omega_r) psi_Rq
///   dpsi_Rq/dt = Rr' I_qs - a psi_Rq - (omega_k - omega_r) psi_Rd
///   J dw_m/dt = (3/2) Np (psi_Rd I_qs - psi_Rq I_ds) - (B + Bl) w_m - T_extra(w_m)
/// ```
/// R = Rs + Rr', Rr' = (Lm/Lr)^2 Rr, L_M = Lm^2/Lr, a = Rr'/L_M = Rr/Lr. Each state not
/// dynamic replaces its part by the paper's simplification ([`Switches`]). The refitted Ra
/// scales Rs and Rr, Ls scales L_M and L_sigma; the stator current's La sets L_sigma
/// (L_M = Ls - La), the rotor flux's tau_r sets a. Integration: classic RK4 per working
/// sample, inputs linear between samples (L_sigma/R is about 7 samples at 2 kHz, RK4's
/// error is below 1e-6 of a step). Core loss adds g j omega_k psi_s to the output current
/// (no feedback: 1 % of the current at Rfe = 8 Xm).
pub(super) fn simulate_full(run: ModelRun<'_>, rot_at: impl Fn(usize) -> C64) -> Prediction {
    let Some(full) = FullRun::new(run, false) else {
        return Prediction::default();
    };
    let len = run.d.len();
    let mut out = Prediction::with_capacity(len);
    let form = FrameForm {
        full: &full,
        sw: Switches::of(&run.t.dynamics),
    };
    out.predicts_d_axis = form.sw.id;
    let mut x = full.x0;
    for k in 0..len {
        let m = full.machine(k);
        let wk = form.frame_speed(k);
        form.output(k, &m, wk, &x, rot_at(k), &mut out);
        if k + 1 == len {
            break;
        }
        x = form.step(k, &m, wk, &x);
        if !(x.id.is_finite() && x.iq.is_finite() && x.pd.is_finite() && x.wm.is_finite()) {
            // A diverging trial of the fit: stop; the residuals of the missing samples are
            // large (the fit treats a short prediction as a bad one).
            break;
        }
    }
    out
}

impl Switches {
    /// The switches of the dynamics channel.
    fn of(dy: &super::Dynamics) -> Self {
        Switches {
            iq: dy.stator_current_la_h.is_some(),
            id: dy.stator_d_axis,
            flux: dy.rotor_flux_tau_s.is_some(),
            cross: dy.rotor_flux_q_axis,
        }
    }
}

/// The full-order form in the analysis frame over one run ([`simulate_full`]).
struct FrameForm<'a> {
    full: &'a FullRun<'a>,
    sw: Switches,
}

impl FrameForm<'_> {
    /// Frame speed in the equations at sample `k` [rad/s]: the angle's increment over the
    /// step, kept within 5 % (+ 20 rad/s) of the smoothed omega_s (the increments jump
    /// where the flux estimate starts at a start); after each step the state is turned by
    /// what the frame turned beyond that ([`FrameForm::step`]), so the frame the model runs
    /// in is exactly the measurements' frame.
    fn frame_speed(&self, k: usize) -> f64 {
        let d = self.full.run.d;
        let ws = d.omega_s[k];
        if k + 1 < d.len() {
            let lim = 0.05 * ws.abs() + 20.0;
            ((d.theta[k + 1] - d.theta[k]) / d.dt_s).clamp(ws - lim, ws + lim)
        } else {
            ws
        }
    }

    /// The inputs at the fraction `s` of the interval from sample `k`: (V_ds, V_qs), I_ds,
    /// i_f, linear between the samples.
    fn input(&self, k: usize, s: f64) -> ((f64, f64), f64, f64) {
        let d = self.full.run.d;
        let k1 = (k + 1).min(d.len() - 1);
        let lerp = |a: &[f64]| a[k] + s * (a[k1] - a[k]);
        ((lerp(&d.vd), lerp(&d.vq)), lerp(&d.id), lerp(&d.i_f))
    }

    /// The outputs at sample `k` (the algebraic parts of the state resolved), the frame
    /// turned by `rot`.
    fn output(
        &self,
        k: usize,
        m: &FullMachine,
        wk: f64,
        x: &FullState,
        rot: C64,
        out: &mut Prediction,
    ) {
        let ModelRun { d, n, t, .. } = self.full.run;
        let (v0, id0, if0) = self.input(k, 0.0);
        let (xa, _) = m.deriv(self.sw, x, v0, id0, if0, wk, n.np);
        let ineg = t.reduced_i_neg(d, k);
        let mut i_dq = C64::new(if self.sw.id { xa.id } else { d.id[k] }, xa.iq);
        let g = t.magnetising.core_loss_s;
        if g != 0.0 {
            let psd = m.l_sigma * xa.id + xa.pd;
            let psq = m.l_sigma * xa.iq + xa.pq;
            i_dq += C64::new(-psq, psd) * (g * wk);
        }
        out.iq.push(i_dq.im + (ineg * rot.conj()).im);
        out.omega_r.push(n.np * xa.wm);
        out.i_ab.push(i_dq * rot + ineg);
    }

    /// RK4 over [k, k+1] for the electrical states, the speed with the torque; then the
    /// state turned by what the frame turned beyond `wk`.
    fn step(&self, k: usize, m: &FullMachine, wk: f64, x: &FullState) -> FullState {
        let (d, np) = (self.full.run.d, self.full.run.n.np);
        let ModelMechanics { j, btot } = self.full.mech;
        let dt = d.dt_s;
        let f = |st: &FullState, s: f64| -> FullState {
            let (v, idm, ifm) = self.input(k, s);
            let (xa, mut dx) = m.deriv(self.sw, st, v, idm, ifm, wk, np);
            let te = 1.5 * np * (xa.pd * xa.iq - xa.pq * xa.id);
            dx.wm = (te - btot * xa.wm - self.full.run.t.shaft.extra_nm(k, xa.wm)) / j;
            dx
        };
        let add = |a: &FullState, b: &FullState, h: f64| FullState {
            id: a.id + h * b.id,
            iq: a.iq + h * b.iq,
            pd: a.pd + h * b.pd,
            pq: a.pq + h * b.pq,
            wm: a.wm + h * b.wm,
        };
        let k1 = f(x, 0.0);
        let k2 = f(&add(x, &k1, 0.5 * dt), 0.5);
        let k3 = f(&add(x, &k2, 0.5 * dt), 0.5);
        let k4 = f(&add(x, &k3, dt), 1.0);
        let sum = FullState {
            id: k1.id + 2.0 * (k2.id + k3.id) + k4.id,
            iq: k1.iq + 2.0 * (k2.iq + k3.iq) + k4.iq,
            pd: k1.pd + 2.0 * (k2.pd + k3.pd) + k4.pd,
            pq: k1.pq + 2.0 * (k2.pq + k3.pq) + k4.pq,
            wm: k1.wm + 2.0 * (k2.wm + k3.wm) + k4.wm,
        };
        let mut x = add(x, &sum, dt / 6.0);
        let corr = (d.theta[k + 1] - d.theta[k]) - wk * dt;
        if corr != 0.0 {
            let r = C64::from_polar(1.0, -corr);
            let i = C64::new(x.id, x.iq) * r;
            let p = C64::new(x.pd, x.pq) * r;
            (x.id, x.iq, x.pd, x.pq) = (i.re, i.im, p.re, p.im);
        }
        x
    }
}
