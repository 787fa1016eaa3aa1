//! The sequence analysis' synchronous-reference-frame PLL, stepped once per block
//! ([`BlockPll`]) on the block's mean vector turned back by the least-squares reference
//! angle ([`super::lanes::Demod`]), instead of once per sample.
//!
//! The loop is the core's [`SrfPll`](monitor_core::angle::SrfPll)'s: the phase detector is
//! the q component of the vector on the PLL's angle (its d axis on the vector),
//! `e = Im(x e^{-j theta_pll})`, normalised by the nominal peak voltage where the PLL
//! follows the voltages and by the block's own magnitude where it follows the currents
//! (`e = sin` of the angle error, whatever the currents' scale); the loop filter is a PI,
//! `kp = 2 zeta wn`, `ki = wn^2`, `zeta = 0.707`, `wn = 2 pi 10 Hz`, with the integral
//! limited to `+-w0` and the frequency to `[0, 2 w0]`.
//!
//! What the block rate changes. The state is the PLL's angle less the reference angle,
//! `phi`, which turns at `w_pll - w_ref` (both held over a block): a few hundredths of a
//! radian per block at most. The detector reads the block's mean vector on the angle
//! `phi` in the block's middle: the mean over a block of an eighth of a supply period
//! passes the vector's own angle exactly and a negative sequence's `2f` image at
//! `sinc(1/4)` = 0.90 (the per-sample detector passed it whole, for the loop to filter at
//! 10 Hz), so the PLL is a little quieter under unbalance. The loop is a sampled one at
//! the block rate (480 Hz at 60 Hz), a one-block delay in the loop: `wn T` = 0.13, a phase
//! margin lower by about `1.5 wc T` (some 15 degrees of the continuous loop's 65), the
//! same steady state and a step response within a block of the per-sample one's. The
//! loop starts on the first block's vector (its angle; the per-sample loop started on the
//! first current sample's angle, or pulled in from zero on the voltages).
//!
//! Per sample nothing is left but a count: the sums the detector reads are the
//! least-squares fit's (no product of its own), and its one `sin_cos` is per block.

use super::lanes::Demod;
use monitor_core::frames::wrap_angle;
use std::f32::consts::TAU;

/// Damping of the loop (the core's `SrfPll`'s).
const ZETA: f32 = 0.707;

/// The PLL (module docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockPll {
    /// Sample period [s].
    dt: f32,
    kp: f32,
    ki: f32,
    /// Nominal angular frequency [rad/s].
    w0: f32,
    /// `1 / V_nominal` where the loop follows the voltages; `None`: the currents.
    inv_v: Option<f32>,
    integ: f32,
    /// The frequency held over the open block [rad/s].
    omega: f32,
    /// The PLL's angle less the reference angle at the open block's start [rad].
    phi: f32,
    /// Samples in the open block.
    rows: u32,
    /// The angle has been set on a block's vector.
    aligned: bool,
}

