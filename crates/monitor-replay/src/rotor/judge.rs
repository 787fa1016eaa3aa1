//! From the sidebands' level to the rotor's judgement: the severity band of MCSA practice
//! ([`RotorBand`]), the probability that the rotor has a fault ([`fault_probability`]),
//! and the broken bars where the cage's bar count is known.

use super::{RotorBand, EDGE_SPREAD_DB, FAULT_EDGE_DB};
use monitor_core::rotor_cage::{broken_bars_of_delta, delta_of_sideband_ratio};

/// The band of a `(1 - 2s) f` sideband `level_db` below the line (negative dB).
pub fn band_of(level_db: f64) -> RotorBand {
    RotorBand::ALL
        .into_iter()
        .find(|b| level_db < b.upper_db())
        .unwrap_or(RotorBand::SeveralBrokenBars)
}

/// The standard normal distribution function `Phi(x)`, from the complementary error
/// function of Abramowitz and Stegun, *Handbook of Mathematical Functions* (1964), 7.1.26
/// (absolute error below 1.5e-7).
pub fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-z * z).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// What the record's noise gives at the sideband's reading: the expected largest of `m`
/// independent noise bins of mean power `noise` (relative to the line's), `noise (1 +
/// ln m)` (the largest of `m` exponential powers averages `H_m < 1 + ln m`). The reading
/// takes the largest bin of a zero-padded spectrum over an interval `W` resolution bins
/// wide, which behaves as the largest of about `W` independent bins (measured on
/// noise-only records: mean, median and 90th percentile of the reading over the noise
/// those of 3.5 to 4 exponentials for `W` = 4.8); `m` = `W`.
pub fn noise_max(noise: f64, m: f64) -> f64 {
    noise * (1.0 + m.max(1.0).ln())
}

/// The probability that the rotor has a fault, from the `(1 - 2s) f` sideband's measured
/// power `a2` and the record's noise (`noise` per bin, `m` bins searched, `k` spectra
/// averaged), all relative to the line's power (module docs of `super`, "Confidence"): the
/// probability that the sideband's true amplitude stands above the fault edge
/// `a_E = 10^(E/20)`, the edge `E` normal about [`FAULT_EDGE_DB`] with the spread
/// [`EDGE_SPREAD_DB`] (the published guidelines' disagreement). The true amplitude is
/// taken as normal about `a = sqrt(a2 - noise_max)` (the reading less what the noise's
/// largest bin gives) with the spread of one averaged reading's amplitude,
/// `sqrt(noise / (2 k))`: `P = E_E[Phi((a - a_E) / sigma)]`, the expectation over the edge
/// summed on a grid of 0.1 dB over +/- 4 spreads.
pub fn fault_probability(a2: f64, noise: f64, m: f64, k: usize) -> f64 {
    let a = (a2 - noise_max(noise, m)).max(0.0).sqrt();
    let sigma = (noise / (2.0 * k.max(1) as f64)).sqrt().max(1e-15);
    let steps = (8.0 * EDGE_SPREAD_DB / 0.1).round().max(1.0) as usize;
    let (mut sum, mut weights) = (0.0, 0.0);
    for j in 0..=steps {
        let z = -4.0 + 8.0 * j as f64 / steps as f64;
        let w = (-0.5 * z * z).exp();
        let edge = 10f64.powf((FAULT_EDGE_DB + z * EDGE_SPREAD_DB) / 20.0);
        sum += w * normal_cdf((a - edge) / sigma);
        weights += w;
    }
    sum / weights
}

/// The torque-producing share `I_q / |I|` of the current at slip `s` on a supply of `w_s`
/// [rad/s] for a rotor time constant `lr/rr` [s]: in steady state the slip frequency is
/// `s w_s = I_q / (tau_r I_d)`, so `I_q / I_d = s w_s tau_r` and the share is
/// `x / sqrt(1 + x^2)` (the magnetising part carries no sideband:
/// `monitor_core::rotor_cage`).
pub fn torque_share(s: f64, w_s: f64, tau_r_s: f64) -> f64 {
    let x = (s * w_s * tau_r_s).abs();
    x / (1.0 + x * x).sqrt()
}

/// The asymmetry delta and, for a cage of `bars`, the adjacent broken bars the sidebands
/// `a_l`, `a_u` (amplitudes over the line's) say at torque share `share`
/// (`monitor_core::rotor_cage`): (delta, broken bars).
pub fn bars_of(a_l: f64, a_u: f64, share: f64, bars: Option<u32>) -> (Option<f64>, Option<f64>) {
    let delta = (share > 0.0)
        .then(|| delta_of_sideband_ratio((a_l + a_u) / share))
        .flatten();
    let n = delta
        .zip(bars)
        .map(|(d, nb)| broken_bars_of_delta(d, f64::from(nb)));
    (delta, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_normal_distribution_at_known_points() {
        for (x, p) in [
            (0.0, 0.5),
            (1.0, 0.841_344_746),
            (-1.959_964, 0.025),
            (3.0, 0.998_650_102),
        ] {
            assert!((normal_cdf(x) - p).abs() < 2e-7, "{x}");
        }
    }

    #[test]
    fn the_bands_follow_the_level() {
        assert_eq!(band_of(-60.0), RotorBand::NoSign);
        assert_eq!(band_of(-50.0), RotorBand::Watch);
        assert_eq!(band_of(-45.0), RotorBand::CrackedBarOrJoint);
        assert_eq!(band_of(-40.0), RotorBand::BrokenBars);
        assert_eq!(band_of(-30.0), RotorBand::SeveralBrokenBars);
    }

    #[test]
    fn the_probability_crosses_one_half_at_the_edge_and_not_at_the_noise() {
        let db = |x: f64| 10f64.powf(x / 10.0);
        // A clean record: one half at the edge, low in the watch band, high a band above.
        let quiet = db(-100.0);
        let p = |l: f64| fault_probability(db(l), quiet, 10.0, 1);
        // A clean record: the edge's own spread alone, Phi((level + 48) / 2).
        for (level, want) in [
            (-48.0, 0.5),
            (-50.0, 0.158_655),
            (-51.0, 0.066_807),
            (-45.0, 0.933_193),
            (-42.0, 0.998_650),
        ] {
            assert!((p(level) - want).abs() < 0.02, "{level}: {}", p(level));
        }
        assert!((p(FAULT_EDGE_DB) - 0.5).abs() < 0.01);
        // A noisy record: a reading at the noise's largest bin is no fault, whatever its
        // level.
        let noise = db(-50.0);
        let at_noise = noise_max(noise, 10.0);
        assert!(fault_probability(at_noise, noise, 10.0, 1) < 0.2);
    }
}
