//! An independent textbook induction machine for the ladder tests, written from scratch
//! (it shares no code with `monitor-sim`: the point is a second, independent model).
//!
//! # The model
//! Krause, Wasynczuk and Sudhoff, "Analysis of Electric Machinery", the fifth-order model
//! of the symmetrical induction machine in the stationary reference frame, with flux
//! linkages as states. Space vectors are amplitude invariant,
//! `x = (2/3) (x_a + a x_b + a^2 x_c)`, `a = exp(j 2 pi / 3)`, so `x_alpha = x_a` when the
//! zero sequence is zero (a star winding with a floating neutral). Rotor quantities are
//! referred to the stator.
//! ```text
//! d psi_s / dt = v_s - R_s i_s
//! d psi_r / dt = -R_r i_r + j w_r psi_r            w_r = (poles / 2) w_m  (electrical)
//! psi_s = L_ls i_s + psi_m,  psi_r = L_lr i_r + psi_m,  psi_m = L_m (i_s + i_r)
//! T_e   = 1.5 (poles / 2) (psi_s x i_s) = 1.5 (poles / 2) (psi_sa i_sb - psi_sb i_sa)
//! J d w_m / dt = T_e - T_load - B w_m - T_friction - T_windage
//! ```
//! Integrated with the classical fourth-order Runge-Kutta method at a fixed inner step
//! ([`Scenario::step_s`], 20-50 us), logged every `1 / rate_hz` with sensor noise and
//! 12-bit quantisation ([`Sensors`]).
//!
//! # Hidden effects ([`Hidden`]), each switchable, several at once
//! * `thermal_drift`: `R(t) = R_0 (1 + 0.00393 dT (1 - exp(-t / tau)))` for `R_s` and
//!   `R_r` (copper, a heat run with an accelerated time constant).
//! * `coulomb_friction`: `T_c tanh(w_m / 1 rad/s)` (dry friction, smoothed near standstill).
//! * `windage`: `k w_m |w_m|`.
//! * `supply_unbalance`: a negative-sequence voltage `u V exp(-j theta)` on top of the
//!   positive sequence `V exp(j theta)`.
//! * `load_torque`: the load as a torque with steps ([`Load::Torque`]) instead of the
//!   paper's viscous `B_l w_m`.
//! * `saturation`: `L_m(|psi_m|) = L_m0 / (1 + (|psi_m| / psi_sat)^6)`; the currents are
//!   solved from the fluxes with the magnetising flux's scalar equation (Newton).
//! * `phase_asymmetry`: phase a's resistance `R_s + dR`. With the floating star point the
//!   extra drop `dR i_a` on phase a enters the space-vector equation as its
//!   amplitude-invariant transform `(2/3) dR i_a` along alpha (its zero-sequence third is
//!   taken up by the star point's shift).
//! * `rotor_asymmetry`: a rotor cage asymmetry, rotor phase a's resistance `R_r (1 + delta)`
//!   (broken bars: [`broken_bars_delta`]). In the rotor's own two-axis frame (amplitude
//!   invariant Clarke of the three rotor phases, star-connected with no zero sequence) the
//!   extra drop `dR i_ra` on rotor phase a, `dR = delta R_r`, transforms like the stator's:
//!   `(2/3) dR i_ra` along the rotor's a axis, and `i_ra = e . i_r` with `e` that axis's unit
//!   vector; the resistance matrix is `R_r I + (2/3) dR e e^T`. Rotated into the stationary
//!   frame (rotation keeps the form, `e e^T -> e' e'^T`), `e = (cos theta_r, sin theta_r)`
//!   with `theta_r = int w_r dt` the electrical rotor angle (the state's last element):
//!   ```text
//!   d psi_r / dt = -R_r i_r - (2/3) dR (e . i_r) e + j w_r psi_r
//!   ```
//!   The extra rotor copper loss is `1.5 (2/3) dR (e . i_r)^2 = dR i_ra^2`, phase a's own.
//!   Seen from the stator, the asymmetric rotor field has a backward component at
//!   `-s f` in rotor coordinates, i.e. `(1 - 2 s) f` in the stator: the classic sideband.
//!   Sized as `n` adjacent broken bars of an `N`-bar cage with the usual approximation
//!   `delta = 3 n / (N - 3 n)` (the project's `monitor-sim` uses it too; this module only
//!   shares the formula).
//!
//! The energy the model stores is `W = 1.5 (L_ls |i_s|^2 / 2 + L_lr |i_r|^2 / 2 +
//! int_0^|psi_m| i_m(psi) d psi)` plus `J w_m^2 / 2`; `textbook_machine_physics.rs` checks
//! that input power = copper losses + mechanical losses/output + dW/dt.
#![allow(dead_code, missing_docs)]

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod log;
pub use log::*;

