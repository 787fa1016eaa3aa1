//! The full-order T-equivalent machine the simulator integrates, in the stationary
//! alpha-beta frame (amplitude-invariant Clarke).
//!
//! States x = [psi_s_alpha, psi_s_beta, psi_r_alpha, psi_r_beta, omega_m, theta_m]
//! (flux linkages [Wb], mechanical speed [rad/s], mechanical angle [rad]):
//! ```text
//!   dpsi_s/dt = u,      (1 + Rs/Rfe) u = v_s - Rs i_s   (u = v_s - Rs i_s without iron loss)
//!   dpsi_r/dt  = -Rr i_r + J omega_r psi_r,   J = [[0,-1],[1,0]],  omega_r = Np omega_m
//!   psi_s = Lls i_s + psi_m,  psi_r = Llr i_r + psi_m,  psi_m = Lm (i_s + i_r)
//!   T_e = (3/2) Np (psi_r_beta i_r_alpha - psi_r_alpha i_r_beta)   (= (3/2) Np psi_s x i_s)
//!   J_m domega_m/dt = T_e - B omega_m - T_load(omega_m, t),   dtheta_m/dt = omega_m
//! ```
//! (i_s there is the machine's own stator current: the MMF current i_s' below.)
//! Shorted turns (`phase_asymmetry`; Tallam, Habetler, Harley, "Transient model for induction
//! machines with stator winding turn faults", IEEE Trans. Ind. Appl. 38(3), 2002): a fraction
//! mu of phase k's turns shorted through a fault resistance r_f. The shorted turns stay in
//! the winding and link mu of its flux; the loop carries i_f. With the MMF current
//! i_s' = i_s - (2/3) mu i_f u_k (u_k = (cos th_k, sin th_k), th_k = 0, 2pi/3, 4pi/3 for a, b,
//! c; amplitude-invariant Clarke, isolated neutral) the stator equation is the symmetric
//! machine's, dpsi_s/dt = v_s - Rs i_s', and the loop's (the shorted part's drop
//! mu Rs (i_k - i_f) plus its EMF mu dlambda_k/dt across r_f, with the zero-sequence leakage
//! of the loop's own current) is
//! ```text
//!   (mu Lls/3) di_f/dt = u_k . v_s - R_f i_f,   R_f = Rs (1 - 2mu/3) + r_f/mu
//! ```
//! so the machine's states are those of the healthy machine and the terminals draw
//! i_s = i_s' + (2/3) mu i_f u_k on top ([`TurnLoop`]). The loop dissipates mu R_f i_f^2 and
//! stores mu (mu Lls/3) i_f^2 / 2. Its time constant (tens of microseconds) is as short as a
//! step, so it is integrated exactly, for the supply's sinusoid over each step.
//!
//! Rotor cage asymmetry (`rotor_asymmetry`, broken bars): rotor phase a's resistance is
//! Rr (1 + delta). With the rotor's isolated neutral its resistance in the rotor's own
//! alpha-beta frame is R' = Rr I + (2/3) Rr delta e_a e_a^T (the projection of a one-phase change:
//! C diag(R_k) C^+ = R I + (2/3) sum_k dR_k u_k u_k^T). Turned into the stator frame by the
//! rotor's electrical angle theta_r = Np theta_m, R_r(theta_r) = Rot R' Rot^T =
//! Rr I + (2/3) Rr delta u u^T, u = (cos theta_r, sin theta_r), and the rotor equation is
//! dpsi_r/dt = -R_r(theta_r) i_r + J omega_r psi_r (R_r is symmetric, so the rotational EMF
//! term is unchanged). Rotor copper loss (3/2) i_r^T R_r i_r.

use monitor_laws::{library, BoundLaw, LawInputs, MagnetisingCurve};
use std::cell::Cell;
use std::sync::Arc;

