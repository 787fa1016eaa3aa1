//! Reference frames and the Clarke/Park transforms, the one implementation for the board
//! (`f32`) and the host (`f64`).
//!
//! One type per frame ([`Abc`], [`AlphaBeta`], [`Dq`]) so a signature says which frame a
//! value is in; each is generic over the scalar ([`Real`]: `f32` on the board, the default,
//! and `f64` in the host's analysis). The Clarke transform is amplitude invariant: a balanced set
//! `x_a = X cos(theta)`, `x_b = X cos(theta - 2pi/3)`, `x_c = X cos(theta + 2pi/3)` becomes the
//! vector `X (cos theta, sin theta)`, so d-q magnitudes equal phase peak values.
//!
//! Angle convention of the whole crate: the Park angle `theta` is the angle of the d axis
//! measured from the alpha (phase-a) axis, electrical radians. In rotor-flux orientation the
//! rotor flux lies on +d and the stator voltage is close to +q; in voltage orientation (the
//! paper's phase-a zero-crossing method, section 4) the voltage lies exactly on +q, so
//! `V_ds = 0` and `V_qs = |V|`, matching the paper's model where `V_qs` is the input (eq. 32).
//!
//! The host's analysis writes space vectors as complex numbers; there the Park transform
//! is the product `x_dq = x_alphabeta e^{-j theta}`, the same transform as [`park`].

use core::ops::{Add, Div, Mul, Neg, Sub};
use micromath::F32Ext;

/// The scalar of the frame types and of [`crate::MotorModel`]: `f32` (the board, the
/// default) or `f64` (the host).
pub trait Real:
    Copy
    + Default
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 3/2.
    const THREE_HALVES: Self;
    /// 1/3.
    const ONE_THIRD: Self;
    /// 1/2.
    const HALF: Self;
    /// 2.
    const TWO: Self;
    /// 1/sqrt(3).
    const INV_SQRT3: Self;
    /// sqrt(3)/2.
    const SQRT3_2: Self;
    /// The nearest value of `x` (rounding for `f32`).
    fn from_f64(x: f64) -> Self;
    /// `n` exactly.
    fn from_u8(n: u8) -> Self;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> bool;
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
    const THREE_HALVES: f32 = 1.5;
    const ONE_THIRD: f32 = 1.0 / 3.0;
    const HALF: f32 = 0.5;
    const TWO: f32 = 2.0;
    const INV_SQRT3: f32 = 0.577_350_26;
    const SQRT3_2: f32 = 0.866_025_4;
    #[inline]
    fn from_f64(x: f64) -> f32 {
        x as f32
    }
    #[inline]
    fn from_u8(n: u8) -> f32 {
        f32::from(n)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
    const THREE_HALVES: f64 = 1.5;
    const ONE_THIRD: f64 = 1.0 / 3.0;
    const HALF: f64 = 0.5;
    const TWO: f64 = 2.0;
    const INV_SQRT3: f64 = 0.577_350_269_189_625_8;
    const SQRT3_2: f64 = 0.866_025_403_784_438_6;
    #[inline]
    fn from_f64(x: f64) -> f64 {
        x
    }
    #[inline]
    fn from_u8(n: u8) -> f64 {
        f64::from(n)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// A phase of the three-phase system (the machine's windings, the supply's lines).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Phase {
    /// Phase a (on the alpha axis).
    A,
    /// Phase b (120 electrical degrees behind a).
    B,
    /// Phase c.
    C,
}

impl Phase {
    /// The three phases in order.
    pub const ALL: [Phase; 3] = [Phase::A, Phase::B, Phase::C];

    /// "a", "b" or "c".
    pub fn name(self) -> &'static str {
        match self {
            Phase::A => "a",
            Phase::B => "b",
            Phase::C => "c",
        }
    }

    /// The phase named "a", "b" or "c" ([`Phase::name`]); `None` for any other text.
    pub fn from_name(name: &str) -> Option<Phase> {
        Phase::ALL.into_iter().find(|p| p.name() == name)
    }

    /// 0, 1, 2 for a, b, c: the index `k` of the winding axis at `k 2pi/3`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The phase whose axis is `k` thirds of a turn from phase a (any integer, taken
    /// modulo 3).
    pub fn from_turns(k: i32) -> Phase {
        match k.rem_euclid(3) {
            0 => Phase::A,
            1 => Phase::B,
            _ => Phase::C,
        }
    }
}

