//! Encoder speed by the M/T method.
//!
//! The encoder is a quadrature disc read by a hardware counter (x4 decoding, so a
//! 1024-line disc gives `counts_per_rev = 4096`). The counter is free running and `bits`
//! wide (16 for the STM32's TIM4, 32 on the host); every sample brings the raw counter and a
//! free-running `u32` timestamp in ticks of `tick_hz`.
//!
//! M/T method (Ohmae et al.): over a measurement window of at least `min_window_s`, count
//! the pulses `M` *and* measure the time `T` between the first and the last counter change
//! of the window, so both the count and the time are whole-edge quantities:
//!
//! `omega_m = 2 pi M / (counts_per_rev * T)`   [mechanical rad/s]
//!
//! Here the edge times are the sample timestamps at which the counter was seen to change,
//! so the timing uncertainty is one sample period `Ts`. Resolution therefore is:
//! - any speed with at least one edge per window: relative error <= Ts / T_window
//!   (10 kHz samples, default 50 ms window: 0.2 %; the count M is exact, so only the edge
//!   timing limits it, and the error averages out over successive windows);
//! - low speed: at 1 rad/s mechanical (652 counts/s) a 50 ms window holds about 33 counts,
//!   still 0.2 %; with fewer than one edge per window the window stretches to the next
//!   edge, so the estimate is one count over the edge interval, `2 pi / 4096 / T` rad/s;
//!   below `2 pi / (4096 * timeout_s)` (0.006 rad/s for the 0.25 s timeout) the speed
//!   reads 0.
//!
//! Wrap: differences are taken modulo `2^bits` as signed numbers, so a wrap of the counter
//! or of the timestamp is harmless as long as fewer than `2^(bits-1)` counts pass between
//! two samples (checked against `max_speed_rad_s`). Direction changes give negative `M`;
//! a window that holds a reversal gives the mean speed over it.

use core::f32::consts::TAU;

/// Configuration of the encoder speed estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncoderConfig {
    /// Counts per mechanical revolution after quadrature decoding (1024 lines x 4 = 4096).
    pub counts_per_rev: u32,
    /// Width of the hardware counter in bits, 8..=32 (TIM4 on the G474: 16).
    pub counter_bits: u8,
    /// Minimum M/T window [s], > 0 (default 0.05).
    pub min_window_s: f32,
    /// With no edge for this long the speed is 0 [s], > min_window_s (default 0.25).
    pub timeout_s: f32,
}

impl Default for EncoderConfig {
    fn default() -> Self {
        EncoderConfig {
            counts_per_rev: 4096,
            counter_bits: 32,
            min_window_s: 0.05,
            timeout_s: 0.25,
        }
    }
}

/// Signed difference `new - old` of two `bits`-wide counter readings (modulo 2^bits).
#[inline]
pub fn counter_delta(new: u32, old: u32, bits: u8) -> i32 {
    let shift = 32u32.saturating_sub(u32::from(bits.clamp(1, 32)));
    ((new.wrapping_sub(old) << shift) as i32) >> shift
}

/// M/T speed estimator. Feed it every sample with [`MtSpeed::update`].
#[derive(Debug, Clone, Copy)]
pub struct MtSpeed {
    rad_per_count: f32,
    s_per_tick: f32,
    bits: u8,
    min_window_ticks: u32,
    timeout_ticks: u32,
    started: bool,
    last_count: u32,
    /// Accumulated counts since the window's first edge.
    acc: i32,
    win_start_ticks: u32,
    last_edge_ticks: u32,
    speed_rad_s: f32,
    max_speed_rad_s: f32,
    /// Largest believable counter step per sample period (at `max_speed_rad_s`, plus 2).
    max_step: u32,
    /// Timestamp ticks per sample period.
    ticks_per_sample: u32,
}

