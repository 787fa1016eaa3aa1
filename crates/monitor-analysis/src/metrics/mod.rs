//! Error measures: per-channel RMS error, `normalized_rms_error`, worst windows, error
//! spectrum and the noise floor.
//!
//! Channels: `iqs_A` (I_qs, rotor-flux frame), `omega_r_rad_s` (electrical rotor speed,
//! when the log has `wm_rad_s`), `ia_A`, `ib_A`, `ic_A` (phase currents). Each channel's
//! RMS error is divided by that channel's measured RMS; `normalized_rms_error` is the mean
//! over the channels present (the JSON key's definition: `docs/design.md`).

use super::prep::{phase_values, Prepared, C64};
use super::simplified_model::Prediction;
use serde::Serialize;

mod noise;
mod trace;
mod worst;

pub use noise::white_noise_sigma;

pub use trace::{error_over_time, TRACE_POINTS};
pub use worst::{error_kind, windows, Condition, WorstWindow};

/// Channel names, in order.
pub const CHANNELS: [&str; 5] = ["iqs_A", "omega_r_rad_s", "ia_A", "ib_A", "ic_A"];

/// Per-channel normalisation and the training mask of a fit.
#[derive(Debug, Clone)]
pub struct Weights {
    /// 1 / RMS of each measured channel (0 for an absent channel).
    pub inv_rms: [f64; 5],
    /// Samples used by the fit (held-back windows are false).
    pub train: Vec<bool>,
    /// Use every `stride`-th sample in the fit's residuals.
    pub stride: usize,
}

fn phase_currents(d: &Prepared, k: usize, i_ab: C64) -> [f64; 3] {
    phase_values(i_ab, d.i0[k])
}

/// Measured values of the five channels at sample k (omega_r = 0 if absent).
pub fn measured(d: &Prepared, k: usize) -> [f64; 5] {
    let ph = phase_currents(d, k, d.i_ab[k]);
    [
        d.iq[k],
        d.omega_r.get(k).copied().unwrap_or(0.0),
        ph[0],
        ph[1],
        ph[2],
    ]
}

/// Predicted values of the five channels at sample k.
pub fn predicted(d: &Prepared, p: &Prediction, k: usize) -> [f64; 5] {
    let ph = phase_currents(d, k, p.i_ab[k]);
    [p.iq[k], p.omega_r[k], ph[0], ph[1], ph[2]]
}

impl Weights {
    /// Weights from the measured channel RMS; `holdout` = number of interleaved windows
    /// (0 = train on everything; n > 0: the log is cut into 2n windows and every second
    /// one is held back).
    pub fn new(d: &Prepared, holdout: usize, max_fit_samples: usize) -> Self {
        let inv = inv_rms_over(d, None);
        let len = d.len();
        let train = if holdout == 0 {
            vec![true; len]
        } else {
            let nw = 2 * holdout;
            (0..len)
                .map(|k| (k * nw / len.max(1)).is_multiple_of(2))
                .collect()
        };
        Weights {
            inv_rms: inv,
            train,
            stride: (len / max_fit_samples.max(1)).max(1),
        }
    }

    /// Number of channels present.
    pub fn n_channels(&self) -> usize {
        self.inv_rms.iter().filter(|&&v| v > 0.0).count()
    }

    /// Weighted residuals (training samples when `train_only`), scaled so that the sum of
    /// squares is comparable to `normalized_rms_error`^2 times the channel count.
    pub fn residuals(&self, d: &Prepared, p: &Prediction, train_only: bool) -> Vec<f64> {
        let mut r = Vec::with_capacity(5 * d.len() / self.stride + 5);
        let n_used = (0..d.len())
            .step_by(self.stride)
            .filter(|&k| !train_only || self.train[k])
            .count()
            .max(1) as f64;
        let norm = 1.0 / n_used.sqrt();
        for k in (0..d.len()).step_by(self.stride) {
            if train_only && !self.train[k] {
                continue;
            }
            if p.iq.len() <= k {
                for c in 0..5 {
                    if self.inv_rms[c] > 0.0 {
                        r.push(1e3);
                    }
                }
                continue;
            }
            let m = measured(d, k);
            let q = predicted(d, p, k);
            for c in 0..5 {
                if self.inv_rms[c] > 0.0 {
                    let e = (q[c] - m[c]) * self.inv_rms[c] * norm;
                    r.push(if e.is_finite() { e } else { 1e3 });
                }
            }
        }
        r
    }
}