/// Phase quantities a, b, c (volts or amperes, instantaneous).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Abc<T = f32> {
    /// Phase a.
    pub a: T,
    /// Phase b.
    pub b: T,
    /// Phase c.
    pub c: T,
}

impl<T: Copy> Abc<T> {
    /// From `[a, b, c]`.
    pub fn from_array(x: [T; 3]) -> Self {
        Abc {
            a: x[0],
            b: x[1],
            c: x[2],
        }
    }

    /// As `[a, b, c]`.
    pub fn to_array(self) -> [T; 3] {
        [self.a, self.b, self.c]
    }

    /// The value of one phase.
    pub fn phase(self, p: Phase) -> T {
        match p {
            Phase::A => self.a,
            Phase::B => self.b,
            Phase::C => self.c,
        }
    }
}

/// Stationary two-axis frame (alpha on phase a), amplitude-invariant scaling.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AlphaBeta<T = f32> {
    /// Alpha component (along phase a).
    pub alpha: T,
    /// Beta component (90 electrical degrees ahead of alpha).
    pub beta: T,
}

/// Synchronous (rotating) d-q frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dq<T = f32> {
    /// Direct-axis component.
    pub d: T,
    /// Quadrature-axis component (90 electrical degrees ahead of d).
    pub q: T,
}

/// A precomputed sine/cosine pair of a frame angle, so one trig evaluation serves several
/// transforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinCos<T = f32> {
    /// sin(theta).
    pub sin: T,
    /// cos(theta).
    pub cos: T,
}

impl Default for SinCos {
    fn default() -> Self {
        SinCos { sin: 0.0, cos: 1.0 }
    }
}

impl<T: Real> SinCos<T> {
    /// The angle rotated by -90 degrees: (sin(t - pi/2), cos(t - pi/2)) = (-cos t, sin t).
    #[inline]
    pub fn minus_quarter_turn(self) -> Self {
        SinCos {
            sin: -self.cos,
            cos: self.sin,
        }
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
        let inv = 1.0 / crate::math::sqrt(n2);
        Some(SinCos {
            sin: y * inv,
            cos: x * inv,
        })
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
    #[inline]
    pub fn negated(self) -> Self {
        SinCos {
            sin: -self.sin,
            cos: self.cos,
        }
    }
}

/// Clarke transform, amplitude invariant:
/// `alpha = (2a - b - c)/3`, `beta = (b - c)/sqrt(3)`.
/// Any zero-sequence part `(a+b+c)/3` is discarded (see [`zero_sequence`]).
#[inline]
pub fn clarke<T: Real>(x: Abc<T>) -> AlphaBeta<T> {
    AlphaBeta {
        alpha: (T::TWO * x.a - x.b - x.c) * T::ONE_THIRD,
        beta: (x.b - x.c) * T::INV_SQRT3,
    }
}

/// The zero-sequence part `(a + b + c)/3` that [`clarke`] discards (zero for the currents
/// of a star-connected machine with an isolated neutral; a current sensor's offset shows
/// here).
#[inline]
pub fn zero_sequence<T: Real>(x: Abc<T>) -> T {
    (x.a + x.b + x.c) * T::ONE_THIRD
}

/// Inverse Clarke transform plus a zero-sequence part `x0` (0 for a balanced set):
/// `a = alpha + x0`, `b = -alpha/2 + sqrt(3)/2 beta + x0`, `c = -alpha/2 - sqrt(3)/2 beta + x0`.
#[inline]
pub fn inverse_clarke<T: Real>(x: AlphaBeta<T>, x0: T) -> Abc<T> {
    Abc {
        a: x.alpha + x0,
        b: -T::HALF * x.alpha + T::SQRT3_2 * x.beta + x0,
        c: -T::HALF * x.alpha - T::SQRT3_2 * x.beta + x0,
    }
}

/// Park transform into the frame at angle theta:
/// `d = alpha cos + beta sin`, `q = -alpha sin + beta cos`.
#[inline]
pub fn park<T: Real>(x: AlphaBeta<T>, sc: SinCos<T>) -> Dq<T> {
    Dq {
        d: x.alpha * sc.cos + x.beta * sc.sin,
        q: -x.alpha * sc.sin + x.beta * sc.cos,
    }
}

/// Inverse Park transform: `alpha = d cos - q sin`, `beta = d sin + q cos`.
#[inline]
pub fn inverse_park<T: Real>(x: Dq<T>, sc: SinCos<T>) -> AlphaBeta<T> {
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
            let y = inverse_clarke(clarke(x), 0.0);
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
