//! Levenberg-Marquardt for bounded nonlinear least squares, apart from any model.
//!
//! The problem ([`LeastSquares`]) gives residuals; the solver minimises half their sum of
//! squares over the free parameters, with box bounds enforced by clamping each trial step,
//! a forward-difference Jacobian computed in parallel (rayon), Marquardt's diagonal
//! scaling, and reports how it ended ([`Report`]). Priors are the problem's business: they
//! are residuals like any other. (The `levenberg-marquardt` crate has no bounds and
//! argmin's LM neither; clamping to the physical bounds is what the fits here need, so the
//! solver stays this small one, separated from the analysis model.)

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// A least-squares problem: residuals of a parameter vector.
pub trait LeastSquares: Sync {
    /// What the residuals need that is costly and depends only on some parameters
    /// (computed once per point and reused by the Jacobian columns that leave it valid).
    type Cache: Sync;
    /// The cache at `x`.
    fn cache(&self, x: &[f64]) -> Self::Cache;
    /// The residuals at `x`; `cache` is [`LeastSquares::cache`] of `x` or of a point that
    /// differs from `x` only in parameters for which [`LeastSquares::keeps_cache`] holds.
    fn residuals(&self, x: &[f64], cache: &Self::Cache) -> Vec<f64>;
    /// True when changing parameter `i` leaves the cache valid.
    fn keeps_cache(&self, _i: usize) -> bool {
        false
    }
}

/// Box bounds and typical magnitudes of the parameter vector.
#[derive(Debug, Clone)]
pub struct Bounds {
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// Typical magnitudes (finite-difference steps: 1e-4 of them).
    pub scale: Vec<f64>,
}

/// Why the solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// Two accepted steps in a row lowered the cost by less than [`REL_TOL`] of it.
    Converged,
    /// The cost fell by less than [`FLAT_TOL`] of itself over the last [`FLAT_ITERATIONS`]
    /// iterations: the fit crawls along a flat valley (a parameter the data hardly
    /// identify, or one held at a bound) and more iterations would change the cost, and so
    /// every figure derived from it, by less than that.
    SlowProgress,
    /// The iteration limit was reached while steps still lowered the cost.
    IterationLimit,
    /// No step lowered the cost, even with the damping raised [`DAMPING_TRIES`] times (a
    /// minimum within the finite-difference accuracy, or a bound in the way).
    Stalled,
    /// No free parameter.
    NothingToFit,
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Termination::Converged => "converged",
            Termination::SlowProgress => "slow progress",
            Termination::IterationLimit => "iteration limit",
            Termination::Stalled => "stalled",
            Termination::NothingToFit => "nothing to fit",
        })
    }
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Report {
    /// Iterations run (Jacobians computed).
    pub iterations: usize,
    /// Final cost: half the sum of squared residuals (priors included).
    pub cost: f64,
    /// Why it stopped.
    pub termination: Termination,
}

/// Relative cost decrease below which a step counts as small.
pub const REL_TOL: f64 = 1e-7;
/// Relative cost decrease over [`FLAT_ITERATIONS`] iterations below which the solve stops
/// as [`Termination::SlowProgress`]. Measured on the 1 h analysis benchmark's log: the
/// `saturation` candidate lowered its cost by 0.14 % over its last 31 of 40 iterations
/// (about 4e-5 per iteration, its saturation parameter at a bound), `windage` by 1e-6 per
/// iteration; a tenth of the benchmark's CPU went into such iterations.
pub const FLAT_TOL: f64 = 1e-4;
/// Iterations over which [`FLAT_TOL`] is judged.
pub const FLAT_ITERATIONS: usize = 5;
/// Damping increases tried per iteration before the solve counts as stalled.
pub const DAMPING_TRIES: usize = 8;

