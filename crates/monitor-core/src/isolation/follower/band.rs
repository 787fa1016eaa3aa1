//! The band of steadiness about the follower's average: [`STEADY_FRACTION`] of each
//! quantity, its limits computed once per average.

use super::STEADY_FRACTION;
use crate::isolation::SteadyPoint;
use crate::math::fast_hypot;

/// [`steady_against`](super::steady_against) for one average, its limits computed once (the follower judges every
/// point against the same average until a block closes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SteadyBand {
    /// The average the band is about.
    pub(super) avg: SteadyPoint,
    /// [`STEADY_FRACTION`] of the current's magnitude (at least 1e-6 A) [A].
    i: f32,
    /// [`STEADY_FRACTION`] of the voltage's magnitude (at least 1e-6 V) [V].
    v: f32,
    /// [`STEADY_FRACTION`] of the supply's speed (at least 1 rad/s) [rad/s].
    w: f32,
}

impl SteadyBand {
    /// The band about the average `avg`.
    pub(super) fn of(avg: SteadyPoint) -> Self {
        let i = crate::math::maxf(fast_hypot(avg.i.d, avg.i.q), 1e-6);
        let v = crate::math::maxf(fast_hypot(avg.v.d, avg.v.q), 1e-6);
        let w = crate::math::maxf(avg.we_rad_s.abs(), 1.0);
        SteadyBand {
            avg,
            i: STEADY_FRACTION * i,
            v: STEADY_FRACTION * v,
            w: STEADY_FRACTION * w,
        }
    }

    /// Every quantity of `p` within the band ([`steady_against`](super::steady_against)).
    #[inline]
    pub(super) fn admits(&self, p: &SteadyPoint) -> bool {
        let avg = &self.avg;
        hypot_within(p.i.d - avg.i.d, p.i.q - avg.i.q, self.i)
            && hypot_within(p.v.d - avg.v.d, p.v.q - avg.v.q, self.v)
            && (p.we_rad_s - avg.we_rad_s).abs() <= self.w
            && (p.wr_rad_s - avg.wr_rad_s).abs() <= self.w
    }

    /// The current and voltage vectors of `p` within the band: with
    /// [`SteadyBand::admits_speeds`], [`SteadyBand::admits`] in two parts (the host's replay
    /// checks the vectors, which move once per block, only when they changed).
    #[inline]
    pub(super) fn admits_vectors(&self, p: &SteadyPoint) -> bool {
        let avg = &self.avg;
        hypot_within(p.i.d - avg.i.d, p.i.q - avg.i.q, self.i)
            && hypot_within(p.v.d - avg.v.d, p.v.q - avg.v.q, self.v)
    }

    /// The supply's and the rotor's speeds of `p` within the band (see
    /// [`SteadyBand::admits_vectors`]).
    #[inline]
    pub(super) fn admits_speeds(&self, p: &SteadyPoint) -> bool {
        let avg = &self.avg;
        (p.we_rad_s - avg.we_rad_s).abs() <= self.w && (p.wr_rad_s - avg.wr_rad_s).abs() <= self.w
    }
}

/// `fast_hypot(x, y) <= limit`, the same answer, with the square root taken only within
/// 0.1 % of the limit. Elsewhere `x^2 + y^2` (the same sum `fast_hypot` takes the root of)
/// against `limit^2` decides: for a normal sum, [`crate::sqrt`] is within 2e-6 of the true
/// root (micromath's estimate, within 6.1 %, refined by two Newton steps: 1.7e-3, then
/// 1.5e-6, plus f32 rounding), far inside the 0.1 % margin. Zero, subnormal, infinite or
/// NaN sums and limits, and limits that are not positive, take the root.
#[inline]
fn hypot_within(x: f32, y: f32, limit: f32) -> bool {
    let s = x * x + y * y;
    let l2 = limit * limit;
    if limit > 0.0 && s.is_normal() && l2.is_normal() {
        if s < 0.998 * l2 {
            return true;
        }
        if s > 1.002 * l2 {
            return false;
        }
    }
    fast_hypot(x, y) <= limit
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shortcut gives `fast_hypot`'s answer: random magnitudes over the whole f32 range,
    /// points near the limit, and the special values.
    #[test]
    fn hypot_within_answers_as_the_root() {
        let mut r: u32 = 0x9E37_79B9;
        let mut next = || {
            r ^= r << 13;
            r ^= r >> 17;
            r ^= r << 5;
            r
        };
        let special = [
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            1e-40,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let mut cases = 0;
        for k in 0..2_000_000 {
            let (x, y, limit) = match k % 4 {
                // Any bit patterns.
                0 => (
                    f32::from_bits(next()),
                    f32::from_bits(next()),
                    f32::from_bits(next()),
                ),
                // Ordinary magnitudes.
                1 => {
                    let u = |n: u32| (n as f32 / u32::MAX as f32 - 0.5) * 20.0;
                    (u(next()), u(next()), u(next()).abs())
                }
                // Near the limit: within 1 % of it, either side.
                2 => {
                    let (x, y) = (
                        (next() as f32 / u32::MAX as f32 - 0.5) * 300.0,
                        (next() as f32 / u32::MAX as f32 - 0.5) * 300.0,
                    );
                    let f = 1.0 + (next() as f32 / u32::MAX as f32 - 0.5) * 0.02;
                    (x, y, fast_hypot(x, y) * f)
                }
                // Special values.
                _ => {
                    let n = special.len() as u32;
                    let pick = |v: u32| special[(v % n) as usize];
                    (pick(next()), pick(next()), pick(next()))
                }
            };
            assert_eq!(
                hypot_within(x, y, limit),
                fast_hypot(x, y) <= limit,
                "{x:e} {y:e} {limit:e}"
            );
            cases += 1;
        }
        assert_eq!(cases, 2_000_000);
    }
}
