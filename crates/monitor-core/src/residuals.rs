//! The simplified D-Q model and its parity-equation residuals (paper section 3).
//!
//! Symbols (the paper's, "Fault Diagnosis of Induction Motor Using D-Q Simplified Model and
//! Parity Equations", Energies 2022, 15(22), 8372; computed by [`MotorModel`]'s methods;
//! the paper's typos: `docs/paper-errata.md`): `Ra = Rs + (Ls/Lr) Rr`
//! (eq. 24), `La = sigma Ls`,
//! `Psi = Ls i_f` (the paper prints `Psi = Ls` and `i_f = Ls i_ds` under eq. 34: both are
//! typos; the coefficient of omega_r in eq. 28 is `Ls i_f`), `Kf = 3/2 Np Lm^2/Lr i_f`
//! (eq. 25 with `P/2 = Np`), `k1 = Psi Kf Np + Ra (B+Bl)`, `k2 = La (B+Bl) + J Ra` (eq. 35).
//!
//! Steady-state residuals, eq. (37):
//! - `r1 = Ra Iqs + Psi wr - Vqs`
//! - `r2 = -Kf Np Iqs + (B+Bl) wr`
//! - `r3 = k1 Iqs - (B+Bl) Vqs`
//! - `r4 = k1 wr - Kf Np Vqs`
//!
//! Full residuals, eq. (36), valid in transients:
//! - `r1 = Ra Iqs + Psi wr + La dIqs/dt - Vqs`
//! - `r2 = -Kf Np Iqs + (B+Bl) wr + J dwr/dt`
//! - `r3 = k1 Iqs + k2 dIqs/dt + J La d2Iqs/dt2 - (B+Bl) Vqs - J dVqs/dt`
//! - `r4 = k1 wr + k2 dwr/dt + J La d2wr/dt2 - Kf Np Vqs`
//!
//! The paper prints `L_a k2` as the coefficient of the first derivatives in r3 and r4; that
//! is a typo (k2 already contains La): eliminating wr from r1 and r2 gives
//! `r3 = (B + Bl + J d/dt) r1 - Psi r2` and eliminating Iqs gives
//! `r4 = Kf Np r1 + (Ra + La d/dt) r2`, whose derivative coefficients are `k2` and `J La`.
//!
//! Units: V for r1, N m s/rad * rad/s... (r2 in N m referred through Np), so every residual
//! is also returned *normalised*: divided by the sum of the magnitudes of its terms plus a
//! floor (see [`Normaliser`]). A normalised residual is dimensionless in [-1, 1], zero for a
//! healthy machine in steady state in rotor-flux orientation, and comparable across motors,
//! which is what the thresholds act on.

use crate::machine::MotorModel;

/// The model's inputs and outputs at one instant, in the chosen d-q frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Operating {
    /// Torque-producing current Iqs = i_T [A].
    pub iqs: f32,
    /// Flux-producing current i_f = i_ds [A] (eq. 17).
    pub i_f: f32,
    /// Voltage Vqs [V].
    pub vqs: f32,
    /// Electrical rotor speed wr = Np x mechanical speed [rad/s].
    pub wr_rad_s: f32,
}

/// First and second time derivatives for the full residuals (eq. 36).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Derivatives {
    /// dIqs/dt [A/s].
    pub diqs: f32,
    /// d2Iqs/dt2 [A/s^2].
    pub ddiqs: f32,
    /// dwr/dt [rad/s^2].
    pub dwr: f32,
    /// d2wr/dt2 [rad/s^3].
    pub ddwr: f32,
    /// dVqs/dt [V/s].
    pub dvqs: f32,
}

/// Raw residuals r1..r4 with the magnitude of their terms.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Residuals {
    /// r1..r4 in their own units (r1: V; r2: N m (electrical-speed form); r3: V N m s/rad...).
    pub r: [f32; 4],
    /// Sum of the magnitudes of each residual's terms (same units), >= 0.
    pub terms: [f32; 4],
}

