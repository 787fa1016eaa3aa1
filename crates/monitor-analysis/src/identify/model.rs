//! The full-order T-equivalent machine of the simulator (`monitor_sim`'s `machine`) driven
//! by a log's measured phase voltages, and the least-squares problem of `identify`: the
//! simulated stator currents against the measured ones.
//!
//! With the log's speed the machine's speed is imposed (the mean of the two samples over
//! each step), which decouples the electrical parameters from the mechanics; without it
//! the shaft is integrated with `J domega_m/dt = T_e - (B + Bl) omega_m`.
//!
//! The initial state: a log that starts de-energised (the first current below 5 % of the
//! peak of its first 0.1 s) starts from zero flux; otherwise from the circuit's sinusoidal
//! steady state at the first sample (positive sequence, the supply's phasor and angular
//! frequency from the first 0.1 s of the voltages, the measured speed):
//! ```text
//!   (Rs + j w Ls) I_s + j w Lm I_r = V,   j s w Lm I_s + (Rr + j s w Lr) I_r = 0,
//!   s w = w - Np w_m,   Psi_s = Ls I_s + Lm I_r,   Psi_r = Lm I_s + Lr I_r.
//! ```

use super::Samples;
use crate::lm::LeastSquares;
use monitor_sim::machine::{LoadLaw, Machine};
use nalgebra::Complex;

/// The parameters `identify` varies, physical units. The leakage is the total
/// `Lls + Llr`, split by the fixed stator fraction [`IdentifiedCircuit::stator_leakage_share`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiedCircuit {
    /// Stator resistance Rs [ohm].
    pub rs_ohm: f64,
    /// Rotor resistance Rr (referred to the stator) [ohm].
    pub rr_ohm: f64,
    /// Total leakage Lls + Llr [H].
    pub leakage_h: f64,
    /// Magnetising inductance Lm [H].
    pub lm_h: f64,
    /// Moment of inertia J [kg m^2].
    pub j_kgm2: f64,
    /// Total viscous coefficient B + Bl [N m s/rad].
    pub b_total_nms: f64,
    /// Lls / (Lls + Llr), 0..1 (kept from the start file: the terminals cannot tell it).
    pub stator_leakage_share: f64,
    /// Pole pairs Np.
    pub np: f64,
}

/// Number of parameters in [`IdentifiedCircuit::to_vec`].
pub const N_PARAMS: usize = 6;

impl IdentifiedCircuit {
    /// The varied parameters as a vector, in [`super::PARAMS`]' order.
    pub fn to_vec(&self) -> [f64; N_PARAMS] {
        [
            self.rs_ohm,
            self.rr_ohm,
            self.leakage_h,
            self.lm_h,
            self.j_kgm2,
            self.b_total_nms,
        ]
    }

    /// This circuit with the varied parameters `p` (same order).
    pub fn with(&self, p: &[f64]) -> IdentifiedCircuit {
        let g = |k: usize| p.get(k).copied().unwrap_or(f64::NAN);
        IdentifiedCircuit {
            rs_ohm: g(0),
            rr_ohm: g(1),
            leakage_h: g(2),
            lm_h: g(3),
            j_kgm2: g(4),
            b_total_nms: g(5),
            ..*self
        }
    }

    fn lls(&self) -> f64 {
        self.stator_leakage_share * self.leakage_h
    }

    fn llr(&self) -> f64 {
        (1.0 - self.stator_leakage_share) * self.leakage_h
    }

    /// The simulator's machine; with `speed_imposed` a shaft so heavy that the speed set
    /// before each step stays.
    fn machine(&self, speed_imposed: bool) -> Option<Machine> {
        let j = if speed_imposed { 1e30 } else { self.j_kgm2 };
        let load = LoadLaw {
            bl_nms: 0.0,
            torque_nm: 0.0,
            coulomb_nm: 0.0,
            inv_w0: 0.0,
            windage: 0.0,
        };
        Machine::new(
            self.rs_ohm,
            None,
            self.lls(),
            self.llr(),
            self.rr_ohm,
            self.lm_h,
            None,
            None,
            self.np,
            j,
            self.b_total_nms,
            load,
        )
        .ok()
    }

    /// The steady state (psi_s, psi_r) at supply phasor `v` (alpha + j beta at t = 0),
    /// angular frequency `w` [rad/s] and mechanical speed `wm` [rad/s].
    fn steady_flux(&self, v: Complex<f64>, w: f64, wm: f64) -> ([f64; 2], [f64; 2]) {
        let (lls, llr, lm) = (self.lls(), self.llr(), self.lm_h);
        let (ls, lr) = (lls + lm, llr + lm);
        let j = Complex::new(0.0, 1.0);
        let sw = w - self.np * wm;
        let a11 = self.rs_ohm + j * w * ls;
        let a12 = j * w * lm;
        let a21 = j * sw * lm;
        let a22 = self.rr_ohm + j * sw * lr;
        let det = a11 * a22 - a12 * a21;
        let is = v * a22 / det;
        let ir = -v * a21 / det;
        let ps = is * ls + ir * lm;
        let pr = is * lm + ir * lr;
        ([ps.re, ps.im], [pr.re, pr.im])
    }
}