/// Symmetric 2x2 matrix [[a, b], [b, c]].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sym2 {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl Sym2 {
    pub fn scalar(x: f64) -> Self {
        Sym2 { a: x, b: 0.0, c: x }
    }
    /// x I - k u u^T with u = (cos th, sin th).
    pub fn scalar_minus_rank1(x: f64, k: f64, th: f64) -> Self {
        let (s, c) = th.sin_cos();
        Sym2 {
            a: x - k * c * c,
            b: -k * c * s,
            c: x - k * s * s,
        }
    }
    #[inline(always)]
    pub fn mul(&self, v: [f64; 2]) -> [f64; 2] {
        [self.a * v[0] + self.b * v[1], self.b * v[0] + self.c * v[1]]
    }
    /// Quadratic form v^T S v.
    pub fn quad(&self, v: [f64; 2]) -> f64 {
        let w = self.mul(v);
        v[0] * w[0] + v[1] * w[1]
    }
}

/// Main-flux saturation law Lm = lm0 / (1 + (|psi_m| / psi_sat)^n).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatLaw {
    /// Saturation flux psi_sat [Wb].
    pub psi_sat_wb: f64,
    /// Exponent of the saturation law (module docs).
    pub exponent: f64,
}

/// Load torque law (without the machine's own B omega).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadLaw {
    /// Viscous coefficient [N m s/rad].
    pub bl_nms: f64,
    /// Constant torque [N m].
    pub torque_nm: f64,
    /// Coulomb friction torque [N m] and 1/omega_0 [s/rad].
    pub coulomb_nm: f64,
    /// 1/omega_0 of the Coulomb law's tanh [s/rad].
    pub inv_w0: f64,
    /// Windage k [N m s^2/rad^2].
    pub windage: f64,
}

impl LoadLaw {
    /// The load torque [N m] at mechanical speed `wm` [rad/s]: the viscous part, the
    /// constant torque, dry friction and windage, the last two by the library's laws
    /// ([`monitor_laws::library::coulomb_nm`], [`monitor_laws::library::windage_nm`]: the
    /// functions the analysis fits).
    #[inline(always)]
    pub fn torque(&self, wm: f64) -> f64 {
        let mut t = self.bl_nms * wm + self.torque_nm;
        if self.coulomb_nm != 0.0 {
            t += library::coulomb_nm(self.coulomb_nm, 1.0 / self.inv_w0, wm);
        }
        if self.windage != 0.0 {
            t += library::windage_nm(self.windage, wm);
        }
        t
    }
}

/// The magnetising inductance's law: the library's saturation or a user's law of the
/// magnetising flux (an expression, or a no-load test's curve).
#[derive(Debug, Clone)]
pub enum MagLaw {
    /// The library's saturation law ([`SatLaw`], from the machine's unsaturated Lm0).
    Saturation(SatLaw),
    /// A user's law Lm(psi_m) [H] (`acts_on = "magnetising_inductance"`).
    Law(BoundLaw),
    /// A no-load test's curve (`acts_on = "magnetising_curve"`).
    Curve(Arc<MagnetisingCurve>),
}

impl MagLaw {
    /// The largest Lm [H] the law gives over the flux of any machine (0.1 mWb to 50 Wb,
    /// 97 points a decade apart by 1/24), and at least `lm0`: the upper bound of the
    /// saturation iteration. A measured curve rises before it falls (a no-load test's
    /// lowest points carry the friction's in-phase current), so its largest Lm is not the
    /// one at zero flux.
    pub fn largest_lm_h(&self, lm0: f64) -> f64 {
        (0..=24 * 4)
            .map(|k| 1e-4 * 10f64.powf(f64::from(k) / 24.0) * 5.0)
            .chain([0.0])
            .map(|psi| self.lm_h(lm0, psi))
            .filter(|l| l.is_finite() && *l > 0.0)
            .fold(lm0, f64::max)
            * 1.01
    }

    /// Lm [H] at the magnetising flux `psi_m` [Wb, peak] for a machine whose unsaturated
    /// Lm is `lm0` [H] (read by the library's law only).
    #[inline(always)]
    pub fn lm_h(&self, lm0: f64, psi_m: f64) -> f64 {
        match self {
            MagLaw::Saturation(s) => library::saturation_lm_h(lm0, s.psi_sat_wb, s.exponent, psi_m),
            MagLaw::Law(b) => b.eval(&LawInputs {
                psi_m_wb: psi_m,
                ..LawInputs::default()
            }),
            MagLaw::Curve(c) => c.lm_h(psi_m),
        }
    }
}

