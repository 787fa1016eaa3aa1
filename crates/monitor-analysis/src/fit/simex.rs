//! SIMEX (simulation-extrapolation, Cook and Stefanski, J. Am. Stat. Assoc. 89(428), 1994):
//! the correction of a fit whose values are biased by the sensor noise of the model's
//! *inputs* (errors in variables).
//!
//! The output-error fit drives the model with the measured voltages and I_ds, noise and all.
//! That noise, carried through the model, is part of the prediction's error, and how much of
//! it reaches the currents depends on the values being fitted: near 0 Hz in the stationary
//! frame the machine's admittance is about 1/Rs, so a larger resistance passes less of it.
//! The fit then buys a lower error with a resistance that is too high. On the 3 hp machine
//! warming by 50 K over 40 s at 2 kHz with 0.5 V of voltage noise, the thermal drift's rise
//! came out 112 K, and 49 K with 0.05 V.
//!
//! SIMEX measures the bias instead of modelling it: the fit is repeated with more noise of
//! the same kind added to the inputs (a variance of `lambda` times the measured one, for
//! `lambda` = 1 and 2, [`LAMBDAS`]), each value is read as a function of the total noise
//! variance `1 + lambda`, and a quadratic through the three points is extrapolated to
//! `lambda = -1`, no noise: `x(-1) = 3 x(0) - 3 x(1) + x(2)`.

use super::lm::{self, LeastSquares};
use crate::metrics;
use crate::prep::Prepared;
use crate::simplified_model::InputNoise;

/// The added noise variances, in units of the measured inputs' noise variance.
pub const LAMBDAS: [f64; 2] = [1.0, 2.0];

/// The least share of the fit's squared error that the inputs' noise, added once more,
/// adds to it, for the correction to run: below it the bias is small and the refits are
/// not worth their time. On the ladder benchmark's log (2.2 kW, 10 kHz, 12-bit sensors) the
/// drift's fits see 0.04-0.06 and the correction moved its 60 K rise by 0.09 K, while it
/// doubled the ladder's CPU time; on the 3 hp log of the module's doc 0.85-0.92.
pub const SHARE_MIN: f64 = 0.1;

/// The seed of the added noise: fixed, so that a fit is reproducible and its objective a
/// smooth function of the values. Both refits take the same draw, scaled (common random
/// numbers): on the 3 hp log of the module's doc, four seeds gave rises of 58-61 K so, and
/// 52-65 K with a draw of its own for each refit.
const SEED: u64 = 0x5349_4d45_5800;

/// The SIMEX values for a fit on `d` that ended at `x` (`bounds`, `free` and `max_iter` as
/// that fit's): the same problem with extra input noise (`renoised`, handed the noise to
/// add) refitted at [`LAMBDAS`] from `x`, each free value extrapolated to no input noise
/// and clamped to the bounds. `None` where the log's inputs carry no measurable noise
/// (nothing to correct), where that noise added once more adds less than [`SHARE_MIN`] of
/// the squared error at `x` (`renoised` with no noise is the fit's own problem), or where
/// an extrapolated value is not finite.
pub(super) fn corrected<P, F>(
    d: &Prepared,
    renoised: F,
    x: &[f64],
    bounds: &lm::Bounds,
    free: &[usize],
    max_iter: usize,
) -> Option<Vec<f64>>
where
    P: LeastSquares + Sync,
    F: Fn(InputNoise) -> P + Sync,
{
    let measured = metrics::input_noise(d, SEED);
    if measured.sigma_v.is_nan() || measured.sigma_v <= 0.0 && measured.sigma_i <= 0.0 {
        return None;
    }
    let cost = |p: &P| {
        p.residuals(x, &p.cache(x))
            .iter()
            .map(|r| r * r)
            .sum::<f64>()
    };
    let once = renoised(InputNoise {
        seed: SEED,
        ..measured
    });
    let share = {
        let plain = renoised(InputNoise {
            seed: SEED,
            sigma_v: 0.0,
            sigma_i: 0.0,
        });
        let (c0, c1) = (cost(&plain), cost(&once));
        (c1 - c0) / c0
    };
    if share.is_nan() || share < SHARE_MIN {
        return None;
    }
    let refit = |lambda: f64| {
        let noisy = renoised(InputNoise {
            seed: SEED,
            sigma_v: measured.sigma_v * lambda.sqrt(),
            sigma_i: measured.sigma_i * lambda.sqrt(),
        });
        lm::solve(&noisy, x.to_vec(), bounds, free, max_iter).0
    };
    let (x1, x2) = rayon::join(|| refit(LAMBDAS[0]), || refit(LAMBDAS[1]));
    let mut out = x.to_vec();
    for &i in free {
        let v = 3.0 * x[i] - 3.0 * x1[i] + x2[i];
        if !v.is_finite() {
            return None;
        }
        out[i] = v.clamp(bounds.lo[i], bounds.hi[i]);
    }
    Some(out)
}
