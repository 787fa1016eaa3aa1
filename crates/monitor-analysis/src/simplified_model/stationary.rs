//! The full-order machine in the stationary frame (all four states of [`super::Dynamics`]
//! dynamic).

mod saturated;
mod voltage;

use super::full_order::{FullMachine, FullRun};
use super::terms::{Shaft, WindingAsymmetryTerm};
use super::{ModelMechanics, ModelRun, ModelTerms, Prediction};
use crate::prep::{Prepared, C64};
use saturated::SatMachine;
pub(super) use voltage::StatVoltage;

/// The state of the stationary-frame full-order model: stator current, rotor flux
/// psi_R (both alpha + j beta), mechanical speed.
#[derive(Debug, Clone, Copy)]
struct StatState {
    i: C64,
    psi: C64,
    wm: f64,
}

/// An unequal rotor cage in the stationary-frame model over one working sample: rotor
/// phase a's resistance Rr (1 + delta). As in the simulator (`monitor_sim`'s machine), the
/// rotor resistance matrix in the stator frame is Rr (I + D), D = (2/3) delta u u^T, u along
/// rotor phase a at the electrical angle theta_a = Np theta_m + phi/2; on a complex vector
/// `D z = (delta/3) (z + e^{j 2 theta_a} conj(z))`. In the inverse-Gamma form (psi_R =
/// (Lm/Lr) psi_r, Rr' = (Lm/Lr)^2 Rr, a = Rr/Lr) the rotor equation
/// `dpsi_r/dt = -R_r i_r + j omega_r psi_r` becomes
/// `dpsi_R/dt = (I + D) (Rr' i - a psi_R) + j omega_r psi_R`.
#[derive(Debug, Clone, Copy)]
struct CageOverSample {
    /// delta / 3.
    d3: f64,
    /// e^{j 2 theta_a} at the sample's start.
    u0: C64,
    /// d(2 theta_a)/dt over the sample [rad/s] (twice the measured electrical speed).
    w2: f64,
}

/// One working sample's machine and shaft for [`simulate_stationary`].
struct StatMachine<'a> {
    m: FullMachine,
    np: f64,
    mech: ModelMechanics,
    /// The shaft's extra torques and the sample they are taken at.
    shaft: &'a Shaft,
    k: usize,
    /// Shorted turns (the terminal current adds the loop's, see
    /// [`WindingAsymmetryTerm`]).
    wind: Option<WindingAsymmetryTerm>,
    /// An unequal rotor cage.
    cage: Option<CageOverSample>,
    /// A magnetising law: the states are the fluxes of the T-equivalent circuit.
    sat: Option<SatMachine<'a>>,
}