/// RMS error of one channel.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelError {
    /// Channel name (`iqs_A`, ...).
    pub channel: String,
    /// RMS of the error (model - measured), in the channel's unit.
    pub rms_error: f64,
    /// RMS of the measured signal.
    pub rms_measured: f64,
    /// rms_error / rms_measured (by at least [`MIN_SCALE_OF_PREDICTED`] of the model's
    /// RMS).
    pub normalized: f64,
}

/// Channel errors over a set of samples.
#[derive(Debug, Clone, Serialize)]
pub struct ErrorSummary {
    /// Per channel.
    pub channels: Vec<ChannelError>,
    /// Mean of the channels' normalised errors.
    pub normalized_rms_error: f64,
}

/// The smallest normalisation of a channel's error in [`errors`], as a fraction of the
/// model's RMS of that channel: a measured RMS near zero (a dead sensor, a channel
/// recorded in the wrong unit) does not turn a large error into a small one.
pub const MIN_SCALE_OF_PREDICTED: f64 = 0.1;

/// Errors over the samples where `mask` is true (all when `None`): per channel the RMS
/// error over `max(RMS measured, `[`MIN_SCALE_OF_PREDICTED`]` x RMS predicted)`.
pub fn errors(d: &Prepared, p: &Prediction, mask: Option<&[bool]>) -> ErrorSummary {
    let mut se = [0.0f64; 5];
    let mut sm = [0.0f64; 5];
    let mut sp = [0.0f64; 5];
    let mut n = 0.0;
    for k in 0..d.len().min(p.iq.len()) {
        if let Some(m) = mask {
            if !m[k] {
                continue;
            }
        }
        let a = measured(d, k);
        let b = predicted(d, p, k);
        for c in 0..5 {
            se[c] += (b[c] - a[c]).powi(2);
            sm[c] += a[c] * a[c];
            sp[c] += b[c] * b[c];
        }
        n += 1.0;
    }
    let n = f64::max(n, 1.0);
    let mut channels = Vec::new();
    let mut sum = 0.0;
    for c in 0..5 {
        if c == 1 && !d.channels.speed {
            continue;
        }
        let rms_e = (se[c] / n).sqrt();
        let rms_m = (sm[c] / n).sqrt();
        // Normalised by the measured RMS, but never by less than a tenth of the model's:
        // a dead channel (all zero) is a 100 % misfit of a model that predicts current, not
        // a perfect fit divided by zero.
        let scale = rms_m.max(MIN_SCALE_OF_PREDICTED * (sp[c] / n).sqrt());
        let norm = if scale > 0.0 { rms_e / scale } else { 0.0 };
        sum += norm;
        channels.push(ChannelError {
            channel: CHANNELS[c].to_string(),
            rms_error: rms_e,
            rms_measured: rms_m,
            normalized: norm,
        });
    }
    let nc = channels.len().max(1) as f64;
    ErrorSummary {
        channels,
        normalized_rms_error: sum / nc,
    }
}

/// How far beyond the largest measured stator current a predicted one may go before the
/// prediction counts as diverged: 20 times (a locked-rotor current is 5-8 times rated; a
/// model that predicts 20 times the largest current the log holds has left the physics).
pub const DIVERGED_CURRENT_RATIO: f64 = 20.0;

