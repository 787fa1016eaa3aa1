//! The stationary-frame model's voltage input ([`StatVoltage`]): the positive-sequence
//! voltage per working sample, the block mean's gain on it and the supply steps.

use super::{median, phase_step};
use crate::prep::{self, Prepared, C64};
use crate::simplified_model::InputNoise;
use std::sync::Arc;

/// The stationary-frame model's voltage input, per working sample (see
/// [`super::simulate_stationary`]).
pub(crate) struct StatVoltage {
    /// Positive-sequence voltage, stationary frame, after the block mean [V].
    pub(super) v_mean: Vec<C64>,
    /// The voltage's phase step over each working sample [rad].
    pub(super) ph: Vec<f64>,
    /// The block mean's gain on the voltage's rotation.
    pub(super) gains: Vec<f64>,
    /// How far the voltage leaves its rotation over each sample (relative).
    pub(super) dev: Vec<f64>,
    /// `dev` above this is a supply step.
    pub(super) step_thr: f64,
    /// `e^{j ph/2}`: half of each working sample's phase step.
    pub(super) half: Vec<C64>,
    /// An unequal cage's turn over half of each working sample, `e^{j w2 dt/2}`, `w2` the
    /// sum of the measured electrical speeds at its ends (empty without a speed column):
    /// the series' alone, so a fit's runs share it ([`super::CageOverSample`]).
    pub(super) cage_half: Vec<C64>,
    /// The last few unequal cages' turns ([`StatVoltage::cage_turns`]), by `phi`'s bits.
    cage_turns: std::sync::Mutex<Vec<(u64, Arc<Vec<C64>>)>>,
}

/// How many cage angles `phi` [`StatVoltage::cage_turns`] keeps (a Jacobian's columns run
/// in parallel, one of them with its own `phi`).
const CAGE_TURNS_KEPT: usize = 4;

impl StatVoltage {
    /// The positive-sequence voltage at sample `k` before the block mean [V].
    #[inline]
    pub(super) fn v_at(&self, k: usize) -> C64 {
        self.v_mean[k] / self.gains[k]
    }

    /// The unequal cage's turn `e^{j (2 theta_a + phi)}` at each working sample of `d` (the
    /// series this input was built from), kept for the last few `phi`.
    pub(super) fn cage_turns(&self, d: &Prepared, phi: f64) -> Arc<Vec<C64>> {
        let key = phi.to_bits();
        let found = |kept: &[(u64, Arc<Vec<C64>>)]| {
            kept.iter().find(|(k, _)| *k == key).map(|(_, u)| u.clone())
        };
        if let Some(u) = self.cage_turns.lock().ok().and_then(|kept| found(&kept)) {
            return u;
        }
        let u = Arc::new(super::cage_turns_of(d, phi));
        if let Ok(mut kept) = self.cage_turns.lock() {
            if found(&kept).is_none() {
                if kept.len() >= CAGE_TURNS_KEPT {
                    kept.remove(0);
                }
                kept.push((key, u.clone()));
            }
        }
        u
    }

