//! From a log to the synchronous-frame signals the simplified model needs.
//!
//! Three stages:
//! 1. **Stream and decimate** ([`decimate_log`]): rows are read one at a time (the one log
//!    reader, [`crate::log::LogFile`]), Clarke transformed (`monitor_core::frames::clarke`,
//!    amplitude invariant) and block-averaged to a
//!    working rate of about 2 kHz (never below 1 kHz, at most [`MAX_WORK_SAMPLES`]
//!    samples), so memory is bounded by the working series, not the log.
//! 2. **Rotor-flux frame, voltage model** ([`voltage_model_flux_frame`]; the monitor's
//!    frame is the core's current model, a different estimator): the stator flux is the
//!    leaky integral of
//!    `v - Rs i` (voltage model; the leak, [`FLUX_LEAK_RAD_S`], removes drift at a phase
//!    error of `leak/omega`, 0.2 degrees at 50 Hz), the rotor flux is
//!    `psi_r = (Lr/Lm) (psi_s - sigma Ls i)`, and its angle is the Park angle. DESIGN.md §2:
//!    in this frame the paper's model (23) is exact in steady state, in a voltage-oriented
//!    frame it is not. Current-only logs use the nominal supply angle `2 pi f t` instead.
//! 3. **Sequence separation**: the negative-sequence part of `x_alphabeta` is
//!    `e^{-j theta} LPF(e^{+j theta} x)` (three first-order low-passes at
//!    [`SEQ_LPF_HZ`]), the positive-sequence part is the rest. The balanced-machine model
//!    is driven by the positive-sequence voltage and `i_f` = positive-sequence `i_ds`.

use crate::log::{Channels, LogError, LogFile, Row, RowSink, RATE_ESTIMATE_ROWS};
use crate::params::ParamFile;
use monitor_core::frames::{clarke, zero_sequence, Abc};
use nalgebra::Complex;
use std::path::Path;

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

/// Block-averaged stationary-frame signals (the working series).
#[derive(Debug, Clone, Default)]
pub struct Decimated {
    /// Block-centre times [s].
    pub t_s: Vec<f64>,
    /// Stator voltage vector (alpha, beta) [V]; empty for current-only logs.
    pub v_ab: Vec<[f32; 2]>,
    /// Stator current vector (alpha, beta) [A].
    pub i_ab: Vec<[f32; 2]>,
    /// Zero-sequence current (ia+ib+ic)/3 [A] (kept for the phase-current channels).
    pub i0: Vec<f32>,
    /// Mechanical speed [rad/s]; empty when the log has no `wm_rad_s`.
    pub wm: Vec<f32>,
    /// Which optional channels the log has.
    pub channels: Channels,
    /// Rows read from the log (after the time window).
    pub rows: u64,
    /// Log sample rate [Hz] (mean).
    pub log_rate_hz: f64,
    /// Decimation factor (log rows per working sample).
    pub factor: usize,
    /// Time of the log's first row [s] (before any time window): "time since start".
    pub log_start_s: f64,
}

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

