//! The sensors' white noise in a measured series, apart from what is periodic in it.

use super::fft;
use crate::prep::C64;

/// Robust white-noise estimate of a series [its unit]: the smaller of two estimates when
/// the second is clearly smaller, else the first.
///
/// 1. **The fourth difference**: sigma = 1.4826 MAD(D^4 x) / sqrt(70), the median absolute
///    deviation of the fourth difference (70 = C(8,4), its variance gain on white noise). A
///    smooth signal and sparse steps do not move it; the fourth (not the second) difference
///    also ignores a 2f ripple, which an unbalanced machine puts on I_qs (0.1 A of second
///    difference per A of 100 Hz ripple at 2 kHz, as much as the sensor noise; 0.01 A with
///    the fourth). A line high in the band does move it: the supply's 5th and 7th
///    harmonics (6f in the machine's frame, 300 Hz at 50 Hz) pass a fourth difference at
///    1.4 kHz 2.4x, and 3 % of the voltage in them read as 10x the sensors' noise.
/// 2. **The spectrum's low quantile** ([`spectral_sigma`]): lines (the harmonics, the 2f of
///    an unbalance, a broken bar's 2sf) occupy a few bins of a long segment's spectrum,
///    the sensors' noise all of them.
///
/// The second replaces the first only below [`SPECTRAL_TAKES_OVER`] of it: on white noise
/// the two agree within a few per cent, and the first is the one every floor was measured
/// with; a log whose lines inflate the first by a quarter or more reads the second.
/// Fewer than 9 samples: 0.
pub fn white_noise_sigma(x: &[f64]) -> f64 {
    let d4 = fourth_difference_sigma(x);
    match spectral_sigma(x) {
        Some(s) if s < SPECTRAL_TAKES_OVER * d4 => s,
        _ => d4,
    }
}

/// Below this share of the fourth difference's estimate the spectrum's is taken
/// ([`white_noise_sigma`]).
pub const SPECTRAL_TAKES_OVER: f64 = 0.8;

/// Segment length of [`spectral_sigma`]: 2048 samples (0.7 Hz bins at 1.4 kHz; a Hann
/// line with the sidelobes above the noise of a 3 % harmonic spans about 17 bins of 1024).
const SEGMENT: usize = 2048;
/// The quantile of the bins' powers [`spectral_sigma`] reads: low, so that a share of bins
/// taken by lines moves it little (13 % of the bins lines: sigma +8 %).
const QUANTILE: f64 = 0.2;
/// Bins from DC left out (what the segment's linear trend leaves, the Hann main lobe).
const LOW_BINS: usize = 4;

/// The fourth difference's estimate ([`white_noise_sigma`], 1).
fn fourth_difference_sigma(x: &[f64]) -> f64 {
    if x.len() < 9 {
        return 0.0;
    }
    let mut dd: Vec<f64> = x
        .windows(5)
        .map(|v| (v[4] - 4.0 * v[3] + 6.0 * v[2] - 4.0 * v[1] + v[0]).abs())
        .collect();
    let mid = dd.len() / 2;
    let (_, m, _) = dd.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    1.4826 * *m / 70f64.sqrt()
}