/// Copper's temperature coefficient of resistance [1/K].
pub const ALPHA_CU: f64 = 0.00393;

/// A machine: the T-equivalent circuit's values, the mechanics and the rated supply.
#[derive(Clone, Copy, Debug)]
pub struct Machine {
    pub name: &'static str,
    pub rs: f64,
    pub rr: f64,
    /// Stator and rotor leakage and magnetising inductances [H].
    pub lls: f64,
    pub llr: f64,
    pub lm: f64,
    pub poles: u32,
    pub j: f64,
    /// Bearing friction [N m s].
    pub b: f64,
    /// The viscous load's coefficient [N m s] when the load is the paper's `B_l w_m`.
    pub bl: f64,
    pub v_ll_rms: f64,
    pub f_hz: f64,
    /// Rated torque [N m].
    pub rated_nm: f64,
}

impl Machine {
    /// The 2.2 kW machine: 400 V, 50 Hz, 4 poles, Gamma model (no stator leakage).
    pub fn kw2p2() -> Self {
        Self {
            name: "2.2kW",
            rs: 3.7,
            rr: 2.5,
            lls: 0.0,
            llr: 0.268 - 0.245,
            lm: 0.245,
            poles: 4,
            j: 0.015,
            b: 0.005,
            bl: 14.6 / 149.7,
            v_ll_rms: 400.0,
            f_hz: 50.0,
            rated_nm: 14.6,
        }
    }

    /// Krause's 3 hp machine: 220 V, 60 Hz, 4 poles, Xls = Xlr = 0.754, Xm = 26.13 ohm.
    pub fn hp3() -> Self {
        let w = 2.0 * PI * 60.0;
        Self {
            name: "3hp",
            rs: 0.435,
            rr: 0.816,
            lls: 0.754 / w,
            llr: 0.754 / w,
            lm: 26.13 / w,
            poles: 4,
            j: 0.089,
            b: 0.002,
            // 12 N m at about 1710 rpm.
            bl: 12.0 / 179.0,
            v_ll_rms: 220.0,
            f_hz: 60.0,
            rated_nm: 12.0,
        }
    }

    /// Krause's 50 hp machine: 460 V, 60 Hz, 4 poles, Xls = Xlr = 0.302, Xm = 13.08 ohm.
    pub fn hp50() -> Self {
        let w = 2.0 * PI * 60.0;
        Self {
            name: "50hp",
            rs: 0.087,
            rr: 0.228,
            lls: 0.302 / w,
            llr: 0.302 / w,
            lm: 13.08 / w,
            poles: 4,
            j: 1.662,
            b: 0.02,
            // 198 N m at about 1770 rpm.
            bl: 198.0 / 185.4,
            v_ll_rms: 460.0,
            f_hz: 60.0,
            rated_nm: 198.0,
        }
    }

    pub fn pp(&self) -> f64 {
        f64::from(self.poles) / 2.0
    }

    /// Peak phase voltage at rated supply [V].
    pub fn v_peak(&self) -> f64 {
        self.v_ll_rms * (2.0f64 / 3.0).sqrt()
    }

