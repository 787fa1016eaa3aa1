//! sin and cos of two angles at once: the values of the core's [`SinCos::from_angle`]
//! (micromath's approximations), bit for bit, computed on four lanes that the compiler
//! keeps in one vector register. The sequence analysis turns two angles every sample (the
//! PLL's and the least-squares reference's).

use monitor_core::frames::SinCos;

/// micromath's `cos` of each lane, operation by operation: `x / (2 pi)`, less the nearest
/// quarter-shifted integer, then the parabola and its correction.
#[inline(always)]
fn cos4(x: [f32; 4]) -> [f32; 4] {
    x.map(|x| {
        let mut x = x * (core::f32::consts::FRAC_1_PI / 2.0);
        let t = x + 0.25;
        let mut floor = (t as i32) as f32;
        if t < floor {
            floor -= 1.0;
        }
        x -= 0.25 + floor;
        x *= 16.0 * (x.abs() - 0.5);
        x += 0.225 * x * (x.abs() - 1.0);
        x
    })
}

/// [`SinCos::from_angle`] of `a` and of `b`.
#[inline]
pub(super) fn sin_cos_pair(a: f32, b: f32) -> (SinCos, SinCos) {
    // micromath's sin(x) is cos(x - pi/2).
    const HALF_PI: f32 = core::f32::consts::PI / 2.0;
    let [sa, ca, sb, cb] = cos4([a - HALF_PI, a, b - HALF_PI, b]);
    (SinCos { sin: sa, cos: ca }, SinCos { sin: sb, cos: cb })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_values_as_the_core_to_the_last_bit() {
        let same = |a: f32, b: f32| {
            let (x, y) = sin_cos_pair(a, b);
            for (got, want) in [(x, SinCos::from_angle(a)), (y, SinCos::from_angle(b))] {
                assert_eq!(got.sin.to_bits(), want.sin.to_bits(), "sin {a} {b}");
                assert_eq!(got.cos.to_bits(), want.cos.to_bits(), "cos {a} {b}");
            }
        };
        let mut s: u32 = 0x2545_F491;
        for k in 0..400_000 {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            // Angles of every magnitude, then the PLL's range finely.
            let a = if k % 2 == 0 {
                f32::from_bits(s)
            } else {
                (s as f32 / u32::MAX as f32 - 0.5) * 8.0
            };
            if a.is_nan() {
                continue;
            }
            same(a, -a);
        }
        for a in [
            0.0,
            -0.0,
            core::f32::consts::PI,
            -core::f32::consts::PI,
            core::f32::consts::FRAC_PI_2,
            1e-30,
            3e9,
            -3e9,
            1e30,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ] {
            same(a, a + 1.0);
        }
        // NaN in, NaN out, as the core.
        let (x, _) = sin_cos_pair(f32::NAN, 0.0);
        assert!(x.sin.is_nan() && SinCos::from_angle(f32::NAN).sin.is_nan());
    }
}