/// Streams a log and block-averages it to the working rate.
///
/// `progress` is called with the fraction of the file read (0..1), at most a few hundred
/// times. Errors are the log reader's (one line, naming the file, line and column), or
/// [`LogError::Empty`] when the time window holds fewer than 16 rows.
pub fn decimate_log(
    path: &Path,
    opts: ReadOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Decimated, LogError> {
    let file = LogFile::open(path)?;
    let mut sink = Decimator::new(&file, opts);
    file.for_each_row(progress, &mut sink)?;
    if let Some(e) = sink.error.take() {
        return Err(e);
    }
    if !sink.started {
        // Fewer rows than the rate estimate looks at: decimate what there is.
        sink.start()?;
    }
    let mut d = sink.out;
    d.rows = sink.averager.rows;
    d.log_start_s = sink.first_t.unwrap_or(0.0);
    if d.t_s.len() < 16 {
        return Err(LogError::Empty {
            path: format!(
                "{} (in the selected time window, too few rows)",
                path.display()
            ),
        });
    }
    progress(1.0);
    Ok(d)
}

/// Chooses the decimation factor for a log of `est_rows` rows at `log_rate_hz`: the
/// working rate near [`TARGET_RATE_HZ`], coarser if the series would exceed
/// [`MAX_WORK_SAMPLES`], never below 1 kHz.
fn decimation_factor(log_rate_hz: f64, est_rows: f64) -> usize {
    let mut factor = ((log_rate_hz / TARGET_RATE_HZ).floor() as usize).max(1);
    while est_rows / factor as f64 > MAX_WORK_SAMPLES as f64
        && log_rate_hz / (factor as f64 + 1.0) >= 1000.0
    {
        factor += 1;
    }
    factor
}

/// The decimation as a [`RowSink`]: holds the first rows until the sample rate (and so the
/// decimation factor) is known, then block-averages the rows inside the time window.
struct Decimator {
    shown: String,
    opts: ReadOptions,
    est_rows: f64,
    head: Vec<Row>,
    started: bool,
    first_t: Option<f64>,
    averager: BlockAverager,
    out: Decimated,
    error: Option<LogError>,
}

impl Decimator {
    fn new(file: &LogFile, opts: ReadOptions) -> Self {
        Decimator {
            shown: file.shown().to_string(),
            opts,
            est_rows: file.estimated_rows(),
            head: Vec::new(),
            started: false,
            first_t: None,
            averager: BlockAverager::default(),
            out: Decimated {
                channels: file.channels(),
                ..Default::default()
            },
            error: None,
        }
    }

    /// Fixes the factor from the rows held and averages them; the rows' errors (no rows,
    /// no usable time step) are returned.
    fn start(&mut self) -> Result<(), LogError> {
        self.started = true;
        let times: Vec<f64> = self.head.iter().map(|r| r.t_s).collect();
        let log_rate = match crate::log::sample_rate_hz(&times) {
            Some(r) => r,
            None if times.len() < 2 => {
                return Err(LogError::Empty {
                    path: self.shown.clone(),
                })
            }
            None => {
                return Err(LogError::Csv {
                    path: self.shown.clone(),
                    line: 0,
                    message: "cannot determine the sample period from t_s".into(),
                })
            }
        };
        let factor = decimation_factor(log_rate, self.est_rows);
        let d = &mut self.out;
        d.factor = factor;
        d.log_rate_hz = log_rate;
        let cap = (self.est_rows / factor as f64) as usize + 16;
        d.t_s.reserve(cap.min(MAX_WORK_SAMPLES + 16));
        let head = std::mem::take(&mut self.head);
        for r in &head {
            if !self.push(r) {
                break;
            }
        }
        Ok(())
    }

    /// Averages one row inside the time window; false past its end.
    fn push(&mut self, row: &Row) -> bool {
        if row.t_s < self.opts.from_s {
            return true;
        }
        if row.t_s > self.opts.to_s {
            return false;
        }
        self.averager.push(&mut self.out, row);
        true
    }
}

impl RowSink for Decimator {
    fn row(&mut self, row: &Row) -> bool {
        self.first_t.get_or_insert(row.t_s);
        if self.started {
            return self.push(row);
        }
        self.head.push(*row);
        if self.head.len() < RATE_ESTIMATE_ROWS {
            return true;
        }
        match self.start() {
            Ok(()) => row.t_s <= self.opts.to_s,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    fn restart(&mut self) {
        let channels = self.out.channels;
        self.head.clear();
        self.started = false;
        self.first_t = None;
        self.averager = BlockAverager::default();
        self.out = Decimated {
            channels,
            ..Default::default()
        };
        self.error = None;
    }
}

/// Block average of `factor` rows: time, current vector and zero sequence, voltage
/// vector, speed.
#[derive(Default)]
struct BlockAverager {
    sum: [f64; 7],
    k: usize,
    rows: u64,
}

impl BlockAverager {
    fn push(&mut self, d: &mut Decimated, row: &Row) {
        self.rows += 1;
        let i = Abc::from_array(row.i_abc);
        let iab = clarke(i);
        let a = &mut self.sum;
        a[0] += row.t_s;
        a[1] += iab.alpha;
        a[2] += iab.beta;
        a[3] += zero_sequence(i);
        if let Some(v) = row.v_abc {
            let vab = clarke(Abc::from_array(v));
            a[4] += vab.alpha;
            a[5] += vab.beta;
        }
        if let Some(w) = row.wm_rad_s {
            a[6] += w;
        }
        self.k += 1;
        if self.k == d.factor {
            let inv = 1.0 / self.k as f64;
            d.t_s.push(a[0] * inv);
            d.i_ab.push([(a[1] * inv) as f32, (a[2] * inv) as f32]);
            d.i0.push((a[3] * inv) as f32);
            if d.channels.voltages {
                d.v_ab.push([(a[4] * inv) as f32, (a[5] * inv) as f32]);
            }
            if d.channels.speed {
                d.wm.push((a[6] * inv) as f32);
            }
            *a = [0.0; 7];
            self.k = 0;
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
    let a = 1.0 - (-2.0 * std::f64::consts::PI * fc * dt).exp();
    // Each pass starts from the mean over one time constant at its end of the series, not
    // from a single (noisy) sample: a start from one sample carries that sample's noise into
    // the first time constants of the output.
    let m =
        ((1.0 / (2.0 * std::f64::consts::PI * fc * dt)).ceil() as usize).clamp(1, x.len().max(1));
    let head = |y: &[f64]| y.iter().take(m).sum::<f64>() / m.min(y.len()).max(1) as f64;
    let tail = |y: &[f64]| y.iter().rev().take(m).sum::<f64>() / m.min(y.len()).max(1) as f64;
    let mut y = x.to_vec();
    for _ in 0..2 {
        let mut s = head(&y);
        for v in y.iter_mut() {
            s += a * (*v - s);
            *v = s;
        }
        let mut s = tail(&y);
        for v in y.iter_mut().rev() {
            s += a * (*v - s);
            *v = s;
        }
    }
    y
}

/// Hann weight of sample `k` of `n` (unnormalised, 0..2): the weighted mean of a rotating
/// vector over a few whole turns is zero even when the sample grid cuts the last turn short.
fn hann(k: usize, n: usize) -> f64 {
    1.0 - (2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n.max(1) as f64).cos()
}

/// Third-order low-pass (three first-order stages at `fc`) of the demodulated signal
/// `x = c + P e^{j omega k}`: a slowly varying part `c` (what the filter is for) plus a
/// rotating remainder at `omega` [rad/sample] (the other sequence).
///
/// The states start in their periodic steady state, `s_i = c + H^i P e^{-j omega}` with
/// `H = a / (1 - (1 - a) e^{-j omega})`, `c` the Hann-weighted mean of the first `init_len`
/// samples (whole turns) and `P = x_0 - c`: started from the plain mean, each stage would
/// begin with a transient the size of its ripple, which the next stages pass as a slow
/// bump (0.15 A on a 9 A current over the first 0.3 s).
fn lpf3(x: &[C64], dt: f64, fc: f64, init_len: usize, omega: f64) -> Vec<C64> {
    let a = 1.0 - (-2.0 * std::f64::consts::PI * fc * dt).exp();
    let m = init_len.clamp(1, x.len().max(1));
    let (mut sum, mut wsum) = (C64::new(0.0, 0.0), 0.0);
    for (k, v) in x.iter().take(m).enumerate() {
        let w = hann(k, m);
        sum += v * w;
        wsum += w;
    }
    let c = sum / wsum.max(1e-12);
    let p0 = x.first().copied().unwrap_or_default() - c;
    let back = C64::from_polar(1.0, -omega);
    let h = C64::new(a, 0.0) / (C64::new(1.0, 0.0) - back * (1.0 - a));
    let mut s = [
        c + h * p0 * back,
        c + h * h * p0 * back,
        c + h * h * h * p0 * back,
    ];
    x.iter()
        .map(|&v| {
            s[0] += a * (v - s[0]);
            s[1] += a * (s[0] - s[1]);
            s[2] += a * (s[1] - s[2]);
            s[2]
        })
        .collect()
}

/// Builds the voltage-model rotor-flux frame and the d-q signals from the working series.
///
/// `p` gives the parameters of the flux estimator (Rs, sigma Ls, Lr/Lm) and, for
/// current-only logs, the supply frequency of the frame. Pole pairs convert the measured
/// mechanical speed to electrical omega_r.
pub fn voltage_model_flux_frame(d: &Decimated, p: &ParamFile) -> Prepared {
    let n = d.t_s.len();
    let dt = if n > 1 {
        (d.t_s[n - 1] - d.t_s[0]) / (n - 1) as f64
    } else {
        1e-3
    };
    let to_c64 = |x: &[f32; 2]| C64::new(x[0] as f64, x[1] as f64);
    let i_ab: Vec<C64> = d.i_ab.iter().map(to_c64).collect();
    let v_ab: Vec<C64> = d.v_ab.iter().map(to_c64).collect();
    let theta = if d.channels.voltages {
        let raw = flux_angle(&v_ab, &i_ab, dt, p);
        smooth_angle(raw, dt)
    } else {
        let w0 = p.supply.omega_rad_s();
        d.t_s.iter().map(|t| w0 * t).collect()
    };
    // Frame speed: central difference of the unwrapped angle, low-passed (20 Hz).
    let mut omega_s = vec![0.0; n];
    for k in 0..n {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
        if b > a {
            omega_s[k] = (theta[b] - theta[a]) / (d.t_s[b] - d.t_s[a]);
        }
    }
    // Smoothed without phase shift: a causal filter would lag a V/f ramp by its group delay.
    let omega_s = zero_phase_lpf(&omega_s, dt, 20.0);
    let rot: Vec<C64> = theta
        .iter()
        .map(|&th| C64::new(th.cos(), th.sin()))
        .collect();
    let sep = SequenceSeparator::new(&theta, &omega_s, dt);
    let i_neg = sep.negative(&i_ab, &rot);
    let v_neg = if d.channels.voltages {
        sep.negative(&v_ab, &rot)
    } else {
        vec![C64::new(0.0, 0.0); n]
    };
    // Park transforms in complex form: x_dq = x_alphabeta e^{-j theta}.
    let mut vd = Vec::new();
    let mut vq = Vec::new();
    if d.channels.voltages {
        for k in 0..n {
            let v = (v_ab[k] - v_neg[k]) * rot[k].conj();
            vd.push(v.re);
            vq.push(v.im);
        }
    }
    let mut id = Vec::with_capacity(n);
    let mut iq = Vec::with_capacity(n);
    let mut iq_pos = Vec::with_capacity(n);
    for k in 0..n {
        let ip = (i_ab[k] - i_neg[k]) * rot[k].conj();
        let it = i_ab[k] * rot[k].conj();
        id.push(ip.re);
        iq_pos.push(ip.im);
        iq.push(it.im);
    }
    let np = p.motor.model::<f64>().np();
    let i_f = zero_phase_lpf(&id, dt, I_F_SMOOTH_HZ);
    Prepared {
        i_f,
        t_s: d.t_s.clone(),
        dt_s: dt,
        theta,
        omega_s,
        vd,
        vq,
        id,
        iq,
        iq_pos,
        i_ab,
        i0: d.i0.iter().map(|&x| x as f64).collect(),
        v_neg,
        i_neg,
        omega_r: d.wm.iter().map(|&w| w as f64 * np).collect(),
        channels: d.channels,
        rows: d.rows,
        log_rate_hz: d.log_rate_hz,
        log_start_s: d.log_start_s,
    }
}

/// Initial stator flux of the voltage model: zero when the log starts de-energised (a
/// start from standstill), otherwise the value that makes the flux zero-mean over the first
/// eight nominal supply periods (a log that starts mid-run), Hann-weighted: a plain mean
/// over a period count that the sample grid cuts short leaves a flux offset of about
/// (missing fraction) x |psi|, which the leak then takes a second to remove and which shows
/// as a supply-frequency ripple on I_qs meanwhile.
fn initial_stator_flux(v_ab: &[C64], i_ab: &[C64], dt: f64, rs: f64, w0: f64) -> C64 {
    let n = i_ab.len();
    let n_per = ((8.0 * 2.0 * std::f64::consts::PI / w0) / dt)
        .round()
        .max(1.0) as usize;
    let n_per = n_per.min(n);
    let i_rms_all = (i_ab.iter().map(|x| x.norm_sqr()).sum::<f64>() / n as f64).sqrt();
    let n_head = ((0.002 / dt).ceil() as usize).clamp(1, n);
    let i_rms_head =
        (i_ab[..n_head].iter().map(|x| x.norm_sqr()).sum::<f64>() / n_head as f64).sqrt();
    if i_rms_head <= 0.02 * i_rms_all {
        return C64::new(0.0, 0.0);
    }
    let mut acc = C64::new(0.0, 0.0);
    let mut sum = C64::new(0.0, 0.0);
    let mut wsum = 0.0;
    for k in 0..n_per {
        if k > 0 {
            acc += (v_ab[k] - i_ab[k] * rs + v_ab[k - 1] - i_ab[k - 1] * rs) * (0.5 * dt);
        }
        let w = hann(k, n_per);
        sum += acc * w;
        wsum += w;
    }
    -sum / wsum.max(1e-12)
}

/// The unwrapped angle of the voltage-model rotor flux: stator flux by a leaky
/// (trapezoidal) integrator of `v - Rs i`, the leak's quasi-steady phase lead undone,
/// `psi_r = (Lr/Lm) (psi_s - sigma Ls i)`.
fn flux_angle(v_ab: &[C64], i_ab: &[C64], dt: f64, p: &ParamFile) -> Vec<f64> {
    let n = i_ab.len();
    let m = p.motor.model::<f64>();
    let sls = m.la_h();
    let kr = m.lr_h / m.lm_h;
    let decay = (-FLUX_LEAK_RAD_S * dt).exp();
    let w0 = p.supply.omega_rad_s();
    let mut psi_s = initial_stator_flux(v_ab, i_ab, dt, m.rs_ohm, w0);
    let mut theta = Vec::with_capacity(n);
    let mut prev_e = v_ab[0] - i_ab[0] * m.rs_ohm;
    let mut unwrapped = 0.0f64;
    let mut prev_ang: Option<f64> = None;
    // Stator-flux frequency (causal, 20 Hz) for the leak compensation.
    let mut w_flux = w0;
    let a_w = 1.0 - (-2.0 * std::f64::consts::PI * THETA_SMOOTH_HZ * dt).exp();
    let mut prev_psi = psi_s;
    for k in 0..n {
        let e = v_ab[k] - i_ab[k] * m.rs_ohm;
        if k > 0 {
            psi_s = psi_s * decay + (e + prev_e) * (0.5 * dt);
            let turn = psi_s * prev_psi.conj();
            if turn.norm() > 1e-12 {
                w_flux += a_w * (turn.im.atan2(turn.re) / dt - w_flux);
            }
        }
        prev_e = e;
        prev_psi = psi_s;
        // The leak turns a flux rotating at w by atan(leak / w) (0.6 degrees at 15 Hz)
        // and a frame error tilts I_qs by about (Ls w / Ra) x I_ds x the angle; so the
        // quasi-steady leak response jw/(jw + leak) is undone: psi = psi_leaky (1 - j leak/w).
        let psi_c = if w_flux.abs() > 5.0 * FLUX_LEAK_RAD_S {
            psi_s * C64::new(1.0, -FLUX_LEAK_RAD_S / w_flux)
        } else {
            psi_s
        };
        let psi_r = (psi_c - i_ab[k] * sls) * kr;
        let ang = if psi_r.norm() > 1e-6 {
            psi_r.im.atan2(psi_r.re)
        } else {
            // No flux yet: follow the nominal supply.
            prev_ang.map(|a| a + w0 * dt).unwrap_or(0.0)
        };
        match prev_ang {
            None => unwrapped = ang,
            Some(pa) => {
                let mut da = ang - pa;
                da = (da + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                unwrapped += da;
            }
        }
        prev_ang = Some(ang);
        theta.push(unwrapped);
    }
    theta
}

/// The frame angle: the voltage-model angle carries a 2f wobble when the machine or the
/// supply is unbalanced; the frame follows its zero-phase smoothed version (20 Hz), which
/// keeps start-up and step transients and makes the sequence separation clean.
/// (Smoothing the angle's increments and summing them back avoids the end effects a
/// filter has on a ramp.)
fn smooth_angle(theta: Vec<f64>, dt: f64) -> Vec<f64> {
    let n = theta.len();
    if n <= 2 {
        return theta;
    }
    let inc: Vec<f64> = theta.windows(2).map(|w| w[1] - w[0]).collect();
    let inc = zero_phase_lpf(&inc, dt, THETA_SMOOTH_HZ);
    let mut th = theta[0];
    let mut smooth = Vec::with_capacity(n);
    smooth.push(th);
    for v in inc {
        th += v;
        smooth.push(th);
    }
    // A zero-phase filter moves the running sum of a ramp's increments at every kink
    // (by the slope change times half the kernel's variance: 0.02 rad for a V/f ramp
    // of 150 rad/s^2 at 20 Hz, enough to tilt I_qs by 13 % of I_ds x 0.02 in a sweep). The
    // summed angle is therefore only the reference: the raw angle's deviation from it,
    // itself smoothed, is added back, so the frame follows the flux at every kink.
    let dev: Vec<f64> = theta.iter().zip(&smooth).map(|(a, b)| a - b).collect();
    let dev = zero_phase_lpf(&dev, dt, THETA_SMOOTH_HZ);
    smooth.into_iter().zip(dev).map(|(v, e)| v + e).collect()
}

/// Positive/negative sequence separation by demodulation in the `-theta` frame
/// ([`lpf3`] at [`SEQ_LPF_HZ`], states started in their periodic steady state).
struct SequenceSeparator {
    dt: f64,
    init_len: usize,
    /// Rotation of the positive sequence per sample in the demodulated signal [rad].
    omega_2: f64,
}

impl SequenceSeparator {
    fn new(theta: &[f64], omega_s: &[f64], dt: f64) -> Self {
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
        SequenceSeparator {
            dt,
            init_len,
            omega_2,
        }
    }

    /// The negative-sequence part of `x` (stationary frame), `rot` = e^{j theta}.
    fn negative(&self, x: &[C64], rot: &[C64]) -> Vec<C64> {
        let shifted: Vec<C64> = x.iter().zip(rot).map(|(v, r)| v * r).collect();
        let f = lpf3(&shifted, self.dt, SEQ_LPF_HZ, self.init_len, self.omega_2);
        f.iter().zip(rot).map(|(v, r)| v * r.conj()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
