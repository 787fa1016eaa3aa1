//! The least-squares reference angle ([`Reference`]): it turns at the reference frequency,
//! which the slow filters update once per block ([`super::slow`]), so within a block the
//! angle and its offset from `w0 t` are straight lines in the row count. Per row only the
//! count moves and the sin/cos is rotated by the block's step; the angle and the offset are
//! read off the line where needed (a resynchronisation, the rotor's block ends), and a
//! window's sums of the frequency and the offset are added up line by line
//! ([`Reference::settle`]) where the line changes: at a block's end, a gap, a window's end.

use super::super::trig::{step_of, Oscillator};
use monitor_core::frames::{wrap_angle, SinCos};

/// A window's sums over its rows of the reference frequency and offset (what
/// [`super::SequenceWindow`] reports as their means and range).
#[derive(Debug, Clone, Copy)]
pub(super) struct RampSums {
    /// Sum of the reference frequency [rad/s] and of the offset [rad].
    pub w_sum: f64,
    pub offset_sum: f64,
    /// The frequency's range [rad/s] (infinite and zero before the first row).
    pub w_min: f32,
    pub w_max: f32,
}

impl Default for RampSums {
    fn default() -> Self {
        RampSums {
            w_sum: 0.0,
            offset_sum: 0.0,
            w_min: f32::INFINITY,
            w_max: 0.0,
        }
    }
}

/// The reference angle and its offset from the nominal frequency's angle (module docs).
#[derive(Debug, Clone)]
pub(super) struct Reference {
    /// Sample period [s] and the nominal angular frequency `w0` [rad/s].
    dt_s: f64,
    w0: f64,
    /// The frequency of the present line [rad/s], its step per row [rad] and that step's
    /// sin/cos, and the offset's slope per row [rad].
    w: f32,
    step: f32,
    rot: Option<SinCos>,
    slope: f64,
    /// Angle [rad] and offset [rad, unwrapped] at the line's start, and the rows since.
    theta_base: f32,
    offset_base: f64,
    rows: u32,
    osc: Oscillator,
}

impl Reference {
    /// A reference at rest at angle 0, turning at `w` [rad/s], for a log sampled every
    /// `dt_s` [s] of a supply of nominal angular frequency `w0` [rad/s].
    pub fn new(dt_s: f64, w0: f64, w: f32) -> Self {
        let mut r = Reference {
            dt_s,
            w0,
            w,
            step: 0.0,
            rot: None,
            slope: 0.0,
            theta_base: 0.0,
            offset_base: 0.0,
            rows: 0,
            osc: Oscillator::default(),
        };
        r.set_frequency(w);
        r
    }

    /// One row: the angle advances by a step.
    #[inline]
    pub fn row(&mut self) {
        self.rows += 1;
    }

    /// The sin/cos of the present angle (by rotation, [`Oscillator::turn`]).
    #[inline]
    pub fn sin_cos(&mut self) -> SinCos {
        let (base, step, rows) = (self.theta_base, self.step, self.rows);
        self.osc
            .turn(|| wrap_angle(base + step * rows as f32), self.rot)
    }

    /// The frequency the angle turns at [rad/s].
    #[inline]
    pub fn frequency(&self) -> f32 {
        self.w
    }

    /// The present angle [rad].
    pub fn theta(&self) -> f32 {
        wrap_angle(self.theta_base + self.step * self.rows as f32)
    }

    /// The present offset from `w0 t` [rad, unwrapped].
    #[inline]
    pub fn offset(&self) -> f64 {
        self.offset_base + self.slope * f64::from(self.rows)
    }

    /// Adds the rows since the line's start to a window's sums `o` and starts a new line
    /// at the present angle and offset (a no-op without rows).
    pub fn settle(&mut self, o: &mut RampSums) {
        if self.rows == 0 {
            return;
        }
        let k = f64::from(self.rows);
        o.w_sum += f64::from(self.w) * k;
        // The offsets of rows 1..k: base + slope j.
        o.offset_sum += self.offset_base * k + self.slope * k * (k + 1.0) * 0.5;
        o.w_min = o.w_min.min(self.w);
        o.w_max = o.w_max.max(self.w);
        self.theta_base = self.theta();
        self.offset_base = self.offset();
        self.rows = 0;
    }

    /// A new frequency `w` [rad/s] from the next row on (after [`Reference::settle`]).
    pub fn set_frequency(&mut self, w: f32) {
        self.w = w;
        self.step = w * self.dt_s as f32;
        self.rot = step_of(self.step);
        self.slope = (f64::from(w) - self.w0) * self.dt_s;
    }

    /// `missing` seconds without rows (a gap bridged): the angle and the offset advance at
    /// the frequency (after [`Reference::settle`]).
    pub fn skip(&mut self, missing: f64) {
        self.theta_base = wrap_angle(self.theta_base + self.w * missing as f32);
        self.offset_base += (f64::from(self.w) - self.w0) * missing;
        self.osc.restart();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the row-by-row accumulation: the angle, the offset, the window's sums
    /// over lines of 21 rows with a frequency change at each, a window closing within one.
    #[test]
    fn the_lines_add_up_to_the_rows() {
        let (dt, w0) = (1e-4, std::f64::consts::TAU * 60.0);
        let mut r = Reference::new(dt, w0, 377.0);
        let mut sums = RampSums::default();
        let (mut theta, mut offset, mut w) = (0.0f64, 0.0f64, 377.0f32);
        let (mut w_sum, mut offset_sum) = (0.0f64, 0.0f64);
        for n in 1..=1000u32 {
            r.row();
            theta += f64::from(w) * dt;
            offset += (f64::from(w) - w0) * dt;
            w_sum += f64::from(w);
            offset_sum += offset;
            let sc = r.sin_cos();
            assert!((f64::from(sc.sin) - theta.sin()).abs() < 2e-5, "{n}");
            assert!((r.offset() - offset).abs() < 1e-9, "{n}");
            if n % 21 == 0 {
                r.settle(&mut sums);
                w = 377.0 + (n as f32 * 0.01).sin();
                r.set_frequency(w);
            }
        }
        r.settle(&mut sums);
        assert!(
            (sums.w_sum - w_sum).abs() < 1e-9 * w_sum,
            "{} {w_sum}",
            sums.w_sum
        );
        assert!(
            (sums.offset_sum - offset_sum).abs() < 1e-9,
            "{} {offset_sum}",
            sums.offset_sum
        );
        assert!(sums.w_min >= 376.0 && sums.w_max <= 378.0 && sums.w_max > sums.w_min);
    }
}
