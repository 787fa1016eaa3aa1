//! Change points of a series' mean, located to the sample: least-squares binary
//! segmentation, each split then re-optimised between its neighbours, splits that do not
//! move the level pruned, and each split placed within its sample.
//!
//! The model: the series is piecewise constant plus noise, `x_k = m_j` for the samples of
//! segment `j`. Splitting the segment `a..b` at `k` lowers the sum of squares by
//! ```text
//!   G(k) = (mean(a..k) - mean(k..b))^2 (k - a)(b - k) / (b - a)
//! ```
//! (the likelihood-ratio statistic of one change in the mean of Gaussian noise; binary
//! segmentation adds the split of largest `G` in turn). Every `G` is computed from the
//! series' cumulative sum, so the search is exact over every sample of a segment in one
//! pass (Killick, Fearnhead & Eckley, "Optimal detection of changepoints with a linear
//! computational cost", JASA 107 (500), 2012, give the cost and the binary segmentation
//! this implements; Bai, "Estimating multiple breaks one at a time", Econometric Theory 13
//! (3), 1997, the re-optimisation of each split between its neighbours, which makes the
//! splits of binary segmentation consistent to the sample).

/// What a change point must be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Search {
    /// Shortest segment [samples], >= 1.
    pub min_len: usize,
    /// A split must move the mean by more than this (the series' unit), >= 0.
    pub min_shift: f64,
    /// Most splits searched for.
    pub max_splits: usize,
}

/// A series' cumulative sum (`len + 1` values, the first 0): segment means in O(1).
#[derive(Debug, Clone, PartialEq)]
pub struct Cumulative(Vec<f64>);

impl Cumulative {
    /// The cumulative sum of `x`.
    pub fn new(x: impl IntoIterator<Item = f64>) -> Self {
        let mut c = vec![0.0];
        let mut s = 0.0;
        for v in x {
            s += v;
            c.push(s);
        }
        Cumulative(c)
    }

    /// Number of samples of the series.
    pub fn len(&self) -> usize {
        self.0.len() - 1
    }

    /// True when the series is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Mean of samples `a..b` (`a < b <= len`; 0 for an empty range).
    pub fn mean(&self, a: usize, b: usize) -> f64 {
        match (self.0.get(a), self.0.get(b)) {
            (Some(x), Some(y)) if b > a => (y - x) / (b - a) as f64,
            _ => 0.0,
        }
    }

    /// Sample `k` of the series (0 past the end).
    pub fn sample(&self, k: usize) -> f64 {
        self.mean(k, k + 1)
    }

