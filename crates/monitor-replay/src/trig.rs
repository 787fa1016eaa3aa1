//! sin and cos of an angle that advances by small steps, by rotation: a recursive
//! oscillator ([`Oscillator`]) resynchronised from the angle itself. The sequence analysis
//! turns two angles every sample (the PLL's and the least-squares reference's); a sin/cos
//! evaluation per angle and row was a tenth of `diagnose`'s work on the reading thread
//! (docs/performance.md).

use monitor_core::frames::{wrap_angle, SinCos};

/// Largest step the oscillator rotates by [rad]: [`SinCos::rotated`]'s series is exact to
/// 2e-10 up to 0.1 rad (a supply period in 63 samples); a larger step (a low sample rate, a
/// gap, the PLL aligned) is evaluated afresh.
const MAX_STEP_RAD: f32 = 0.1;

/// Rotations between two evaluations afresh: f32 rounding adds about 6e-8 per rotation, a
/// random walk of about 1e-6 over 64 of them (the oscillator's magnitude drifts by as much;
/// resynchronising also renormalises it).
const RESYNC_STEPS: u32 = 64;

/// The sin and cos of an angle that moves by small steps (module docs). Each call gives
/// the sin/cos of the angle passed: the last value rotated by the step from the last angle
/// where the step is at most [`MAX_STEP_RAD`] and fewer than [`RESYNC_STEPS`] rotations
/// were made since the last evaluation; else `f32::sin_cos` of the angle (within an ulp or
/// two of the true values). Error against the true values: below 2e-6. A NaN angle gives
/// NaN values and the next angle is evaluated afresh.
#[derive(Debug, Clone, Copy)]
pub(super) struct Oscillator {
    /// The angle of `sc` [rad] (NaN before the first).
    angle: f32,
    sc: SinCos,
    /// Rotations since the last evaluation.
    steps: u32,
}

impl Default for Oscillator {
    fn default() -> Self {
        Oscillator {
            angle: f32::NAN,
            sc: SinCos::default(),
            steps: 0,
        }
    }
}

impl Oscillator {
    /// The sin and cos of `angle` [rad] (any value; the step from the last one is wrapped).
    #[inline]
    pub fn at(&mut self, angle: f32) -> SinCos {
        let d = wrap_angle(angle - self.angle);
        if d.abs() <= MAX_STEP_RAD && self.steps < RESYNC_STEPS {
            self.sc = self.sc.rotated(d);
            self.steps += 1;
        } else {
            let (sin, cos) = angle.sin_cos();
            self.sc = SinCos { sin, cos };
            self.steps = 0;
        }
        self.angle = angle;
        self.sc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against f64 sin/cos along angles as the PLL and the reference turn them (wrapped
    /// every period), at the sample rates a log has, with frequency wobble, jumps and NaN.
    #[test]
    fn follows_the_angle_within_2e_6() {
        for (rate_hz, f_hz) in [(10_000.0f32, 60.0f32), (50_000.0, 50.0), (1_000.0, 60.0)] {
            let mut osc = Oscillator::default();
            let mut theta = 0.3f32;
            let mut worst = 0.0f64;
            for n in 0..200_000u32 {
                let w = core::f32::consts::TAU * f_hz * (1.0 + 0.01 * (n as f32 * 1e-3).sin());
                theta = wrap_angle(theta + w / rate_hz);
                if n % 50_000 == 7 {
                    // A jump (the PLL aligned, a gap bridged).
                    theta = wrap_angle(theta + 2.0);
                }
                let sc = osc.at(theta);
                let (s, c) = f64::from(theta).sin_cos();
                worst = worst
                    .max((f64::from(sc.sin) - s).abs())
                    .max((f64::from(sc.cos) - c).abs());
            }
            assert!(worst < 2e-6, "{rate_hz} Hz: error {worst:e}");
        }
        let mut osc = Oscillator::default();
        osc.at(1.0);
        assert!(osc.at(f32::NAN).sin.is_nan());
        let sc = osc.at(0.5);
        assert!((sc.sin - 0.5f32.sin()).abs() < 1e-6 && (sc.cos - 0.5f32.cos()).abs() < 1e-6);
    }
}