impl StatMachine<'_> {
    /// The derivative at the time into the working sample where the unequal cage has
    /// turned by `turn` = `e^{j w2 tau}` since the sample's start (1 without one).
    #[inline(always)]
    fn deriv(&self, x: &StatState, v: C64, turn: C64) -> StatState {
        if let Some(sat) = &self.sat {
            return self.deriv_sat(sat, x, v, turn);
        }
        let m = &self.m;
        let wr = self.np * x.wm;
        // Rotor: q = Rr' i - a psi_R, dpsi_R/dt = (I + D) q + j omega_r psi_R.
        let mut q = x.i * m.rr - x.psi * m.a;
        if let Some(c) = &self.cage {
            let u = c.u0 * turn;
            q += (q + u * q.conj()) * c.d3;
        }
        let dpsi = q + C64::new(0.0, wr) * x.psi;
        let te = 1.5 * self.np * (x.psi.conj() * x.i).im;
        // Stator: L_sigma di/dt = v - Rs i - dpsi_R/dt (shorted turns leave the machine
        // symmetric: their loop is drawn at the terminals).
        StatState {
            i: (v - x.i * m.rs - dpsi) / m.l_sigma.max(1e-9),
            psi: dpsi,
            wm: (te - self.mech.btot * x.wm - self.shaft.extra_nm(self.k, x.wm)) / self.mech.j,
        }
    }

    /// [`StatMachine::deriv`] of the saturated machine ([`SatMachine`]).
    #[inline(always)]
    fn deriv_sat(&self, sat: &SatMachine, x: &StatState, v: C64, turn: C64) -> StatState {
        let (i_s, i_r) = sat.currents(x.i, x.psi);
        let wr = self.np * x.wm;
        let mut ri = i_r * sat.rr;
        if let Some(c) = &self.cage {
            let u = c.u0 * turn;
            ri += (ri + u * ri.conj()) * c.d3;
        }
        let te = 1.5 * self.np * (x.psi * i_r.conj()).im;
        StatState {
            i: v - i_s * self.m.rs,
            psi: C64::new(0.0, wr) * x.psi - ri,
            wm: (te - self.mech.btot * x.wm - self.shaft.extra_nm(self.k, x.wm)) / self.mech.j,
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

    /// The terminal current of the state with the stator voltage `v` (the shorted loop's
    /// current on top of the machine's, [`WindingAsymmetryTerm::loop_current`]).
    #[inline(always)]
    fn terminal(&self, x: &StatState, v: C64) -> C64 {
        let i = self.current(x);
        match &self.wind {
            Some(w) => i + w.loop_current(v),
            None => i,
        }
    }

    /// Classic RK4 over `h` from `t0` into the sample, with the input at the start,
    /// middle and end.
    fn rk4(&self, x: &StatState, h: f64, v: [C64; 3], t0: f64) -> StatState {
        // The unequal cage's turn at the start, the middle and the end (one turn of half
        // the step, squared; none without a cage).
        let one = C64::new(1.0, 0.0);
        let (r0, r_half) = match &self.cage {
            Some(c) if t0 != 0.0 => (
                C64::from_polar(1.0, c.w2 * t0),
                C64::from_polar(1.0, c.w2 * 0.5 * h),
            ),
            Some(c) => (one, C64::from_polar(1.0, c.w2 * 0.5 * h)),
            None => (one, one),
        };
        self.rk4_turning(x, h, v, r0, r_half)
    }

    /// [`StatMachine::rk4`] with the unequal cage's turn at the start `r0` and over half
    /// the step `r_half` given (1 and 1 without a cage).
    #[inline(always)]
    fn rk4_turning(&self, x: &StatState, h: f64, v: [C64; 3], r0: C64, r_half: C64) -> StatState {
        let add = |a: &StatState, b: &StatState, s: f64| StatState {
            i: a.i + b.i * s,
            psi: a.psi + b.psi * s,
            wm: a.wm + b.wm * s,
        };
        let r_mid = r0 * r_half;
        let k1 = self.deriv(x, v[0], r0);
        let k2 = self.deriv(&add(x, &k1, 0.5 * h), v[1], r_mid);
        let k3 = self.deriv(&add(x, &k2, 0.5 * h), v[1], r_mid);
        let k4 = self.deriv(&add(x, &k3, h), v[2], r_mid * r_half);
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
/// with the symbols of `full_order::simulate_full`. Nothing of the machine's dynamics depends on
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
/// [`crate::prep::SUPPLY_STEP_REL`]) is placed where the current says it is:
/// where in the
/// sampling interval it fell changes the interval's volt-seconds by up to `dV dt / 2`
/// (2 % of the current for 0.2 s on the reference motors at 2 kHz), so the interval is
/// integrated with the step at its start and at its end (the old vector turning on
/// before it, the new one after), and the fraction that brings the current at the next
/// sample nearest the measured one (less the model's error at this sample) is used.
///
/// Measured on effect-free simulated logs with a start, a V/f step and a dip, ideal
/// sensors, true parameters (2.2 kW, 11 kW; 2, 5, 10 kHz): `normalized_rms_error`
/// 0.0003-0.0007 (on the simulator's own rows at the log rate, point samples: below 1e-5).
pub(super) fn simulate_stationary(run: ModelRun<'_>, rot_at: impl Fn(usize) -> C64) -> Prediction {
    let volt = StatVoltage::new(run.d, &rot_at, run.t.input_noise);
    simulate_stationary_with(run, rot_at, &volt)
}

/// [`simulate_stationary`] with the voltage input `volt` built beforehand
/// ([`StatVoltage::new`] of the same series, rotations and input noise): it depends on the
/// series alone, so a fit's many runs share it.
pub(super) fn simulate_stationary_with(
    run: ModelRun<'_>,
    rot_at: impl Fn(usize) -> C64,
    volt: &StatVoltage,
) -> Prediction {
    let ModelRun { d, t, .. } = run;
    // With a magnetising law the machine saturates with its own flux ([`SatMachine`]), not
    // with the reduced model's scale from the measured i_f.
    let Some(full) = FullRun::new(run, t.magnetising.law.is_some()) else {
        return Prediction::default();
    };
    let len = d.len();
    let mut out = Prediction::with_capacity(len);
    out.predicts_d_axis = true;
    let form = StatForm { full: &full, volt };
    let (x0, r0) = (full.x0, rot_at(0));
    let mut x = StatState {
        i: C64::new(x0.id, x0.iq) * r0,
        psi: C64::new(x0.pd, x0.pq) * r0,
        wm: x0.wm,
    };
    let mut v = [form.volt.v_at(0), form.volt.v_at(1.min(len - 1))];
    let cage = CageAngle::new(d, t, volt);
    let lm_guess = std::cell::Cell::new(0.0);
    for k in 0..len {
        let sm = form.machine_at(k, cage.at(d, k), &lm_guess, &mut x);
        form.output(&sm, &x, k, rot_at(k), &mut out);
        if k + 1 == len {
            break;
        }
        let v_after = form.volt.v_at((k + 2).min(len - 1));
        x = form.step(&sm, &x, k, v);
        // The measured (positive-sequence) voltages move on; `y V_neg` is added per sample
        // (carrying `v1` over counted it twice at each sample's start).
        v = [v[1], v_after];
        if !(x.i.re.is_finite() && x.i.im.is_finite() && x.psi.re.is_finite() && x.wm.is_finite()) {
            break;
        }
    }
    out
}

/// The stationary-frame model over one run: its set-up and its voltage input.
struct StatForm<'a> {
    full: &'a FullRun<'a>,
    volt: &'a StatVoltage,
}

impl<'a> StatForm<'a> {
    /// The machine at sample `k` with its unequal cage there `cage`. With the terms'
    /// magnetising law it saturates with its own flux ([`SatMachine`], `lm_guess` its last
    /// solve), and at the first sample the state `x`'s linear fluxes become the saturated
    /// machine's.
    fn machine_at<'g>(
        &self,
        k: usize,
        cage: Option<CageOverSample>,
        lm_guess: &'g std::cell::Cell<f64>,
        x: &mut StatState,
    ) -> StatMachine<'g>
    where
        'a: 'g,
    {
        let ModelRun { n, t, .. } = self.full.run;
        let sm = StatMachine {
            m: self.full.machine(k),
            np: n.np,
            mech: self.full.mech,
            shaft: &t.shaft,
            k,
            wind: t.stator_winding,
            cage,
            sat: None,
        };
        match &t.magnetising.law {
            Some(law) => {
                let sat = SatMachine::new(n, &sm.m, law, lm_guess);
                if k == 0 {
                    *x = sat.linear_to_fluxes(&sm.m, x);
                }
                StatMachine {
                    sat: Some(sat),
                    ..sm
                }
            }
            None => sm,
        }
    }
}

impl StatForm<'_> {
    /// The outputs at sample `k`: the terminal current (with the core-loss current, after
    /// the block mean), projected on the analysis frame `rot`.
    fn output(
        &self,
        sm: &StatMachine<'_>,
        x: &StatState,
        k: usize,
        rot: C64,
        out: &mut Prediction,
    ) {
        let ModelRun { d, n, t, .. } = self.full.run;
        // With a negative-sequence voltage drive the negative sequence is in the machine's
        // own current.
        let ineg = match t.negative_sequence.voltage_gain {
            Some(_) => C64::default(),
            None => t
                .negative_sequence
                .current
                .get(k)
                .copied()
                .unwrap_or_default(),
        };
        let mut i_out = sm.terminal(x, self.volt.v_at(k));
        let g = t.magnetising.core_loss_s;
        if g != 0.0 {
            let psi_s = sm.stator_flux(x);
            i_out += C64::new(0.0, g * d.omega_s[k]) * psi_s;
        }
        let i_ab = i_out * self.volt.gains[k] + ineg;
        out.iq.push((i_ab * rot.conj()).im);
        out.omega_r.push(n.np * x.wm);
        out.i_ab.push(i_ab);
    }

    /// The state at sample `k + 1` from `x` at `k`, `v` the positive-sequence voltages
    /// before the block mean at `k` and `k + 1`: RK4 along the rotation, or across a supply
    /// step placed where the measured current says it fell.
    fn step(&self, sm: &StatMachine<'_>, x: &StatState, k: usize, v: [C64; 2]) -> StatState {
        let ModelRun { d, t, .. } = self.full.run;
        let (volt, dt) = (&self.volt, d.dt_s);
        let [v_cur, v_next] = v;
        // The negative sequence (a negative-sequence voltage drive), rotating the other way.
        let (vn0, vn1) = match t.negative_sequence.voltage_gain {
            Some(g) => {
                let at = |j: usize| d.v_neg.get(j).copied().unwrap_or_default();
                (g * at(k), g * at(k + 1))
            }
            None => (C64::default(), C64::default()),
        };
        let (v0, v1) = (v_cur + vn0, v_next + vn1);
        let ph = &volt.ph;
        if volt.dev[k] > volt.step_thr {
            let w = [ph[k - 1] / dt, ph[k + 1] / dt];
            let (s0, s1) = ([v_cur, vn0], [v_next, vn1]);
            let early = sm.across_step(x, dt, 0.0, s0, s1, w);
            let late = sm.across_step(x, dt, 1.0, s0, s1, w);
            // The measured currents before the block mean, as the model's.
            let gain = |k: usize| volt.gains[k];
            let i_meas = |k: usize| d.i_ab[k] - d.i_neg[k];
            let target = i_meas(k + 1) / gain(k + 1) - (i_meas(k) / gain(k) - sm.current(x));
            let (early_i, late_i) = (sm.current(&early), sm.current(&late));
            let span = late_i - early_i;
            let phi = if span.norm_sqr() > 0.0 {
                ((target - early_i) * span.conj()).re / span.norm_sqr()
            } else {
                0.5
            };
            sm.across_step(x, dt, phi.clamp(0.0, 1.0), s0, s1, w)
        } else {
            let half = volt.half[k];
            let vm = (v_cur * half + v_next * half.conj()) * 0.5
                + (vn0 * half.conj() + vn1 * half) * 0.5;
            // A whole working sample: the cage's half turn is the series' own.
            let one = C64::new(1.0, 0.0);
            let r_half = match (&sm.cage, volt.cage_half.get(k)) {
                (Some(_), Some(&r)) => r,
                (Some(c), None) => C64::from_polar(1.0, c.w2 * 0.5 * dt),
                (None, _) => one,
            };
            sm.rk4_turning(x, dt, [v0, vm, v1], one, r_half)
        }
    }
}