    /// Synchronous mechanical speed at rated frequency [rad/s].
    pub fn w_sync(&self) -> f64 {
        2.0 * PI * self.f_hz / self.pp()
    }

    /// Rated magnetising flux amplitude [Wb] (about V / w_e).
    pub fn psi_rated(&self) -> f64 {
        self.v_peak() / (2.0 * PI * self.f_hz)
    }

    /// The parameter file (docs/design.md format) with this machine's true values (its Lm
    /// the unsaturated one, `lm_at = "unsaturated"`: a saturating machine's law starts there);
    /// `bl_nms` is `bl` (0 for a torque load), every electrical and mechanical value
    /// scaled by `1 + off` with alternating signs when `off` is not 0.
    pub fn params_toml(&self, bl: f64, off: f64) -> String {
        let (up, dn) = (1.0 + off, 1.0 - off);
        let lm = self.lm * up;
        let ls = lm + self.lls * dn;
        let lr = lm + self.llr * up;
        format!(
            "# Textbook machine {} (crates/monitor-testkit/src/textbook_machine)\n[motor]\nrs_ohm = {}\n\
             rr_ohm = {}\nls_h = {}\nlr_h = {}\nlm_h = {}\nlm_at = \"unsaturated\"\npoles = {}\nj_kgm2 = {}\n\
             b_nms = {}\nbl_nms = {}\n\n[supply]\nv_ll_rms = {}\nf_hz = {}\n",
            self.name,
            self.rs * up,
            self.rr * dn,
            ls,
            lr,
            lm,
            self.poles,
            self.j * dn,
            self.b * up,
            bl * dn,
            self.v_ll_rms,
            self.f_hz
        )
    }
}

/// The load on the shaft.
#[derive(Clone, Debug)]
pub enum Load {
    /// The paper's viscous load `B_l w_m` [N m s].
    Viscous(f64),
    /// A torque [N m] from t = 0 and steps `(t_s, torque)`, smoothed near standstill so
    /// the machine is not driven backwards before it moves.
    Torque { t0: f64, steps: Vec<(f64, f64)> },
}

/// Switchable hidden effects (all off by default).
#[derive(Clone, Debug, Default)]
pub struct Hidden {
    /// (temperature rise [K], time constant [s]).
    pub thermal_drift: Option<(f64, f64)>,
    /// Dry friction torque [N m].
    pub coulomb_friction: Option<f64>,
    /// Windage coefficient k [N m s^2].
    pub windage: Option<f64>,
    /// Negative-sequence voltage as a fraction of the positive sequence.
    pub supply_unbalance: Option<f64>,
    /// `psi_sat` [Wb] of `L_m(psi) = L_m0 / (1 + (psi / psi_sat)^6)`.
    pub saturation: Option<f64>,
    /// Extra resistance of stator phase a [ohm].
    pub phase_asymmetry: Option<f64>,
    /// Rotor phase a's resistance raised to `R_r (1 + delta)`: `delta` (relative).
    pub rotor_asymmetry: Option<f64>,
}

/// The rotor asymmetry `delta = 3 n / (N - 3 n)` of `n` adjacent broken bars of an `N`-bar
/// cage, and back: `n = delta N / (3 (1 + delta))`.
pub fn broken_bars_delta(n: f64, bars: f64) -> f64 {
    3.0 * n / (bars - 3.0 * n)
}

/// The number of adjacent broken bars of an `N`-bar cage for an asymmetry `delta`.
pub fn broken_bars_of(delta: f64, bars: f64) -> f64 {
    delta * bars / (3.0 * (1.0 + delta))
}

/// The supply: a piecewise-linear profile of (t [s], voltage scale, frequency scale);
/// two points at the same time are a step. Before the first point and after the last the
/// profile is constant.
#[derive(Clone, Debug)]
pub struct Supply {
    pub points: Vec<(f64, f64, f64)>,
}

impl Supply {
    pub fn rated() -> Self {
        Self {
            points: vec![(0.0, 1.0, 1.0)],
        }
    }