impl BlockPll {
    /// A PLL for samples every `dt_s` [s], nominal frequency `f0_hz`, bandwidth `bw_hz`
    /// (`wn = 2 pi bw`); on the voltages normalised by their nominal peak `v_nominal` [V]
    /// (`Some`, > 0), else on the currents.
    pub fn new(dt_s: f32, f0_hz: f32, bw_hz: f32, v_nominal: Option<f32>) -> Self {
        let wn = TAU * bw_hz;
        BlockPll {
            dt: dt_s,
            kp: 2.0 * ZETA * wn,
            ki: wn * wn,
            w0: TAU * f0_hz,
            inv_v: v_nominal.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 }),
            integ: 0.0,
            omega: TAU * f0_hz,
            phi: 0.0,
            rows: 0,
            aligned: false,
        }
    }

    /// One sample of the open block.
    #[inline]
    pub fn row(&mut self) {
        self.rows += 1;
    }

    /// The frequency estimate, held over the open block [rad/s].
    #[inline]
    pub fn omega_rad_s(&self) -> f32 {
        self.omega
    }

    /// `missing_s` seconds without samples (a gap bridged), the reference turning at
    /// `w_ref` [rad/s]: the angle advances at the PLL's frequency.
    pub fn skip(&mut self, missing_s: f32, w_ref: f32) {
        let a = self.phi + (self.omega - w_ref) * missing_s;
        if a.is_finite() {
            self.phi = wrap_angle(a);
        }
    }

    /// Ends the open block: `d` its sums on the reference angle, which turned at `w_ref`
    /// [rad/s] over it. Returns the PLL's angle less the reference angle in the block's
    /// middle [rad] (what the block's vectors are turned by into the PLL's frame), and
    /// steps the loop on the block's vector (where it has one).
    pub fn end_block(&mut self, d: &Demod, w_ref: f32) -> f32 {
        let t = self.rows as f32 * self.dt;
        self.rows = 0;
        let drift = (self.omega - w_ref) * t;
        let mut mid = wrap_angle(self.phi + 0.5 * drift);
        let mut end = wrap_angle(self.phi + drift);
        let (z, n) = match self.inv_v {
            Some(_) if d.n_v > 0 => (d.v, d.n_v),
            _ if d.n_i > 0 => (d.i, d.n_i),
            _ => {
                self.phi = end;
                return mid;
            }
        };
        let k = 1.0 / n as f32;
        let (re, im) = (z[0] * k, z[1] * k);
        let angle = im.atan2(re);
        if !angle.is_finite() {
            self.phi = end;
            return mid;
        }
        if !self.aligned {
            // The loop starts on the vector: its angle is the PLL's in the middle.
            end = wrap_angle(end + angle - mid);
            mid = angle;
            self.aligned = true;
        }
        let (s, c) = mid.sin_cos();
        let q = im * c - re * s;
        let e = match (self.inv_v, d.n_v > 0) {
            (Some(inv_v), true) => q * inv_v,
            _ => q / re.hypot(im),
        };
        if e.is_finite() {
            self.integ = (self.integ + self.ki * e * t).clamp(-self.w0, self.w0);
            self.omega = (self.w0 + self.integ + self.kp * e).clamp(0.0, 2.0 * self.w0);
        }
        self.phi = end;
        mid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block's sums of a vector of magnitude `m` at angle `a` [rad] on the reference
    /// angle, `n` samples, in the current lanes (and the voltage lanes with `v`).
    fn block(m: f32, a: f32, n: u32, v: bool) -> Demod {
        let z = [m * a.cos() * n as f32, m * a.sin() * n as f32];
        Demod {
            i: z,
            v: if v { z } else { [0.0; 2] },
            n_i: n,
            n_v: if v { n } else { 0 },
        }
    }

    /// A supply 1 Hz above the nominal 60 Hz, against a reference held at 60 Hz: the
    /// vector on the reference angle turns at 2 pi rad/s. The loop must find the
    /// frequency (a PI loop has no steady error for a frequency step) and hold its angle
    /// on the vector's in the block's middle.
    #[test]
    fn follows_a_frequency_offset() {
        let (dt, n) = (1e-4_f32, 21u32);
        let w0 = TAU * 60.0;
        for v in [false, true] {
            let mut pll = BlockPll::new(dt, 60.0, 10.0, v.then_some(100.0));
            let t_blk = n as f32 * dt;
            let mut mid = 0.0;
            let mut a_mid = 0.0;
            for b in 0..2000 {
                // The vector's angle in the block's middle (turning at 2 pi rad/s).
                a_mid = wrap_angle(TAU * (b as f32 + 0.5) * t_blk + 0.3);
                for _ in 0..n {
                    pll.row();
                }
                mid = pll.end_block(&block(100.0, a_mid, n, v), w0);
            }
            let w = pll.omega_rad_s();
            assert!((w - TAU * 61.0).abs() < 1e-2, "{w} rad/s (voltages {v})");
            assert!(wrap_angle(mid - a_mid).abs() < 1e-3, "{mid} vs {a_mid}");
        }
    }

    /// A block without good samples leaves the frequency alone; a gap moves the angle by
    /// the frequency difference over it.
    #[test]
    fn holds_over_empty_blocks_and_gaps() {
        let mut pll = BlockPll::new(1e-4, 50.0, 10.0, None);
        let w0 = TAU * 50.0;
        for _ in 0..25 {
            pll.row();
        }
        let mid = pll.end_block(&block(5.0, 1.0, 25, false), w0);
        assert!((mid - 1.0).abs() < 1e-6, "starts on the vector: {mid}");
        let w = pll.omega_rad_s();
        for _ in 0..25 {
            pll.row();
        }
        pll.end_block(&Demod::default(), w0);
        assert_eq!(pll.omega_rad_s(), w);
        // Held 1 rad/s above the reference over 0.5 s: half a radian.
        let mut fast = pll;
        fast.skip(0.5, w - 1.0);
        let d = wrap_angle(fast.phi - pll.phi);
        assert!((d - 0.5).abs() < 1e-5, "{d}");
    }
}
