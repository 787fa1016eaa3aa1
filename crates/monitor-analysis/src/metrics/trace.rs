//! The model's error over time ([`error_over_time`]): what the ladder's charts draw falling
//! step by step.

use super::{measured, predicted};
use crate::prep::Prepared;
use crate::simplified_model::Prediction;

/// The most points [`error_over_time`] gives (a chart of 900 pixels draws no more).
pub const TRACE_POINTS: usize = 600;

/// The error of the prediction `p` over the log `d` in time: per bin of one supply period
/// (of the log's mean frame speed, 50 Hz where it does not turn), merged into at most
/// [`TRACE_POINTS`] bins, (the bin's mid time [s], its `normalized_rms_error`: each
/// channel's RMS error over the bin times its weight `inv_rms` (1 / the channel's RMS over
/// the whole log, [`super::Weights::inv_rms`]; 0 leaves a channel out), averaged over the
/// channels weighted). A bin whose error is not finite (a prediction that diverged) is
/// NaN; a prediction shorter than the log ends where it does.
pub fn error_over_time(d: &Prepared, p: &Prediction, inv_rms: &[f64; 5]) -> Vec<(f64, f64)> {
    let len = d
        .len()
        .min(p.iq.len())
        .min(p.i_ab.len())
        .min(p.omega_r.len());
    let channels = inv_rms.iter().filter(|w| **w > 0.0).count();
    if len == 0 || channels == 0 {
        return Vec::new();
    }
    let w_mean = d.omega_s.iter().take(len).map(|w| w.abs()).sum::<f64>() / len as f64;
    let f_hz = if w_mean > 1.0 {
        w_mean / std::f64::consts::TAU
    } else {
        50.0
    };
    let period = ((1.0 / (f_hz * d.dt_s.max(1e-9))).round() as usize).max(1);
    let bin = period.max(len.div_ceil(TRACE_POINTS));
    (0..len)
        .step_by(bin)
        .map(|a| {
            let b = (a + bin).min(len);
            let mut se = [0.0f64; 5];
            for k in a..b {
                let (m, q) = (measured(d, k), predicted(d, p, k));
                for c in 0..5 {
                    se[c] += (q[c] - m[c]).powi(2);
                }
            }
            let n = (b - a) as f64;
            let e = (0..5)
                .filter(|&c| inv_rms[c] > 0.0)
                .map(|c| (se[c] / n).sqrt() * inv_rms[c])
                .sum::<f64>()
                / channels as f64;
            (0.5 * (d.t_s[a] + d.t_s[b - 1]), e)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prep::C64;

    /// A log of `n` samples at 2 kHz and 50 Hz whose prediction is off by 1 A in I_qs
    /// from 1 s on.
    fn off_after_one_second(n: usize) -> (Prepared, Prediction) {
        let dt = 5e-4;
        let mut d = Prepared {
            dt_s: dt,
            ..Default::default()
        };
        let mut p = Prediction::default();
        for k in 0..n {
            let t = k as f64 * dt;
            d.t_s.push(t);
            d.omega_s.push(std::f64::consts::TAU * 50.0);
            d.iq.push(4.0);
            d.i_ab.push(C64::new(2.0, 4.0));
            d.i0.push(0.0);
            p.iq.push(if t >= 1.0 { 5.0 } else { 4.0 });
            p.omega_r.push(0.0);
            p.i_ab.push(C64::new(2.0, 4.0));
        }
        (d, p)
    }

    /// The trace is 0 before the error and the weighted error after, bin by bin (one
    /// supply period each), and a long log is merged down to [`TRACE_POINTS`] bins.
    #[test]
    fn the_trace_is_the_error_where_it_is() {
        let (d, p) = off_after_one_second(4000);
        // I_qs weighted 1 / 4 A, the phase currents left out.
        let w = [0.25, 0.0, 0.0, 0.0, 0.0];
        let tr = error_over_time(&d, &p, &w);
        // One supply period (40 samples) per bin: 100 bins.
        assert_eq!(tr.len(), 100);
        for &(t, e) in &tr {
            let want = if t > 1.0 { 0.25 } else { 0.0 };
            assert!((e - want).abs() < 1e-12, "{t}: {e}");
        }
        let (d, p) = off_after_one_second(100_000);
        let tr = error_over_time(&d, &p, &w);
        assert!(
            tr.len() <= TRACE_POINTS && tr.len() > TRACE_POINTS / 2,
            "{}",
            tr.len()
        );
        assert!(tr.windows(2).all(|w| w[1].0 > w[0].0));
    }
}
