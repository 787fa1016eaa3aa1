//! Reference frames and the Clarke/Park transforms.
//!
//! One type per frame ([`Abc`], [`AlphaBeta`], [`Dq`]) so a signature says which frame a
//! value is in. The Clarke transform is amplitude invariant: a balanced set
//! `x_a = X cos(theta)`, `x_b = X cos(theta - 2pi/3)`, `x_c = X cos(theta + 2pi/3)` becomes the
//! vector `X (cos theta, sin theta)`, so d-q magnitudes equal phase peak values.
//!
//! Angle convention of the whole crate: the Park angle `theta` is the angle of the d axis
//! measured from the alpha (phase-a) axis, electrical radians. In rotor-flux orientation the
//! rotor flux lies on +d and the stator voltage is close to +q; in voltage orientation (the
//! paper's phase-a zero-crossing method, section 4) the voltage lies exactly on +q, so
//! `V_ds = 0` and `V_qs = |V|`, matching the paper's model where `V_qs` is the input (eq. 32).

use micromath::F32Ext;

/// 1/sqrt(3).
const INV_SQRT3: f32 = 0.577_350_26;
/// sqrt(3)/2.
const SQRT3_2: f32 = 0.866_025_4;

/// Phase quantities a, b, c (volts or amperes, instantaneous).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Abc {
    /// Phase a.
    pub a: f32,
    /// Phase b.
    pub b: f32,
    /// Phase c.
    pub c: f32,
}

/// Stationary two-axis frame (alpha on phase a), amplitude-invariant scaling.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AlphaBeta {
    /// Alpha component (along phase a).
    pub alpha: f32,
    /// Beta component (90 electrical degrees ahead of alpha).
    pub beta: f32,
}

/// Synchronous (rotating) d-q frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dq {
    /// Direct-axis component.
    pub d: f32,
    /// Quadrature-axis component (90 electrical degrees ahead of d).
    pub q: f32,
}

/// A precomputed sine/cosine pair of a frame angle, so one trig evaluation serves several
/// transforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinCos {
    /// sin(theta).
    pub sin: f32,
    /// cos(theta).
    pub cos: f32,
}

impl Default for SinCos {
    fn default() -> Self {
        SinCos { sin: 0.0, cos: 1.0 }
    }
}

impl SinCos {
    /// sin and cos of `theta_rad` with micromath's approximations (about 6e-4 absolute error
    /// after range reduction; tens of Cortex-M4F instructions, no f64). Any finite angle.
    pub fn from_angle(theta_rad: f32) -> Self {
        SinCos {
            sin: F32Ext::sin(theta_rad),
            cos: F32Ext::cos(theta_rad),
        }
    }

    /// Unit vector of `(x, y)`, or `None` when its length is below `min_norm` or not finite.
    pub fn from_vector(x: f32, y: f32, min_norm: f32) -> Option<Self> {
        let n2 = x * x + y * y;
        if !(n2.is_finite() && n2 > min_norm * min_norm) {
            return None;
        }
        let inv = 1.0 / crate::sqrt(n2);
        Some(SinCos {
            sin: y * inv,
            cos: x * inv,
        })
    }

    /// The angle rotated by -90 degrees: (sin(t - pi/2), cos(t - pi/2)) = (-cos t, sin t).
    pub fn minus_quarter_turn(self) -> Self {
        SinCos {
            sin: -self.cos,
            cos: self.sin,
        }
    }

    /// The angle advanced by a small step `delta_rad` (|delta| <= 0.1 rad), by rotation
    /// with the truncated series `cos d = 1 - d^2/2 + d^4/24`, `sin d = d - d^3/6 + d^5/120`:
    /// truncation error below 2e-10 per step for |d| <= 0.1, plus f32 rounding. About ten
    /// floating-point operations instead of a sin/cos evaluation; callers resynchronise
    /// with [`SinCos::from_angle`] now and then so rounding cannot accumulate.
    #[inline]
    pub fn rotated(self, delta_rad: f32) -> Self {
        let d2 = delta_rad * delta_rad;
        let c = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
        let s = delta_rad * (1.0 - d2 * ((1.0 / 6.0) - d2 * (1.0 / 120.0)));
        SinCos {
            sin: self.sin * c + self.cos * s,
            cos: self.cos * c - self.sin * s,
        }
    }

    /// The negated angle: (sin(-t), cos(-t)).
    pub fn negated(self) -> Self {
        SinCos {
            sin: -self.sin,
            cos: self.cos,
        }
    }
}

/// Clarke transform, amplitude invariant:
/// `alpha = (2a - b - c)/3`, `beta = (b - c)/sqrt(3)`.
/// Any zero-sequence part `(a+b+c)/3` is discarded.
pub fn clarke(x: Abc) -> AlphaBeta {
    AlphaBeta {
        alpha: (2.0 * x.a - x.b - x.c) * (1.0 / 3.0),
        beta: (x.b - x.c) * INV_SQRT3,
    }
}