    /// (voltage scale, frequency scale) at `t`.
    pub fn at(&self, t: f64) -> (f64, f64) {
        let p = &self.points;
        if t < p[0].0 {
            return (p[0].1, p[0].2);
        }
        for w in p.windows(2) {
            let (a, b) = (w[0], w[1]);
            if t >= a.0 && t < b.0 {
                let x = (t - a.0) / (b.0 - a.0);
                return (a.1 + x * (b.1 - a.1), a.2 + x * (b.2 - a.2));
            }
        }
        let l = p[p.len() - 1];
        (l.1, l.2)
    }
}

/// The sensor chain: Gaussian noise of `noise` times each channel's full scale, then a
/// `bits`-bit converter over +/- full scale.
#[derive(Clone, Copy, Debug)]
pub struct Sensors {
    pub noise: f64,
    pub bits: u32,
    pub seed: u64,
}

impl Default for Sensors {
    fn default() -> Self {
        Self {
            noise: 0.001,
            bits: 12,
            seed: 1,
        }
    }
}

/// One run: the machine starts from standstill with zero flux and is switched direct on
/// line at t = 0.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub duration_s: f64,
    pub rate_hz: f64,
    /// RK4 inner step [s].
    pub step_s: f64,
    pub supply: Supply,
    pub load: Load,
    pub hidden: Hidden,
    pub sensors: Sensors,
    /// Hold the shaft at this speed [rad/s] (an ideal dynamometer; for the steady-state
    /// checks) instead of integrating the mechanics.
    pub hold_speed: Option<f64>,
}

impl Scenario {
    pub fn new(m: &Machine, duration_s: f64, rate_hz: f64) -> Self {
        Self {
            duration_s,
            rate_hz,
            step_s: 25e-6,
            supply: Supply::rated(),
            load: Load::Viscous(m.bl),
            hidden: Hidden::default(),
            sensors: Sensors::default(),
            hold_speed: None,
        }
    }
}

/// The state: psi_s (alpha, beta), psi_r (alpha, beta), w_m, the supply angle theta,
/// three energy integrals (input, copper losses, mechanical output incl. friction) and the
/// electrical rotor angle theta_r (used by `rotor_asymmetry` only).
pub type State = [f64; 10];

/// Everything derived from a state at a time.
#[derive(Clone, Copy, Debug, Default)]
pub struct Point {
    pub v: [f64; 2],
    pub is: [f64; 2],
    pub ir: [f64; 2],
    pub psi_m: [f64; 2],
    pub te: f64,
    /// Torque on the shaft other than T_e (load + bearing + friction + windage) [N m].
    pub t_out: f64,
    pub p_in: f64,
    pub p_cu: f64,
    /// Magnetic energy stored [J].
    pub w_mag: f64,
    pub rs: f64,
    pub rr: f64,
    /// The rotor asymmetry's extra drop `(2/3) dR (e . i_r) e` (zero without it).
    pub rotor_drop: [f64; 2],
}

/// The model's right-hand side.
pub struct Model<'a> {
    pub m: &'a Machine,
    pub s: &'a Scenario,
}