/// Where the prediction `p` of the log `d` diverged: the time [s] of the first sample whose
/// predicted current vector exceeds [`DIVERGED_CURRENT_RATIO`] times the largest measured
/// one, or that is not finite, or where the prediction stops short of the log (a fit's
/// trial that blew up); `None` for a prediction that stays physical. An error measured
/// against a diverged prediction says nothing about the model (its normalisation caps it at
/// `1 / MIN_SCALE_OF_PREDICTED`), so it must not be reported as one.
pub fn diverged_at(d: &Prepared, p: &Prediction) -> Option<f64> {
    let n = d.len().min(d.i_ab.len());
    let i_max = d.i_ab.iter().take(n).map(|c| c.norm()).fold(0.0, f64::max);
    let limit = DIVERGED_CURRENT_RATIO * i_max.max(1e-9);
    let t = |k: usize| d.t_s.get(k).copied().unwrap_or(f64::NAN);
    if let Some(k) = p
        .i_ab
        .iter()
        .take(n)
        .position(|c| c.norm().is_nan() || c.norm() > limit)
    {
        return Some(t(k));
    }
    (p.i_ab.len() < n).then(|| t(p.i_ab.len()))
}

/// The sensor noise of the model's inputs on `d`, as white noise of that level with the
/// generator's `seed`: V_ds and V_qs share the mean of their two [`white_noise_sigma`]
/// [V], I_ds takes its own [A] (0 for a series that is absent). Read by the noise floor's
/// renoised run ([`noise_floor`]) and by SIMEX's refits (`crate::fit`).
pub fn input_noise(d: &Prepared, seed: u64) -> crate::simplified_model::InputNoise {
    crate::simplified_model::InputNoise {
        seed,
        sigma_v: 0.5 * (white_noise_sigma(&d.vd) + white_noise_sigma(&d.vq)),
        sigma_i: white_noise_sigma(&d.id),
    }
}

/// Noise floor: the `normalized_rms_error` a perfect model would show on this log.
///
/// Two parts, added in quadrature per channel:
/// - the noise of the measured outputs, from [`white_noise_sigma`] of I_qs and omega_r;
///   phase currents take sigma(I_qs) / sqrt(2): the predicted phase currents reuse the
///   measured I_ds, so only the q-axis noise shows in their error, spread over the
///   rotating phase;
/// - with `propagated = Some((pred, pred_renoised))`: the sensor noise of the model's
///   *inputs* (V_qs, V_ds, I_ds) carried through the model. A perfect model driven by noisy
///   inputs shows it too: `pred_renoised` is the same model driven by the measured inputs
///   plus a second, independent noise of the same size, so `pred_renoised - pred` has the
///   statistics of the propagated noise (on the 3 hp motor at 3x noise it is as large as
///   the output noise).
pub fn noise_floor(
    d: &Prepared,
    w: &Weights,
    propagated: Option<(&Prediction, &Prediction)>,
) -> f64 {
    normalized_noise(&channel_noise(d, propagated, None), &w.inv_rms)
}

/// [`noise_floor`] as [`errors`] with `Some(mask)` normalizes: the channels' noise over
/// the RMS of what was measured on the samples of `mask` (the held-back windows), and the
/// propagated part summed there. An error measured on the held-back windows is compared
/// with this, not with the whole log's floor: where a start's inrush current is in the
/// training windows, the held-back channels' RMS is smaller and the same noise is a larger
/// part of it (on an 11 kW start it was 1.6x the whole log's floor, and a missing effect
/// that took the error to the noise read as only 37 % explained).
pub fn noise_floor_on(
    d: &Prepared,
    mask: &[bool],
    propagated: Option<(&Prediction, &Prediction)>,
) -> f64 {
    let inv = inv_rms_over(d, Some(mask));
    normalized_noise(&channel_noise(d, propagated, Some(mask)), &inv)
}

