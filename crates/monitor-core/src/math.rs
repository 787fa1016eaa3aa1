//! The float helpers the core's blocks share, written for the Cortex-M4F: [`maxf`] and
//! [`minf`] without a call to the C library, [`sqrt`] and [`fast_hypot`] at f32 rounding
//! level from micromath's estimate. (The trigonometry is micromath's, through
//! [`crate::frames::Real`].)

/// The larger of two floats in two instructions (`vcmp` + conditional move). The
/// Cortex-M4F has no `vmaxnm`, so `f32::max` becomes a call to the C `fmaxf`; this does
/// not follow IEEE maxNum for NaN (returns `b` when either is NaN), which callers allow.
#[inline(always)]
pub fn maxf(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two floats; NaN behaviour as [`maxf`] (returns `b`).
#[inline(always)]
pub fn minf(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// sqrt(x^2 + y^2) via [`sqrt`].
#[inline]
pub fn fast_hypot(x: f32, y: f32) -> f32 {
    sqrt(x * x + y * y)
}

/// Square root for `x >= 0`: micromath's estimate (relative error up to a few 1e-2)
/// refined by two Newton steps `y <- (y + x/y)/2`, which square the error twice: relative
/// error at f32 rounding level (~1e-7). Returns 0 for `x <= 0` and NaN for NaN.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    if !(x > 0.0) {
        return if x.is_nan() { x } else { 0.0 };
    }
    let y = micromath::F32Ext::sqrt(x);
    if y > 0.0 && y.is_finite() {
        let y = 0.5 * (y + x / y);
        0.5 * (y + x / y)
    } else {
        y
    }
}
