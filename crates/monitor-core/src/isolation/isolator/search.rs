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
/// misfit (each keeps the size it needs on its own). A fault not `seen` takes no part (its
/// probability is 0; [`ALL_SEEN`]: every fault takes part).
pub(super) fn rank(
    out: &mut Isolation,
    fits: &mut [(f32, f32); FAULT_COUNT],
    heat: (f32, f32),
    (chi0, dims): (f32, f32),
    eps: f32,
    seen: &[bool; FAULT_COUNT],
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
    let chi_min = fits.iter().zip(seen).filter(|(_, s)| **s).fold(
        if heat_in { chi_heat } else { f32::INFINITY },
        |a, ((c, _), _)| crate::math::minf(a, *c),
    );
    let chi_unknown = crate::math::maxf(UNKNOWN_CHI2, 0.1 * chi0);
    let t = temperature(chi_min, (chi0, dims), eps);
    let w = |c: f32| F32Ext::exp(-(c - chi_min) / (2.0 * t));
    let w_fault = |c: f32, seen: bool| if seen { w(c) } else { 0.0 };
    let mut total = w(chi_unknown);
    for ((c, _), s) in fits.iter().zip(seen) {
        total += w_fault(*c, *s);
    }
    if heat_in {
        total += w(chi_heat);
    }
    out.heating = Heating {
        probability: if heat_in { w(chi_heat) / total } else { 0.0 },
        factor: k_heat,
        misfit: crate::math::sqrt(chi_heat),
    };
    for (((cand, (c, k)), f), s) in out
        .candidates
        .iter_mut()
        .zip(*fits)
        .zip(Fault::ALL)
        .zip(seen)
    {
        *cand = Candidate {
            fault: f,
            probability: w_fault(c, *s) / total,
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

/// Every fault takes part in the ranking ([`rank`]).
pub(super) const ALL_SEEN: [bool; FAULT_COUNT] = [true; FAULT_COUNT];

/// The ranking's temperature (module docs of [`crate::isolation`], "How sure a name is"):
/// the directions' own uncertainty (a model error of `eps` times the deviation of misfit
/// `chi0`, spread over `dims` equations), or a poor best fit (`chi_min` over the two
/// degrees of freedom left), whichever is larger.
fn temperature(chi_min: f32, (chi0, dims): (f32, f32), eps: f32) -> f32 {
    let t_model = 1.0 + eps * eps * chi0 / crate::math::maxf(dims, 1.0);
    crate::math::maxf(t_model, 0.5 * chi_min)
}

/// Where each fault's size search found its best point of the grid the last time, to
/// start the next search there (module docs of [`crate::isolation`], "Searches started
/// from the last result"): one per search that is repeated on a moving point (the
/// follower's single point, the joint fit over the kept points). The default starts every
/// search afresh.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SearchHints {
    /// Per fault ([`Fault::ALL`]'s order): 0, no hint; `g + 1`, grid point `g`, the one
    /// minimum of the misfit over the whole grid when it was last searched.
    grid: [u8; FAULT_COUNT],
    /// Isolations since the whole grid was last searched for every fault.
    since_whole: u8,
    /// Where the hints were found: the deviation's residuals in spreads, its misfit's
    /// root, and the number of points ([`SearchHints::begin`]).
    at: ([f32; 4], usize),
    /// The hints were used at the last isolation.
    used: bool,
}

/// Every this many isolations the whole grid is searched for every fault, hints or not
/// (once a second on the follower's 0.1 s schedule): a misfit that grew a second minimum
/// since is found again.
const WHOLE_GRID_EVERY: u8 = 10;

/// How far the deviation may have moved since the hints were found for them to be used:
/// half a spread, or [`HINT_MOVE_FRACTION`] of the deviation where that is more (a point
/// averaged again 0.1 s later moves by a fraction of its scatter).
const HINT_MOVE_SIGMA: f32 = 0.5;
/// See [`HINT_MOVE_SIGMA`]: 1 %.
const HINT_MOVE_FRACTION: f32 = 0.01;

impl SearchHints {
    /// At the start of an isolation of a deviation `at` (its residuals in spreads and its
    /// misfit's root) over `points` points: whether the hints are used this time. Not
    /// where the whole grid is due ([`WHOLE_GRID_EVERY`]), nor where the number of points
    /// changed or the deviation moved by more than [`HINT_MOVE_SIGMA`] or
    /// [`HINT_MOVE_FRACTION`] of it since the last isolation.
    pub(super) fn begin(&mut self, at: [f32; 4], points: usize) -> bool {
        let (last, n) = self.at;
        self.at = (at, points);
        let (mut moved, mut size) = (0.0, 0.0);
        for (a, b) in at.iter().zip(last) {
            moved += (a - b) * (a - b);
            size += a * a;
        }
        let near = moved
            <= crate::math::maxf(
                HINT_MOVE_SIGMA * HINT_MOVE_SIGMA,
                HINT_MOVE_FRACTION * HINT_MOVE_FRACTION * size,
            );
        self.since_whole = self.since_whole.saturating_add(1);
        self.used = !(self.since_whole >= WHOLE_GRID_EVERY || n != points || !near);
        if !self.used {
            self.since_whole = 0;
        }
        self.used
    }

    /// The last isolation's searches started from the hints ([`SearchHints::begin`]).
    pub fn used(&self) -> bool {
        self.used
    }

    /// Fault `f`'s hint (0: none), where hints are used (`use_hints`).
    pub(super) fn get(&self, f: Fault, use_hints: bool) -> u8 {
        let h = self.grid.get(f.index()).copied().unwrap_or(0);
        if use_hints {
            h
        } else {
            0
        }
    }

    /// Sets fault `f`'s hint.
    pub(super) fn set(&mut self, f: Fault, hint: u8) {
        if let Some(h) = self.grid.get_mut(f.index()) {
            *h = hint;
        }
    }
}

/// Best factor `k` of a misfit `chi(k)` over [`K_MIN`]..[`K_MAX`]: a geometric grid of
/// [`GRID`] points (and `k = 1`), then [`GOLDEN_STEPS`] of golden section around the best
/// grid point. `hint`: the grid point that was best the last time (`g + 1`; 0: none).
/// Where it is still a strict local minimum of the grid, below `k = 1`, it is taken as the
/// grid's best without the rest of the grid (for a misfit unimodal over the grid, the same
/// point the whole grid finds, so the same result); else the whole grid is searched.
/// Returns `(chi2, k)` and the hint for the next search: the best grid point where the
/// whole grid has one minimum, else none.
pub(super) fn fit_factor(chi: impl Fn(f32) -> f32, hint: u8) -> ((f32, f32), u8) {
    let step = F32Ext::powf(K_MAX / K_MIN, 1.0 / (GRID - 1) as f32);
    let c_one = chi(1.0);
    let ((best_k, best_c), next) = match from_hint(&chi, step, c_one, hint) {
        Some(best) => (best, hint),
        None => whole_grid(&chi, step, c_one),
    };
    let (c, x) = golden(
        &chi,
        crate::math::maxf(best_k / step, K_MIN),
        crate::math::minf(best_k * step, K_MAX),
        GOLDEN_STEPS,
    );
    let fit = if c < best_c { (c, x) } else { (best_c, best_k) };
    (fit, next)
}

/// The grid's best point `(k, chi2)` (`k = 1` first, then the grid in order, a later
/// point only when strictly better), with its hint: `g + 1` where the grid's misfits
/// fall strictly to one minimum at `g` and rise strictly after it, else 0 (a second
/// minimum, a flat stretch, `k = 1` best, a value that is not a number).
fn whole_grid(chi: &impl Fn(f32) -> f32, step: f32, c_one: f32) -> ((f32, f32), u8) {
    let (mut best_k, mut best_c, mut best_g) = (1.0f32, c_one, None);
    let (mut k, mut last, mut turns, mut monotone) = (K_MIN, f32::NAN, 0u32, true);
    for g in 0..GRID {
        let c = chi(k);
        if c < best_c {
            (best_k, best_c, best_g) = (k, c, Some(g));
        }
        if g > 0 {
            // Falling, then rising once: a turn from a fall to a rise.
            let (falls, rises) = (c < last, c > last);
            monotone &= falls || rises;
            if rises && turns == 0 {
                turns = 1;
            } else if falls && turns == 1 {
                turns = 2;
            }
        }
        last = c;
        k *= step;
    }
    let hint = match best_g {
        Some(g) if monotone && turns <= 1 => g as u8 + 1,
        _ => 0,
    };
    ((best_k, best_c), hint)
}

/// The hinted grid point `(k, chi2)` where it is strictly below its two neighbours and
/// `k = 1`'s misfit `c_one` (an inner grid point only); `None` otherwise. The grid's
/// points are formed as [`whole_grid`] forms them (the same floats).
fn from_hint(chi: &impl Fn(f32) -> f32, step: f32, c_one: f32, hint: u8) -> Option<(f32, f32)> {
    let g = usize::from(hint).checked_sub(1)?;
    if g == 0 || g + 1 >= GRID {
        return None;
    }
    let mut below = K_MIN;
    for _ in 1..g {
        below *= step;
    }
    let k = below * step;
    let c = chi(k);
    (c < c_one && c < chi(below) && c < chi(k * step)).then_some((k, c))
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

#[cfg(test)]
mod tests {
    use super::*;
    use core::cell::Cell;

    /// A search from its last result finds what the whole grid finds, with half the
    /// misfits evaluated, on a minimum that drifts over the whole range of sizes, jumps,
    /// and sits at k = 1 or at the range's ends (where the whole grid is searched again).
    #[test]
    fn a_search_from_its_last_result_finds_what_the_grid_finds() {
        let calls = Cell::new(0u32);
        let mut hint = 0u8;
        let (mut warm_calls, mut cold_calls, mut searches) = (0u32, 0u32, 0u32);
        for j in 0..600 {
            // The best size: drifting from 0.3 to 3.8 and back, a jump every 150 searches,
            // and a stretch at k = 1.
            let x = j as f32 / 300.0;
            let mut k0 = 0.3 + 3.5 * if x < 1.0 { x } else { 2.0 - x };
            if j % 150 == 75 {
                k0 = 4.0 - k0 * 0.5;
            }
            if (400..420).contains(&j) {
                k0 = 1.0;
            }
            let chi = |k: f32| {
                calls.set(calls.get() + 1);
                let d = (k - k0) / k0;
                7.0 + 40.0 * d * d + 3.0 * d * d * d * d
            };
            calls.set(0);
            let cold = fit_factor(chi, 0);
            cold_calls += calls.get();
            calls.set(0);
            let warm = fit_factor(chi, hint);
            warm_calls += calls.get();
            searches += 1;
            assert_eq!(warm.0, cold.0, "search {j}, best size {k0}");
            assert_eq!(warm.1, cold.1, "search {j}: hint");
            hint = warm.1;
        }
        assert_eq!(cold_calls, 44 * searches);
        // 22 evaluations where the hint holds (4 + the golden section's 18), 47 where it
        // does not.
        assert!(
            warm_calls < 26 * searches,
            "{warm_calls} for {searches} searches"
        );
    }
}
