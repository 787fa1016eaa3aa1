//! The searches of the isolator's fits and the ranking: golden section, the factor grid,
//! the candidates' probabilities.

use super::*;

/// The minimum of a unimodal `chi` over `lo..hi` by `steps` golden-section steps:
/// `(chi, x)`.
pub(super) fn golden(chi: impl Fn(f32) -> f32, lo: f32, hi: f32, steps: usize) -> (f32, f32) {
    const G: f32 = 0.618_034;
    let (mut lo, mut hi) = (lo, hi);
    let mut x1 = hi - G * (hi - lo);
    let mut x2 = lo + G * (hi - lo);
    let (mut c1, mut c2) = (chi(x1), chi(x2));
    for _ in 0..steps {
        if c1 < c2 {
            hi = x2;
            (x2, c2) = (x1, c1);
            x1 = hi - G * (hi - lo);
            c1 = chi(x1);
        } else {
            lo = x1;
            (x1, c1) = (x2, c2);
            x2 = lo + G * (hi - lo);
            c2 = chi(x2);
        }
    }
    if c1 < c2 {
        (c1, x1)
    } else {
        (c2, x2)
    }
}

/// Ranks the faults' fits `(chi2, k)`, the heating fit `heat` and the unknown fault into
/// `out` (candidates, probabilities, state), for a deviation of misfit `chi0` over `dims`
/// equations, with the fault directions known to a relative `eps` (module docs,
/// "How sure a name is"). B and Bl scale the same load term: one friction class with one
/// misfit (each keeps the size it needs on its own).
pub(super) fn rank(
    out: &mut Isolation,
    fits: &mut [(f32, f32); FAULT_COUNT],
    heat: (f32, f32),
    (chi0, dims): (f32, f32),
    eps: f32,
) {
    let friction = [Fault::B.index(), Fault::Bl.index()];
    let chi_friction = friction
        .iter()
        .filter_map(|k| fits.get(*k))
        .fold(f32::INFINITY, |a, (c, _)| crate::math::minf(a, *c));
    for k in friction {
        if let Some((c, _)) = fits.get_mut(k) {
            *c = chi_friction;
        }
    }
    // Heating takes part in the ranking only where it can explain the deviation (misfit
    // within HEATING_MAX_MISFIT): elsewhere the faults rank among themselves as without it.
    let (chi_heat, k_heat) = heat;
    let heat_in = crate::math::sqrt(chi_heat) <= HEATING_MAX_MISFIT;
    let chi_min = fits.iter().fold(
        if heat_in { chi_heat } else { f32::INFINITY },
        |a, (c, _)| crate::math::minf(a, *c),
    );
    let chi_unknown = crate::math::maxf(UNKNOWN_CHI2, 0.1 * chi0);
    let t = temperature(chi_min, (chi0, dims), eps);
    let w = |c: f32| F32Ext::exp(-(c - chi_min) / (2.0 * t));
    let mut total = w(chi_unknown);
    for (c, _) in fits.iter() {
        total += w(*c);
    }
    if heat_in {
        total += w(chi_heat);
    }
    out.heating = Heating {
        probability: if heat_in { w(chi_heat) / total } else { 0.0 },
        factor: k_heat,
        misfit: crate::math::sqrt(chi_heat),
    };
    for ((cand, (c, k)), f) in out.candidates.iter_mut().zip(*fits).zip(Fault::ALL) {
        *cand = Candidate {
            fault: f,
            probability: w(c) / total,
            change: k - 1.0,
            misfit: crate::math::sqrt(c),
            at_limit: k <= K_MIN * 1.001 || k >= K_MAX * 0.999,
        };
    }
    out.unknown_probability = w(chi_unknown) / total;
    sort_by_probability(&mut out.candidates);
    out.state = if out.unknown_probability >= out.candidates.first().map_or(0.0, |c| c.probability)
    {
        IsolationState::Unknown
    } else {
        IsolationState::Isolated
    };
}

/// The ranking's temperature (module docs of [`crate::isolation`], "How sure a name is"):
/// the directions' own uncertainty (a model error of `eps` times the deviation of misfit
/// `chi0`, spread over `dims` equations), or a poor best fit (`chi_min` over the two
/// degrees of freedom left), whichever is larger.
fn temperature(chi_min: f32, (chi0, dims): (f32, f32), eps: f32) -> f32 {
    let t_model = 1.0 + eps * eps * chi0 / crate::math::maxf(dims, 1.0);
    crate::math::maxf(t_model, 0.5 * chi_min)
}

/// Best factor `k` of a misfit `chi(k)` over [`K_MIN`]..[`K_MAX`]: a geometric grid of
/// [`GRID`] points (and `k = 1`), then [`GOLDEN_STEPS`] of golden section around the best
/// grid point. Returns `(chi2, k)`.
pub(super) fn fit_factor(chi: impl Fn(f32) -> f32) -> (f32, f32) {
    let step = F32Ext::powf(K_MAX / K_MIN, 1.0 / (GRID - 1) as f32);
    let (mut best_k, mut best_c) = (1.0f32, chi(1.0));
    let mut k = K_MIN;
    for _ in 0..GRID {
        let c = chi(k);
        if c < best_c {
            (best_k, best_c) = (k, c);
        }
        k *= step;
    }
    let (c, x) = golden(
        &chi,
        crate::math::maxf(best_k / step, K_MIN),
        crate::math::minf(best_k * step, K_MAX),
        GOLDEN_STEPS,
    );
    if c < best_c {
        (c, x)
    } else {
        (best_c, best_k)
    }
}

/// Sorts candidates by probability, most probable first (insertion sort: nine entries,
/// no allocation, stable so Table 1's order breaks ties).
fn sort_by_probability(c: &mut [Candidate; FAULT_COUNT]) {
    for n in 1..c.len() {
        let mut j = n;
        while j > 0 {
            let swap = match (c.get(j - 1), c.get(j)) {
                (Some(a), Some(b)) => b.probability > a.probability,
                _ => false,
            };
            if !swap {
                break;
            }
            c.swap(j - 1, j);
            j -= 1;
        }
    }
}
