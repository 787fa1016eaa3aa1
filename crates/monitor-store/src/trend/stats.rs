//! The robust statistics of a trend: the Theil-Sen slope with Sen's confidence interval,
//! the median absolute deviation, and a least-squares fit for the operating point.

/// A Theil-Sen line `y = intercept + slope x` with Sen's interval of the slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SenLine {
    /// The median of the pairwise slopes.
    pub slope: f64,
    /// The interval's low end.
    pub low: f64,
    /// Its high end.
    pub high: f64,
    /// `median(y - slope x)`.
    pub intercept: f64,
}

/// The standard normal quantile for a two-sided `confidence` (0.5..0.999), by the
/// Acklam rational approximation (relative error below 1.2e-9).
pub fn normal_quantile_two_sided(confidence: f64) -> f64 {
    let p = 0.5 + confidence.clamp(0.5, 0.999_999) / 2.0;
    // Upper half of Acklam's approximation (p >= 0.5).
    let a = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    let b = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    let cc = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    let d = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    if p <= 0.97575 {
        let q = p - 0.5;
        let r = q * q;
        (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q
            / (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((cc[0] * q + cc[1]) * q + cc[2]) * q + cc[3]) * q + cc[4]) * q + cc[5])
            / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0)
    }
}

/// The median of `v` (sorted in place); `None` for an empty slice.
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let hi = v.get(n / 2).copied()?;
    if n % 2 == 1 {
        Some(hi)
    } else {
        v.get(n / 2 - 1).map(|lo| 0.5 * (lo + hi))
    }
}

/// The scatter of `v` about zero-free median: 1.4826 x the median absolute deviation (the
/// standard deviation for normal noise, robust to a few outliers).
pub fn mad_sigma(v: &[f64]) -> Option<f64> {
    let mut w = v.to_vec();
    let m = median(&mut w)?;
    let mut dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    median(&mut dev).map(|d| 1.4826 * d)
}

/// The value at 1-based fractional rank `r` of the ascending `sorted`, interpolated.
fn at_rank(sorted: &[f64], r: f64) -> Option<f64> {
    let n = sorted.len();
    let r = r.clamp(1.0, n as f64);
    let lo = r.floor() as usize;
    let frac = r - r.floor();
    let a = *sorted.get(lo - 1)?;
    let b = sorted.get(lo).copied().unwrap_or(a);
    Some(a + frac * (b - a))
}

/// Theil-Sen's line through `(x, y)` with Sen's two-sided `confidence` interval of the
/// slope (Sen, J. Am. Stat. Assoc. 63, 1968; Gilbert, "Statistical methods for
/// environmental pollution monitoring", 1987, sec. 16.5): the slopes of all pairs with
/// distinct x, their median; with `C = z sqrt(Var S)`, `Var S = n (n-1) (2n+5) / 18`
/// (Kendall's S without ties), the interval runs from the `(N - C)/2`-th to the
/// `(N + C)/2 + 1`-th of the `N` ordered slopes. `None` with fewer than 3 points or all x
/// equal.
pub fn theil_sen(x: &[f64], y: &[f64], confidence: f64) -> Option<SenLine> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let mut slopes = Vec::with_capacity(n * (n - 1) / 2);
    for i in 0..n {
        for j in i + 1..n {
            let (xi, xj, yi, yj) = (x.get(i)?, x.get(j)?, y.get(i)?, y.get(j)?);
            if xj != xi {
                slopes.push((yj - yi) / (xj - xi));
            }
        }
    }
    let slope = median(&mut slopes)?;
    let nf = n as f64;
    let var_s = nf * (nf - 1.0) * (2.0 * nf + 5.0) / 18.0;
    let c = normal_quantile_two_sided(confidence) * var_s.sqrt();
    let big_n = slopes.len() as f64;
    let low = at_rank(&slopes, (big_n - c) / 2.0)?;
    let high = at_rank(&slopes, (big_n + c) / 2.0 + 1.0)?;
    let mut b: Vec<f64> = x.iter().zip(y).map(|(xi, yi)| yi - slope * xi).collect();
    let intercept = median(&mut b)?;
    Some(SenLine {
        slope,
        low,
        high,
        intercept,
    })
}

/// Least squares `y ~ a + sum b_k x_k` (the normal equations, Gaussian elimination with
/// partial pivoting); the coefficients `[a, b_1, ...]`, or `None` when the covariates do
/// not vary enough to fit (a singular system) or there are too few points.
pub fn least_squares(xs: &[Vec<f64>], y: &[f64]) -> Option<Vec<f64>> {
    let k = xs.first().map_or(0, Vec::len) + 1;
    if y.len() < k + 2 {
        return None;
    }
    let mut m = vec![vec![0.0; k + 1]; k];
    for (row, yi) in xs.iter().zip(y) {
        let v: Vec<f64> = std::iter::once(1.0).chain(row.iter().copied()).collect();
        for (i, mi) in m.iter_mut().enumerate() {
            for (j, vj) in v.iter().enumerate() {
                *mi.get_mut(j)? += v.get(i)? * vj;
            }
            *mi.get_mut(k)? += v.get(i)? * yi;
        }
    }
    for col in 0..k {
        let piv = (col..k).max_by(|a, b| {
            let va = m.get(*a).and_then(|r| r.get(col)).map_or(0.0, |x| x.abs());
            let vb = m.get(*b).and_then(|r| r.get(col)).map_or(0.0, |x| x.abs());
            va.total_cmp(&vb)
        })?;
        m.swap(col, piv);
        let p = *m.get(col)?.get(col)?;
        let scale = m.get(col)?.iter().map(|x| x.abs()).fold(0.0, f64::max);
        if p.abs() <= 1e-12 * scale.max(1e-300) {
            return None;
        }
        let pivot_row = m.get(col)?.clone();
        for (r, row) in m.iter_mut().enumerate() {
            if r != col {
                let f = row.get(col)? / p;
                for (x, pv) in row.iter_mut().zip(&pivot_row) {
                    *x -= f * pv;
                }
            }
        }
    }
    (0..k)
        .map(|i| Some(m.get(i)?.get(k)? / m.get(i)?.get(i)?))
        .collect()
}
