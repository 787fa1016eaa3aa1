//! Stage 3 of [`super`]: positive/negative sequence separation.

use super::{hann, C64, SEQ_LPF_HZ};

/// Third-order low-pass (three first-order stages at `fc`) of the demodulated signal
/// `x = c + P e^{j omega k}`: a slowly varying part `c` (what the filter is for) plus a
/// rotating remainder at `omega` [rad/sample] (the other sequence). In place; with
/// `backward` the series is filtered from its last sample to its first (as the reversed
/// series would be, each output left at its own sample).
///
/// The states start in their periodic steady state, `s_i = c + H^i P e^{-j omega}` with
/// `H = a / (1 - (1 - a) e^{-j omega})`, `c` the Hann-weighted mean of the first `init_len`
/// samples (whole turns) and `P = x_0 - c`: started from the plain mean, each stage would
/// begin with a transient the size of its ripple, which the next stages pass as a slow
/// bump (0.15 A on a 9 A current over the first 0.3 s).
///
/// `fc` is the corner [Hz] at each sample (of the series' own order; [`corner_hz`]).
fn lpf3(x: &mut [C64], dt: f64, fc: &[f64], init_len: usize, omega: f64, backward: bool) {
    let gain = |f: f64| 1.0 - (-2.0 * std::f64::consts::PI * f * dt).exp();
    let n = x.len();
    let fc_at = |k: usize| fc.get(k).copied().unwrap_or(SEQ_LPF_HZ);
    let a = gain(fc_at(if backward { n.saturating_sub(1) } else { 0 }));
    let at = |k: usize| if backward { n - 1 - k } else { k };
    let m = init_len.clamp(1, n.max(1));
    let (mut sum, mut wsum) = (C64::new(0.0, 0.0), 0.0);
    for k in 0..m.min(n) {
        let w = hann(k, m);
        sum += x[at(k)] * w;
        wsum += w;
    }
    let c = sum / wsum.max(1e-12);
    let p0 = if n > 0 { x[at(0)] } else { C64::default() } - c;
    let back = C64::from_polar(1.0, -omega);
    let h = C64::new(a, 0.0) / (C64::new(1.0, 0.0) - back * (1.0 - a));
    let mut s = [
        c + h * p0 * back,
        c + h * h * p0 * back,
        c + h * h * h * p0 * back,
    ];
    let mut stage = |v: &mut C64, a: f64| {
        s[0] += a * (*v - s[0]);
        s[1] += a * (s[0] - s[1]);
        s[2] += a * (s[1] - s[2]);
        *v = s[2];
    };
    if backward {
        for (k, v) in x.iter_mut().enumerate().rev() {
            stage(v, gain(fc_at(k)));
        }
    } else {
        for (k, v) in x.iter_mut().enumerate() {
            stage(v, gain(fc_at(k)));
        }
    }
}

/// The sequence separation's corner at a supply frequency of `omega_s` [rad/s]:
/// [`SEQ_LPF_HZ`], but at most an eighth of the supply frequency, so that the other
/// sequence, turning at twice the supply frequency in the demodulated signal, is damped
/// by at least (1/16)^3 = 2.4e-4 whatever the frequency. At 4 Hz fixed, a V/f drive at
/// 15 Hz left 0.24 % of its positive sequence as an apparent negative sequence, which the
/// full-order model driven by the positive sequence alone then missed (a balanced
/// converter's log named a 0.4 % "supply unbalance").
pub(super) fn corner_hz(omega_s: f64) -> f64 {
    SEQ_LPF_HZ
        .min(omega_s.abs() / (2.0 * std::f64::consts::PI) / 8.0)
        .max(0.05)
}

/// Relative jump of the supply voltage between two working samples that marks a supply
/// step (a V/f or voltage step, a switch-on) for the sequence separation: 3 % of the
/// median voltage, far above sensor noise (0.1 %) and the 0.2 % steps of a variac-like
/// ramp, below a 10 % dip.
pub const SUPPLY_STEP_REL: f64 = 0.03;

/// Working samples where the supply voltage steps: the voltage in its own frame
/// (`rot` = e^{j theta_v}) jumps by more than [`SUPPLY_STEP_REL`] of the median voltage
/// and ten times the median jump.
pub(super) fn supply_steps(v_ab: &[C64], rot: &[C64]) -> Vec<usize> {
    // The voltage in its own frame, its magnitude and its jumps, in one pass.
    let n = v_ab.len().min(rot.len());
    let mut mags: Vec<f64> = Vec::with_capacity(n);
    let mut jumps: Vec<f64> = Vec::with_capacity(n.saturating_sub(1));
    let mut prev: Option<C64> = None;
    for (v, r) in v_ab.iter().zip(rot) {
        let u = v * r.conj();
        mags.push(u.norm());
        if let Some(p) = prev {
            jumps.push((u - p).norm());
        }
        prev = Some(u);
    }
    if mags.is_empty() {
        return Vec::new();
    }
    let mid = mags.len() / 2;
    let median = *mags.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    // The magnitudes' buffer takes the jumps to be ordered.
    let mut sorted = mags;
    sorted.clear();
    sorted.extend_from_slice(&jumps);
    let typical = if sorted.is_empty() {
        0.0
    } else {
        let m = sorted.len() / 2;
        *sorted.select_nth_unstable_by(m, |a, b| a.total_cmp(b)).1
    };
    // An outlier, too: harmonics in a real supply move the vector every sample.
    let thr = (SUPPLY_STEP_REL * median).max(10.0 * typical);
    (1..n).filter(|&k| jumps[k - 1] > thr).collect()
}

