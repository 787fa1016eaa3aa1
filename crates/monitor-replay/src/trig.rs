//! sin and cos of an angle that advances by small steps, by rotation: a recursive
//! oscillator ([`Oscillator`]) resynchronised from the angle itself. The sequence analysis
//! turns the least-squares reference's angle every sample; a sin/cos evaluation per row
//! was a large share of `diagnose`'s work on the reading thread (docs/performance.md). The
//! angle advances by a step held over a block of the analysis, whose sin/cos is computed
//! once per block ([`Oscillator::turn`], [`step_of`]).

use monitor_core::frames::SinCos;

/// Largest step the oscillator rotates by [rad]: [`step_of`]'s series is exact to 3e-11 up
/// to 0.1 rad (a supply period in 63 samples); with a larger step (a low sample rate) every
/// angle is evaluated afresh.
const MAX_STEP_RAD: f32 = 0.1;

/// Rotations between two evaluations afresh: f32 rounding adds about 6e-8 per rotation, a
/// random walk of about 1e-6 over 64 of them (the oscillator's magnitude drifts by as much;
/// resynchronising also renormalises it).
const RESYNC_STEPS: u32 = 64;

/// The sin and cos of an angle that moves by small steps the caller knows (module docs):
/// each call gives the last value rotated by the step, where the step is at most
/// [`MAX_STEP_RAD`] and fewer than [`RESYNC_STEPS`] rotations were made since the last
/// evaluation; else `f32::sin_cos` of the angle (within an ulp or two of the true values).
/// Error against the sin/cos of the angle the steps make: below 3e-6 (a caller that
/// accumulates its angle in f32 drifts from that by its own rounding, up to half an ulp per
/// step, which the rotation follows only at the evaluations afresh). A
/// non-finite angle gives non-finite values and the next angle is evaluated afresh.
#[derive(Debug, Clone, Copy)]
pub(super) struct Oscillator {
    sc: SinCos,
    /// Rotations since the last evaluation.
    steps: u32,
}

impl Default for Oscillator {
    fn default() -> Self {
        Oscillator {
            sc: SinCos::default(),
            steps: RESYNC_STEPS,
        }
    }
}

/// The sin and cos of a step `delta` [rad] for [`Oscillator::turn`], up to
/// [`MAX_STEP_RAD`] (else `None`: the oscillator then evaluates every angle afresh). By
/// their series in f64 (exact to 3e-11 up to 0.1 rad), rounded to f32: the step's magnitude
/// is then within 3e-8 of one, which the rotations between two evaluations afresh add up.
pub(super) fn step_of(delta: f32) -> Option<SinCos> {
    (delta.abs() <= MAX_STEP_RAD).then(|| {
        let d = f64::from(delta);
        let d2 = d * d;
        SinCos {
            sin: (d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 / 5040.0)))) as f32,
            cos: (1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 / 720.0))) as f32,
        }
    })
}

impl Oscillator {
    /// The sin and cos of `angle` [rad] afresh (the rotations counted from here).
    fn afresh(&mut self, angle: f32) -> SinCos {
        let (sin, cos) = angle.sin_cos();
        self.sc = SinCos { sin, cos };
        self.steps = if sin.is_finite() { 0 } else { RESYNC_STEPS };
        self.sc
    }

    /// The sin and cos of the angle `angle()` [rad], which the caller turned from the last
    /// angle by a step whose sin/cos is `step` ([`step_of`]; `None`: evaluated afresh): the
    /// last value rotated by it, one complex product (class docs; `angle` is called only
    /// where the value is evaluated afresh).
    #[inline]
    pub fn turn(&mut self, angle: impl FnOnce() -> f32, step: Option<SinCos>) -> SinCos {
        match step {
            Some(r) if self.steps < RESYNC_STEPS => {
                self.sc = SinCos {
                    sin: self.sc.sin * r.cos + self.sc.cos * r.sin,
                    cos: self.sc.cos * r.cos - self.sc.sin * r.sin,
                };
                self.steps += 1;
                self.sc
            }
            _ => self.afresh(angle()),
        }
    }

    /// The angle jumped (a gap bridged): the next value is evaluated
    /// afresh.
    pub fn restart(&mut self) {
        self.steps = RESYNC_STEPS;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::frames::wrap_angle;

    /// Turned by a step held over blocks of 10 (as the reference is), against f64 sin/cos of
    /// the angle the steps make, with a jump (restart) and a step too large to rotate by.
    #[test]
    fn turns_by_a_held_step_within_3e_6() {
        for (rate_hz, f_hz) in [(10_000.0f32, 60.0f32), (50_000.0, 50.0), (500.0, 60.0)] {
            let mut osc = Oscillator::default();
            let (mut theta, mut worst, mut step) = (0.3f64, 0.0f64, (0.0, None));
            for n in 0..200_000u32 {
                if n % 10 == 0 {
                    let w = core::f32::consts::TAU * f_hz * (1.0 + 0.01 * (n as f32 * 1e-3).sin());
                    step = (w / rate_hz, step_of(w / rate_hz));
                }
                theta = (theta + f64::from(step.0)) % std::f64::consts::TAU;
                if n % 50_000 == 7 {
                    theta += 2.0;
                    osc.restart();
                }
                let sc = osc.turn(|| wrap_angle(theta as f32), step.1);
                let (s, c) = theta.sin_cos();
                worst = worst
                    .max((f64::from(sc.sin) - s).abs())
                    .max((f64::from(sc.cos) - c).abs());
            }
            assert!(worst < 3e-6, "{rate_hz} Hz: error {worst:e}");
        }
    }
}