/// 1 / RMS of each of the five measured channels ([`measured`]) over the samples `mask`
/// keeps (all when `None`); 0 for a channel that is absent (no speed column) or whose RMS
/// is below 1e-9 (it is then not weighted at all).
fn inv_rms_over(d: &Prepared, mask: Option<&[bool]>) -> [f64; 5] {
    let mut sm = [0.0f64; 5];
    let mut n = 0usize;
    for k in 0..d.len() {
        if mask.is_some_and(|m| !m.get(k).copied().unwrap_or(false)) {
            continue;
        }
        let m = measured(d, k);
        for c in 0..5 {
            sm[c] += m[c] * m[c];
        }
        n += 1;
    }
    std::array::from_fn(|c| {
        let rms = (sm[c] / n.max(1) as f64).sqrt();
        if rms > 1e-9 && (c != 1 || d.channels.speed) {
            1.0 / rms
        } else {
            0.0
        }
    })
}

/// The noise of each of the five channels of [`errors`] in their units (see
/// [`noise_floor`]); the propagated part is summed over `mask`'s samples when given.
fn channel_noise(
    d: &Prepared,
    propagated: Option<(&Prediction, &Prediction)>,
    mask: Option<&[bool]>,
) -> [f64; 5] {
    let s_iq = white_noise_sigma(&d.iq);
    let s_w = white_noise_sigma(&d.omega_r);
    // A model whose current vector is its own shows both axes' noise in each phase
    // current's error (s^2 cos^2 + s^2 sin^2); one that takes the measured I_ds only the
    // q axis's, spread over the rotating phase (s^2 sin^2, mean s^2 / 2).
    let own_d = propagated.is_some_and(|(a, _)| a.predicts_d_axis);
    let s_ph = if own_d { s_iq } else { s_iq / 2f64.sqrt() };
    let mut s = [s_iq, s_w, s_ph, s_ph, s_ph];
    if let Some((a, b)) = propagated {
        let mut se = [0.0f64; 5];
        let mut count = 0usize;
        let n = d.len().min(a.iq.len()).min(b.iq.len());
        for k in 0..n {
            if mask.is_some_and(|m| !m.get(k).copied().unwrap_or(false)) {
                continue;
            }
            let pa = predicted(d, a, k);
            let pb = predicted(d, b, k);
            for c in 0..5 {
                se[c] += (pb[c] - pa[c]).powi(2);
            }
            count += 1;
        }
        for c in 0..5 {
            s[c] = (s[c] * s[c] + se[c] / count.max(1) as f64).sqrt();
        }
    }
    s
}

/// The mean over the present channels (`inv_rms` > 0) of noise / RMS.
fn normalized_noise(s: &[f64; 5], inv_rms: &[f64; 5]) -> f64 {
    let mut sum = 0.0;
    let mut c = 0.0;
    for k in 0..5 {
        if inv_rms[k] > 0.0 {
            sum += s[k] * inv_rms[k];
            c += 1.0;
        }
    }
    if c > 0.0 {
        sum / c
    } else {
        0.0
    }
}

/// In-place forward FFT, unnormalised (`X_k = sum x_n e^{-2 pi j k n / N}`), by `rustfft`
/// (any length; the callers use powers of two).
pub fn fft(x: &mut [C64]) {
    thread_local! {
        // Plans (twiddles, algorithm choice) are kept per length and thread.
        static PLANNER: std::cell::RefCell<rustfft::FftPlanner<f64>> =
            std::cell::RefCell::new(rustfft::FftPlanner::new());
    }
    if x.len() < 2 {
        return;
    }
    let plan = PLANNER.with(|p| p.borrow_mut().plan_fft_forward(x.len()));
    plan.process(x);
}