/// The shorted loop of an inter-turn fault (module docs): a fraction `mu` of one phase's
/// turns through a fault resistance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnLoop {
    /// Unit vector u_k of the faulty phase's axis.
    pub u: [f64; 2],
    /// Fraction mu of the phase's turns shorted (0..0.5].
    pub mu: f64,
    /// Loop resistance R_f = Rs (1 - 2mu/3) + r_f/mu [ohm] (per unit of mu^2 of the loop).
    pub r: f64,
    /// Loop inductance mu Lls / 3 [H] (same scaling).
    pub l: f64,
}

impl TurnLoop {
    /// The loop of `mu` of phase `phase` (0, 1, 2 for a, b, c) through `r_f_ohm`, with the
    /// healthy winding's `rs` [ohm] and leakage `lls` [H].
    pub fn new(phase: usize, mu: f64, r_f_ohm: f64, rs: f64, lls: f64) -> Self {
        let th = phase as f64 * 2.0 * std::f64::consts::PI / 3.0;
        TurnLoop {
            u: [th.cos(), th.sin()],
            mu,
            r: rs * (1.0 - 2.0 * mu / 3.0) + r_f_ohm / mu,
            l: mu * lls / 3.0,
        }
    }

    /// The loop's voltage `u.v` over a step, from its values `p0`, `p1` at the step's ends:
    /// a sinusoid at the supply's `we` [rad/s] (both sequences project onto the phase at
    /// `we`), `p(t) = Re(P e^{j we t})`, `P = p0 - j p'(0)/we`; `None` where `we h` is too
    /// small to tell the slope (then the voltage is taken linear).
    fn phasor(p0: f64, p1: f64, we: f64, h: f64) -> Option<(f64, f64)> {
        let (s, c) = (we * h).sin_cos();
        (s.abs() > 1e-9).then(|| (p0, -(p1 - p0 * c) / s))
    }

    /// The forced currents at the step's start and end: `Re(P e^{j we t} / (r + j we l))`,
    /// or, for a linear voltage, `(p - tau p')/r`.
    fn forced_ends(&self, p0: f64, p1: f64, we: f64, h: f64) -> (f64, f64) {
        match Self::phasor(p0, p1, we, h) {
            Some((pr, pi)) => {
                let (zr, zi) = (self.r, we * self.l);
                let d = zr * zr + zi * zi;
                // P / Z, then turned by we h.
                let (qr, qi) = ((pr * zr + pi * zi) / d, (pi * zr - pr * zi) / d);
                let (s, c) = (we * h).sin_cos();
                (qr, qr * c - qi * s)
            }
            None => {
                let slope = (p1 - p0) / h;
                let tau = self.l / self.r;
                ((p0 - tau * slope) / self.r, (p1 - tau * slope) / self.r)
            }
        }
    }

    /// The loop current after `h` [s] from `i_f` [A] with the supply going from `v0` to
    /// `v1` (alpha-beta) at `we` [rad/s] over the step: the exact solution of
    /// `l di/dt = u.v(t) - r i` for a sinusoidal `u.v`, `i(t) = forced(t) + c e^{-t/tau}`,
    /// `tau = l/r`.
    #[inline(always)]
    pub fn step(&self, i_f: f64, v0: [f64; 2], v1: [f64; 2], we: f64, h: f64) -> f64 {
        let p = |v: [f64; 2]| self.u[0] * v[0] + self.u[1] * v[1];
        let (p0, p1) = (p(v0), p(v1));
        if self.l <= 0.0 {
            return p1 / self.r;
        }
        let (f0, f1) = self.forced_ends(p0, p1, we, h);
        f1 + (i_f - f0) * (-h * self.r / self.l).exp()
    }

    /// The loop's forced current at the start of a step from `v0` to `v1` (its own
    /// transient, tens of microseconds, left out): where a run starts the loop.
    pub fn forced(&self, v0: [f64; 2], v1: [f64; 2], we: f64, h: f64) -> f64 {
        let p = |v: [f64; 2]| self.u[0] * v[0] + self.u[1] * v[1];
        if self.l <= 0.0 {
            return p(v0) / self.r;
        }
        self.forced_ends(p(v0), p(v1), we, h).0
    }