/// Evaluates eq. (37) (`d = None`) or eq. (36) (`d = Some(..)`) with nominal parameters.
pub fn residuals(m: &MotorModel, op: Operating, d: Option<Derivatives>) -> Residuals {
    let ra = m.ra_ohm();
    let bb = m.b_nms + m.bl_nms;
    let np = m.np();
    let psi = m.ls_h * op.i_f;
    let kfnp = m.kf_per_if() * op.i_f * np;
    let k1 = psi * kfnp + ra * bb;
    let a1 = [ra * op.iqs, psi * op.wr_rad_s, op.vqs];
    let a2 = [kfnp * op.iqs, bb * op.wr_rad_s];
    let a3 = [k1 * op.iqs, bb * op.vqs];
    let a4 = [k1 * op.wr_rad_s, kfnp * op.vqs];
    let mut r = [
        a1[0] + a1[1] - a1[2],
        -a2[0] + a2[1],
        a3[0] - a3[1],
        a4[0] - a4[1],
    ];
    let mut terms = [
        a1[0].abs() + a1[1].abs() + a1[2].abs(),
        a2[0].abs() + a2[1].abs(),
        a3[0].abs() + a3[1].abs(),
        a4[0].abs() + a4[1].abs(),
    ];
    if let Some(d) = d {
        let la = m.la_h();
        let j = m.j_kgm2;
        let k2 = la * bb + j * ra;
        let e1 = la * d.diqs;
        let e2 = j * d.dwr;
        let e3 = k2 * d.diqs + j * la * d.ddiqs - j * d.dvqs;
        let e4 = k2 * d.dwr + j * la * d.ddwr;
        r[0] += e1;
        r[1] += e2;
        r[2] += e3;
        r[3] += e4;
        terms[0] += e1.abs();
        terms[1] += e2.abs();
        terms[2] += e3.abs();
        terms[3] += e4.abs();
    }
    Residuals { r, terms }
}

/// Turns raw residuals into dimensionless ones: `r_n = r / (terms + floor)`, clamped to
/// [-1, 1]. The floors are each residual's term sum at a reference operating point times
/// `floor_fraction`, so that near standstill (all terms small) noise does not blow up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normaliser {
    floor: [f32; 4],
}

impl Normaliser {
    /// Floors from a reference operating point (typically rated voltage at no load).
    pub fn new(m: &MotorModel, reference: Operating, floor_fraction: f32) -> Self {
        let t = residuals(m, reference, None).terms;
        Normaliser {
            floor: [
                t[0] * floor_fraction + 1e-6,
                t[1] * floor_fraction + 1e-9,
                t[2] * floor_fraction + 1e-9,
                t[3] * floor_fraction + 1e-9,
            ],
        }
    }

