//! The baseband's spectra: Welch segments of at most [`SEGMENT_S`] over the steady
//! stretch, each re-centred on its own mean supply frequency, windowed with the 4-term
//! Blackman-Harris window, zero-padded 4x and normalised by its line's power, so that a
//! tone `a` times the line's amplitude reads `a^2` at its peak (within 0.1 dB: 1/8 bin).

use super::baseband::Block;
use super::{BLACKMAN_HARRIS_4, MAIN_LOBE_HALF_BINS};
use rustfft::num_complex::Complex;
use std::f64::consts::{LN_2, TAU};
use std::ops::Range;

/// Longest Welch segment [s]: longer stretches are cut into segments of this length,
/// overlapping by half, whose spectra are read one by one (each at its own slip) and
/// averaged. 20 s resolve 0.05 Hz, 25 times the resolution the sidebands need at 1 % slip
/// and 50 Hz, while a slip that wanders slowly over minutes smears no peak.
pub const SEGMENT_S: f64 = 20.0;

/// The 4-term Blackman-Harris window [`BLACKMAN_HARRIS_4`] at sample `k` of `n`.
pub fn blackman_harris(k: usize, n: usize) -> f64 {
    let [a0, a1, a2, a3] = BLACKMAN_HARRIS_4;
    let x = TAU * k as f64 / n.max(1) as f64;
    a0 - a1 * x.cos() + a2 * (2.0 * x).cos() - a3 * (3.0 * x).cos()
}

/// The Welch segments of the blocks `r` ([`SEGMENT_S`] long, `seg_blocks` blocks, half
/// overlapping, the last ending at the stretch's end); the whole stretch when it is at
/// most twice that long.
pub(super) fn segments(r: Range<usize>, seg_blocks: usize) -> Vec<Range<usize>> {
    if r.len() <= 2 * seg_blocks {
        return vec![r];
    }
    let hop = (seg_blocks / 2).max(1);
    let mut out = Vec::new();
    let mut end = r.end;
    while end >= r.start + seg_blocks {
        out.push(end - seg_blocks..end);
        end -= hop;
    }
    out.reverse();
    out
}

/// One segment's power spectrum around the line, relative to the line's power.
#[derive(Debug, Clone)]
pub(super) struct Spectrum {
    /// Bin spacing [Hz] (a quarter of the resolution `1/T`).
    pub df: f64,
    /// The resolution `1/T` [Hz].
    pub resolution_hz: f64,
    /// Power per bin over the line's power, from `-nfft/2 df` to `(nfft/2 - 1) df`
    /// (bin `nfft/2` is 0 Hz: the line).
    pub power: Vec<f64>,
    /// The segment's mean supply frequency [Hz] and its mean slip (NaN without speed).
    pub f_supply: f64,
    /// See `f_supply`.
    pub slip: f64,
}

impl Spectrum {
    /// The bin of frequency `f` [Hz] (clamped to the spectrum).
    fn bin(&self, f: f64) -> usize {
        let mid = (self.power.len() / 2) as f64;
        (mid + (f / self.df).round()).clamp(0.0, self.power.len().saturating_sub(1) as f64) as usize
    }

    /// The largest power within `lo..=hi` [Hz]: (frequency [Hz], power).
    pub fn peak(&self, lo: f64, hi: f64) -> (f64, f64) {
        let mid = (self.power.len() / 2) as f64;
        let (a, b) = (self.bin(lo), self.bin(hi));
        self.power
            .get(a..=b.max(a))
            .unwrap_or(&[])
            .iter()
            .enumerate()
            .map(|(k, p)| (((a + k) as f64 - mid) * self.df, *p))
            .fold((0.5 * (lo + hi), 0.0), |m, x| if x.1 > m.1 { x } else { m })
    }

