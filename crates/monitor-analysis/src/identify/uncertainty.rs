//! The identified values' uncertainty with the model's error in it: the Gauss-Newton
//! covariance `s^2 (J^T J)^-1` assumes white residuals, the sensors' noise alone; a model
//! that misses an effect of the real motor (saturation, heating, friction, a sensor's
//! chain) leaves residuals with structure, correlated over many samples, and the fit's
//! values then move with the parts of the log it weighs. The sandwich (heteroscedasticity
//! and autocorrelation consistent) covariance over blocks of the log measures that:
//!
//! ```text
//! Cov = A^-1 S A^-1,   A = J^T J,   S = nb/(nb - m) sum_b g_b g_b^T,   g_b = sum_{t in b} J_t r_t
//! ```
//!
//! with `nb` blocks of each length of [`BLOCK_S`] (Newey and West, Econometrica 55(3), 1987, the batch
//! form; Ljung, *System Identification*, 2nd ed., 9.6 on correlated residuals). Each
//! value's standard deviation is the larger of the two, and its 95 % interval takes
//! Student's t with `nb - m` degrees of freedom. White residuals give about the
//! Gauss-Newton figure; a model error that changes along the log widens it by what the
//! parts of the log disagree on.

use nalgebra::DMatrix;

/// Lengths of the blocks the residual's structure is judged over [s], the larger figure
/// taken: five supply periods at 50 Hz (longer than a residual's correlation within a
/// period; a few seconds of log give tens of blocks) and 0.4 s (the scale of a log's
/// steps and of heating or saturation that moves with them).
pub const BLOCK_S: [f64; 2] = [0.1, 0.4];
/// Fewest and most blocks: fewer leave the block covariance itself too uncertain, more
/// than a log needs.
const BLOCKS: (usize, usize) = (8, 200);

/// The log-space standard deviations of the `m` free parameters: the largest of the
/// white covariance's (`s2` times the diagonal of `A^+`) and the block sandwiches' (one per
/// block length), each scaled by Student's t over the normal's 1.96 (the interval
/// `exp(x +- 1.96 sigma)` is then the t interval). `cols` the Jacobian's columns, `r` the residuals (two per sample, alpha
/// and beta), `dt_s` the sample interval; `flat`: relative eigenvalue below which a
/// direction is flat (infinite sigma for every parameter in it by more than 1e-3).
pub fn sigmas_with_model_error(
    cols: &[Vec<f64>],
    r: &[f64],
    dt_s: f64,
    s2: f64,
    flat: f64,
) -> Vec<f64> {
    let m = cols.len();
    let a = DMatrix::from_fn(m, m, |i, j| {
        cols[i]
            .iter()
            .zip(&cols[j])
            .map(|(u, v)| u * v)
            .sum::<f64>()
    });
    let eig = a.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0f64, |t, e| t.max(e.abs()));
    // A^+ over the directions that are not flat, and which parameters a flat one involves.
    let mut pinv = DMatrix::<f64>::zeros(m, m);
    let mut infinite = vec![false; m];
    for (k, &lam) in eig.eigenvalues.iter().enumerate() {
        let u = eig.eigenvectors.column(k);
        if lam.is_nan() || lam <= flat * top {
            for (i, inf) in infinite.iter_mut().enumerate() {
                *inf |= u[i].abs() > 1e-3;
            }
        } else {
            pinv += u * u.transpose() / lam;
        }
    }
    let samples = r.len() / 2;
    let mut sigma: Vec<f64> = (0..m).map(|i| (s2 * pinv[(i, i)]).sqrt()).collect();
    for block_s in BLOCK_S {
        let nb = ((samples as f64 * dt_s / block_s).round() as usize).clamp(BLOCKS.0, BLOCKS.1);
        let s = block_scores(cols, r, nb);
        let dof = nb.saturating_sub(m).max(1);
        let sandwich = &pinv * (s * (nb as f64 / dof as f64)) * &pinv;
        let t = student_t_975(dof as f64) / 1.96;
        for (i, sg) in sigma.iter_mut().enumerate() {
            *sg = sg.max(t * sandwich[(i, i)].max(0.0).sqrt());
        }
    }
    sigma
        .into_iter()
        .zip(infinite)
        .map(|(sg, inf)| if inf { f64::INFINITY } else { sg })
        .collect()
}

