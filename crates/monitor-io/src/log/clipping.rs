//! Clipped sensors: a voltage or current channel whose readings sit at one extreme value
//! for a large share of the samples (the flat tops of a sensor or ADC driven past its full
//! scale).
//!
//! A clipped sine's fundamental is not the signal's: a +50 % voltage-sensor gain error on
//! a front end with 1.2 x headroom reads as +36 % (measured with the simulator's default
//! ranges), so every figure that rests on the amplitude (the residuals, the isolation's
//! sizes, the sequence analysis) would be wrong with no sign of it. The data-quality stage
//! ([`super::quality`]) counts, per channel, the samples equal to the channel's largest and
//! its smallest value that lie in a run of two or more such samples (a flat top; streaming:
//! the count restarts when a new extreme appears). A lone sample at the extreme is a peak,
//! not a flat top: a noise-free sine sampled at a whole number of samples per period (a
//! simulator's log at 1 kHz, 20 samples per 50 Hz period) repeats its peak value once per
//! period, 5 % of its samples, and was taken for a clip before runs were required. An
//! unclipped sine sampled by an `n`-bit ADC spends about `2 sqrt(2 / 2^(n-1)) / (2 pi)` of
//! its samples within one code of each peak (1 % at 12 bits, 4 % at 8 bits) and, with any
//! noise, far fewer at exactly one value; a sine clipped to `c` of its amplitude spends
//! `acos(c) / pi` at each flat top (19.5 % for the +50 % case above, 5 % when the peak is
//! 1.2 % over full scale). The share is over the whole log: a fault that clips for the
//! last 3 s of a 7.5 s log shows 7.8 %, and one that clips for less than a quarter of a
//! log can go unnoticed (a windowed count would find it; not done yet).

use super::Column;

/// A channel is clipped when more than this share of its samples equal its largest or its
/// smallest value (module docs: 4 % for an unclipped full-scale sine at 8 bits).
pub const CLIP_FRACTION: f64 = 0.05;

/// Fewer samples than this in a channel are not judged.
pub const MIN_SAMPLES: u64 = 1000;

/// One channel's extremes and how often each was seen.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Extremes {
    n: u64,
    max: f64,
    /// Samples at `max` in runs of two or more.
    n_max: u64,
    /// Length of the run at `max` that the last sample ended (0: the last was not at it).
    run_max: u64,
    min: f64,
    n_min: u64,
    run_min: u64,
}

/// One extreme's count after a sample: `run` is the length of the run at the extreme the
/// sample continues (0 when it is not at it), `count` the samples in runs of two or more;
/// a sample that sets a new extreme starts a run of one and the count again.
#[inline(always)]
fn count_run(count: u64, run: u64, new: bool, at: bool) -> (u64, u64) {
    let run = if new {
        1
    } else if at {
        run + 1
    } else {
        0
    };
    // The second sample of a run brings the first with it.
    let add = match run {
        2 => 2,
        r if r > 2 => 1,
        _ => 0,
    };
    (if new { 0 } else { count + add }, run)
}

impl Extremes {
    /// Counts one value (selects rather than jumps where it can: the reading thread calls
    /// it six times a row, with comparisons no predictor gets right at the extremes of a
    /// noisy sine).
    #[inline(always)]
    fn push(&mut self, x: f64) {
        // Strictly between the extremes (most samples; never the first, where they are
        // equal): both runs end, nothing else changes.
        if x < self.max && x > self.min {
            self.n += 1;
            self.run_max = 0;
            self.run_min = 0;
            return;
        }
        if self.n == 0 {
            *self = Extremes {
                n: 1,
                max: x,
                n_max: 0,
                run_max: 1,
                min: x,
                n_min: 0,
                run_min: 1,
            };
            return;
        }
        self.n += 1;
        let (gt, eq_max) = (x > self.max, x == self.max);
        (self.n_max, self.run_max) = count_run(self.n_max, self.run_max, gt, eq_max);
        self.max = if gt { x } else { self.max };
        let (lt, eq_min) = (x < self.min, x == self.min);
        (self.n_min, self.run_min) = count_run(self.n_min, self.run_min, lt, eq_min);
        self.min = if lt { x } else { self.min };
    }

    /// Counts a series of values, the state kept in registers. A series strictly between
    /// the extremes (most of a live channel's blocks) only ends the runs and adds to the
    /// count, as each value's [`Extremes::push`] would.
    #[inline]
    fn push_all(&mut self, xs: &[f64]) {
        let (max, min) = (self.max, self.min);
        let between = xs.iter().fold(true, |all, &x| all & (x < max) & (x > min));
        if between && !xs.is_empty() {
            self.n += xs.len() as u64;
            self.run_max = 0;
            self.run_min = 0;
            return;
        }
        let mut e = *self;
        for &x in xs {
            e.push(x);
        }
        *self = e;
    }

    /// The share of samples at the more frequent extreme and that value, when the channel
    /// is clipped: a channel that varies, with an extreme at least half its largest
    /// magnitude (a flat top, not a stuck zero).
    fn clipped(&self) -> Option<(f64, f64)> {
        if self.n < MIN_SAMPLES || self.max <= self.min {
            return None;
        }
        let peak = self.max.abs().max(self.min.abs());
        let (count, value) = if self.n_max >= self.n_min {
            (self.n_max, self.max)
        } else {
            (self.n_min, self.min)
        };
        let share = count as f64 / self.n as f64;
        (share > CLIP_FRACTION && value.abs() >= 0.5 * peak).then_some((share, value))
    }
}

/// The six analog channels' extremes (voltages a, b, c, currents a, b, c: the first six
/// of [`Column::MEASURED`]; zips stop at the six).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClipTracker {
    channels: [Extremes; 6],
}

