//! The reduced model: the paper's simplified model with the effects' steady-state terms.

use super::{InputNoise, MachineConstants, ModelMechanics, ModelRun, ModelTerms, Prediction};
use crate::prep::{Prepared, C64};

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
    fn new(d: &'a Prepared, t: &ModelTerms) -> Self {
        let noise = t.input_noise.map(|nz| {
            use rand::SeedableRng;
            (
                nz,
                rand_chacha::ChaCha8Rng::seed_from_u64(nz.seed),
                [0.0f64; 4],
            )
        });
        let a_if = 1.0 - (-2.0 * std::f64::consts::PI * crate::prep::I_F_SMOOTH_HZ * d.dt_s).exp();
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

/// The machine behind the core-loss conductance ([`super::Magnetising::core_loss_s`]) at
/// one sample.
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

/// Core loss (g = 1/Rfe across the magnetising branch, behind Rs): the
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

impl CoreLoss {
    /// No core loss: the measured inputs as they are.
    fn none(x: Inputs) -> Self {
        CoreLoss {
            i_f: x.i_f,
            id_raw: x.id,
            vq: x.vq,
            eps: 0.0,
            id_term: x.id,
            i_fe_q: 0.0,
            iq_shift: 0.0,
        }
    }
}

/// The reduced model's constants over a run.
struct Reduced<'a> {
    run: ModelRun<'a>,
    mech: ModelMechanics,
    /// Rs and the rotor term of Ra with the refitted Ra scale [ohm].
    rs0: f64,
    rr0: f64,
    /// Largest |I_ds| [A] (the floor of the flux in the slip term).
    i_f_ref: f64,
    /// Decay of the rotor flux over a sample with rotor-flux dynamics.
    flux_decay: Option<f64>,
    /// Decay over a sample of the flux's deviation driven by the rotor flux drive.
    drive_decay: f64,
}

/// The reduced model's state: speed [rad/s, mechanical], I_qs [A], the normalised rotor
/// flux phi = psi_r/Lm [A] and its driven deviation [A].
struct ReducedState {
    wm: f64,
    iq: f64,
    phi: f64,
    phi_dev: f64,
}

/// The machine at one sample: resistances, inductances [ohm, H].
struct AtSample {
    rs: f64,
    rr: f64,
    lm: f64,
    ls: f64,
    /// Lm^2 / Lr [H].
    lmr: f64,
}

/// The flux's part of eqs. (28)-(29) at one sample: Psi' [Wb] of eq. (28), the resistance
/// of its quasi-static solution [ohm], and the flux current the torque uses [A].
struct FluxTerms {
    psi_p: f64,
    rden: f64,
    phi_t: f64,
}

impl<'a> Reduced<'a> {
    fn new(run: ModelRun<'a>) -> Self {
        let ModelRun { d, n, b, t } = run;
        let dt = d.dt_s;
        Reduced {
            run,
            mech: ModelMechanics::new(n, b),
            rs0: n.rs_ohm * b.ra_scale,
            rr0: n.rr_a_ohm * b.ra_scale,
            i_f_ref: d.id.iter().fold(0.0f64, |a, &x| a.max(x.abs())).max(1e-6),
            flux_decay: t
                .dynamics
                .rotor_flux_tau_s
                .map(|tau| (-dt / tau.max(1e-5)).exp()),
            drive_decay: (-dt * n.rr_ohm / n.lr_h).exp(),
        }
    }

    /// The initial state (the measurement's first 10 ms, the flux at i_f).
    fn initial(&self) -> ReducedState {
        let (wm, iq) = initial_state(self.run.d, self.run.n);
        let start = self.run.t.rotor_cage.flux_drive_start;
        ReducedState {
            wm,
            iq,
            phi: self.run.d.i_f[0] + start,
            phi_dev: start,
        }
    }

    /// The machine at sample `k`: the resistance and magnetising channels applied.
    fn at(&self, k: usize) -> AtSample {
        let (n, t) = (self.run.n, self.run.t);
        let rf = t.resistance.scale.get(k).copied().unwrap_or(1.0);
        let mf = t.magnetising.lm_scale.get(k).copied().unwrap_or(1.0);
        let lm = n.lm_h * mf;
        AtSample {
            rs: self.rs0 * rf * t.resistance.stator_scale.get(k).copied().unwrap_or(1.0),
            rr: self.rr0 * rf * t.resistance.rotor_scale.get(k).copied().unwrap_or(1.0),
            lm,
            ls: self.run.b.ls_scale * (n.lls_h + lm),
            lmr: lm * lm / (n.llr_h + lm),
        }
    }

    /// The core loss at sample `k`; at the first sample the states start from the
    /// machine's own currents, not the terminal ones.
    fn core_loss(&self, k: usize, m: &AtSample, x: Inputs, s: &mut ReducedState) -> CoreLoss {
        let g = self.run.t.magnetising.core_loss_s;
        if g == 0.0 {
            return CoreLoss::none(x);
        }
        let cl = core_loss(g, self.run.d.omega_s[k], self.run.n, m.ls, m.lm, m.rs, x);
        if k == 0 {
            s.iq += cl.iq_shift;
            s.phi = cl.i_f + self.run.t.rotor_cage.flux_drive_start;
        }
        cl
    }