    /// What the terminals draw on top of the machine, (2/3) mu i_f u_k [A].
    #[inline(always)]
    pub fn terminal(&self, i_f: f64) -> [f64; 2] {
        let k = 2.0 / 3.0 * self.mu * i_f;
        [k * self.u[0], k * self.u[1]]
    }

    /// Power the loop dissipates at `i_f`, mu R_f i_f^2 [W].
    pub fn loss_w(&self, i_f: f64) -> f64 {
        self.mu * self.r * i_f * i_f
    }

    /// Energy the loop's leakage stores at `i_f`, mu l i_f^2 / 2 [J].
    pub fn stored_j(&self, i_f: f64) -> f64 {
        0.5 * self.mu * self.l * i_f * i_f
    }
}

/// Everything the derivative needs, precomputed (rebuilt when a parameter changes).
#[derive(Debug, Clone)]
pub struct Machine {
    /// Stator resistance of the healthy phases [ohm].
    pub rs: f64,
    /// The shorted loop of a turn fault, if any.
    pub turn: Option<TurnLoop>,
    /// Stator leakage inductance [H].
    pub lls: f64,
    /// Rotor leakage inductance [H].
    pub llr: f64,
    /// Rotor resistance, stator-referred [ohm].
    pub rr: f64,
    /// Rotor cage asymmetry (2/3) Rr delta [ohm] (0: symmetric cage).
    pub rr_asym: f64,
    /// Unsaturated (or constant) magnetising inductance [H].
    pub lm0: f64,
    /// Main-flux saturation, if any.
    pub sat: Option<MagLaw>,
    /// 1/Rfe [S], 0 without iron loss, and 1/(1 + Rs/Rfe).
    pub inv_rfe: f64,
    /// 1/(1 + Rs/Rfe) (1 without iron loss).
    pub k_fe: f64,
    /// Pole pairs.
    pub np: f64,
    /// 1/J [1/(kg m^2)].
    pub inv_j: f64,
    /// The machine's own viscous friction B [N m s/rad].
    pub b: f64,
    /// The load's torque law.
    pub load: LoadLaw,
    /// Users' load-torque laws of time, speed and the shaft's angle, added to `load`'s.
    pub load_laws: Arc<[BoundLaw]>,
    /// The largest Lm the magnetising law gives (at zero flux) or Lm0 [H]: the bound of the
    /// saturation iteration.
    lm_hi: f64,
    // Linear-case derived constants.
    minv: f64,
    kr: f64,
    inv_lr: f64,
    /// Warm start of the saturation iteration.
    lm_guess: Cell<f64>,
}

/// Currents and magnetising inductance at a state.
#[derive(Debug, Clone, Copy)]
pub struct Currents {
    /// The machine's stator current (the winding's MMF current i_s') [A].
    pub i_s: [f64; 2],
    /// Rotor current [A].
    pub i_r: [f64; 2],
    /// Magnetising inductance in effect [H].
    pub lm: f64,
}

/// A machine the simulator cannot integrate (the scenario's key is named by the caller,
/// [`super::SimError::Invalid`]).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MachineError {
    /// The stator/rotor inductance matrix is not positive definite.
    #[error("the inductance matrix is not positive definite (Lls = {lls_h} H, Lm = {lm_h} H, Llr = {llr_h} H)")]
    Inductances {
        /// Stator leakage [H].
        lls_h: f64,
        /// Magnetising inductance [H].
        lm_h: f64,
        /// Rotor leakage [H].
        llr_h: f64,
    },
    /// A shorted-turn loop whose fault resistance is not positive.
    #[error("the shorted loop's resistance must be positive (R_f = {r_f_ohm} ohm)")]
    ShortedLoop {
        /// The fault resistance [ohm].
        r_f_ohm: f64,
    },
}