/// Positive/negative sequence separation by demodulation in the `-theta` frame
/// ([`lpf3`] at [`SEQ_LPF_HZ`], states started in their periodic steady state).
///
/// A step of the positive sequence (a supply step) is a switched `2 omega` sinusoid in
/// the demodulated signal, whose low-frequency content the low-pass takes for negative
/// sequence for its memory (0.2 s; 1 V after a 40 % V/f step on a 230 V supply). With
/// supply steps in the log the low-pass is also run backwards in time, which sees each
/// step only after (in its time) the samples before it: each sample takes the pass whose
/// last step lies further back in that pass's own direction (weights `a_f^2 : a_b^2`,
/// `a` the time since the pass's last step), so between steps both passes are clean
/// where they are used. Without steps the separation is the forward pass alone.
pub(super) struct SequenceSeparator {
    dt: f64,
    init_len: usize,
    /// Rotation of the positive sequence per sample in the demodulated signal [rad].
    omega_2: f64,
    /// The same at the log's end (for the backward pass).
    init_len_end: usize,
    omega_2_end: f64,
    /// Working samples where the supply steps ([`supply_steps`]).
    pub(super) steps: Vec<usize>,
    /// The low-pass corner at each working sample [Hz] ([`corner_hz`]).
    fc: Vec<f64>,
}

impl SequenceSeparator {
    pub(super) fn new(theta: &[f64], omega_s: &[f64], dt: f64) -> Self {
        let n = theta.len();
        let w_first = omega_s.iter().take(64).sum::<f64>() / omega_s.len().clamp(1, 64) as f64;
        let period = 2.0 * std::f64::consts::PI / w_first.abs().max(1.0);
        // Four whole turns of the frame itself (not of the nominal period): a part-period
        // mean leaves a positive-sequence remainder that the low-pass then releases as a
        // decaying 2f ripple over the first 0.2 s.
        let init_len = theta
            .iter()
            .position(|&th| (th - theta[0]).abs() >= 8.0 * std::f64::consts::PI)
            .unwrap_or(((2.0 * period / dt).round() as usize).max(1));
        // The positive sequence turns at twice the frame's step in the demodulated signal.
        let omega_2 =
            2.0 * (theta[init_len.min(n - 1)] - theta[0]) / init_len.min(n - 1).max(1) as f64;
        let last = theta.last().copied().unwrap_or(0.0);
        let init_len_end = theta
            .iter()
            .rev()
            .position(|&th| (last - th).abs() >= 8.0 * std::f64::consts::PI)
            .unwrap_or(init_len);
        let m = init_len_end.min(n - 1).max(1);
        let omega_2_end = 2.0 * (last - theta[n - 1 - m.min(n - 1)]) / m as f64;
        SequenceSeparator {
            dt,
            init_len,
            omega_2,
            init_len_end,
            omega_2_end,
            steps: Vec::new(),
            fc: omega_s.iter().map(|&w| corner_hz(w)).collect(),
        }
    }

    /// The negative-sequence part of `x` (stationary frame), `rot` = e^{j theta}.
    pub(super) fn negative(&self, x: &[C64], rot: &[C64]) -> Vec<C64> {
        let mut f: Vec<C64> = x.iter().zip(rot).map(|(v, r)| v * r).collect();
        // The backward pass runs on its own copy of the demodulated signal.
        let b = (!self.steps.is_empty()).then(|| {
            let mut b = f.clone();
            lpf3(
                &mut b,
                self.dt,
                &self.fc,
                self.init_len_end,
                -self.omega_2_end,
                true,
            );
            b
        });
        lpf3(
            &mut f,
            self.dt,
            &self.fc,
            self.init_len,
            self.omega_2,
            false,
        );
        if let Some(b) = b {
            let mut next = 0usize;
            for (k, fk) in f.iter_mut().enumerate() {
                while next < self.steps.len() && self.steps[next] <= k {
                    next += 1;
                }
                // Samples since the forward pass's last step, to the backward pass's.
                let a_f = match next {
                    0 => f64::INFINITY,
                    i => (k - self.steps[i - 1]) as f64,
                };
                let a_b = self
                    .steps
                    .get(next)
                    .map_or(f64::INFINITY, |&s| (s - k) as f64);
                let w_f = if a_f.is_infinite() {
                    1.0
                } else if a_b.is_infinite() {
                    0.0
                } else {
                    a_f * a_f / (a_f * a_f + a_b * a_b).max(1e-12)
                };
                *fk = *fk * w_f + b[k] * (1.0 - w_f);
            }
        }
        for (v, r) in f.iter_mut().zip(rot) {
            *v *= r.conj();
        }
        f
    }
}