/// The white noise of `x` from its spectrum: non-overlapping segments of [`SEGMENT`]
/// samples (half of `x` when shorter, at least 256), each detrended (its least-squares
/// line removed) and Hann-windowed; over every bin from [`LOW_BINS`] to below Nyquist of
/// every segment, the [`QUANTILE`] of the power `|X_k|^2`. For white noise of variance
/// sigma^2 each `|X_k|^2` is exponential with mean sigma^2 sum(w^2) (sum(w^2) = 3L/8 for
/// Hann), so sigma^2 = quantile / (-ln(1 - q) sum(w^2)). `None` for fewer than 512 samples.
pub fn spectral_sigma(x: &[f64]) -> Option<f64> {
    let mut l = 256usize;
    while l * 2 <= SEGMENT && l * 4 <= x.len() {
        l *= 2;
    }
    if x.len() < 2 * l {
        return None;
    }
    let w: Vec<f64> = (0..l)
        .map(|n| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * n as f64 / l as f64).cos())
        .collect();
    let sw2: f64 = w.iter().map(|v| v * v).sum();
    let mut powers = Vec::with_capacity((x.len() / l) * (l / 2));
    let mut buf = vec![C64::default(); l];
    for seg in x.chunks_exact(l) {
        // The segment's least-squares line: mean and slope about its middle.
        let mid = 0.5 * (l as f64 - 1.0);
        let mean = seg.iter().sum::<f64>() / l as f64;
        let (sxy, sxx) = seg.iter().enumerate().fold((0.0, 0.0), |(a, b), (n, v)| {
            let t = n as f64 - mid;
            (a + t * (v - mean), b + t * t)
        });
        let slope = sxy / sxx;
        for (n, (b, v)) in buf.iter_mut().zip(seg).enumerate() {
            *b = C64::new((v - mean - slope * (n as f64 - mid)) * w[n], 0.0);
        }
        fft(&mut buf);
        powers.extend(buf[LOW_BINS..l / 2].iter().map(|c| c.norm_sqr()));
    }
    if powers.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let k = ((powers.len() as f64 * QUANTILE) as usize).min(powers.len() - 1);
    let (_, q, _) = powers.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    Some((*q / (-(1.0 - QUANTILE).ln() * sw2)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use std::f64::consts::PI;

    /// `n` samples at 1.4 kHz of white noise `sigma` on a DC level, with `lines` (amplitude,
    /// frequency [Hz]) added.
    fn series(n: usize, sigma: f64, lines: &[(f64, f64)], seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let noise = Normal::new(0.0, sigma).unwrap();
        (0..n)
            .map(|k| {
                let t = k as f64 / 1400.0;
                let l: f64 = lines
                    .iter()
                    .map(|(a, f)| a * (2.0 * PI * f * t).sin())
                    .sum();
                320.0 + l + noise.sample(&mut rng)
            })
            .collect()
    }

    #[test]
    fn the_spectrum_reads_white_noise_as_the_fourth_difference_does() {
        for (n, seed) in [
            (20_000, 2),
            (100_000, 3),
            (2800, 1),
            (2800, 5),
            (2800, 6),
            (2800, 7),
        ] {
            let x = series(n, 0.5, &[], seed);
            let s = spectral_sigma(&x).unwrap();
            let d = fourth_difference_sigma(&x);
            let tol = if n < 10_000 { 0.12 } else { 0.04 };
            assert!((s / 0.5 - 1.0).abs() < tol, "n {n}: spectrum {s}");
            assert!((d / 0.5 - 1.0).abs() < 0.06, "n {n}: fourth difference {d}");
            // White noise: the estimate is the fourth difference's, as before.
            assert_eq!(white_noise_sigma(&x), d, "n {n}");
        }
    }

    /// A supply's 5th and 7th harmonics and its 11th in the machine's frame (6f and 12f at
    /// 50 Hz: 300 and 600 Hz), a 2f ripple and a slow line, at 2 s and 1.4 kHz: the
    /// fourth difference reads them as noise many times the sensors', the estimate does not.
    #[test]
    fn lines_high_in_the_band_are_not_noise() {
        let lines = [(9.8, 300.0), (2.6, 600.0), (1.5, 100.0), (0.8, 4.4)];
        let x = series(2800, 0.5, &lines, 4);
        let d = fourth_difference_sigma(&x);
        assert!(
            d > 3.0 * 0.5,
            "the fourth difference {d}: the lines no longer inflate it"
        );
        let s = white_noise_sigma(&x);
        assert!((s / 0.5 - 1.0).abs() < 0.15, "estimated {s}, true 0.5");
    }

    #[test]
    fn short_series_have_no_spectral_estimate() {
        assert_eq!(spectral_sigma(&[1.0; 400]), None);
        assert_eq!(white_noise_sigma(&[1.0; 5]), 0.0);
    }
}