    /// The voltage input of `d` in the stationary frame (`rot_at` the frame rotation),
    /// with `noise`'s white noise added to each component of every working sample when
    /// given (the renoised run of `metrics::noise_floor`: the sensors' noise, as it is in
    /// the measured series, again, so that the steps, the phase steps and the block
    /// mean's gains below see it as they see the measured noise).
    pub(crate) fn new(
        d: &Prepared,
        rot_at: &impl Fn(usize) -> C64,
        noise: Option<InputNoise>,
    ) -> Self {
        let len = d.len();
        let dt = d.dt_s;
        // A working sample is the mean of `factor` log rows: a vector turning at w comes out
        // of the block mean scaled by `gain(w)`, the input voltage and the measured current
        // alike. The machine is not linear in the voltage (the torque goes with its square:
        // 0.2 % less torque through a start at 10 kHz, 1 % of the start current), so the
        // model is driven by the voltage before the mean (v / gain) and its current is
        // compared after it (gain i). `h` is the log's row spacing; a coarsened series'
        // sample spans several blocks but carries one block's gain (`Prepared::block_rows`).
        let rows = (d.log_rate_hz * dt).round().max(1.0);
        let h = dt / rows;
        let factor = match d.block_rows {
            0 => rows,
            b => b as f64,
        };
        // Positive-sequence voltage (stationary frame, after the block mean) and the gain.
        let mut v_mean: Vec<C64> = (0..len)
            .map(|k| C64::new(d.vd[k], d.vq[k]) * rot_at(k))
            .collect();
        if let Some(nz) = noise {
            add_white_noise(&mut v_mean, nz);
        }
        // The voltage's phase step over each working sample [rad].
        let ph: Vec<f64> = (0..len)
            .map(|k| {
                let a = k.min(len.saturating_sub(2));
                phase_step(v_mean[a], v_mean[(a + 1).min(len - 1)])
            })
            .collect();
        let gains: Vec<f64> = ph.iter().map(|&p| block_gain(p / dt, h, factor)).collect();
        let dev = off_rotation(&v_mean, &gains, &ph);
        let step_thr = prep::SUPPLY_STEP_REL.max(10.0 * median(&dev));
        let half = ph.iter().map(|&p| C64::from_polar(1.0, 0.5 * p)).collect();
        StatVoltage {
            cage_half: cage_half_turns(d),
            cage_turns: Default::default(),
            v_mean,
            ph,
            gains,
            dev,
            step_thr,
            half,
        }
    }
}

/// [`StatVoltage::cage_half`] of `d`: `e^{j w2 dt/2}` per working sample, `w2` as
/// [`super::CageAngle::at`] takes it (the same expression, so the same bits).
fn cage_half_turns(d: &Prepared) -> Vec<C64> {
    let len = d.len();
    if d.omega_r.len() != len || len == 0 {
        return Vec::new();
    }
    (0..len)
        .map(|k| {
            let w2 = d.omega_r[k] + d.omega_r[(k + 1).min(len - 1)];
            C64::from_polar(1.0, w2 * 0.5 * d.dt_s)
        })
        .collect()
}

/// Adds `nz`'s white noise (seeded, standard deviation `sigma_v`) to each component of
/// every voltage sample of `v`.
fn add_white_noise(v: &mut [C64], nz: InputNoise) {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(nz.seed);
    for v in v {
        let (a, b): (f64, f64) = (
            StandardNormal.sample(&mut rng),
            StandardNormal.sample(&mut rng),
        );
        *v += C64::new(a, b) * nz.sigma_v;
    }
}

/// How far the voltage before the block mean (`v_mean / gains`) leaves its rotation (the
/// phase steps `ph`) over each working sample, relative to its magnitude (0 at the ends);
/// a supply step is an outlier of it: above [`prep::SUPPLY_STEP_REL`] and ten times the
/// median (harmonics in a real supply move the vector off its circle every sample).
fn off_rotation(v_mean: &[C64], gains: &[f64], ph: &[f64]) -> Vec<f64> {
    let len = v_mean.len();
    let v_at = |k: usize| v_mean[k] / gains[k];
    (0..len)
        .map(|k| {
            if k == 0 || k + 1 >= len {
                return 0.0;
            }
            let (v0, v1) = (v_at(k), v_at(k + 1));
            (v1 - v0 * C64::from_polar(1.0, ph[k - 1])).norm() / v0.norm().max(v1.norm()).max(1e-12)
        })
        .collect()
}

/// The discrete block mean's gain on a vector turning at `w` [rad/s]: the mean of
/// `factor` samples `h` apart, `sin(F w h / 2) / (F sin(w h / 2))`.
fn block_gain(w: f64, h: f64, factor: f64) -> f64 {
    let x = 0.5 * w * h;
    if x.abs() < 1e-9 {
        1.0
    } else {
        (factor * x).sin() / (factor * x.sin())
    }
}
