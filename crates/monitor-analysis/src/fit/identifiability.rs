//! How well a log identifies the base parameters: the fit's data Jacobian at the fitted
//! point, its rank and conditioning, and each base parameter's sensitivity with every other
//! value refitted to compensate (`compare`'s `identifiability`).

use super::{paired, ActiveEffect, BaseSpec, FitResult, Problem};
use crate::effects::EffectValuesError;
use crate::metrics::Weights;
use crate::prep::Prepared;
use crate::simplified_model::{BaseParameter, MachineConstants};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// How well a log identifies one base parameter (`compare`'s `identifiability`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ParameterSensitivity {
    /// Base parameter (its key as in `base_parameters`).
    pub parameter: BaseParameter,
    /// Change of the model error (normalized, root-sum over the channels) that a 10 %
    /// change of this parameter causes when every other fitted parameter is refitted to
    /// compensate: `0.1 |x_i| / sqrt((J^T J)^-1_ii)`, J the Jacobian of the data residuals
    /// (no priors) at the fit. Small: the log cannot tell the parameter's value.
    pub error_change_per_10_percent: f64,
    /// True when that change is at least [`IDENTIFIED_MIN`].
    pub identified: bool,
}

/// A 10 % change that moves the model error by less than this (0.4 % normalized error,
/// about the frame estimate's own accuracy on noise-free data) is not identified.
pub const IDENTIFIED_MIN: f64 = 0.004;

/// Rank and conditioning of the fit's data Jacobian, and per-parameter sensitivities.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Jacobian {
    /// Free parameters of the fit (base and effect parameters).
    pub n_parameters: usize,
    /// Numerical rank of the relative Jacobian (singular values above 1e-6 of the largest).
    pub rank: usize,
    /// Condition number of the relative Jacobian (largest over smallest singular value;
    /// each column scaled by its parameter's magnitude).
    pub condition_number: f64,
    /// The four base parameters.
    pub base: Vec<ParameterSensitivity>,
}

/// The data Jacobian at the fitted point `f` (forward differences, in parallel), relative
/// to each parameter's magnitude, and what it says about the base parameters. `None` when
/// the base parameters were not fitted.
///
/// # Errors
/// As [`terms`]: the fitted values do not match the effects.
pub fn jacobian(
    d: &Prepared,
    n: &MachineConstants,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    f: &FitResult,
    fit_base: bool,
) -> Result<Option<Jacobian>, EffectValuesError> {
    if !fit_base {
        return Ok(None);
    }
    // Data residuals only: the priors are not information from the log.
    let prob = Problem::new(d, n, effects, w, BaseSpec::FIXED);
    let bs = prob.btot_scale;
    let mut x = vec![
        f.base.ra_scale,
        f.base.ls_scale,
        f.base.btot_nms,
        f.base.j_scale,
    ];
    let mut mag = vec![1.0, 1.0, f.base.btot_nms.abs().max(0.1 * bs), 1.0];
    for (e, p) in paired(effects, &f.effect_params)? {
        x.extend_from_slice(p);
        for (v, q) in p.iter().zip(&e.setup.params) {
            mag.push(v.abs().max(q.scale));
        }
    }
    prob.terms(&x)?;
    let g = Gram::of(&relative_columns(&prob, &x, &mag));
    let base = BaseParameter::ALL
        .iter()
        .enumerate()
        .map(|(i, &name)| {
            let inv = g.inverse_diagonal(i);
            let ch = if inv.is_finite() && inv > 0.0 {
                0.1 / inv.sqrt()
            } else {
                0.0
            };
            ParameterSensitivity {
                parameter: name,
                error_change_per_10_percent: ch,
                identified: ch >= IDENTIFIED_MIN,
            }
        })
        .collect();
    Ok(Some(Jacobian {
        n_parameters: x.len(),
        rank: g.rank(),
        condition_number: g.condition_number(),
        base,
    }))
}

/// The Jacobian's columns at `x`, each relative to its parameter's magnitude `mag`
/// (d r / d ln|x|: a change of 100 % of the magnitude), by forward differences of 1e-3 of
/// the magnitude, in parallel.
fn relative_columns(prob: &Problem<'_>, x: &[f64], mag: &[f64]) -> Vec<Vec<f64>> {
    let r = prob.residuals_of(x);
    (0..x.len())
        .into_par_iter()
        .map(|i| {
            let h = 1e-3 * mag[i];
            let mut xp = x.to_vec();
            xp[i] += h;
            let rp = prob.residuals_of(&xp);
            rp.iter()
                .zip(&r)
                .map(|(a, b)| (a - b) / h * mag[i])
                .collect()
        })
        .collect()
}

/// The Gram matrix J^T J of a Jacobian's columns, by its eigen-decomposition.
pub(super) struct Gram {
    eig: nalgebra::SymmetricEigen<f64, nalgebra::Dyn>,
    /// The largest eigenvalue (at least 0).
    smax: f64,
}

impl Gram {
    pub(super) fn of(cols: &[Vec<f64>]) -> Self {
        let m = cols.len();
        let mut jtj = DMatrix::<f64>::zeros(m, m);
        for a in 0..m {
            for c in a..m {
                let s: f64 = cols[a].iter().zip(&cols[c]).map(|(u, v)| u * v).sum();
                jtj[(a, c)] = s;
                jtj[(c, a)] = s;
            }
        }
        let eig = jtj.symmetric_eigen();
        let smax = eig
            .eigenvalues
            .iter()
            .fold(0.0f64, |a, &v| a.max(v))
            .max(0.0);
        Gram { eig, smax }
    }

    /// Numerical rank: eigenvalues above 1e-12 of the largest (singular values above 1e-6).
    pub(super) fn rank(&self) -> usize {
        self.eig
            .eigenvalues
            .iter()
            .filter(|&&v| v > 1e-12 * self.smax)
            .count()
    }

    /// Largest over smallest singular value (infinite when singular).
    pub(super) fn condition_number(&self) -> f64 {
        let smin = self
            .eig
            .eigenvalues
            .iter()
            .fold(f64::INFINITY, |a, &v| a.min(v));
        if smin > 0.0 {
            (self.smax / smin).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// Diagonal element `i` of the pseudo-inverse: the sum over the eigenpairs above the
    /// rank threshold; infinite when parameter `i` lies in the null space.
    pub(super) fn inverse_diagonal(&self, i: usize) -> f64 {
        let mut s = 0.0;
        for (k, &lam) in self.eig.eigenvalues.iter().enumerate() {
            let v = self.eig.eigenvectors[(i, k)];
            if lam > 1e-12 * self.smax {
                s += v * v / lam;
            } else if v.abs() > 1e-6 {
                return f64::INFINITY;
            }
        }
        s
    }
}