/// A simulation of the log: stator currents, torque and speed at every sample.
#[derive(Debug, Clone, Default)]
pub struct Trace {
    /// Stator current alpha, beta [A].
    pub i_ab: Vec<[f64; 2]>,
    /// Electromagnetic torque [N m].
    pub torque_nm: Vec<f64>,
    /// Mechanical speed [rad/s] (the measured one when imposed).
    pub wm_rad_s: Vec<f64>,
}

/// Simulates the log `s` with circuit `c` (speed imposed when the log has it). `None` when
/// the circuit is not physical or the simulation diverges.
pub fn simulate(c: &IdentifiedCircuit, s: &Samples) -> Option<Trace> {
    let wm_meas = s.wm_rad_s.as_deref();
    let m = c.machine(wm_meas.is_some())?;
    let n = s.i_ab.len();
    let wm0 = wm_meas.and_then(|w| w.first().copied()).unwrap_or(0.0);
    let mut x = [0.0; 6];
    x[4] = wm0;
    if !s.starts_dead {
        let (ps, pr) = c.steady_flux(s.v0, s.supply_w_rad_s, wm0);
        x[..4].copy_from_slice(&[ps[0], ps[1], pr[0], pr[1]]);
    }
    let mut t = Trace {
        i_ab: Vec::with_capacity(n),
        torque_nm: Vec::with_capacity(n),
        wm_rad_s: Vec::with_capacity(n),
    };
    for k in 0..n {
        let cur = m.currents([x[0], x[1]], [x[2], x[3]]);
        t.i_ab.push(cur.i_s);
        t.torque_nm.push(m.torque([x[2], x[3]], cur.i_r));
        t.wm_rad_s.push(x[4]);
        if k + 1 == n {
            break;
        }
        let (v0, v1) = (s.v_ab[k], s.v_ab[k + 1]);
        let vm = midpoint(&s.v_ab, k);
        if let Some(w) = wm_meas {
            x[4] = 0.5 * (w[k] + w[k + 1]);
        }
        m.rk4(&mut x, k as f64 * s.dt_s, s.dt_s, v0, vm, v1);
        if let Some(w) = wm_meas {
            x[4] = w[k + 1];
        }
        if !x.iter().all(|v| v.is_finite()) {
            return None;
        }
    }
    Some(t)
}

/// The voltage vector halfway between samples `k` and `k + 1` of `v`: the cubic through
/// the four samples around it (Catmull-Rom, `(-v[k-1] + 9 v[k] + 9 v[k+1] - v[k+2]) / 16`),
/// the straight line at the log's ends. The line's midpoint of a sinusoid falls short of it
/// by `1 - cos(w dt / 2)`, `(w dt)^2 / 8`: at 2 kHz and 50 Hz 0.3 %, which the fit turned
/// into every impedance 0.2-0.3 % low (motulator's 2.2 kW, 7.5 kW and 50 hp logs); the
/// cubic's is `(w dt)^4 / 128`, 4e-6 there.
fn midpoint(v: &[[f64; 2]], k: usize) -> [f64; 2] {
    let at = |j: usize| v.get(j).copied();
    match (k.checked_sub(1).and_then(at), at(k), at(k + 1), at(k + 2)) {
        (Some(a), Some(b), Some(c), Some(d)) => {
            [0, 1].map(|i| (-a[i] + 9.0 * b[i] + 9.0 * c[i] - d[i]) / 16.0)
        }
        (_, Some(b), Some(c), _) => [0.5 * (b[0] + c[0]), 0.5 * (b[1] + c[1])],
        _ => [0.0; 2],
    }
}

/// The least-squares problem: the parameters are `ln(p / p_start)` (all of
/// [`IdentifiedCircuit::to_vec`]); the residuals the current errors over the measured current's RMS,
/// alpha and beta of every sample.
pub struct CurrentFit<'a> {
    /// The log.
    pub samples: &'a Samples,
    /// The start circuit (the scale of the parameters).
    pub start: IdentifiedCircuit,
}

impl CurrentFit<'_> {
    /// The circuit at the solver's vector `x`.
    pub fn circuit(&self, x: &[f64]) -> IdentifiedCircuit {
        let p0 = self.start.to_vec();
        let p: Vec<f64> = p0.iter().zip(x).map(|(p, x)| p * x.exp()).collect();
        self.start.with(&p)
    }
}

/// The residual given to a circuit that cannot be simulated (a large error, so the solver
/// steps back).
const FAILED_RESIDUAL: f64 = 1e3;

impl LeastSquares for CurrentFit<'_> {
    type Cache = ();
    fn cache(&self, _x: &[f64]) {}
    fn residuals(&self, x: &[f64], _c: &()) -> Vec<f64> {
        let s = self.samples;
        let scale = 1.0 / s.i_rms_a;
        match simulate(&self.circuit(x), s) {
            Some(t) => t
                .i_ab
                .iter()
                .zip(&s.i_ab)
                .flat_map(|(a, b)| [(b[0] - a[0]) * scale, (b[1] - a[1]) * scale])
                .collect(),
            None => vec![FAILED_RESIDUAL; 2 * s.i_ab.len()],
        }
    }
}