impl ClipTracker {
    /// Counts one row's good cells (`good(c)`: the cell of `c` is finite and in range).
    pub fn push(&mut self, row: &super::Row, good: impl Fn(Column) -> bool) {
        let cols = Column::MEASURED;
        if let Some(v) = row.v_abc {
            for i in 0..3 {
                if good(cols[i]) {
                    self.channels[i].push(v[i]);
                }
            }
        }
        for i in 0..3 {
            if good(cols[3 + i]) {
                self.channels[3 + i].push(row.i_abc[i]);
            }
        }
    }

    /// Counts a block of rows whose cells are all good, channel by channel (`v`: the
    /// voltages a, b, c when the rows have them; `i`: the currents), the same counts as
    /// [`ClipTracker::push`] row by row.
    pub fn push_block(&mut self, v: Option<[&[f64]; 3]>, i: [&[f64]; 3]) {
        let (ev, ei) = self.channels.split_at_mut(3);
        if let Some(v) = v {
            for (e, xs) in ev.iter_mut().zip(v) {
                e.push_all(xs);
            }
        }
        for (e, xs) in ei.iter_mut().zip(i) {
            e.push_all(xs);
        }
    }

    /// The clipped channels: name, share of samples at the flat top, and its value.
    pub fn clipped(&self) -> Vec<(String, f64, f64)> {
        self.channels
            .iter()
            .zip(Column::MEASURED)
            .filter_map(|(e, c)| e.clipped().map(|(s, v)| (c.name().to_string(), s, v)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::Row;

    /// A 50 Hz sine of amplitude `a` at 5 kHz on every channel, clipped to `full_scale`,
    /// quantised to `bits`, with a little deterministic dither.
    fn rows(a: f64, full_scale: f64, bits: u32, n: usize) -> ClipTracker {
        let lsb = full_scale / f64::from(1u32 << (bits - 1));
        let mut t = ClipTracker::default();
        for k in 0..n {
            let th = std::f64::consts::TAU * 50.0 * k as f64 / 5000.0;
            let dither = 0.3 * lsb * ((k * 7919) % 13) as f64 / 13.0;
            let x = |ph: f64| {
                let y = (a * (th - ph).sin() + dither).clamp(-full_scale, full_scale);
                (y / lsb).round() * lsb
            };
            push_three_phase(&mut t, k as f64 / 5000.0, x);
        }
        t
    }

    /// One row of three phases `x(0)`, `x(2 pi/3)`, `x(-2 pi/3)` on the voltages and the
    /// currents at `t_s`.
    fn push_three_phase(t: &mut ClipTracker, t_s: f64, x: impl Fn(f64) -> f64) {
        let p = std::f64::consts::TAU / 3.0;
        let r = Row {
            t_s,
            v_abc: Some([x(0.0), x(p), x(-p)]),
            i_abc: [x(0.0), x(p), x(-p)],
            wm_rad_s: None,
            enc_count: None,
            t_winding_c: None,
        };
        t.push(&r, |_| true);
    }

    #[test]
    fn a_sine_within_full_scale_is_not_clipped_even_at_8_bits() {
        for bits in [8, 12, 16] {
            let c = rows(0.98, 1.0, bits, 20_000).clipped();
            assert!(c.is_empty(), "{bits} bits: {c:?}");
        }
    }

    #[test]
    fn a_sine_past_full_scale_is_clipped_with_the_share_of_its_flat_tops() {
        // 1.5 x clipped at 1.225: acos(1.225 / 1.5) / pi = 19.5 % at each flat top.
        let c = rows(1.5, 1.225, 12, 20_000).clipped();
        assert_eq!(c.len(), 6, "{c:?}");
        for (name, share, value) in &c {
            assert!((share - 0.195).abs() < 0.01, "{name}: {share}");
            assert!((value.abs() - 1.225).abs() < 1e-3, "{name}: {value}");
        }
        // 10 % over full scale: acos(1 / 1.1) / pi = 13.7 % at each top.
        let mild = rows(1.1, 1.0, 12, 20_000).clipped();
        assert_eq!(mild.len(), 6, "{mild:?}");
    }

    /// A noise-free sine sampled at 20 samples per period repeats its peak value once per
    /// period (5 % of the samples, each alone): a peak, not a flat top.
    #[test]
    fn a_noise_free_sine_at_whole_samples_per_period_is_not_clipped() {
        // 325 V peak at 20 samples per period (1 kHz, 50 Hz), clipped at `clip` volts.
        let sync = |clip: f64| {
            let mut t = ClipTracker::default();
            for k in 0..20_000 {
                let th = std::f64::consts::TAU * (k % 20) as f64 / 20.0;
                let x = |ph: f64| (325.0 * (th - ph).sin()).clamp(-clip, clip);
                push_three_phase(&mut t, k as f64 / 1000.0, x);
            }
            t.clipped()
        };
        let clean = sync(400.0);
        assert!(clean.is_empty(), "{clean:?}");
        // The same sine clipped at 90 % of its peak: flat tops of three samples.
        let clipped = sync(292.5);
        assert_eq!(clipped.len(), 6, "{clipped:?}");
    }

    #[test]
    fn a_constant_or_short_channel_is_not_judged() {
        let mut t = ClipTracker::default();
        for k in 0..5000 {
            let r = Row {
                t_s: k as f64,
                v_abc: Some([0.0; 3]),
                i_abc: [1.0, 0.0, -1.0],
                wm_rad_s: None,
                enc_count: None,
                t_winding_c: None,
            };
            t.push(&r, |_| true);
        }
        assert!(t.clipped().is_empty(), "{:?}", t.clipped());
        assert!(rows(1.5, 1.0, 12, 500).clipped().is_empty());
    }
}