/// Inverse Clarke transform (zero sequence set to 0):
/// `a = alpha`, `b = -alpha/2 + sqrt(3)/2 beta`, `c = -alpha/2 - sqrt(3)/2 beta`.
pub fn inverse_clarke(x: AlphaBeta) -> Abc {
    Abc {
        a: x.alpha,
        b: -0.5 * x.alpha + SQRT3_2 * x.beta,
        c: -0.5 * x.alpha - SQRT3_2 * x.beta,
    }
}

/// Park transform into the frame at angle theta:
/// `d = alpha cos + beta sin`, `q = -alpha sin + beta cos`.
pub fn park(x: AlphaBeta, sc: SinCos) -> Dq {
    Dq {
        d: x.alpha * sc.cos + x.beta * sc.sin,
        q: -x.alpha * sc.sin + x.beta * sc.cos,
    }
}

/// Inverse Park transform: `alpha = d cos - q sin`, `beta = d sin + q cos`.
pub fn inverse_park(x: Dq, sc: SinCos) -> AlphaBeta {
    AlphaBeta {
        alpha: x.d * sc.cos - x.q * sc.sin,
        beta: x.d * sc.sin + x.q * sc.cos,
    }
}

/// Wraps an angle into [-pi, pi). Valid for |theta| < 1e6 rad.
pub fn wrap_angle(theta: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    if (-PI..PI).contains(&theta) {
        return theta;
    }
    let mut t = theta - TAU * F32Ext::floor((theta + PI) / TAU);
    if t >= PI {
        t -= TAU;
    }
    if t < -PI {
        t += TAU;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn balanced(theta: f32, amp: f32) -> Abc {
        use core::f32::consts::FRAC_PI_3;
        Abc {
            a: amp * libm_cos(theta),
            b: amp * libm_cos(theta - 2.0 * FRAC_PI_3),
            c: amp * libm_cos(theta + 2.0 * FRAC_PI_3),
        }
    }
    fn libm_cos(x: f32) -> f32 {
        (x as f64).cos() as f32
    }

    #[test]
    fn balanced_set_is_a_vector_of_the_phase_peak() {
        for k in 0..36 {
            let th = k as f32 * 0.17;
            let ab = clarke(balanced(th, 10.0));
            assert!((ab.alpha - 10.0 * th.cos()).abs() < 1e-4);
            assert!((ab.beta - 10.0 * th.sin()).abs() < 1e-4);
            // In a frame at the vector's own angle minus 90 degrees, the vector is on +q.
            let dq = park(ab, SinCos::from_angle(th).minus_quarter_turn());
            // micromath sin/cos: ~1e-3 relative.
            assert!(dq.d.abs() < 2e-2 && (dq.q - 10.0).abs() < 2e-2, "{dq:?}");
        }
    }

    proptest! {
        #[test]
        fn park_then_inverse_is_identity(a in -1e3f32..1e3, b in -1e3f32..1e3, th in -100f32..100.0) {
            let sc = SinCos::from_angle(th);
            let x = AlphaBeta { alpha: a, beta: b };
            let y = inverse_park(park(x, sc), sc);
            // micromath's sin/cos are not exactly on the unit circle (|err| ~ 1e-3 relative).
            let tol = 3e-3 * (a.abs() + b.abs()) + 1e-3;
            prop_assert!((y.alpha - a).abs() < tol && (y.beta - b).abs() < tol);
        }

        #[test]
        fn park_with_normalised_sincos_is_exact_inverse(a in -1e3f32..1e3, b in -1e3f32..1e3, x in -1f32..1.0, y in -1f32..1.0) {
            prop_assume!(x * x + y * y > 1e-4);
            let sc = SinCos::from_vector(x, y, 1e-3).unwrap(); // ok: test
            let v = AlphaBeta { alpha: a, beta: b };
            let back = inverse_park(park(v, sc), sc);
            let tol = 1e-5 * (a.abs() + b.abs()) + 1e-4;
            prop_assert!((back.alpha - a).abs() < tol && (back.beta - b).abs() < tol);
        }

        #[test]
        fn rotation_steps_track_the_angle(t0 in -3f32..3.0, d in -0.1f32..0.1) {
            let mut sc = SinCos { sin: (t0 as f64).sin() as f32, cos: (t0 as f64).cos() as f32 };
            for _ in 0..20 {
                sc = sc.rotated(d);
            }
            let t = t0 as f64 + 20.0 * d as f64;
            prop_assert!((sc.sin as f64 - t.sin()).abs() < 2e-6 && (sc.cos as f64 - t.cos()).abs() < 2e-6);
        }

        #[test]
        fn clarke_then_inverse_keeps_zero_sum_sets(a in -1e3f32..1e3, b in -1e3f32..1e3) {
            let x = Abc { a, b, c: -a - b };
            let y = inverse_clarke(clarke(x));
            prop_assert!((y.a - x.a).abs() < 1e-3 && (y.b - x.b).abs() < 1e-3 && (y.c - x.c).abs() < 1e-3);
        }

        #[test]
        fn wrap_angle_stays_in_range(t in -1e5f32..1e5) {
            let w = wrap_angle(t);
            prop_assert!((-core::f32::consts::PI..core::f32::consts::PI).contains(&w));
            prop_assert!((w.sin() - t.sin()).abs() < 2e-2);
        }
    }
}