impl MtSpeed {
    /// Builds the estimator; `tick_hz` is the timestamp rate, `max_speed_rad_s` the largest
    /// believable |speed| (a window whose estimate exceeds it is discarded and the previous
    /// estimate kept: timestamps that stalled while the encoder counted, not motion), `dt_s`
    /// the sample period (for [`MtSpeed::update_checked`]'s largest step per sample).
    /// Invalid settings are caught by [`crate::MonitorConfig::validate`] (which also checks
    /// that the largest step fits in half the counter's range).
    pub fn new(cfg: &EncoderConfig, tick_hz: f32, max_speed_rad_s: f32, dt_s: f32) -> Self {
        let cpr = cfg.counts_per_rev.max(1) as f32;
        MtSpeed {
            max_speed_rad_s,
            max_step: (max_speed_rad_s / TAU * cfg.counts_per_rev as f32 * dt_s) as u32 + 2,
            ticks_per_sample: (tick_hz * dt_s + 0.5) as u32,
            rad_per_count: TAU / cpr,
            s_per_tick: 1.0 / tick_hz,
            bits: cfg.counter_bits,
            min_window_ticks: (cfg.min_window_s * tick_hz) as u32,
            timeout_ticks: (cfg.timeout_s * tick_hz) as u32,
            started: false,
            last_count: 0,
            acc: 0,
            win_start_ticks: 0,
            last_edge_ticks: 0,
            speed_rad_s: 0.0,
        }
    }

    /// Feeds one sample: raw counter and timestamp. Returns the mechanical speed [rad/s].
    pub fn update(&mut self, count: u32, ticks: u32) -> f32 {
        if !self.started {
            self.start(count, ticks);
            return 0.0;
        }
        self.advance(
            counter_delta(count, self.last_count, self.bits),
            count,
            ticks,
        )
    }

    /// The first reading (or the first after a restart): the window starts here.
    fn start(&mut self, count: u32, ticks: u32) {
        self.started = true;
        self.last_count = count;
        self.win_start_ticks = ticks;
        self.last_edge_ticks = ticks;
    }

    /// A reading `d` counts after the last one: the window's count and time, the speed.
    fn advance(&mut self, d: i32, count: u32, ticks: u32) -> f32 {
        self.last_count = count;
        if d != 0 {
            self.acc = self.acc.saturating_add(d);
            self.last_edge_ticks = ticks;
            let span = ticks.wrapping_sub(self.win_start_ticks);
            if span >= self.min_window_ticks && span > 0 {
                let w = self.acc as f32 * self.rad_per_count / (span as f32 * self.s_per_tick);
                // Beyond the largest believable speed the time base, not the shaft, is
                // wrong (a stalled timer): the window is dropped, the estimate held.
                if w.abs() <= self.max_speed_rad_s {
                    self.speed_rad_s = w;
                }
                self.acc = 0;
                self.win_start_ticks = ticks;
            }
        } else {
            let idle = ticks.wrapping_sub(self.last_edge_ticks);
            if idle >= self.timeout_ticks {
                self.speed_rad_s = 0.0;
                self.acc = 0;
                self.win_start_ticks = ticks;
                self.last_edge_ticks = ticks;
            } else if idle > self.ticks_per_sample {
                // Between edges the speed cannot exceed one count per elapsed time: this
                // bounds the estimate while decelerating to a stop. An edge is seen only at
                // the sample after it and the sample times jitter by a tick, so one sample
                // period of the elapsed time is not counted (else a sample without a count
                // near one count per sample clamps the estimate by the jitter).
                let bound =
                    self.rad_per_count / ((idle - self.ticks_per_sample) as f32 * self.s_per_tick);
                if self.speed_rad_s.abs() > bound {
                    self.speed_rad_s = bound.copysign(self.speed_rad_s);
                }
            }
        }
        self.speed_rad_s
    }

    /// Like [`MtSpeed::update`], but a step of more counts per sample period than the
    /// largest believable speed allows (see [`MtSpeed::new`]) is not taken as motion: the
    /// estimator restarts from this reading and `None` is returned (the caller flags the
    /// speed sensor). Samples missing from the stream (a gap since the last counter change)
    /// allow a proportionally larger step. One counter difference per call.
    pub fn update_checked(&mut self, count: u32, ticks: u32) -> Option<f32> {
        if !self.started {
            self.start(count, ticks);
            return Some(0.0);
        }
        let d = counter_delta(count, self.last_count, self.bits);
        let step = d.unsigned_abs();
        if step > self.max_step && !self.step_fits_gap(step, ticks) {
            self.acc = 0;
            self.start(count, ticks);
            return None;
        }
        Some(self.advance(d, count, ticks))
    }

