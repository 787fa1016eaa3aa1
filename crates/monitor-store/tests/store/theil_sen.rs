//! Theil-Sen's slope and Sen's interval against a textbook computation written here, and
//! the interval's coverage on noisy lines.

use monitor_store::trend::stats::{mad_sigma, theil_sen};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// The textbook Theil-Sen slope: every pair's slope listed, sorted, the middle one (the
/// mean of the middle two for an even count).
fn textbook_slope(x: &[f64], y: &[f64]) -> f64 {
    let mut s = Vec::new();
    for i in 0..x.len() {
        for j in 0..x.len() {
            if x[j] > x[i] {
                s.push((y[j] - y[i]) / (x[j] - x[i]));
            }
        }
    }
    s.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    }
}

#[test]
fn the_slope_is_the_median_of_all_pairwise_slopes() {
    let mut rng = ChaCha8Rng::seed_from_u64(53);
    let noise = Normal::new(0.0, 1.0).unwrap();
    for n in [3usize, 4, 7, 12, 30] {
        let x: Vec<f64> = (0..n).map(|i| i as f64 + 0.3 * (i % 3) as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|xi| 2.0 - 0.7 * xi + noise.sample(&mut rng))
            .collect();
        let line = theil_sen(&x, &y, 0.95).unwrap();
        assert!(
            (line.slope - textbook_slope(&x, &y)).abs() < 1e-12,
            "n = {n}"
        );
        assert!(line.low <= line.slope && line.slope <= line.high);
    }
    // One wild outlier does not move it: a perfect line y = 3x with one point off by 1000.
    let x: Vec<f64> = (0..11).map(f64::from).collect();
    let mut y: Vec<f64> = x.iter().map(|v| 3.0 * v).collect();
    y[5] += 1000.0;
    let line = theil_sen(&x, &y, 0.95).unwrap();
    assert!((line.slope - 3.0).abs() < 1e-12);
    assert!(line.intercept.abs() < 1e-9);
    // Too few points.
    assert!(theil_sen(&[1.0, 2.0], &[1.0, 2.0], 0.95).is_none());
}

#[test]
fn the_mad_scatter_reads_a_normal_sigma() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let noise = Normal::new(0.0, 2.5).unwrap();
    let v: Vec<f64> = (0..20_000).map(|_| noise.sample(&mut rng)).collect();
    let s = mad_sigma(&v).unwrap();
    assert!((s - 2.5).abs() < 0.05, "{s}");
}

/// Sen's 95 % interval covers the true slope in about 95 % of noisy lines (30 daily
/// points, normal noise of 1.5 slopes' worth a day): between 90 % and 98 % of 500 seeds.
#[test]
fn sens_interval_covers_the_true_slope_about_as_often_as_it_says() {
    let noise = Normal::new(0.0, 1.5).unwrap();
    let mut covered = 0;
    let seeds = 500;
    for seed in 0..seeds {
        let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
        let x: Vec<f64> = (0..30).map(f64::from).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|xi| 4.0 + 0.1 * xi + noise.sample(&mut rng))
            .collect();
        let line = theil_sen(&x, &y, 0.95).unwrap();
        if line.low <= 0.1 && 0.1 <= line.high {
            covered += 1;
        }
    }
    let rate = f64::from(covered) / seeds as f64;
    eprintln!("coverage of the 95 % interval: {rate:.3}");
    assert!((0.90..=0.98).contains(&rate), "coverage {rate}");
}