/// Amplitude spectrum (Hann window, averaged over segments of up to 8192 samples):
/// (frequency [Hz], amplitude) pairs up to Nyquist.
pub fn spectrum(x: &[f64], dt: f64) -> Vec<(f64, f64)> {
    let mut n = 1usize;
    while n * 2 <= x.len().min(8192) {
        n *= 2;
    }
    if n < 16 {
        return vec![];
    }
    let segs = (x.len() / n).max(1);
    let mut acc = vec![0.0; n / 2];
    let win: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos())
        .collect();
    for s in 0..segs {
        let seg = &x[s * n..(s + 1) * n];
        let mean = seg.iter().sum::<f64>() / n as f64;
        let mut buf: Vec<C64> = seg
            .iter()
            .zip(&win)
            .map(|(v, w)| C64::new((v - mean) * w, 0.0))
            .collect();
        fft(&mut buf);
        for k in 0..n / 2 {
            acc[k] += buf[k].norm() * 4.0 / n as f64;
        }
    }
    (0..n / 2)
        .map(|k| (k as f64 / (n as f64 * dt), acc[k] / segs as f64))
        .collect()
}

/// Dominant frequency of a signal segment [Hz]: the largest bin of the Hann-windowed
/// spectrum, with the mean (DC) compared against it: returns 0 when the mean dominates.
pub fn dominant_frequency(x: &[f64], dt: f64) -> f64 {
    if x.len() < 16 {
        return 0.0;
    }
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    // Hann window, zero-padded to at least 4x the length (bin spacing well below 2f).
    let mut m = 1usize;
    while m < 4 * n {
        m *= 2;
    }
    let mut buf = vec![C64::new(0.0, 0.0); m];
    let mut wsum = 0.0;
    for k in 0..n {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos();
        wsum += w;
        buf[k] = C64::new((x[k] - mean) * w, 0.0);
    }
    fft(&mut buf);
    // The largest bin by its squared magnitude (no square root per bin), then its amplitude.
    let mut best = (0usize, 0.0);
    for k in 1..m / 2 {
        let a2 = buf[k].norm_sqr();
        if a2 > best.1 {
            best = (k, a2);
        }
    }
    let best = (
        best.0 as f64 / (m as f64 * dt),
        buf[best.0].norm() * 2.0 / wsum.max(1e-12),
    );
    if best.0 == 0.0 || mean.abs() > best.1 {
        0.0
    } else {
        best.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_matches_the_dft() {
        let n = 64;
        let x: Vec<C64> = (0..n)
            .map(|k| C64::new((k as f64 * 0.37).sin(), (k as f64 * 0.11).cos() - 0.2))
            .collect();
        let mut y = x.clone();
        fft(&mut y);
        for (f, yf) in y.iter().enumerate() {
            let d: C64 = x
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    v * C64::from_polar(
                        1.0,
                        -2.0 * std::f64::consts::PI * (f * k) as f64 / n as f64,
                    )
                })
                .sum();
            assert!((d - yf).norm() < 1e-10, "{f}: {d} vs {yf}");
        }
    }

    #[test]
    fn dominant_frequency_finds_a_tone() {
        let dt = 1e-3;
        let x: Vec<f64> = (0..2000)
            .map(|k| (2.0 * std::f64::consts::PI * 100.0 * k as f64 * dt).sin())
            .collect();
        let f = dominant_frequency(&x, dt);
        assert!((f - 100.0).abs() < 0.5, "{f}");
    }

    /// White noise of a known sigma on a signal with a large 100 Hz ripple (an unbalanced
    /// machine's I_qs at a 2 kHz working rate) and a step: the estimate is the noise's sigma.
    #[test]
    fn noise_sigma_ignores_ripple_and_steps() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let sigma = 0.03;
        let noise = Normal::new(0.0, sigma).unwrap();
        let x: Vec<f64> = (0..20_000)
            .map(|k| {
                let t = k as f64 / 2000.0;
                let step = if k > 10_000 { 2.0 } else { 0.0 };
                5.0 + step
                    + 1.0 * (2.0 * std::f64::consts::PI * 100.0 * t).sin()
                    + noise.sample(&mut rng)
            })
            .collect();
        let s = white_noise_sigma(&x);
        assert!(
            (s / sigma - 1.0).abs() < 0.08,
            "estimated {s}, true {sigma}"
        );
    }
}
