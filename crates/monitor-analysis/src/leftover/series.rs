//! The model's error as the leftover reads it: one series per equation, each with the scale
//! it is normalised by and its white sensor noise.

use super::{Equation, EquationShare};
use crate::metrics::white_noise_sigma;
use crate::prep::{Prepared, C64};
use crate::simplified_model::Prediction;

/// Where an equation's error comes from.
enum ErrorSource<'a> {
    /// Model - measured, read from the two series when asked (no copy of a long log).
    Difference(&'a [f64], &'a [f64]),
    /// Computed once (the d axis: the current vectors' difference turned into the frame).
    Stored(Vec<f64>),
}

/// One equation's error series.
pub(super) struct Channel<'a> {
    /// The equation.
    pub(super) equation: Equation,
    /// Where its error comes from.
    source: ErrorSource<'a>,
    /// What it is normalised by: the RMS of what it measures [its unit].
    pub(super) scale: f64,
    /// The channel's white sensor noise [its unit].
    pub(super) noise: f64,
}

impl Channel<'_> {
    /// Its error at sample `k`, model - measured [its unit].
    #[inline]
    pub(super) fn e(&self, k: usize) -> f64 {
        match &self.source {
            ErrorSource::Difference(p, m) => p[k] - m[k],
            ErrorSource::Stored(v) => v[k],
        }
    }
}

/// The error of a prediction over a log, per equation.
pub(super) struct ErrorSeries<'a> {
    /// The equations present (q always; d when the model predicts it; the mechanics with a
    /// speed column).
    pub(super) channels: Vec<Channel<'a>>,
    /// Samples.
    len: usize,
}

impl<'a> ErrorSeries<'a> {
    /// The error of `p` against `d`; `None` when `p` does not cover `d` or a value is not
    /// finite.
    pub(super) fn of(d: &'a Prepared, p: &'a Prediction) -> Option<Self> {
        let n = d.len();
        if n < 16 || p.iq.len() < n || p.i_ab.len() < n || p.omega_r.len() < n {
            return None;
        }
        let rms = |x: &mut dyn Iterator<Item = f64>| {
            let (s, c) = x.fold((0.0, 0usize), |(s, c), v| (s + v * v, c + 1));
            (s / c.max(1) as f64).sqrt()
        };
        let i_scale = rms(&mut d.i_ab.iter().take(n).map(|c| c.norm())).max(1e-9);
        let mut channels = vec![Channel {
            equation: Equation::StatorQ,
            source: ErrorSource::Difference(&p.iq[..n], &d.iq[..n]),
            scale: i_scale,
            noise: white_noise_sigma(&d.iq),
        }];
        if p.predicts_d_axis && d.theta.len() >= n && d.id.len() >= n {
            let e = (0..n)
                .map(|k| ((p.i_ab[k] - d.i_ab[k]) * C64::from_polar(1.0, -d.theta[k])).re)
                .collect();
            channels.push(Channel {
                equation: Equation::StatorD,
                source: ErrorSource::Stored(e),
                scale: i_scale,
                noise: white_noise_sigma(&d.id),
            });
        }
        if d.channels.speed && d.omega_r.len() >= n {
            let scale = rms(&mut d.omega_r.iter().take(n).copied());
            if scale > 1e-9 {
                channels.push(Channel {
                    equation: Equation::Mechanics,
                    source: ErrorSource::Difference(&p.omega_r[..n], &d.omega_r[..n]),
                    scale,
                    noise: white_noise_sigma(&d.omega_r),
                });
            }
        }
        let finite = channels.iter().all(|c| (0..n).all(|k| c.e(k).is_finite()));
        finite.then_some(ErrorSeries { channels, len: n })
    }

    /// Samples.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The error's energy at sample `k`: the sum over the equations of the squared error
    /// over its scale.
    pub(super) fn energy_at(&self, k: usize) -> f64 {
        self.channels
            .iter()
            .map(|c| (c.e(k) / c.scale).powi(2))
            .sum()
    }

    /// Each equation's RMS error and its share of the mean square beyond the noise,
    /// largest first.
    pub(super) fn equation_shares(&self) -> Vec<EquationShare> {
        let n = self.len().max(1) as f64;
        let parts: Vec<(f64, f64)> = self
            .channels
            .iter()
            .map(|c| {
                let ms = (0..self.len).map(|k| c.e(k).powi(2)).sum::<f64>() / n;
                let excess = (ms - c.noise * c.noise).max(0.0) / (c.scale * c.scale);
                (ms.sqrt(), excess)
            })
            .collect();
        let total: f64 = parts.iter().map(|p| p.1).sum();
        let mut out: Vec<EquationShare> = self
            .channels
            .iter()
            .zip(parts)
            .map(|(c, (rms, excess))| EquationShare {
                equation: c.equation,
                rms_error: rms,
                unit: c.equation.unit(),
                normalized: rms / c.scale,
                noise: c.noise,
                share: if total > 0.0 { excess / total } else { 0.0 },
            })
            .collect();
        out.sort_by(|a, b| b.share.total_cmp(&a.share));
        out
    }
}
