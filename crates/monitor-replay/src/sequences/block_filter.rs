//! The core's critically damped low-pass ([`Svf`]) stepped once per block of `n` samples
//! ([`BlockSvf`]): exactly what the per-sample filter makes of `n` samples of one value
//! (the block's mean), so that the slow filters keep the per-sample filter's response
//! (its semi-implicit Euler step taken at the block rate instead would move the corner by
//! about `wc n dt / 2`: 1.3 % for 2 Hz in blocks of 2 ms).
//!
//! The per-sample step `dy' = dy + wc^2 dt (x - y) - 2 wc dt dy`, `y' = y + dt dy'` is
//! linear: `[y', dy'] = A [y, dy] + c x`; over a block of one input it is
//! `[y, dy] -> A^n [y, dy] + (A^(n-1) + ... + 1) c x`, both formed once (in f64).
//!
//! The filter's value is read between two blocks, for the `n` rows until the next: it is
//! given half a block ahead, `y + dy (n - 1) dt / 2` (the per-sample filter's value in the
//! middle of those rows, to first order), so that holding it over the block adds no delay.

use monitor_core::filter::Svf;
use monitor_core::ConfigError;

/// A filter stepped once per block (module docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockSvf {
    /// `A^n` and the input's column.
    m: [[f32; 2]; 2],
    g: [f32; 2],
    /// `(n - 1) dt / 2` [s].
    lead_s: f32,
}

/// A [`BlockSvf`]'s state: the value, its derivative, and the value half a block ahead.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct BlockState {
    y: f32,
    dy: f32,
    ahead: f32,
}

impl BlockState {
    /// A state at rest at `y`.
    pub fn at(y: f32) -> Self {
        BlockState {
            y,
            dy: 0.0,
            ahead: y,
        }
    }

    /// The value half a block ahead (module docs).
    #[inline]
    pub fn value(&self) -> f32 {
        self.ahead
    }

    /// The filtered value at the last block's end.
    #[cfg(test)]
    pub fn y(&self) -> f32 {
        self.y
    }
}

impl BlockSvf {
    /// The core's filter of corner `fc_hz` [Hz] at sample period `dt_s` [s], stepped once
    /// per block of `n` samples (at least one). Errors: [`Svf::new`]'s (the per-sample
    /// filter's checks).
    pub fn new(fc_hz: f32, dt_s: f64, n: u32) -> Result<Self, ConfigError> {
        Svf::new(fc_hz, dt_s as f32)?;
        let wc = std::f64::consts::TAU * f64::from(fc_hz);
        let (a, b) = (wc * wc * dt_s, 2.0 * wc * dt_s);
        let step = [[1.0 - dt_s * a, dt_s * (1.0 - b)], [-a, 1.0 - b]];
        let c = [dt_s * a, a];
        let mul = |p: [[f64; 2]; 2], q: [[f64; 2]; 2]| {
            let e = |i: usize, j: usize| p[i][0] * q[0][j] + p[i][1] * q[1][j];
            [[e(0, 0), e(0, 1)], [e(1, 0), e(1, 1)]]
        };
        let (mut m, mut g) = ([[1.0, 0.0], [0.0, 1.0]], [0.0, 0.0]);
        for _ in 0..n.max(1) {
            // g <- A g + c, m <- A m.
            g = [
                step[0][0] * g[0] + step[0][1] * g[1] + c[0],
                step[1][0] * g[0] + step[1][1] * g[1] + c[1],
            ];
            m = mul(step, m);
        }
        let f = |x: f64| x as f32;
        Ok(BlockSvf {
            m: [[f(m[0][0]), f(m[0][1])], [f(m[1][0]), f(m[1][1])]],
            g: [f(g[0]), f(g[1])],
            lead_s: (f64::from(n.max(1) - 1) * dt_s / 2.0) as f32,
        })
    }

    /// One block of input `x` (its mean); returns the value half a block ahead.
    pub fn step(&self, s: &mut BlockState, x: f32) -> f32 {
        let (y, dy) = (s.y, s.dy);
        s.y = self.m[0][0] * y + self.m[0][1] * dy + self.g[0] * x;
        s.dy = self.m[1][0] * y + self.m[1][1] * dy + self.g[1] * x;
        s.ahead = s.y + s.dy * self.lead_s;
        s.ahead
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::filter::SvfState;

    /// Against the core's filter stepped every sample: the same values (to its own f32
    /// rounding) where each block's samples are one value (a step, then a ramp held per
    /// block), and within 2e-4 of the step where the per-sample filter sees the ramp
    /// itself; the value half a block ahead against the per-sample filter in the middle of
    /// the next block (within 2e-4 of the step: its curvature over half a block).
    #[test]
    fn makes_what_the_per_sample_filter_makes() {
        let (dt, n) = (1e-4, 21u32);
        let svf = Svf::new(2.0, dt as f32).unwrap();
        let block = BlockSvf::new(2.0, dt, n).unwrap();
        let (mut held, mut ramp, mut b) = (
            SvfState::default(),
            SvfState::default(),
            BlockState::default(),
        );
        let mut worst = [0.0f32; 3];
        let x_of = |k: u32| {
            if k < 2100 {
                1.0
            } else {
                1.0 + (k - 2100) as f32 * 1e-4
            }
        };
        for blk in 0..400u32 {
            let mean = (0..n).map(|j| x_of(blk * n + j)).sum::<f32>() / n as f32;
            let mut mid = 0.0;
            for j in 0..n {
                svf.update(&mut held, mean);
                svf.update(&mut ramp, x_of(blk * n + j));
                if j == n / 2 - 1 {
                    mid = ramp.y();
                }
            }
            let before = b.value();
            block.step(&mut b, mean);
            worst[0] = worst[0].max((b.y() - held.y()).abs());
            worst[1] = worst[1].max((b.y() - ramp.y()).abs());
            if blk > 0 {
                // The value read over this block (set at the last one's end).
                worst[2] = worst[2].max((before - mid).abs());
            }
        }
        // (The per-sample f32 filter's own rounding over 8400 steps: about 1e-5.)
        assert!(worst[0] < 5e-5, "{worst:?}");
        assert!(worst[1] < 2e-4, "{worst:?}");
        assert!(worst[2] < 2e-4, "{worst:?}");
        // One sample per block: the core's filter itself.
        let one = BlockSvf::new(2.0, dt, 1).unwrap();
        let (mut s, mut c) = (BlockState::default(), SvfState::default());
        for _ in 0..100 {
            one.step(&mut s, 3.0);
            svf.update(&mut c, 3.0);
        }
        assert!((s.value() - c.y()).abs() < 1e-6 && s.value() > 0.0);
    }
}