    /// The rotor flux at sample `k` (phi = psi_r / Lm [A]): with rotor-flux dynamics it
    /// follows the raw I_ds through the rotor time constant; without, it is i_f (plus the
    /// deviation the flux drive makes through the nominal rotor time constant).
    fn flux(&self, k: usize, m: &AtSample, cl: &CoreLoss, s: &mut ReducedState) -> FluxTerms {
        let (ls, lmr, rs, rr) = (m.ls, m.lmr, m.rs, m.rr);
        let ls_scale = self.run.b.ls_scale;
        let cage = &self.run.t.rotor_cage;
        let drive = cage.flux_drive.get(k).copied().unwrap_or(0.0);
        match self.flux_decay {
            Some(a) => {
                // The rotor flux follows the raw I_ds (its own lag filters the noise).
                let target = cl.id_raw + drive;
                s.phi = target + (s.phi - target) * a;
                let phi = s.phi;
                // sigma Ls part with the raw I_ds (fast), the rotor part through phi.
                let psi_p = (ls - ls_scale * lmr) * cl.id_raw + ls_scale * lmr * phi;
                let phi_c = if phi.abs() < 0.05 * self.i_f_ref {
                    0.05 * self.i_f_ref * if phi < 0.0 { -1.0 } else { 1.0 }
                } else {
                    phi
                };
                let rden = rs + rr * psi_p / (ls * phi_c);
                FluxTerms {
                    psi_p,
                    rden: rden.clamp(0.2 * (rs + rr), 50.0 * (rs + rr)),
                    phi_t: phi,
                }
            }
            None if cage.flux_drive.is_empty() => FluxTerms {
                psi_p: ls * cl.i_f,
                rden: rs + rr,
                phi_t: cl.i_f,
            },
            None => {
                s.phi_dev = drive + (s.phi_dev - drive) * self.drive_decay;
                let phi = cl.i_f + s.phi_dev;
                let psi_p = ls * cl.i_f + ls_scale * lmr * s.phi_dev;
                let phi_c = if phi.abs() < 1e-6 { 1e-6 } else { phi };
                FluxTerms {
                    psi_p,
                    rden: rs + rr * psi_p / (ls * phi_c),
                    phi_t: phi,
                }
            }
        }
    }

    /// Eqs. (28)-(29) over one sample: the new I_qs and speed from V_qs `vq` [V] (the
    /// speed semi-implicit, so the step is stable at any working rate).
    fn mechanics(&self, k: usize, m: &AtSample, f: &FluxTerms, vq: f64, s: &mut ReducedState) {
        let (n, dt) = (self.run.n, self.run.d.dt_s);
        let ModelMechanics { j, btot } = self.mech;
        let kt = 1.5 * n.np * m.lmr * f.phi_t; // Te = kt * iq  [N m/A]
        let extra = |w: f64| self.run.t.shaft.extra_nm(k, w);
        let (psi_p, rden) = (f.psi_p, f.rden);
        match self.run.t.dynamics.stator_current_la_h {
            Some(la) => {
                let iq_ss = (vq - psi_p * n.np * s.wm) / rden;
                let a = (-dt * rden / la.max(1e-6)).exp();
                s.iq = iq_ss + (s.iq - iq_ss) * a;
                let te = kt * s.iq;
                s.wm = (j * s.wm + dt * (te - extra(s.wm))) / (j + dt * btot);
            }
            None => {
                // Te = kt (vq - psi_p Np wm)/rden, linear in wm: implicit.
                let a = kt * vq / rden;
                let bb = kt * psi_p * n.np / rden;
                s.wm = (j * s.wm + dt * (a - extra(s.wm))) / (j + dt * (bb + btot));
                s.iq = (vq - psi_p * n.np * s.wm) / rden;
            }
        }
    }

    /// The outputs at sample `k` in the analysis frame turned by `rot`: the measured d
    /// current, the predicted q current (with the core loss' frame tilt undone, and the
    /// shorted-turn loop's in-phase current `|y| V_qs`, which makes no torque), the
    /// negative sequence added.
    fn output(&self, k: usize, rot: C64, cl: &CoreLoss, s: &ReducedState, out: &mut Prediction) {
        let d = self.run.d;
        let ineg = self.run.t.reduced_i_neg(d, k);
        let loop_q = self
            .run
            .t
            .stator_winding
            .map_or(0.0, |w| w.y.norm() * d.vq[k]);
        let i_dq = if cl.eps != 0.0 {
            let i_true = C64::new(cl.id_term, s.iq + cl.i_fe_q);
            let fwd = C64::new(cl.eps.cos(), cl.eps.sin());
            C64::new(d.id[k], (i_true * fwd).im + loop_q)
        } else {
            // The measured I_ds (not a re-noised one: the error never sees its noise).
            C64::new(d.id[k], s.iq + loop_q)
        };
        let i_ab = i_dq * rot + ineg;
        out.iq.push(i_dq.im + (ineg * rot.conj()).im);
        out.omega_r.push(self.run.n.np * s.wm);
        out.i_ab.push(i_ab);
    }
}

/// The reduced model (no full-order dynamics: see the module doc of [`super`]) over the
/// working series, `rot_at(k)` the frame rotation `e^{j theta_k}`.
#[inline(always)]
pub(super) fn simulate_reduced(run: ModelRun<'_>, rot_at: impl Fn(usize) -> C64) -> Prediction {
    let d = run.d;
    let len = d.len();
    let mut out = Prediction::with_capacity(len);
    if len == 0 || d.vq.len() != len {
        return out;
    }
    let model = Reduced::new(run);
    let mut s = model.initial();
    let mut inputs = InputSource::new(d, run.t);
    for k in 0..len {
        let x = inputs.at(k);
        let m = model.at(k);
        let cl = model.core_loss(k, &m, x, &mut s);
        let f = model.flux(k, &m, &cl, &mut s);
        model.mechanics(k, &m, &f, cl.vq, &mut s);
        model.output(k, rot_at(k), &cl, &s, &mut out);
    }
    out
}