impl Model<'_> {
    fn lm_of(&self, psi: f64) -> f64 {
        match self.s.hidden.saturation {
            Some(ps) => self.m.lm / (1.0 + (psi / ps).powi(6)),
            None => self.m.lm,
        }
    }

    /// Magnetising current for a magnetising flux magnitude, and the energy
    /// `int_0^psi i_m d psi` (per unit of the 1.5 factor).
    fn im_energy(&self, psi: f64) -> (f64, f64) {
        match self.s.hidden.saturation {
            Some(ps) => (
                psi * (1.0 + (psi / ps).powi(6)) / self.m.lm,
                (psi * psi / 2.0 + psi.powi(8) / (8.0 * ps.powi(6))) / self.m.lm,
            ),
            None => (psi / self.m.lm, psi * psi / (2.0 * self.m.lm)),
        }
    }

    /// Currents and magnetising flux from the flux linkages.
    pub fn currents(&self, x: &State) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let (lls, llr) = (self.m.lls, self.m.llr);
        let ps = [x[0], x[1]];
        let pr = [x[2], x[3]];
        let psi_m = if lls <= 0.0 {
            // Gamma model: the stator flux is the magnetising flux.
            ps
        } else {
            // psi_m is parallel to a = psi_s / L_ls + psi_r / L_lr, its magnitude solves
            // g(p) = p (1 / L_m(p) + 1 / L_ls + 1 / L_lr) = |a| (g convex and increasing:
            // Newton from the unsaturated solution, which lies above, converges).
            let a = [ps[0] / lls + pr[0] / llr, ps[1] / lls + pr[1] / llr];
            let an = a[0].hypot(a[1]);
            if an == 0.0 {
                [0.0, 0.0]
            } else {
                let k = 1.0 / lls + 1.0 / llr;
                let mut p = an / (1.0 / self.m.lm + k);
                if let Some(sat) = self.s.hidden.saturation {
                    for _ in 0..50 {
                        let r = (p / sat).powi(6);
                        let g = p * (1.0 + r) / self.m.lm + p * k - an;
                        let dg = (1.0 + 7.0 * r) / self.m.lm + k;
                        let dp = g / dg;
                        p -= dp;
                        if dp.abs() <= 1e-13 * p.max(1e-9) {
                            break;
                        }
                    }
                }
                [a[0] * p / an, a[1] * p / an]
            }
        };
        let pmn = psi_m[0].hypot(psi_m[1]);
        let im = if pmn > 0.0 {
            let (i, _) = self.im_energy(pmn);
            [psi_m[0] * i / pmn, psi_m[1] * i / pmn]
        } else {
            [0.0, 0.0]
        };
        let ir = [(pr[0] - psi_m[0]) / llr, (pr[1] - psi_m[1]) / llr];
        let is = if lls <= 0.0 {
            [im[0] - ir[0], im[1] - ir[1]]
        } else {
            [(ps[0] - psi_m[0]) / lls, (ps[1] - psi_m[1]) / lls]
        };
        (is, ir, psi_m)
    }

    /// Supply voltage space vector at `t` with supply angle `theta`.
    pub fn voltage(&self, t: f64, theta: f64) -> [f64; 2] {
        let (vs, _) = self.s.supply.at(t);
        let v = vs * self.m.v_peak();
        let u = self.s.hidden.supply_unbalance.unwrap_or(0.0);
        [
            v * (theta.cos() + u * theta.cos()),
            v * (theta.sin() - u * theta.sin()),
        ]
    }

    pub fn load_torque(&self, t: f64, w: f64) -> f64 {
        match &self.s.load {
            Load::Viscous(bl) => bl * w,
            Load::Torque { t0, steps } => {
                let mut tl = *t0;
                for &(ts, v) in steps {
                    if t >= ts {
                        tl = v;
                    }
                }
                // A torque load does not drive the shaft backwards: it builds up over the
                // first few rad/s (a pump's or conveyor's breakaway).
                tl * (w / 2.0).tanh()
            }
        }
    }

    /// The rotor asymmetry's extra drop `(2/3) dR (e . i_r) e` and its copper loss, written
    /// as rotor phase a's own `dR i_ra^2` (`i_ra = e . i_r`), not from the drop, so that the
    /// energy balance checks the drop's `2/3` and sign (both zero without it).
    fn rotor_drop(&self, x: &State, ir: [f64; 2], rr: f64) -> ([f64; 2], f64) {
        let Some(delta) = self.s.hidden.rotor_asymmetry else {
            return ([0.0, 0.0], 0.0);
        };
        let dr = delta * rr;
        let e = [x[9].cos(), x[9].sin()];
        let ira = e[0] * ir[0] + e[1] * ir[1];
        let k = 2.0 / 3.0 * dr * ira;
        ([k * e[0], k * e[1]], dr * ira * ira)
    }

    pub fn point(&self, t: f64, x: &State) -> Point {
        let m = self.m;
        let h = &self.s.hidden;
        let heat = match h.thermal_drift {
            Some((dt, tau)) => 1.0 + ALPHA_CU * dt * (1.0 - (-t / tau).exp()),
            None => 1.0,
        };
        let (rs, rr) = (m.rs * heat, m.rr * heat);
        let (is, ir, psi_m) = self.currents(x);
        let v = self.voltage(t, x[5]);
        let w = x[4];
        let te = 1.5 * m.pp() * (x[0] * is[1] - x[1] * is[0]);
        let mut t_out = self.load_torque(t, w) + m.b * w;
        if let Some(tc) = h.coulomb_friction {
            // smoothed over +/- 1 rad/s
            t_out += tc * w.tanh();
        }
        if let Some(k) = h.windage {
            t_out += k * w * w.abs();
        }
        let dr = h.phase_asymmetry.unwrap_or(0.0) * heat;
        let (rotor_drop, p_rotor) = self.rotor_drop(x, ir, rr);
        let p_in = 1.5 * (v[0] * is[0] + v[1] * is[1]);
        let mut p_cu = 1.5
            * (rs * (is[0] * is[0] + is[1] * is[1]) + rr * (ir[0] * ir[0] + ir[1] * ir[1]))
            + dr * is[0] * is[0];
        if h.rotor_asymmetry.is_some() {
            p_cu += p_rotor;
        }
        let pmn = psi_m[0].hypot(psi_m[1]);
        let w_mag = 1.5
            * (0.5 * m.lls * (is[0] * is[0] + is[1] * is[1])
                + 0.5 * m.llr * (ir[0] * ir[0] + ir[1] * ir[1])
                + self.im_energy(pmn).1);
        Point {
            v,
            is,
            ir,
            psi_m,
            te,
            t_out,
            p_in,
            p_cu,
            w_mag,
            rs,
            rr,
            rotor_drop,
        }
    }

    pub fn deriv(&self, t: f64, x: &State) -> State {
        let p = self.point(t, x);
        let m = self.m;
        let wr = m.pp() * x[4];
        let da = self.s.hidden.phase_asymmetry.unwrap_or(0.0) * (p.rs / m.rs);
        let (_, fs) = self.s.supply.at(t);
        let dw = if self.s.hold_speed.is_some() {
            0.0
        } else {
            (p.te - p.t_out) / m.j
        };
        [
            p.v[0] - p.rs * p.is[0] - 2.0 / 3.0 * da * p.is[0],
            p.v[1] - p.rs * p.is[1],
            -p.rr * p.ir[0] - wr * x[3] - p.rotor_drop[0],
            -p.rr * p.ir[1] + wr * x[2] - p.rotor_drop[1],
            dw,
            2.0 * PI * m.f_hz * fs,
            p.p_in,
            p.p_cu,
            p.t_out * x[4],
            wr,
        ]
    }

    /// The initial state: zero flux, standstill (or the held speed).
    pub fn initial(&self) -> State {
        let mut x = [0.0; 10];
        x[4] = self.s.hold_speed.unwrap_or(0.0);
        x
    }

    pub fn rk4(&self, t: f64, x: &State, h: f64) -> State {
        let add = |a: &State, b: &State, k: f64| -> State {
            let mut r = *a;
            for (ri, bi) in r.iter_mut().zip(b) {
                *ri += k * bi;
            }
            r
        };
        let k1 = self.deriv(t, x);
        let k2 = self.deriv(t + h / 2.0, &add(x, &k1, h / 2.0));
        let k3 = self.deriv(t + h / 2.0, &add(x, &k2, h / 2.0));
        let k4 = self.deriv(t + h, &add(x, &k3, h));
        let mut r = *x;
        for (i, ri) in r.iter_mut().enumerate() {
            *ri += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        r
    }
}
