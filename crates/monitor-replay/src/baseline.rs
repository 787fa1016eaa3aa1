//! The healthy machine's negative sequence ([`UnbalanceBaseline`]) and the reference made of
//! several healthy runs ([`HealthyReference`], `diagnose`'s baseline), with the small
//! phasor helpers they and the winding's judgement share.

use monitor_core::sequence::Complex32;
use num_complex::Complex64;
use serde::Serialize;

/// The commissioning window's negative sequence is the winding's baseline only while |I1|
/// stays within this fraction of its value there (a motor's own asymmetry moves with the
/// slip; `diagnose --baseline` is the user's choice and is always used).
pub const BASELINE_I1_TOLERANCE: f32 = 0.1;

/// The healthy machine's negative sequence, relative to its positive sequence: what a
/// motor's own asymmetry and the sensors' mismatch put there before any fault. The
/// winding analysis judges the change from it (`unbalance.baseline`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UnbalanceBaseline {
    /// `I2/I1` (re, im), the sensor-corrected currents'.
    pub i2_over_i1: [f32; 2],
    /// `V2/I1` [ohm] (re, im), where voltages are logged.
    pub v2_over_i1: Option<[f32; 2]>,
    /// |I1| [A, peak] where it was taken (the operating point).
    pub i1_peak_a: f32,
    /// The electrical rotor speed [rad/s] where it was taken, where the log has a speed
    /// (the operating point).
    pub wr_rad_s: Option<f32>,
}

/// The healthy machine's negative sequence from several runs: their mean, how many, and
/// their scatter (JSON `unbalance.baseline_runs`, `unbalance.baseline_spread`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HealthyReference {
    /// The runs' mean (`I2/I1`, `V2/I1` where every run has voltages, `|I1|`).
    pub mean: UnbalanceBaseline,
    /// How many runs.
    pub runs: u32,
    /// `sum |h_i - mean|^2` of the runs' `I2/I1` (0 for one run).
    pub sum_sq_dev: f32,
}

impl From<UnbalanceBaseline> for HealthyReference {
    fn from(b: UnbalanceBaseline) -> Self {
        HealthyReference {
            mean: b,
            runs: 1,
            sum_sq_dev: 0.0,
        }
    }
}

/// [`HealthyReference::change_sigma`] of `runs` runs whose readings' squared distances
/// from their mean sum to `sum_sq_dev`, with the default spread `s0`.
pub(crate) fn pooled_change_sigma(s0: f32, runs: u32, sum_sq_dev: f32) -> f32 {
    let n = runs.max(1) as f32;
    ((2.0 * s0 * s0 + sum_sq_dev) / (2.0 * n)).sqrt() * (1.0 + 1.0 / n).sqrt()
}

impl HealthyReference {
    /// The reference made of several healthy runs (`diagnose --baseline` with several
    /// logs); `None` for none.
    pub fn from_runs(runs: &[UnbalanceBaseline]) -> Option<Self> {
        let n = runs.len();
        if n == 0 {
            return None;
        }
        let i2 = mean(runs.iter().map(|r| of_pair(r.i2_over_i1)));
        let v2 = runs
            .iter()
            .map(|r| r.v2_over_i1.map(of_pair))
            .collect::<Option<Vec<_>>>()
            .map(|v| mean(v.into_iter()));
        Some(HealthyReference {
            mean: UnbalanceBaseline {
                i2_over_i1: pair(i2),
                v2_over_i1: v2.map(pair),
                i1_peak_a: runs.iter().map(|r| r.i1_peak_a).sum::<f32>() / n as f32,
                wr_rad_s: runs
                    .iter()
                    .map(|r| r.wr_rad_s)
                    .collect::<Option<Vec<f32>>>()
                    .map(|w| w.iter().sum::<f32>() / n as f32),
            },
            runs: n as u32,
            sum_sq_dev: runs
                .iter()
                .map(|r| abs(of_pair(r.i2_over_i1) - i2).powi(2))
                .sum(),
        })
    }

    /// The runs' RMS distance from their mean, `sqrt(sum / (n - 1))`; `None` for one run.
    pub fn measured_spread(&self) -> Option<f32> {
        (self.runs >= 2).then(|| (self.sum_sq_dev / (self.runs - 1) as f32).sqrt())
    }

    /// The spread `sigma_run` of one healthy run's reading (each component), with the
    /// default `s0` counted as one run: `sqrt((2 s0^2 + sum |h_i - mean|^2) / (2 n))`
    /// (module docs, step 3).
    pub fn sigma(&self, s0: f32) -> f32 {
        ((2.0 * s0 * s0 + self.sum_sq_dev) / (2 * self.runs.max(1)) as f32).sqrt()
    }

    /// The spread of a new healthy reading's change from the runs' mean (each component):
    /// `sigma_run sqrt(1 + 1/n)`.
    pub fn change_sigma(&self, s0: f32) -> f32 {
        pooled_change_sigma(s0, self.runs, self.sum_sq_dev)
    }
}

/// `|a|` (the core's hypotenuse).
pub(crate) fn abs(a: Complex32) -> f32 {
    monitor_core::math::fast_hypot(a.re, a.im)
}

/// Mean of complex values (summed in double precision).
pub(crate) fn mean(xs: impl Iterator<Item = Complex32>) -> Complex32 {
    let (mut s, mut n) = (Complex64::new(0.0, 0.0), 0u32);
    for x in xs {
        s += Complex64::new(f64::from(x.re), f64::from(x.im));
        n += 1;
    }
    if n == 0 {
        return Complex32::new(0.0, 0.0);
    }
    let m = s / f64::from(n);
    Complex32::new(m.re as f32, m.im as f32)
}

/// A phasor from its JSON pair `[re, im]`.
pub(crate) fn of_pair(x: [f32; 2]) -> Complex32 {
    Complex32::new(x[0], x[1])
}

/// A phasor's JSON pair `[re, im]`.
pub(crate) fn pair(x: Complex32) -> [f32; 2] {
    [x.re, x.im]
}