/// `sum_b g_b g_b^T` over `nb` blocks of equal length (whole samples: two residuals each).
fn block_scores(cols: &[Vec<f64>], r: &[f64], nb: usize) -> DMatrix<f64> {
    let m = cols.len();
    let samples = r.len() / 2;
    let mut s = DMatrix::<f64>::zeros(m, m);
    for b in 0..nb {
        let (from, to) = (2 * (b * samples / nb), 2 * ((b + 1) * samples / nb));
        let g: Vec<f64> = cols
            .iter()
            .map(|c| {
                c.get(from..to)
                    .unwrap_or_default()
                    .iter()
                    .zip(r.get(from..to).unwrap_or_default())
                    .map(|(j, e)| j * e)
                    .sum()
            })
            .collect();
        for i in 0..m {
            for j in 0..m {
                s[(i, j)] += g[i] * g[j];
            }
        }
    }
    s
}

/// Student's t's 97.5 % quantile with `nu` degrees of freedom (Cornish-Fisher's expansion
/// about the normal's 1.96; within 0.2 % of the table from 5 degrees of freedom on).
pub fn student_t_975(nu: f64) -> f64 {
    let z: f64 = 1.959_964;
    let nu = nu.max(1.0);
    z + (z.powi(3) + z) / (4.0 * nu)
        + (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / (96.0 * nu * nu)
        + (3.0 * z.powi(7) + 19.0 * z.powi(5) + 17.0 * z.powi(3) - 15.0 * z) / (384.0 * nu.powi(3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_are_the_tables() {
        for (nu, t) in [
            (5.0, 2.5706),
            (10.0, 2.2281),
            (30.0, 2.0423),
            (120.0, 1.9799),
        ] {
            assert!(
                (student_t_975(nu) / t - 1.0).abs() < 0.005,
                "{nu}: {}",
                student_t_975(nu)
            );
        }
    }

    /// A straight line fitted to data with white noise: about the white figure; the same
    /// line with a slow wave on it (a model error): wider, by about what the wave moves the
    /// fitted mean over the blocks.
    #[test]
    fn structure_in_the_residuals_widens_the_interval_white_noise_does_not() {
        let n = 4000;
        let col: Vec<f64> = (0..2 * n).map(|_| 1.0).collect();
        let mut seed = 7u64;
        let mut noise = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.46
        };
        let white: Vec<f64> = (0..2 * n).map(|_| 0.01 * noise()).collect();
        let s2 = white.iter().map(|e| e * e).sum::<f64>() / (2 * n) as f64;
        let sig_w = sigmas_with_model_error(std::slice::from_ref(&col), &white, 1e-3, s2, 1e-9)[0];
        let gauss_newton = (s2 / (2 * n) as f64).sqrt();
        assert!(sig_w / gauss_newton < 1.3, "{sig_w} vs {gauss_newton}");
        let wave: Vec<f64> = (0..2 * n)
            .map(|t| 0.01 * (t as f64 / (2.0 * n as f64) * 6.0 * std::f64::consts::PI).sin())
            .collect();
        let s2 = wave.iter().map(|e| e * e).sum::<f64>() / (2 * n) as f64;
        let sig_s = sigmas_with_model_error(&[col], &wave, 1e-3, s2, 1e-9)[0];
        let gauss_newton = (s2 / (2 * n) as f64).sqrt();
        assert!(sig_s / gauss_newton > 5.0, "{sig_s} vs {gauss_newton}");
    }
}