/// Half the sum of squares.
pub fn cost_of(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

/// Minimises from `x` over the `free` parameters, at most `max_iter` iterations. Returns
/// the parameter vector and how the solve ended.
pub fn solve<P: LeastSquares>(
    prob: &P,
    x: Vec<f64>,
    b: &Bounds,
    free: &[usize],
    max_iter: usize,
) -> (Vec<f64>, Report) {
    let mut p = Point::at(prob, x);
    let mut report = Report {
        iterations: 0,
        cost: p.cost,
        termination: Termination::IterationLimit,
    };
    if free.is_empty() {
        report.termination = Termination::NothingToFit;
        return (p.x, report);
    }
    let mut lambda = 1e-3;
    let mut small_steps = 0;
    // Cost after each iteration, for the slow-progress rule.
    let mut history: Vec<f64> = Vec::with_capacity(max_iter + 1);
    history.push(p.cost);
    for it in 0..max_iter {
        report.iterations = it + 1;
        let step = damped_step(prob, &mut p, &mut lambda, b, free);
        report.cost = p.cost;
        let Some(rel) = step else {
            report.termination = Termination::Stalled;
            break;
        };
        small_steps = if rel < REL_TOL { small_steps + 1 } else { 0 };
        if small_steps >= 2 {
            report.termination = Termination::Converged;
            break;
        }
        history.push(p.cost);
        if slow_progress(&history) {
            report.termination = Termination::SlowProgress;
            break;
        }
    }
    (p.x, report)
}

/// The solver's point: the parameters, their residuals, the residuals' cache and the cost.
struct Point<C> {
    x: Vec<f64>,
    r: Vec<f64>,
    cache: C,
    cost: f64,
}

impl<C> Point<C> {
    /// The point `x` of `prob`.
    fn at<P: LeastSquares<Cache = C>>(prob: &P, x: Vec<f64>) -> Self {
        let cache = prob.cache(&x);
        let r = prob.residuals(&x, &cache);
        Point {
            cost: cost_of(&r),
            x,
            r,
            cache,
        }
    }
}

/// One iteration: the normal equations at `p`, then Marquardt's step tried with the
/// damping `lambda` raised (x10 when the damped matrix is not positive definite, x8 when
/// the step does not lower the cost) up to [`DAMPING_TRIES`] times. The first step that
/// lowers the cost is taken (`p` moves there, the damping falls by 3) and its relative
/// decrease returned; `None` when none did.
fn damped_step<P: LeastSquares>(
    prob: &P,
    p: &mut Point<P::Cache>,
    lambda: &mut f64,
    b: &Bounds,
    free: &[usize],
) -> Option<f64> {
    let (jtj, jtr) = normal_equations(prob, &p.x, &p.r, &p.cache, b, free);
    let m = free.len();
    for _ in 0..DAMPING_TRIES {
        let mut aug = jtj.clone();
        for a in 0..m {
            aug[(a, a)] += *lambda * jtj[(a, a)].max(1e-12) + 1e-12;
        }
        let Some(ch) = aug.cholesky() else {
            *lambda *= 10.0;
            continue;
        };
        let step = ch.solve(&(-&jtr));
        let mut xn = p.x.clone();
        for (a, &i) in free.iter().enumerate() {
            xn[i] = (p.x[i] + step[a]).clamp(b.lo[i], b.hi[i]);
        }
        let next = Point::at(prob, xn);
        if next.cost.is_finite() && next.cost < p.cost {
            let rel = (p.cost - next.cost) / p.cost.max(1e-300);
            *p = next;
            *lambda = (*lambda / 3.0).max(1e-9);
            return Some(rel);
        }
        *lambda *= 8.0;
    }
    None
}

/// True when the last entry of `history` (the cost after each iteration, the start first)
/// is less than [`FLAT_TOL`] of the cost [`FLAT_ITERATIONS`] iterations before it below
/// that cost.
fn slow_progress(history: &[f64]) -> bool {
    let n = history.len();
    match (
        n.checked_sub(FLAT_ITERATIONS + 1)
            .and_then(|k| history.get(k)),
        history.last(),
    ) {
        (Some(&before), Some(&now)) => before - now < FLAT_TOL * before,
        _ => false,
    }
}

/// `J^T J` and `J^T r` at `x` (`r` the residuals at `x`, `cache` its cache), the Jacobian
/// by forward differences (steps 1e-4 of the scale), one column per free parameter, in
/// parallel; rows and columns in `free`'s order. Public for the Gauss-Newton covariance
/// `s^2 (J^T J)^-1` at an optimum (`crate::identify`).
pub fn normal_equations<P: LeastSquares>(
    prob: &P,
    x: &[f64],
    r: &[f64],
    cache: &P::Cache,
    b: &Bounds,
    free: &[usize],
) -> (DMatrix<f64>, DVector<f64>) {
    let cols = jacobian_columns(prob, x, r, cache, b, free);
    let m = free.len();
    let mut jtj = DMatrix::<f64>::zeros(m, m);
    let mut jtr = DVector::<f64>::zeros(m);
    for a in 0..m {
        for c in a..m {
            let s: f64 = cols[a].iter().zip(&cols[c]).map(|(u, v)| u * v).sum();
            jtj[(a, c)] = s;
            jtj[(c, a)] = s;
        }
        jtr[a] = cols[a].iter().zip(r).map(|(u, v)| u * v).sum();
    }
    (jtj, jtr)
}

/// The Jacobian at `x` (residuals `r`, `cache` its cache) by forward differences, one
/// column per parameter of `free` (each as long as `r`), in parallel.
pub fn jacobian_columns<P: LeastSquares>(
    prob: &P,
    x: &[f64],
    r: &[f64],
    cache: &P::Cache,
    b: &Bounds,
    free: &[usize],
) -> Vec<Vec<f64>> {
    free.par_iter()
        .map(|&i| {
            let h = 1e-4 * b.scale[i].max(1e-3 * x[i].abs());
            let mut xp = x.to_vec();
            let dir = if xp[i] + h > b.hi[i] { -1.0 } else { 1.0 };
            xp[i] += dir * h;
            let rp = if prob.keeps_cache(i) {
                prob.residuals(&xp, cache)
            } else {
                prob.residuals(&xp, &prob.cache(&xp))
            };
            rp.iter().zip(r).map(|(a, b)| (a - b) / (dir * h)).collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as residuals (10 (y - x^2), 1 - x): minimum 0 at (1, 1).
    struct Rosenbrock;
    impl LeastSquares for Rosenbrock {
        type Cache = ();
        fn cache(&self, _x: &[f64]) {}
        fn residuals(&self, x: &[f64], _c: &()) -> Vec<f64> {
            vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]
        }
    }

    fn bounds(lo: f64, hi: f64) -> Bounds {
        Bounds {
            lo: vec![lo; 2],
            hi: vec![hi; 2],
            scale: vec![1.0; 2],
        }
    }

    #[test]
    fn converges_on_rosenbrock_and_says_so() {
        let (x, rep) = solve(
            &Rosenbrock,
            vec![-1.2, 1.0],
            &bounds(-5.0, 5.0),
            &[0, 1],
            200,
        );
        assert!(
            (x[0] - 1.0).abs() < 1e-4 && (x[1] - 1.0).abs() < 1e-4,
            "{x:?}"
        );
        assert!(rep.cost < 1e-8, "{rep:?}");
        assert_ne!(rep.termination, Termination::IterationLimit, "{rep:?}");
        assert!(rep.iterations > 1 && rep.iterations < 200, "{rep:?}");
    }

    #[test]
    fn reports_the_iteration_limit_and_nothing_to_fit() {
        let (_, rep) = solve(&Rosenbrock, vec![-1.2, 1.0], &bounds(-5.0, 5.0), &[0, 1], 2);
        assert_eq!(rep.termination, Termination::IterationLimit);
        assert_eq!(rep.iterations, 2);
        let (x, rep) = solve(&Rosenbrock, vec![-1.2, 1.0], &bounds(-5.0, 5.0), &[], 50);
        assert_eq!(rep.termination, Termination::NothingToFit);
        assert_eq!(x, vec![-1.2, 1.0]);
    }

    #[test]
    fn slow_progress_is_judged_over_the_window() {
        // Too short a history: never.
        assert!(!slow_progress(&[1.0, 1.0, 1.0]));
        // 5 iterations that lowered the cost by 0.01 % in all: slow (4e-5 < 1e-4 of 1).
        let crawl = [2.0, 1.0, 0.99999, 0.99998, 0.99997, 0.99996, 0.99996];
        assert!(slow_progress(&crawl));
        // The same, but one of the five a real step: not slow.
        let step = [2.0, 1.0, 0.99999, 0.9, 0.89999, 0.89998, 0.89997];
        assert!(!slow_progress(&step));
        // Only the last window counts: a crawl after fast progress is slow.
        let late = [
            8.0,
            4.0,
            2.0,
            1.0,
            1.0 - 1e-6,
            1.0 - 2e-6,
            1.0 - 3e-6,
            1.0 - 4e-6,
            1.0 - 5e-6,
        ];
        assert!(slow_progress(&late));
    }

    #[test]
    fn respects_the_bounds() {
        // The minimum (1, 1) lies outside x <= 0.5: the solve ends on the bound.
        let (x, _) = solve(
            &Rosenbrock,
            vec![-1.2, 1.0],
            &bounds(-5.0, 0.5),
            &[0, 1],
            200,
        );
        assert!(x[0] <= 0.5 && x[1] <= 0.5, "{x:?}");
        assert!((x[0] - 0.5).abs() < 1e-3, "{x:?}");
    }
}