    /// The best split of `a..b` (`G(k)` largest, [module docs](self)) among the samples
    /// `k` with `a + min_len <= k <= b - min_len` where `allowed(k)` and the means either
    /// side differ by more than `min_shift`: `(k, G(k))`, `None` when there is none.
    pub fn best_split(
        &self,
        (a, b): (usize, usize),
        s: &Search,
        allowed: &dyn Fn(usize) -> bool,
    ) -> Option<(usize, f64)> {
        let min_len = s.min_len.max(1);
        if b < a + 2 * min_len {
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        for k in a + min_len..=b - min_len {
            let (ml, mr) = (self.mean(a, k), self.mean(k, b));
            let g = (ml - mr).powi(2) * ((k - a) * (b - k)) as f64 / (b - a) as f64;
            if (ml - mr).abs() > s.min_shift && best.is_none_or(|(_, bg)| g > bg) && allowed(k) {
                best = Some((k, g));
            }
        }
        best
    }

    /// The splits of the series' mean (sample indices, each the first sample of a new
    /// segment, in order): binary segmentation, then each split re-optimised between its
    /// neighbours and the splits whose means either side differ by no more than
    /// `min_shift` dropped, until nothing moves (at most 10 rounds). Only samples where
    /// `allowed` holds are splits.
    pub fn splits(&self, s: &Search, allowed: &dyn Fn(usize) -> bool) -> Vec<usize> {
        let len = self.len();
        let mut cuts: Vec<usize> = Vec::new();
        for _ in 0..s.max_splits {
            let bounds = bounds(&cuts, len);
            let best = bounds
                .windows(2)
                .filter_map(|w| self.best_split((w[0], w[1]), s, allowed))
                .max_by(|x, y| x.1.total_cmp(&y.1));
            let Some((k, _)) = best else { break };
            cuts.push(k);
            cuts.sort_unstable();
        }
        for _ in 0..10 {
            let before = cuts.clone();
            self.reoptimise(&mut cuts, s, allowed);
            self.prune(&mut cuts, s.min_shift);
            if cuts == before {
                break;
            }
        }
        cuts
    }

    /// Each split moved to its best place between its neighbours (kept where it is when
    /// there is none).
    fn reoptimise(&self, cuts: &mut [usize], s: &Search, allowed: &dyn Fn(usize) -> bool) {
        let len = self.len();
        for i in 0..cuts.len() {
            let a = if i == 0 { 0 } else { cuts[i - 1] };
            let b = cuts.get(i + 1).copied().unwrap_or(len);
            if let Some((k, _)) = self.best_split((a, b), s, allowed) {
                cuts[i] = k;
            }
        }
    }

    /// Drops, one at a time and the smallest first, the splits whose neighbouring means
    /// differ by no more than `min_shift`.
    fn prune(&self, cuts: &mut Vec<usize>, min_shift: f64) {
        loop {
            let b = bounds(cuts, self.len());
            let weakest = (0..cuts.len())
                .map(|i| {
                    let shift = self.mean(b[i], b[i + 1]) - self.mean(b[i + 1], b[i + 2]);
                    (i, shift.abs())
                })
                .filter(|&(_, sh)| sh <= min_shift)
                .min_by(|x, y| x.1.total_cmp(&y.1));
            match weakest {
                Some((i, _)) => {
                    cuts.remove(i);
                }
                None => break,
            }
        }
    }

    /// Where within its sample the change at split `k` (between the means `before` and
    /// `after`) lies [samples, from sample `k`'s start, -1..=1]: a sample that straddles
    /// the change holds the part `f` of it at the new mean, `x = before + f (after -
    /// before)`; the straddling sample is the last one before the split or the first after
    /// it, whichever lies between the means (0 when neither does or the means agree).
    pub fn within_sample(&self, k: usize, before: f64, after: f64) -> f64 {
        let shift = after - before;
        if shift == 0.0 || k == 0 || k >= self.len() {
            return 0.0;
        }
        let part = |x: f64| ((x - before) / shift).clamp(0.0, 1.0);
        // The last sample before the split holds part p at the new mean: the change lies p
        // of a sample before k; the first sample after it holds part q: (1 - q) after k.
        let p = part(self.sample(k - 1));
        let q = part(self.sample(k));
        (1.0 - q - p).clamp(-1.0, 1.0)
    }
}

/// The segments' bounds: 0, the splits, `len`.
fn bounds(cuts: &[usize], len: usize) -> Vec<usize> {
    let mut b = Vec::with_capacity(cuts.len() + 2);
    b.push(0);
    b.extend_from_slice(cuts);
    b.push(len);
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(min_len: usize, min_shift: f64) -> Search {
        Search {
            min_len,
            min_shift,
            max_splits: 6,
        }
    }

    /// A deterministic pseudo-random series in -0.5..0.5 (xorshift).
    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// Two steps in noise, one of them inside a sample: both found at their sample, the
    /// straddling sample placed within 0.05 sample; a level that does not move is no step.
    #[test]
    fn two_steps_are_found_to_the_sample() {
        let n = 2000;
        let e = noise(n, 7);
        // Level 0 to 1234.3 (the sample 1234 holds 0.7 of a step of 4), 4 from 1234.3 to
        // 1600, then 1.
        let x: Vec<f64> = (0..n)
            .map(|k| {
                let level = match k {
                    k if k < 1234 => 0.0,
                    1234 => 0.7 * 4.0,
                    k if k < 1600 => 4.0,
                    _ => 1.0,
                };
                level + 0.01 * e[k]
            })
            .collect();
        let c = Cumulative::new(x.iter().copied());
        let cuts = c.splits(&search(50, 0.5), &|_| true);
        assert!(cuts == [1234, 1600] || cuts == [1235, 1600], "{cuts:?}");
        let k = cuts[0];
        let at = k as f64 + c.within_sample(k, 0.0, 4.0);
        assert!((at - 1234.3).abs() < 0.05, "{at}");
        // A flat series (noise only) has no split; neither has a step smaller than the
        // minimum shift.
        let flat = Cumulative::new(e.iter().copied());
        assert!(flat.splits(&search(50, 0.2), &|_| true).is_empty());
        let small = Cumulative::new(x.iter().map(|v| v * 0.1));
        assert!(small.splits(&search(50, 0.5), &|_| true).is_empty());
    }

    /// Two close steps of the same sign (a staircase) are two splits, each where its step
    /// is.
    #[test]
    fn splits_are_reoptimised_between_their_neighbours() {
        let x: Vec<f64> = (0..1000)
            .map(|k| match k {
                k if k < 450 => 0.0,
                k if k < 550 => 1.0,
                _ => 2.0,
            })
            .collect();
        let c = Cumulative::new(x);
        assert_eq!(c.splits(&search(20, 0.5), &|_| true), [450, 550]);
        // Splits refused where `allowed` says no: the first step goes to the first
        // sample allowed.
        assert_eq!(c.splits(&search(20, 0.5), &|k| k >= 500), [500, 550]);
    }
}
