//! From a log to the synchronous-frame signals the simplified model needs.
//!
//! Three stages:
//! 1. **Stream and decimate** ([`decimate_log`]): rows are read one at a time (the one log
//!    reader, [`monitor_io::log::LogFile`]), Clarke transformed (`monitor_core::frames::clarke`,
//!    amplitude invariant) and block-averaged to a
//!    working rate of about 2 kHz (never below 1 kHz, at most [`MAX_WORK_SAMPLES`]
//!    samples), so memory is bounded by the working series, not the log.
//! 2. **Rotor-flux frame, voltage model** ([`voltage_model_flux_frame`]; the monitor's
//!    frame is the core's current model, a different estimator): the stator flux is the
//!    leaky integral of
//!    `v - Rs i` (voltage model; the leak, [`FLUX_LEAK_RAD_S`], removes drift at a phase
//!    error of `leak/omega`, 0.2 degrees at 50 Hz), the rotor flux is
//!    `psi_r = (Lr/Lm) (psi_s - sigma Ls i)`, and its angle is the Park angle. In this
//!    frame the paper's model (23) is exact in steady state, in a voltage-oriented frame
//!    it is not (`docs/design.md`, the frame orientation). Current-only logs use the nominal supply angle `2 pi f t` instead.
//! 3. **Sequence separation**: the negative-sequence part of `x_alphabeta` is
//!    `e^{-j theta} LPF(e^{+j theta} x)` (three first-order low-passes at
//!    [`SEQ_LPF_HZ`]), the positive-sequence part is the rest; `theta` is the supply
//!    voltage's own smoothed angle (the rotor-flux frame's for current-only logs), and
//!    around supply steps the low-pass also runs backwards in time
//!    (`SequenceSeparator`). The balanced-machine model is driven by the
//!    positive-sequence voltage and `i_f` = positive-sequence `i_ds`.

mod decimate;
mod flux_frame;
mod sequence;

pub use decimate::{decimate_file, decimate_log, Decimated};
pub use flux_frame::voltage_model_flux_frame;
pub use sequence::SUPPLY_STEP_REL;

use monitor_io::log::Channels;
use nalgebra::Complex;

/// Complex number used for space vectors: `re` = alpha (or d), `im` = beta (or q).
pub type C64 = Complex<f64>;

/// Phase values a, b, c of a stationary-frame space vector plus a zero-sequence part (the
/// core's inverse Clarke transform on the complex form).
pub fn phase_values(x: C64, zero: f64) -> [f64; 3] {
    let ab = monitor_core::frames::AlphaBeta {
        alpha: x.re,
        beta: x.im,
    };
    monitor_core::frames::inverse_clarke(ab, zero).to_array()
}

/// Upper bound on the number of samples of the working (decimated) series.
pub const MAX_WORK_SAMPLES: usize = 4_000_000;
/// Target working rate [Hz] when the log is short enough.
pub const TARGET_RATE_HZ: f64 = 2000.0;
/// Leak of the voltage-model flux integrator [rad/s].
pub const FLUX_LEAK_RAD_S: f64 = 1.0;
/// Corner of the zero-phase smoothing of the frame angle [Hz].
pub const THETA_SMOOTH_HZ: f64 = 20.0;
/// Corner of the zero-phase smoothing of i_f [Hz].
pub const I_F_SMOOTH_HZ: f64 = 10.0;
/// Corner of the sequence-separation low-passes [Hz].
pub const SEQ_LPF_HZ: f64 = 4.0;

/// Time window and limits for reading a log.
#[derive(Debug, Clone, Copy)]
pub struct ReadOptions {
    /// Ignore rows before this time [s].
    pub from_s: f64,
    /// Ignore rows after this time [s].
    pub to_s: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            from_s: f64::NEG_INFINITY,
            to_s: f64::INFINITY,
        }
    }
}

