//! The stationary-frame model's saturating machine ([`SatMachine`]): the circuit of the
//! fitted machine with its magnetising inductance following its own flux, by the power law
//! or a user's law's shape.

use super::super::full_order::FullMachine;
use super::super::terms::{LmShape, MagnetisingLaw, SaturationLaw};
use super::super::MachineConstants;
use super::StatState;
use crate::prep::C64;

/// The saturated machine (a magnetising law in the full-order model) as the simulator
/// integrates it (`monitor_sim`'s machine): T-equivalent circuit, states psi_s and psi_r
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
/// The winding and the cage act as in [`WindingAsymmetryTerm`] and [`CageOverSample`], on the
/// fluxes' equations.
#[derive(Clone, Copy)]
pub(super) struct SatMachine<'a> {
    pub(super) inv_lls: f64,
    pub(super) inv_llr: f64,
    pub(super) inv_lm0: f64,
    pub(super) rr: f64,
    pub(super) psi_sat: f64,
    pub(super) nexp: f64,
    /// A user's law's shape `Lm(psi_m) / Lm(0)` in place of the power law
    /// ([`MagnetisingLaw::Shape`]).
    pub(super) shape: Option<&'a LmShape>,
    /// With a stator-flux law ([`LmShape::stator`]): the Gamma-equivalent circuit, whose
    /// stator inductance Ls0 (unsaturated) is `1/inv_lm0` and whose rotor leakage is
    /// `1/inv_llr` (no stator leakage).
    pub(super) gamma: bool,
    /// The last solve's 1/Lm (0: none yet).
    pub(super) guess: &'a std::cell::Cell<f64>,
}

impl<'a> SatMachine<'a> {
    pub(super) fn new(
        n: &MachineConstants,
        m: &FullMachine,
        law: &'a MagnetisingLaw,
        guess: &'a std::cell::Cell<f64>,
    ) -> Self {
        let (power, shape) = match law {
            MagnetisingLaw::Power(p) => (*p, None),
            MagnetisingLaw::Shape(s) => (
                SaturationLaw {
                    psi_sat_wb: 1.0,
                    exponent: 1.0,
                    lm0_over_file: s.lm0_over_file,
                },
                Some(s),
            ),
        };
        let sigma_n = n.lls_h + n.lm_h * n.llr_h / (n.llr_h + n.lm_h);
        let scale = m.l_sigma / sigma_n.max(1e-12);
        let gamma = shape.is_some_and(|s| s.stator);
        // The Gamma circuit of the same machine: Ls = L_sigma + L_M, its rotor leakage
        // Ls L_sigma / L_M (the transient inductance L_sigma kept).
        let (lls, llr) = if gamma {
            (0.0, m.l_sigma * (m.l_sigma + m.l_m) / m.l_m.max(1e-12))
        } else {
            (n.lls_h * scale, n.llr_h * scale)
        };
        let lm0 = (m.l_sigma + m.l_m - lls).max(1e-6);
        SatMachine {
            inv_lls: if gamma { 0.0 } else { 1.0 / lls.max(1e-9) },
            inv_llr: 1.0 / llr.max(1e-9),
            inv_lm0: 1.0 / lm0,
            rr: m.a * (llr + lm0),
            psi_sat: power.psi_sat_wb.max(1e-9),
            nexp: power.exponent,
            shape,
            gamma,
            guess,
        }
    }

    /// The linear model's state (i_s, psi_R) as fluxes (psi_s, psi_r) at Lm0.
    pub(super) fn linear_to_fluxes(&self, m: &FullMachine, x: &StatState) -> StatState {
        let lr_over_lm = 1.0 + self.inv_lm0 / self.inv_llr;
        StatState {
            i: x.i * m.l_sigma + x.psi,
            psi: x.psi * lr_over_lm,
            wm: x.wm,
        }
    }

    /// Stator and rotor currents at the fluxes `ps`, `pr`.
    #[inline(always)]
    pub(super) fn currents(&self, ps: C64, pr: C64) -> (C64, C64) {
        if let (true, Some(s)) = (self.gamma, self.shape) {
            // Gamma: psi_s = Ls(|psi_s|) (i_s + i_R), psi_R = psi_s + L_sR i_R.
            let sh = (s.shape)(ps.norm());
            let sh = if sh.is_finite() && sh > 0.0 { sh } else { 1.0 };
            let i_r = (pr - ps) * self.inv_llr;
            return (ps * (self.inv_lm0 / sh) - i_r, i_r);
        }
        let w = ps * self.inv_lls + pr * self.inv_llr;
        let g = self.inv_lls + self.inv_llr;
        if let Some(s) = self.shape {
            let y = self.solve_shape(s, w.norm(), g);
            let psi_m = w / (y + g);
            return ((ps - psi_m) * self.inv_lls, (pr - psi_m) * self.inv_llr);
        }
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

impl SatMachine<'_> {
    /// `y = 1/Lm` of a user's law: `y = (1/Lm0) / shape(W / (y + G))` ([`SatMachine`]'s
    /// equation with the law's shape), by the secant method from the last solve, kept
    /// within a bracket (`y` from a hundredth to a thousand times 1/Lm0; bisection where a
    /// secant step leaves it), to 1e-12 relative. A shape that is not finite and positive
    /// leaves `y` at the bracket's end its sign points to.
    pub(super) fn solve_shape(&self, s: &LmShape, big_w: f64, g: f64) -> f64 {
        let f = |y: f64| {
            let sh = (s.shape)(big_w / (y + g));
            let sh = if sh.is_finite() && sh > 0.0 {
                sh
            } else {
                1e-12
            };
            y - self.inv_lm0 / sh
        };
        let (mut lo, mut hi) = (1e-2 * self.inv_lm0, 1e3 * self.inv_lm0);
        let mut y0 = self.guess.get().clamp(lo, hi);
        if y0 <= lo {
            y0 = self.inv_lm0;
        }
        let mut f0 = f(y0);
        let mut y1 = (y0 * 1.001).min(hi);
        for _ in 0..60 {
            let f1 = f(y1);
            if f1 == 0.0 {
                break;
            }
            if f1 > 0.0 {
                hi = hi.min(y1);
            } else {
                lo = lo.max(y1);
            }
            let mut y2 = if f1 != f0 {
                y1 - f1 * (y1 - y0) / (f1 - f0)
            } else {
                0.5 * (lo + hi)
            };
            if !(y2 > lo && y2 < hi) {
                y2 = 0.5 * (lo + hi);
            }
            let done = (y2 - y1).abs() <= 1e-12 * y2;
            (y0, f0, y1) = (y1, f1, y2);
            if done {
                break;
            }
        }
        self.guess.set(y1);
        y1
    }
}
