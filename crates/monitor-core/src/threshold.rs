//! Thresholds on the normalised residuals, and lamp logic with debounce and hysteresis.
//!
//! Two kinds (the paper tuned fixed thresholds "heuristically", section 5):
//! - **Fixed**: a band `|r_n| <= limit` per residual.
//! - **Calibrated by commissioning**: over a window of healthy running, learn each
//!   residual's mean `m` and spread `s` (standard deviation, Welford's algorithm). The band
//!   is then `|r_n - m| <= max(k s, min_band)`; `min_band` keeps a noise-free commissioning
//!   (spread ~ 0) from making the lamps hair-triggered.
//!
//! A lamp lights after the residual has stayed outside its band for `debounce_s`, and goes
//! out only after it has stayed inside `hysteresis x band` for `release_s`, so lamps do not
//! flicker at the edge of the band.

/// Learned healthy statistics of the four normalised residuals. This is what the
/// firmware stores in flash.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Calibration {
    /// Healthy mean of r1..r4 (normalised, dimensionless).
    pub mean: [f32; 4],
    /// Healthy standard deviation of r1..r4, >= 0.
    pub spread: [f32; 4],
}

impl Calibration {
    /// True when every value is finite and every spread is >= 0 and the means are in [-1, 1].
    pub fn is_valid(&self) -> bool {
        self.mean
            .iter()
            .all(|m| m.is_finite() && (-1.0..=1.0).contains(m))
            && self
                .spread
                .iter()
                .all(|s| s.is_finite() && *s >= 0.0 && *s <= 2.0)
    }
}

/// Threshold configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThresholdConfig {
    /// Fixed limits on |r_n| used until a calibration exists (dimensionless, 0 < x <= 1).
    pub fixed: [f32; 4],
    /// Band width in spreads for the calibrated thresholds, > 0 (default 6).
    pub k_sigma: f32,
    /// Minimum half-width of the calibrated band (dimensionless, > 0; default 0.002 = 0.2 %).
    pub min_band: [f32; 4],
    /// Time outside the band before a lamp lights [s], >= 0 (default 0.3).
    pub debounce_s: f32,
    /// Time inside the inner band before a lamp goes out [s], >= 0 (default 1.0).
    pub release_s: f32,
    /// Inner band as a fraction of the band, 0 < h <= 1 (default 0.7).
    pub hysteresis: f32,
}

impl Default for ThresholdConfig {
    fn default() -> Self {
        ThresholdConfig {
            fixed: [0.03, 0.03, 0.03, 0.03],
            k_sigma: 6.0,
            min_band: [0.002, 0.002, 0.002, 0.002],
            debounce_s: 0.3,
            release_s: 1.0,
            hysteresis: 0.7,
        }
    }
}

impl ThresholdConfig {
    /// Checks ranges.
    ///
    /// # Errors
    /// [`crate::ConfigErrorKind::Threshold`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), crate::ConfigError> {
        use crate::error::{ensure, ConfigCheck::*};
        let fraction = |x: &f32| x.is_finite() && *x > 0.0 && *x <= 1.0;
        let time = |x: f32| x.is_finite() && x >= 0.0;
        ensure(self.fixed.iter().all(fraction), ThresholdFixed)?;
        ensure(self.min_band.iter().all(fraction), ThresholdMinBand)?;
        ensure(
            self.k_sigma.is_finite() && self.k_sigma > 0.0,
            ThresholdKSigma,
        )?;
        ensure(time(self.debounce_s), ThresholdDebounce)?;
        ensure(time(self.release_s), ThresholdRelease)?;
        ensure(
            self.hysteresis > 0.0 && self.hysteresis <= 1.0,
            ThresholdHysteresis,
        )
    }
}

/// Running mean and variance (Welford), for commissioning.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Welford {
    n: u32,
    mean: [f32; 4],
    m2: [f32; 4],
}

impl Welford {
    /// Adds one observation of the four residuals.
    pub fn push(&mut self, x: [f32; 4]) {
        self.n = self.n.saturating_add(1);
        let n = self.n as f32;
        for ((m, m2), xi) in self.mean.iter_mut().zip(self.m2.iter_mut()).zip(x) {
            let d = xi - *m;
            *m += d / n;
            *m2 += d * (xi - *m);
        }
    }
    /// Number of observations.
    pub fn count(&self) -> u32 {
        self.n
    }
    /// Mean and (population) standard deviation so far.
    pub fn calibration(&self) -> Calibration {
        let n = self.n.max(1) as f32;
        let mut spread = [0.0; 4];
        for (s, m2) in spread.iter_mut().zip(self.m2) {
            *s = crate::math::sqrt(crate::math::maxf(m2 / n, 0.0));
        }
        Calibration {
            mean: self.mean,
            spread,
        }
    }
}