/// Synchronous-frame working signals: the model's inputs and the measured outputs.
#[derive(Debug, Clone, Default)]
pub struct Prepared {
    /// Times [s].
    pub t_s: Vec<f64>,
    /// Working sample period [s] (mean).
    pub dt_s: f64,
    /// Park angle of the frame [rad] (unwrapped).
    pub theta: Vec<f64>,
    /// Frame angular speed omega_s [rad/s] (electrical).
    pub omega_s: Vec<f64>,
    /// Positive-sequence V_ds [V] (zero-length for current-only logs).
    pub vd: Vec<f64>,
    /// Positive-sequence V_qs [V], the model input (eq. 28).
    pub vq: Vec<f64>,
    /// Positive-sequence I_ds [A].
    pub id: Vec<f64>,
    /// i_f of the model [A]: I_ds smoothed without phase shift (forward-backward low-pass at
    /// [`I_F_SMOOTH_HZ`]); eq. (18) takes i_f constant, and the raw I_ds would carry sensor
    /// noise into Psi omega_r with a gain Ls omega / Ra of about 10.
    pub i_f: Vec<f64>,
    /// Measured I_qs [A] (all sequences), the model output to predict.
    pub iq: Vec<f64>,
    /// Positive-sequence measured I_qs [A].
    pub iq_pos: Vec<f64>,
    /// Measured current vector, stationary frame [A].
    pub i_ab: Vec<C64>,
    /// Zero-sequence current [A].
    pub i0: Vec<f64>,
    /// Negative-sequence voltage vector, stationary frame [V] (zeros when no voltages).
    pub v_neg: Vec<C64>,
    /// Negative-sequence current vector, stationary frame [A].
    pub i_neg: Vec<C64>,
    /// Measured electrical rotor speed omega_r = Np wm [rad/s]; empty without speed.
    pub omega_r: Vec<f64>,
    /// Which optional channels the log has.
    pub channels: Channels,
    /// Rows of the log analysed.
    pub rows: u64,
    /// Log sample rate [Hz].
    pub log_rate_hz: f64,
    /// Log rows averaged into each working sample by the block mean of stage 1 (its gain
    /// on a rotating vector, which the full-order model undoes: `simplified_model`). A
    /// coarsened series (a long log's fit series, `Analysis`) keeps its working series'
    /// value: it is averaged in the rotating frame, where a steady vector has no gain.
    /// 0 = not known: one block of `log_rate_hz * dt_s` rows.
    pub block_rows: usize,
    /// Time of the log's first row [s].
    pub log_start_s: f64,
}

impl Prepared {
    /// Number of working samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }
    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }
    /// True when the log can drive the model (voltages present).
    pub fn has_model_inputs(&self) -> bool {
        self.channels.voltages
    }
}

/// Zero-phase low-pass: a first-order filter run forward then backward, twice
/// (fourth-order magnitude, no delay), each pass started at the end value.
pub fn zero_phase_lpf(x: &[f64], dt: f64, fc: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    zero_phase_lpf_in_place(&mut y, dt, fc);
    y
}

/// [`zero_phase_lpf`] in place (the same values, without a copy of a long series: a
/// fresh buffer costs its page faults).
pub fn zero_phase_lpf_in_place(y: &mut [f64], dt: f64, fc: f64) {
    let a = 1.0 - (-2.0 * std::f64::consts::PI * fc * dt).exp();
    // Each pass starts from the mean over one time constant at its end of the series, not
    // from a single (noisy) sample: a start from one sample carries that sample's noise into
    // the first time constants of the output.
    let m =
        ((1.0 / (2.0 * std::f64::consts::PI * fc * dt)).ceil() as usize).clamp(1, y.len().max(1));
    let head = |y: &[f64]| y.iter().take(m).sum::<f64>() / m.min(y.len()).max(1) as f64;
    let tail = |y: &[f64]| y.iter().rev().take(m).sum::<f64>() / m.min(y.len()).max(1) as f64;
    for _ in 0..2 {
        let mut s = head(y);
        for v in y.iter_mut() {
            s += a * (*v - s);
            *v = s;
        }
        let mut s = tail(y);
        for v in y.iter_mut().rev() {
            s += a * (*v - s);
            *v = s;
        }
    }
}

/// Hann weight of sample `k` of `n` (unnormalised, 0..2): the weighted mean of a rotating
/// vector over a few whole turns is zero even when the sample grid cuts the last turn short.
fn hann(k: usize, n: usize) -> f64 {
    1.0 - (2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n.max(1) as f64).cos()
}

#[cfg(test)]
mod tests {
    use monitor_core::frames::{clarke, zero_sequence, Abc};

    #[test]
    fn clarke_round_trip_in_f64() {
        use monitor_core::frames::inverse_clarke;
        let x = Abc::from_array([1.0f64, -0.3, -0.4]);
        let y = inverse_clarke(clarke(x), zero_sequence(x));
        for (a, b) in x.to_array().iter().zip(y.to_array()) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