    /// The mean noise power per bin within `|f|` in `region` [Hz] outside the `skip`
    /// intervals: the median of those bins over the median-to-mean ratio of a power
    /// averaged over `averaged` spectra (`ln 2` for one; Wilson-Hilferty's
    /// `(1 - 1/(9K))^3` for `K`); `None` with fewer than 16 bins.
    pub fn noise(&self, region: (f64, f64), skip: &[(f64, f64)], averaged: usize) -> Option<f64> {
        let mid = (self.power.len() / 2) as f64;
        let mut v: Vec<f64> = (0..self.power.len())
            .filter_map(|k| {
                let f = (k as f64 - mid) * self.df;
                let inside = f.abs() >= region.0 && f.abs() <= region.1;
                let skipped = skip.iter().any(|&(lo, hi)| f >= lo && f <= hi);
                (inside && !skipped)
                    .then(|| self.power.get(k).copied())
                    .flatten()
            })
            .collect();
        if v.len() < 16 {
            return None;
        }
        let m = v.len() / 2;
        let (_, median, _) = v.select_nth_unstable_by(m, f64::total_cmp);
        let k = averaged.max(1) as f64;
        let ratio = if averaged <= 1 {
            LN_2
        } else {
            (1.0 - 1.0 / (9.0 * k)).powi(3)
        };
        Some(*median / ratio)
    }

    /// Adds `other`'s power (same length) into this one: a sum for an average.
    pub fn add(&mut self, other: &Spectrum) {
        for (a, b) in self.power.iter_mut().zip(&other.power) {
            *a += b;
        }
    }

    /// Divides the power by `k` (the end of an average).
    pub fn scale(&mut self, k: f64) {
        for a in &mut self.power {
            *a /= k;
        }
    }
}

/// The spectrum of the blocks `seg` (the current demodulated at `w0` [rad/s], blocks
/// `block_s` apart, mechanical speed over `np` pole pairs), re-centred on their mean
/// supply frequency and normalised by the line's power (the largest within
/// `MAIN_LOBE_HALF_BINS / 2` bins of 0 Hz); `None` without a line.
pub(super) fn spectrum(
    planner: &mut rustfft::FftPlanner<f64>,
    seg: &[Block],
    block_s: f64,
    w0: f64,
    np: f64,
) -> Option<Spectrum> {
    let n = seg.len();
    let first = seg.first()?;
    let w_mean = seg.iter().map(|b| f64::from(b.w_supply)).sum::<f64>() / n as f64;
    let slip = seg
        .iter()
        .map(|b| 1.0 - np * f64::from(b.wm) / f64::from(b.w_supply))
        .sum::<f64>()
        / n as f64;
    let nfft = (4 * n).next_power_of_two().max(16);
    let mut buf = vec![Complex::new(0.0, 0.0); nfft];
    let mut wsum = 0.0;
    for (k, (b, x)) in seg.iter().zip(buf.iter_mut()).enumerate() {
        let w = blackman_harris(k, n);
        wsum += w;
        let turn = Complex::from_polar(1.0, -(w_mean - w0) * (b.t_s - first.t_s));
        *x = Complex::new(f64::from(b.z[0]), f64::from(b.z[1])) * turn * w;
    }
    planner.plan_fft_forward(nfft).process(&mut buf);
    let scale = 1.0 / (wsum * wsum).max(1e-300);
    let half = nfft / 2;
    // fftshift: bin `half` is 0 Hz.
    let power: Vec<f64> = (0..nfft)
        .map(|k| {
            buf.get((k + half) % nfft)
                .map_or(0.0, |c| c.norm_sqr() * scale)
        })
        .collect();
    let df = 1.0 / (nfft as f64 * block_s);
    let mut s = Spectrum {
        df,
        resolution_hz: 1.0 / (n as f64 * block_s),
        power,
        f_supply: w_mean / TAU,
        slip,
    };
    let lobe = 0.5 * MAIN_LOBE_HALF_BINS * s.resolution_hz;
    let (_, line) = s.peak(-lobe, lobe);
    if line.is_nan() || line <= 0.0 {
        return None;
    }
    s.scale(line);
    Some(s)
}