/// Lamp logic for the four residuals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lamps {
    cfg: ThresholdConfig,
    dt_s: f32,
    cal: Option<Calibration>,
    out_s: [f32; 4],
    in_s: [f32; 4],
    lit: [bool; 4],
}

impl Lamps {
    /// New, all lamps off, fixed thresholds until [`Lamps::set_calibration`]; fed every
    /// `dt_s` seconds (> 0: the monitor's block period, `decimation / sample_rate_hz`).
    pub fn new(cfg: ThresholdConfig, dt_s: f32) -> Self {
        Lamps {
            cfg,
            dt_s,
            cal: None,
            out_s: [0.0; 4],
            in_s: [0.0; 4],
            lit: [false; 4],
        }
    }

    /// Uses learned statistics from now on (None: back to the fixed thresholds).
    pub fn set_calibration(&mut self, cal: Option<Calibration>) {
        self.cal = cal;
        self.reset();
    }

    /// The active calibration.
    pub fn calibration(&self) -> Option<Calibration> {
        self.cal
    }

    /// All lamps off, timers cleared.
    pub fn reset(&mut self) {
        self.out_s = [0.0; 4];
        self.in_s = [0.0; 4];
        self.lit = [false; 4];
    }

    /// Centre and half-width of residual k's band.
    pub fn band(&self, k: usize) -> (f32, f32) {
        match self.cal {
            Some(c) => {
                let m = c.mean.get(k).copied().unwrap_or(0.0);
                let s = c.spread.get(k).copied().unwrap_or(0.0);
                let min = self.cfg.min_band.get(k).copied().unwrap_or(0.01);
                (m, crate::math::maxf(self.cfg.k_sigma * s, min))
            }
            None => (0.0, self.cfg.fixed.get(k).copied().unwrap_or(0.03)),
        }
    }

    /// Feeds the normalised residuals, `dt_s` (given at construction) after the previous
    /// call; returns lamp states.
    pub fn update(&mut self, r: [f32; 4]) -> [bool; 4] {
        let dt_s = self.dt_s;
        for k in 0..4 {
            let (c, w) = self.band(k);
            let dev = (r.get(k).copied().unwrap_or(0.0) - c).abs();
            let (Some(out), Some(inn), Some(lit)) = (
                self.out_s.get_mut(k),
                self.in_s.get_mut(k),
                self.lit.get_mut(k),
            ) else {
                continue;
            };
            if dev > w {
                *out += dt_s;
            } else {
                *out = 0.0;
            }
            if dev < w * self.cfg.hysteresis {
                *inn += dt_s;
            } else {
                *inn = 0.0;
            }
            if !*lit && *out >= self.cfg.debounce_s && *out > 0.0 {
                *lit = true;
            } else if *lit && *inn >= self.cfg.release_s && *inn > 0.0 {
                *lit = false;
            }
        }
        self.lit
    }

    /// Present lamp states.
    pub fn lit(&self) -> [bool; 4] {
        self.lit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debounce_and_hysteresis() {
        let cfg = ThresholdConfig::default();
        let mut l = Lamps::new(cfg, 0.01); // fed every 10 ms
        l.set_calibration(Some(Calibration {
            mean: [0.0; 4],
            spread: [0.001; 4],
        }));
        // Band is max(6*0.001, 0.002) = 0.006.
        for _ in 0..20 {
            l.update([0.012, 0.0, 0.0, 0.0]);
        }
        assert!(!l.lit()[0], "lit before the 0.3 s debounce");
        for _ in 0..15 {
            l.update([0.012, 0.0, 0.0, 0.0]);
        }
        assert!(l.lit()[0]);
        // Inside the band but above the inner band: stays lit indefinitely.
        for _ in 0..500 {
            l.update([0.005, 0.0, 0.0, 0.0]);
        }
        assert!(l.lit()[0]);
        for _ in 0..101 {
            l.update([0.0, 0.0, 0.0, 0.0]);
        }
        assert!(!l.lit()[0]);
    }

    #[test]
    fn welford_matches_two_pass() {
        let xs: [f32; 5] = [0.1, 0.2, 0.4, 0.3, 0.5];
        let mut w = Welford::default();
        for x in xs {
            w.push([x, -x, 2.0 * x, 0.0]);
        }
        let c = w.calibration();
        let mean = 0.3f32;
        let var: f32 = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f32>() / 5.0;
        assert!((c.mean[0] - mean).abs() < 1e-6 && (c.mean[1] + mean).abs() < 1e-6);
        assert!((c.spread[0] - var.sqrt()).abs() < 1e-5);
        assert!((c.spread[2] - 2.0 * var.sqrt()).abs() < 1e-5);
        assert_eq!(c.spread[3], 0.0);
    }
}