    /// Whether a large counter step is motion over a gap in the samples: the time since the
    /// last counter change holds enough sample periods for it.
    #[cold]
    fn step_fits_gap(&self, step: u32, ticks: u32) -> bool {
        let periods = ticks.wrapping_sub(self.last_edge_ticks) / self.ticks_per_sample.max(1);
        // A stalled or backward clock gives 0 or a wrapped, absurd count of periods.
        periods > 1
            && periods < (1 << 24)
            && u64::from(step) <= u64::from(self.max_step) * u64::from(periods)
    }

    /// Last speed estimate, mechanical [rad/s].
    pub fn speed_rad_s(&self) -> f32 {
        self.speed_rad_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn run(speed: f32, start_count: u32, start_tick: u32, bits: u8, seconds: f32) -> f32 {
        let cfg = EncoderConfig {
            counter_bits: bits,
            ..EncoderConfig::default()
        };
        let fs = 10_000.0f32;
        let tick_hz = 1_000_000.0;
        let mut mt = MtSpeed::new(&cfg, tick_hz, 1.0e4, 1.0 / fs);
        let n = (seconds * fs) as u32;
        let mut out = 0.0;
        for k in 0..n {
            let t = k as f64 / fs as f64;
            let pos = (speed as f64 * t / core::f64::consts::TAU * 4096.0).floor() as i64;
            let raw = (start_count as i64 + pos) as u32;
            let raw = if bits < 32 {
                raw & ((1u32 << bits) - 1)
            } else {
                raw
            };
            let ticks = start_tick.wrapping_add((t * tick_hz as f64) as u32);
            out = mt.update(raw, ticks);
        }
        out
    }

    proptest! {
        #[test]
        fn speed_is_right_across_counter_and_timer_wrap(
            speed in prop_oneof![-400f32..-2.0, 2f32..400.0],
            start in any::<u32>(),
            tick0 in any::<u32>(),
            bits in prop_oneof![Just(16u8), Just(32u8)],
        ) {
            let w = run(speed, start, tick0, bits, 0.3);
            // Timing quantised to 100 us over a >= 50 ms window: <= 0.2 % + one count.
            let tol = 0.003 * speed.abs() + TAU / 4096.0 / 0.05;
            prop_assert!((w - speed).abs() < tol, "speed {} estimate {}", speed, w);
        }
    }

    /// Near one count per sample a sample without a count must not clamp the estimate by
    /// the one-tick jitter of the sample times (-15.268 rad/s was read as -15.188: the
    /// bound of one count per 101 ticks between two samples 100 us apart).
    #[test]
    fn about_one_count_per_sample_is_not_clamped_by_tick_jitter() {
        for speed in [-15.268f32, 15.268, -15.309, -15.2, 15.0] {
            for tick0 in [0u32, 1, 7, 123_457, u32::MAX - 5_000] {
                let w = run(speed, 65_000, tick0, 16, 0.3);
                let tol = 0.003 * speed.abs() + TAU / 4096.0 / 0.05;
                assert!((w - speed).abs() < tol, "speed {speed} tick0 {tick0}: {w}");
            }
        }
    }

    #[test]
    fn delta_wraps_for_16_bit_counter() {
        assert_eq!(counter_delta(2, 65534, 16), 4);
        assert_eq!(counter_delta(65534, 2, 16), -4);
        assert_eq!(counter_delta(1, u32::MAX, 32), 2);
    }

    #[test]
    fn direction_change_and_stop() {
        let cfg = EncoderConfig::default();
        let mut mt = MtSpeed::new(&cfg, 10_000.0, 1.0e4, 1e-4);
        // 10 counts per sample (153 rad/s) for 0.2 s, then backwards for 0.2 s, then stop.
        let mut c: i64 = 0;
        let mut t: u32 = 0;
        let mut last = 0.0;
        for k in 0..4000u32 {
            c += if k < 2000 { 10 } else { -10 };
            last = mt.update(c as u32, t);
            t = t.wrapping_add(1);
            if k == 1999 {
                assert!((last - 1e5 * TAU / 4096.0).abs() < 2.0, "{last}");
            }
        }
        assert!((last + 1e5 * TAU / 4096.0).abs() < 2.0, "{last}");
        for _ in 0..3000 {
            last = mt.update(c as u32, t);
            t = t.wrapping_add(1);
        }
        assert_eq!(last, 0.0);
    }
}