    /// Normalised residuals; a non-finite input gives `None`.
    pub fn apply(&self, r: &Residuals) -> Option<[f32; 4]> {
        let mut out = [0.0f32; 4];
        for (k, o) in out.iter_mut().enumerate() {
            let (x, t, f) = (*r.r.get(k)?, *r.terms.get(k)?, *self.floor.get(k)?);
            let v = x / (t + f);
            if !v.is_finite() {
                return None;
            }
            *o = crate::math::minf(crate::math::maxf(v, -1.0), 1.0);
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testing::motor_3hp;

    /// Exact steady state of the T-equivalent circuit in rotor-flux orientation at slip s:
    /// solves for the operating point from the equivalent circuit in f64.
    fn steady_point(m: &MotorModel, vph_peak: f64, we: f64, s: f64) -> Operating {
        // Equivalent circuit: Z = Rs + j we Lls + (j we Lm || (Rr/s + j we Llr)).
        let (rs, rr) = (m.rs_ohm as f64, m.rr_ohm as f64);
        let (lm, lls, llr) = (
            m.lm_h as f64,
            (m.ls_h - m.lm_h) as f64,
            (m.lr_h - m.lm_h) as f64,
        );
        let c = |re: f64, im: f64| (re, im);
        let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let div = |a: (f64, f64), b: (f64, f64)| {
            let d = b.0 * b.0 + b.1 * b.1;
            ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
        };
        let add = |a: (f64, f64), b: (f64, f64)| (a.0 + b.0, a.1 + b.1);
        let zm = c(0.0, we * lm);
        let zr = c(rr / s, we * llr);
        let zp = div(mul(zm, zr), add(zm, zr));
        let z = add(c(rs, we * lls), zp);
        let is = div(c(vph_peak, 0.0), z); // stator current phasor, voltage on the real axis
        let im_ = div(mul(is, zr), add(zm, zr)); // magnetising current
        let ir = (is.0 - im_.0, is.1 - im_.1); // into the rotor branch
                                               // Rotor flux psi_r = Lm im + Llr * (-ir)?  psi_r = Lm (is + ir') + Llr ir' with ir' = -ir.
        let psir = (lm * im_.0 - llr * ir.0, lm * im_.1 - llr * ir.1);
        let ang = psir.1.atan2(psir.0);
        // Rotate so the rotor flux is on +d: multiply by e^{-j ang}.
        let rot = |a: (f64, f64)| mul(a, (ang.cos(), -ang.sin()));
        let i_dq = rot(is);
        let v_dq = rot(c(vph_peak, 0.0));
        Operating {
            iqs: i_dq.1 as f32,
            i_f: i_dq.0 as f32,
            vqs: v_dq.1 as f32,
            wr_rad_s: (we * (1.0 - s)) as f32,
        }
    }

    #[test]
    fn r1_is_zero_at_the_analytic_steady_state_for_every_slip() {
        let m = motor_3hp();
        for s in [0.001, 0.01, 0.03, 0.05, 0.1] {
            let op = steady_point(&m, 179.6, 377.0, s);
            let r = residuals(&m, op, None);
            // Only r1 is purely electrical; the mechanical balance needs the matching load.
            assert!(
                r.r[0].abs() < 1e-4 * r.terms[0],
                "s={s} r1={} terms={}",
                r.r[0],
                r.terms[0]
            );
            // Vqs in rotor-flux orientation is not |V|: the voltage leads q by a load angle.
            assert!(op.vqs < 179.7 && op.i_f > 0.0);
        }
    }

    #[test]
    fn all_residuals_vanish_with_the_matching_viscous_load() {
        // Choose Bl so that Kf Np Iqs = (B+Bl) wr at this slip: then r2 = r3 = r4 = 0.
        let base = motor_3hp();
        let op = steady_point(&base, 179.6, 377.0, 0.03);
        let te_np = base.kf_per_if() * op.i_f * base.np() * op.iqs;
        let m = MotorModel {
            bl_nms: te_np / op.wr_rad_s - base.b_nms,
            ..base
        };
        let r = residuals(&m, op, None);
        for k in 0..4 {
            assert!(
                r.r[k].abs() < 1e-3 * r.terms[k],
                "r{} = {} of {}",
                k + 1,
                r.r[k],
                r.terms[k]
            );
        }
        // And r3, r4 are the combinations (B+Bl) r1 - Psi r2 and Kf Np r1 + Ra r2.
        let op2 = Operating {
            vqs: op.vqs * 1.1,
            ..op
        };
        let r = residuals(&m, op2, None);
        let bb = m.b_nms + m.bl_nms;
        let psi = m.ls_h * op.i_f;
        let kfnp = m.kf_per_if() * op.i_f * m.np();
        assert!((r.r[2] - (bb * r.r[0] - psi * r.r[1])).abs() < 1e-3 * r.terms[2]);
        assert!((r.r[3] - (kfnp * r.r[0] + m.ra_ohm() * r.r[1])).abs() < 1e-3 * r.terms[3]);
    }

    #[test]
    fn full_residuals_are_zero_on_a_trajectory_of_the_model() {
        // Integrate eqs. (28)-(29) from rest with a Vqs step; the full residuals of eq. (36)
        // with exact derivatives stay at zero while the steady ones do not.
        let m = motor_3hp();
        let i_f = 4.0f32;
        let (ra, la, np, j) = (m.ra_ohm(), m.la_h(), m.np(), m.j_kgm2);
        let psi = m.ls_h * i_f;
        let kfnp = m.kf_per_if() * i_f * np;
        let bb = m.b_nms + m.bl_nms;
        let (mut iq, mut wr) = (0.0f32, 0.0f32);
        let dt = 1e-6f32;
        let vq = 150.0f32;
        let mut worst_full: f32 = 0.0;
        let mut worst_steady: f32 = 0.0;
        for _ in 0..200_000 {
            let diq = (-ra * iq - psi * wr + vq) / la;
            let dwr = (kfnp * iq - bb * wr) / j;
            let ddiq = (-ra * diq - psi * dwr) / la;
            let ddwr = (kfnp * diq - bb * dwr) / j;
            let op = Operating {
                iqs: iq,
                i_f,
                vqs: vq,
                wr_rad_s: wr,
            };
            let d = Derivatives {
                diqs: diq,
                ddiqs: ddiq,
                dwr,
                ddwr,
                dvqs: 0.0,
            };
            let full = residuals(&m, op, Some(d));
            let steady = residuals(&m, op, None);
            for k in 0..4 {
                worst_full = worst_full.max((full.r[k] / full.terms[k].max(1e-9)).abs());
                worst_steady = worst_steady.max((steady.r[k] / steady.terms[k].max(1e-9)).abs());
            }
            iq += dt * diq;
            wr += dt * dwr;
        }
        assert!(worst_full < 1e-3, "full {worst_full}");
        assert!(worst_steady > 0.1, "steady {worst_steady}");
    }
}