impl Machine {
    /// Builds the model; `Err` names what is not physical.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rs: f64,
        turn: Option<TurnLoop>,
        lls: f64,
        llr: f64,
        rr: f64,
        lm0: f64,
        sat: Option<MagLaw>,
        rfe: Option<f64>,
        np: f64,
        j: f64,
        b: f64,
        load: LoadLaw,
    ) -> Result<Machine, MachineError> {
        let (minv, kr, inv_lr) = Self::linear(lls, llr, lm0)?;
        if let Some(t) = &turn {
            if !(t.r > 0.0 && t.r.is_finite() && t.l >= 0.0) {
                return Err(MachineError::ShortedLoop { r_f_ohm: t.r });
            }
        }
        let inv_rfe = rfe.map(|r| 1.0 / r).unwrap_or(0.0);
        let lm_hi = match &sat {
            Some(law @ (MagLaw::Law(_) | MagLaw::Curve(_))) => law.largest_lm_h(lm0),
            _ => lm0,
        };
        Ok(Machine {
            rs,
            turn,
            lls,
            llr,
            rr,
            rr_asym: 0.0,
            lm0,
            sat,
            inv_rfe,
            k_fe: 1.0 / (1.0 + rs * inv_rfe),
            np,
            inv_j: 1.0 / j,
            b,
            load,
            load_laws: Arc::from(Vec::new()),
            lm_hi,
            minv,
            kr,
            inv_lr,
            lm_guess: Cell::new(lm0),
        })
    }

    fn linear(lls: f64, llr: f64, lm: f64) -> Result<(f64, f64, f64), MachineError> {
        let lr = llr + lm;
        let m = lls + lm * llr / lr;
        if !(m > 0.0 && lr > 0.0 && lm > 0.0 && lls >= 0.0) {
            return Err(MachineError::Inductances {
                lls_h: lls,
                lm_h: lm,
                llr_h: llr,
            });
        }
        Ok((1.0 / m, lm / lr, 1.0 / lr))
    }

    /// Carries the saturation warm start over from a previous model.
    pub fn take_guess(&self, other: &Machine) {
        self.lm_guess.set(other.lm_guess.get());
    }

    #[inline(always)]
    fn currents_lin(&self, ps: [f64; 2], pr: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let is = [
            (ps[0] - self.kr * pr[0]) * self.minv,
            (ps[1] - self.kr * pr[1]) * self.minv,
        ];
        let ir = [
            (pr[0] - self.lm0 * is[0]) * self.inv_lr,
            (pr[1] - self.lm0 * is[1]) * self.inv_lr,
        ];
        (is, ir)
    }

    fn currents_at_lm(&self, ps: [f64; 2], pr: [f64; 2], lm: f64) -> ([f64; 2], [f64; 2], f64) {
        let lr = self.llr + lm;
        let minv = 1.0 / (self.lls + lm * self.llr / lr);
        let kr = lm / lr;
        let is = [(ps[0] - kr * pr[0]) * minv, (ps[1] - kr * pr[1]) * minv];
        let ir = [(pr[0] - lm * is[0]) / lr, (pr[1] - lm * is[1]) / lr];
        let psi_m = lm * (is[0] + ir[0]).hypot(is[1] + ir[1]);
        (is, ir, psi_m)
    }

    /// Currents from flux linkages (exact solution of the saturation law when enabled:
    /// secant iteration on Lm to 1e-13 relative).
    #[inline(always)]
    pub fn currents(&self, ps: [f64; 2], pr: [f64; 2]) -> Currents {
        let Some(sat) = &self.sat else {
            let (i_s, i_r) = self.currents_lin(ps, pr);
            return Currents {
                i_s,
                i_r,
                lm: self.lm0,
            };
        };
        let law = |psi_m: f64| sat.lm_h(self.lm0, psi_m);
        let hi = self.lm_hi;
        let lo = 1e-3 * hi;
        let tol = 1e-13 * hi;
        let g = |lm: f64| {
            let (_, _, pm) = self.currents_at_lm(ps, pr, lm);
            lm - law(pm)
        };
        let mut x0 = self.lm_guess.get().clamp(lo, hi);
        let mut g0 = g(x0);
        let mut x1 = (x0 - g0).clamp(lo, hi);
        if g0.abs() > tol {
            for _ in 0..60 {
                let g1 = g(x1);
                if g1.abs() <= tol || g1 == g0 {
                    break;
                }
                let x2 = (x1 - g1 * (x1 - x0) / (g1 - g0)).clamp(lo, hi);
                x0 = x1;
                g0 = g1;
                x1 = x2;
            }
        } else {
            x1 = x0;
        }
        self.lm_guess.set(x1);
        let (i_s, i_r, _) = self.currents_at_lm(ps, pr, x1);
        Currents { i_s, i_r, lm: x1 }
    }

    /// Voltage behind Rs (= dpsi_s/dt) for supply voltage `v` and the machine's current `i_s`.
    #[inline(always)]
    pub fn u(&self, v: [f64; 2], i_s: [f64; 2]) -> [f64; 2] {
        let e = [v[0] - self.rs * i_s[0], v[1] - self.rs * i_s[1]];
        if self.inv_rfe == 0.0 {
            e
        } else {
            [self.k_fe * e[0], self.k_fe * e[1]]
        }
    }

    /// Rotor resistance matrix R_r(theta_r) at mechanical angle `theta_m` [rad] (scalar Rr
    /// for a symmetric cage).
    #[inline(always)]
    pub(crate) fn rotor_r(&self, theta_m: f64) -> Sym2 {
        if self.rr_asym == 0.0 {
            Sym2::scalar(self.rr)
        } else {
            Sym2::scalar_minus_rank1(self.rr, -self.rr_asym, self.np * theta_m)
        }
    }

    /// Electromagnetic torque [N m].
    #[inline(always)]
    pub fn torque(&self, pr: [f64; 2], ir: [f64; 2]) -> f64 {
        1.5 * self.np * (pr[1] * ir[0] - pr[0] * ir[1])
    }

    /// The load torque [N m] at time `t` [s], mechanical speed `wm` [rad/s] and shaft angle
    /// `theta_m` [rad]: [`LoadLaw::torque`] plus the users' laws ([`Machine::load_laws`]).
    #[inline(always)]
    pub fn load_torque(&self, t: f64, wm: f64, theta_m: f64) -> f64 {
        let mut tl = self.load.torque(wm);
        if !self.load_laws.is_empty() {
            let x = LawInputs {
                t_s: t,
                w_rad_s: wm,
                theta_rad: theta_m,
                psi_m_wb: 0.0,
            };
            for l in self.load_laws.iter() {
                tl += l.eval(&x);
            }
        }
        tl
    }

    /// dx/dt at time `t` [s] and state `x` with supply voltage `v` (alpha-beta, V).
    #[inline(always)]
    pub fn deriv(&self, t: f64, x: &[f64; 6], v: [f64; 2]) -> [f64; 6] {
        let ps = [x[0], x[1]];
        let pr = [x[2], x[3]];
        let wm = x[4];
        let c = self.currents(ps, pr);
        let u = self.u(v, c.i_s);
        let wr = self.np * wm;
        let te = self.torque(pr, c.i_r);
        let tl = self.load_torque(t, wm, x[5]);
        let rdrop = if self.rr_asym == 0.0 {
            [self.rr * c.i_r[0], self.rr * c.i_r[1]]
        } else {
            self.rotor_r(x[5]).mul(c.i_r)
        };
        [
            u[0],
            u[1],
            -rdrop[0] - wr * pr[1],
            -rdrop[1] + wr * pr[0],
            (te - self.b * wm - tl) * self.inv_j,
            wm,
        ]
    }

    /// One classic RK4 step of length `h` from time `t` [s] with the supply at the start,
    /// middle and end.
    #[inline(always)]
    pub fn rk4(&self, x: &mut [f64; 6], t: f64, h: f64, v0: [f64; 2], vm: [f64; 2], v1: [f64; 2]) {
        let k1 = self.deriv(t, x, v0);
        let mut y = [0.0; 6];
        let h2 = 0.5 * h;
        for i in 0..6 {
            y[i] = x[i] + h2 * k1[i];
        }
        let k2 = self.deriv(t + h2, &y, vm);
        for i in 0..6 {
            y[i] = x[i] + h2 * k2[i];
        }
        let k3 = self.deriv(t + h2, &y, vm);
        for i in 0..6 {
            y[i] = x[i] + h * k3[i];
        }
        let k4 = self.deriv(t + h, &y, v1);
        let h6 = h / 6.0;
        for i in 0..6 {
            x[i] += h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
    }
}