/// The angle 2 theta_a + phi of the faulty rotor phase for [`CageOverSample`] (`None`
/// without an unequal cage or without a speed column): Np theta_m integrates the
/// measured electrical speed (trapezoid) from the analysis frame's angle at the first
/// sample, as the reduced model's cage terms do, so that `phi` means the same. Its turn
/// `e^{j (2 theta_a + phi)}` per working sample depends on the series and `phi` alone: the
/// runs of a fit that leave `phi` where it was share it ([`StatVoltage::cage_turns`]).
struct CageAngle {
    /// The unequal cage of the terms.
    p: Option<super::CageAsymmetry>,
    /// `e^{j (2 theta_a + phi)}` at each working sample.
    u: std::sync::Arc<Vec<C64>>,
}

impl CageAngle {
    fn new(d: &Prepared, t: &ModelTerms, volt: &StatVoltage) -> Self {
        let ok = d.omega_r.len() == d.len() && !d.is_empty();
        let p = t.rotor_cage.asymmetry.filter(|_| ok);
        CageAngle {
            u: p.map_or_else(Default::default, |c| volt.cage_turns(d, c.phi_rad)),
            p,
        }
    }

    /// The cage over working sample `k`.
    fn at(&self, d: &Prepared, k: usize) -> Option<CageOverSample> {
        let super::CageAsymmetry { delta, .. } = self.p?;
        let k1 = (k + 1).min(d.len() - 1);
        Some(CageOverSample {
            d3: delta / 3.0,
            u0: self.u[k],
            w2: d.omega_r[k] + d.omega_r[k1],
        })
    }
}

/// `e^{j (2 theta_a + phi)}` at each working sample of `d` ([`CageAngle`]): 2 Np theta_m
/// from twice the frame's first angle, the trapezoid of the measured electrical speed.
fn cage_turns_of(d: &Prepared, phi: f64) -> Vec<C64> {
    let mut th2 = d.theta.first().map_or(0.0, |t| 2.0 * t);
    (0..d.len())
        .map(|k| {
            if k > 0 {
                th2 += d.dt_s * (d.omega_r[k] + d.omega_r[k - 1]);
            }
            C64::from_polar(1.0, th2 + phi)
        })
        .collect()
}
