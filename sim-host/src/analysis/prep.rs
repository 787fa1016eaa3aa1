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
//!    [`SEQ_LPF_HZ`]), the positive-sequence part is the rest; `theta` is the supply
//!    voltage's own smoothed angle (the rotor-flux frame's for current-only logs), and
//!    around supply steps the low-pass also runs backwards in time
//!    (`SequenceSeparator`). The balanced-machine model is driven by the
//!    positive-sequence voltage and `i_f` = positive-sequence `i_ds`.

use crate::log::quality::{
    BadCells, CellLimits, CleanSink, DataQuality, QualityStage, SegmentBreak, TimeBase,
    MAX_BRIDGED_GAP_S,
};
use crate::log::{Channels, LogError, LogFile, Row};
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
    /// Time bridged across holes (dropped samples, bad cells) by [`regrid`] [s].
    pub bridged_s: f64,
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

/// Streams a log through the data-quality stage ([`crate::log::quality`]) and
/// block-averages it to the working rate.
///
/// The stage drops rows whose time repeats or goes back, flags bad cells and splits the
/// log at long gaps, clock resets and rate changes. Here, rows with a bad cell are left
/// out (a hole, like a dropped sample); blocks sit on the segment's own sample grid, so a
/// hole leaves a block short or empty, and [`regrid`] puts the working series back on a
/// uniform grid, bridging the holes across the supply rotation. Of the segments inside the
/// time window the longest is analysed; the others are named in the report's
/// `data_quality.actions`.
///
/// `progress` is called with the fraction of the file read (0..1), at most a few hundred
/// times.
///
/// # Errors
/// The log reader's and the stage's errors (one line, naming the file, line and column,
/// or the sample rate needed), or [`LogError::Empty`] when the time window holds fewer
/// than 16 working samples.
pub fn decimate_log(
    path: &Path,
    params: &ParamFile,
    opts: ReadOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<(Decimated, DataQuality), LogError> {
    decimate_file(&LogFile::open(path)?, params, opts, progress)
}

/// [`decimate_log`] on a log already opened (any format, a TDMS group chosen:
/// [`LogFile::open_with`]).
///
/// # Errors
/// As [`decimate_log`].
pub fn decimate_file(
    file: &LogFile,
    params: &ParamFile,
    opts: ReadOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<(Decimated, DataQuality), LogError> {
    let path = file.path();
    let mut sink = Decimator::new(opts, file.estimated_rows(), file.channels());
    let mut stage = QualityStage::new(&mut sink, CellLimits::for_params(params), file.shown());
    let read = file.for_each_row(progress, &mut stage);
    let quality = stage.finish();
    read?;
    let mut quality = quality?;
    sink.end_segment();
    sink.describe(&mut quality);
    let d = sink.best.take().unwrap_or_default();
    if d.t_s.len() < 16 {
        return Err(LogError::Empty {
            path: format!(
                "{} (in the selected time window, too few rows)",
                path.display()
            ),
        });
    }
    progress(1.0);
    Ok((d, quality))
}

/// Chooses the decimation factor for a log of `est_rows` rows at `log_rate_hz`: the
/// working rate near [`TARGET_RATE_HZ`], coarser if the series would exceed
/// [`MAX_WORK_SAMPLES`], never below 1 kHz.
fn decimation_factor(log_rate_hz: f64, est_rows: f64) -> usize {
    // (A rate estimated as 9999.999999999998 Hz is 10 kHz: neither the floor nor the 1 kHz
    // limit may see the last digit.)
    let rate = log_rate_hz * (1.0 + 1e-9);
    let mut factor = ((rate / TARGET_RATE_HZ).floor() as usize).max(1);
    while est_rows / factor as f64 > MAX_WORK_SAMPLES as f64
        && rate / (factor as f64 + 1.0) >= 1000.0
    {
        factor += 1;
    }
    factor
}

/// The decimation behind the data-quality stage: one working series per segment, the
/// longest kept.
struct Decimator {
    opts: ReadOptions,
    est_rows: f64,
    channels: Channels,
    t0: f64,
    period: f64,
    /// The segment being built, with its first row's time and whether it has holes.
    cur: Decimated,
    seg_t0: Option<f64>,
    holes: bool,
    averager: BlockAverager,
    best: Option<Decimated>,
    /// Every segment with rows in the window: `[from, to]` [s since the log's start] and
    /// whether it is the one kept.
    spans: Vec<[f64; 2]>,
    kept: Option<usize>,
    held_out: u64,
    last_good_t: Option<f64>,
}

impl Decimator {
    fn new(opts: ReadOptions, est_rows: f64, channels: Channels) -> Self {
        Decimator {
            opts,
            est_rows,
            channels,
            t0: 0.0,
            period: 0.0,
            cur: Decimated::default(),
            seg_t0: None,
            holes: false,
            averager: BlockAverager::default(),
            best: None,
            spans: Vec::new(),
            kept: None,
            held_out: 0,
            last_good_t: None,
        }
    }

    /// Starts an empty segment at the current period.
    fn new_series(&mut self) {
        let rate = 1.0 / self.period;
        let factor = decimation_factor(rate, self.est_rows);
        self.cur = Decimated {
            channels: self.channels,
            factor,
            log_rate_hz: rate,
            log_start_s: self.t0,
            ..Default::default()
        };
        // The series' expected length reserved at once: grown by doubling, each step
        // copies the series and touches fresh pages on the reading thread. (Capacity that
        // a shorter segment leaves unused is never touched, so costs no memory.)
        let cap = ((self.est_rows / factor as f64) as usize)
            .saturating_add(16)
            .min(2 * MAX_WORK_SAMPLES);
        let c = &mut self.cur;
        c.t_s.reserve(cap);
        c.i_ab.reserve(cap);
        c.i0.reserve(cap);
        if self.channels.voltages {
            c.v_ab.reserve(cap);
        }
        if self.channels.speed {
            c.wm.reserve(cap);
        }
        self.seg_t0 = None;
        self.holes = false;
        self.averager = BlockAverager::default();
    }

    /// Closes the segment being built: back on a uniform grid if it has holes, kept if it
    /// is the longest so far.
    fn end_segment(&mut self) {
        let Some(t_first) = self.seg_t0 else {
            return;
        };
        let mut d = std::mem::take(&mut self.cur);
        d.rows = self.averager.rows;
        if self.holes {
            let tw = d.factor as f64 * self.period;
            let centre = t_first + 0.5 * (d.factor as f64 - 1.0) * self.period;
            d.bridged_s = regrid(&mut d, centre, tw);
        }
        let (Some(a), Some(b)) = (d.t_s.first(), d.t_s.last()) else {
            return;
        };
        self.spans.push([a - self.t0, b - self.t0]);
        if self.best.as_ref().is_none_or(|k| d.t_s.len() > k.t_s.len()) {
            self.kept = Some(self.spans.len() - 1);
            self.best = Some(d);
        }
        self.new_series();
    }

    /// What the analysis did about the segments and the bad cells.
    fn describe(&self, q: &mut DataQuality) {
        if let (Some(k), true) = (self.kept, self.spans.len() > 1) {
            let others: Vec<String> = self
                .spans
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|(_, s)| format!("{:.2}..{:.2} s", s[0], s[1]))
                .collect();
            let s = self.spans[k];
            q.actions.push(format!(
                "analysed the longest regular segment, {:.2}..{:.2} s; not analysed: {}",
                s[0],
                s[1],
                others.join(", ")
            ));
            q.warnings.push(format!(
                "only the segment {:.2}..{:.2} s was analysed ({} others)",
                s[0],
                s[1],
                others.len()
            ));
        }
        if self.held_out > 0 {
            q.actions.push(format!(
                "{} rows with bad cells left out and bridged like dropped samples",
                self.held_out
            ));
        }
        if let Some(b) = self.best.as_ref().filter(|b| b.bridged_s > 0.0) {
            q.actions.push(format!(
                "{:.4} s of missing data bridged on the working grid (interpolated along the supply rotation)",
                b.bridged_s
            ));
        }
    }
}

impl CleanSink for Decimator {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.t0 = base.t0_s;
        self.period = 1.0 / base.sample_rate_hz;
        self.new_series();
        true
    }

    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        if row.t_s < self.opts.from_s {
            return true;
        }
        if row.t_s > self.opts.to_s {
            return false;
        }
        if bad.any() {
            self.held_out += 1;
            self.holes = true;
            return true;
        }
        // A hole of bad rows longer than the stage bridges (a sensor that failed for a
        // while) ends the segment, like a long gap.
        if self
            .last_good_t
            .is_some_and(|t| row.t_s - t > MAX_BRIDGED_GAP_S)
        {
            self.end_segment();
        }
        self.last_good_t = Some(row.t_s);
        let t_first = *self.seg_t0.get_or_insert(row.t_s);
        // The row's place on the segment's sample grid, and so its block.
        // (`max(0)` then the cast's truncation is the floor of a value >= 0, without a
        // call to `floor`; a negative or NaN place is 0 either way.)
        let n = ((row.t_s - t_first) / self.period + 0.5).max(0.0) as u64;
        let block = self.averager.block_of(n, self.cur.factor as u64);
        if self.averager.push(&mut self.cur, row, block) {
            self.holes = true;
        }
        true
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        self.end_segment();
        self.last_good_t = None;
        if let SegmentBreak::RateChange(r) = why {
            self.period = 1.0 / r;
            self.new_series();
        }
        true
    }

    fn restart(&mut self) {
        *self = Decimator::new(self.opts, self.est_rows, self.channels);
    }
}

/// Puts a working series with holes (short or empty blocks) back on the uniform grid
/// `t = first + k tw`, `k = 0, 1, ..` up to its last sample; returns the time bridged
/// (grid points with no block of their own) [s].
///
/// Scalars (zero sequence, speed) are interpolated linearly. The voltage and current
/// vectors rotate at the supply frequency, so each neighbour is first turned to the grid
/// time along the local rotation, `x(g) ~ x(t_a) e^{j omega (g - t_a)}`, and the two
/// predictions are weighted linearly: exact for a steady positive-sequence vector across
/// any hole, where a straight line between the samples would cut the circle's chord.
/// `omega` is the phase step of the voltage vector (the current's for current-only
/// logs) between the two samples before the hole.
fn regrid(d: &mut Decimated, first: f64, tw: f64) -> f64 {
    let src = std::mem::take(d);
    let n_src = src.t_s.len();
    if n_src < 2 {
        *d = src;
        return 0.0;
    }
    let reference = if src.v_ab.len() == n_src {
        &src.v_ab
    } else {
        &src.i_ab
    };
    let c = |x: [f32; 2]| C64::new(f64::from(x[0]), f64::from(x[1]));
    let omega_at = |j: usize| {
        let (p, q) = if j >= 1 { (j - 1, j) } else { (0, 1) };
        let (a, b) = (c(reference[p]), c(reference[q]));
        let dt = src.t_s[q] - src.t_s[p];
        if a.norm() * b.norm() > 0.0 && dt > 0.0 {
            (b * a.conj()).arg() / dt
        } else {
            0.0
        }
    };
    let last = src.t_s[n_src - 1];
    let mut out = Decimated {
        channels: src.channels,
        rows: src.rows,
        log_rate_hz: src.log_rate_hz,
        factor: src.factor,
        log_start_s: src.log_start_s,
        ..Default::default()
    };
    let mut bridged = 0.0;
    let mut j = 0;
    let mut k = 0u64;
    loop {
        let g = first + k as f64 * tw;
        if g > last + 0.5 * tw {
            break;
        }
        k += 1;
        while j + 2 < n_src && src.t_s[j + 1] <= g {
            j += 1;
        }
        let b = j + 1;
        let (ta, tb) = (src.t_s[j], src.t_s[b]);
        let w = if tb > ta {
            ((g - ta) / (tb - ta)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if (g - ta).abs() > 0.5 * tw && (tb - g).abs() > 0.5 * tw {
            bridged += tw;
        }
        let omega = omega_at(j);
        let turn = |x: &[[f32; 2]]| {
            let pa = c(x[j]) * C64::from_polar(1.0, omega * (g - ta));
            let pb = c(x[b]) * C64::from_polar(1.0, omega * (g - tb));
            let v = pa * (1.0 - w) + pb * w;
            [v.re as f32, v.im as f32]
        };
        let lin = |x: &[f32]| (f64::from(x[j]) * (1.0 - w) + f64::from(x[b]) * w) as f32;
        out.t_s.push(g);
        out.i_ab.push(turn(&src.i_ab));
        out.i0.push(lin(&src.i0));
        if src.v_ab.len() == n_src {
            out.v_ab.push(turn(&src.v_ab));
        }
        if src.wm.len() == n_src {
            out.wm.push(lin(&src.wm));
        }
    }
    *d = out;
    bridged
}

/// Block average of the rows of one block of the sample grid: time, current vector and
/// zero sequence, voltage vector, speed.
#[derive(Default)]
struct BlockAverager {
    sum: [f64; 7],
    k: usize,
    block: Option<u64>,
    rows: u64,
}

impl BlockAverager {
    /// `n / factor`: the current block when `n` falls in it (most rows), without the
    /// division.
    #[inline]
    fn block_of(&self, n: u64, factor: u64) -> u64 {
        match self.block {
            Some(b) if n >= b * factor && n - b * factor < factor => b,
            _ => n / factor,
        }
    }

    /// Adds a row of grid block `block`; a row of a later block first closes the current
    /// one. Returns true when a block closed short or blocks were skipped (a hole).
    fn push(&mut self, d: &mut Decimated, row: &Row, block: u64) -> bool {
        let mut hole = false;
        if let Some(b) = self.block {
            if block != b {
                hole = (self.k > 0 && self.k < d.factor) || block != b + 1;
                self.flush(d);
            }
        }
        self.block = Some(block);
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
            self.flush(d);
        }
        hole
    }

    /// Closes the current block: its means become one working sample.
    fn flush(&mut self, d: &mut Decimated) {
        if self.k == 0 {
            return;
        }
        let a = &mut self.sum;
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
fn lpf3(x: &mut [C64], dt: f64, fc: f64, init_len: usize, omega: f64, backward: bool) {
    let a = 1.0 - (-2.0 * std::f64::consts::PI * fc * dt).exp();
    let n = x.len();
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
    let mut stage = |v: &mut C64| {
        s[0] += a * (*v - s[0]);
        s[1] += a * (s[0] - s[1]);
        s[2] += a * (s[1] - s[2]);
        *v = s[2];
    };
    if backward {
        x.iter_mut().rev().for_each(&mut stage);
    } else {
        x.iter_mut().for_each(&mut stage);
    }
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
    // The frame's angle and the sequence separation's own (the supply voltage's) are
    // independent: built on both cores.
    let frame = || {
        let theta = if d.channels.voltages {
            let raw = flux_angle(&v_ab, &i_ab, dt, p);
            smooth_angle(raw, dt)
        } else {
            let w0 = p.supply.omega_rad_s();
            d.t_s.iter().map(|t| w0 * t).collect()
        };
        let omega_s = frame_speed(&theta, &d.t_s, dt);
        let rot: Vec<C64> = theta
            .iter()
            .map(|&th| C64::new(th.cos(), th.sin()))
            .collect();
        (theta, omega_s, rot)
    };
    // The sequences are separated in the supply voltage's own (smoothed) frame when the log
    // has voltages: any frame turning with the positive sequence separates them alike in
    // steady state, but through a start the rotor-flux frame is still forming (it may
    // turn a whole revolution against the supply in the first 0.1 s), and the
    // demodulated signal then leaks volts into the negative sequence for the low-pass's
    // memory (0.2 s): 4 V on an 11 kW start, which the model takes as its input.
    // (A current-only log separates in the frame above: built first, then used.)
    let separate = |theta: &[f64], omega_s: &[f64]| {
        let (sep_theta, sep_omega) = if d.channels.voltages {
            let th = smooth_angle(unwrapped_angle(&v_ab), dt);
            let w = frame_speed(&th, &d.t_s, dt);
            (th, w)
        } else {
            (theta.to_vec(), omega_s.to_vec())
        };
        let sep_rot: Vec<C64> = sep_theta
            .iter()
            .map(|&th| C64::new(th.cos(), th.sin()))
            .collect();
        let mut sep = SequenceSeparator::new(&sep_theta, &sep_omega, dt);
        if d.channels.voltages {
            sep.steps = supply_steps(&v_ab, &sep_rot);
        }
        rayon::join(
            || sep.negative(&i_ab, &sep_rot),
            || {
                if d.channels.voltages {
                    sep.negative(&v_ab, &sep_rot)
                } else {
                    vec![C64::new(0.0, 0.0); n]
                }
            },
        )
    };
    let ((theta, omega_s, rot), (i_neg, v_neg)) = if d.channels.voltages {
        rayon::join(frame, || separate(&[], &[]))
    } else {
        let f = frame();
        let s = separate(&f.0, &f.1);
        (f, s)
    };
    // Park transforms in complex form: x_dq = x_alphabeta e^{-j theta}; voltages and
    // currents (with the flux current's smoothing) on both cores.
    let voltages = || {
        let mut vd = Vec::new();
        let mut vq = Vec::new();
        if d.channels.voltages {
            vd.reserve(n);
            vq.reserve(n);
            for k in 0..n {
                let v = (v_ab[k] - v_neg[k]) * rot[k].conj();
                vd.push(v.re);
                vq.push(v.im);
            }
        }
        (vd, vq)
    };
    let currents = || {
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
        let i_f = zero_phase_lpf(&id, dt, I_F_SMOOTH_HZ);
        (id, iq, iq_pos, i_f)
    };
    let ((vd, vq), (id, iq, iq_pos, i_f)) = rayon::join(voltages, currents);
    let np = p.motor.model::<f64>().np();
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

/// Frame speed [rad/s]: central difference of the unwrapped angle, low-passed (20 Hz)
/// without phase shift (a causal filter would lag a V/f ramp by its group delay).
fn frame_speed(theta: &[f64], t_s: &[f64], dt: f64) -> Vec<f64> {
    let n = theta.len();
    let mut omega = vec![0.0; n];
    for k in 0..n {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(n.saturating_sub(1)));
        if b > a {
            omega[k] = (theta[b] - theta[a]) / (t_s[b] - t_s[a]);
        }
    }
    zero_phase_lpf_in_place(&mut omega, dt, 20.0);
    omega
}

/// The unwrapped angle of a vector series (a zero vector keeps the previous angle).
fn unwrapped_angle(x: &[C64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut acc = 0.0f64;
    // (Each vector's magnitude computed once: `prev` keeps it.)
    let mut prev: Option<(C64, f64)> = None;
    for &v in x {
        let nv = v.norm();
        match prev {
            None => acc = if nv > 0.0 { v.arg() } else { 0.0 },
            Some((p, np)) if nv * np > 0.0 => acc += (v * p.conj()).arg(),
            Some(_) => {}
        }
        if nv > 0.0 {
            prev = Some((v, nv));
        }
        out.push(acc);
    }
    out
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
            // (Squared magnitudes against squared thresholds: no square root per sample.)
            if turn.norm_sqr() > 1e-24 {
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
        let ang = if psi_r.norm_sqr() > 1e-12 {
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
fn smooth_angle(mut theta: Vec<f64>, dt: f64) -> Vec<f64> {
    let n = theta.len();
    if n <= 2 {
        return theta;
    }
    let mut inc: Vec<f64> = theta.windows(2).map(|w| w[1] - w[0]).collect();
    zero_phase_lpf_in_place(&mut inc, dt, THETA_SMOOTH_HZ);
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
    // (The deviation takes the raw angle's buffer.)
    for (a, b) in theta.iter_mut().zip(&smooth) {
        *a -= b;
    }
    zero_phase_lpf_in_place(&mut theta, dt, THETA_SMOOTH_HZ);
    for (v, e) in smooth.iter_mut().zip(&theta) {
        *v += e;
    }
    smooth
}

/// Relative jump of the supply voltage between two working samples that marks a supply
/// step (a V/f or voltage step, a switch-on) for the sequence separation: 3 % of the
/// median voltage, far above sensor noise (0.1 %) and the 0.2 % steps of a variac-like
/// ramp, below a 10 % dip.
pub const SUPPLY_STEP_REL: f64 = 0.03;

/// Working samples where the supply voltage steps: the voltage in its own frame
/// (`rot` = e^{j theta_v}) jumps by more than [`SUPPLY_STEP_REL`] of the median voltage
/// and ten times the median jump.
fn supply_steps(v_ab: &[C64], rot: &[C64]) -> Vec<usize> {
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
struct SequenceSeparator {
    dt: f64,
    init_len: usize,
    /// Rotation of the positive sequence per sample in the demodulated signal [rad].
    omega_2: f64,
    /// The same at the log's end (for the backward pass).
    init_len_end: usize,
    omega_2_end: f64,
    /// Working samples where the supply steps ([`supply_steps`]).
    steps: Vec<usize>,
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
        }
    }

    /// The negative-sequence part of `x` (stationary frame), `rot` = e^{j theta}.
    fn negative(&self, x: &[C64], rot: &[C64]) -> Vec<C64> {
        let mut f: Vec<C64> = x.iter().zip(rot).map(|(v, r)| v * r).collect();
        // The backward pass runs on its own copy of the demodulated signal.
        let b = (!self.steps.is_empty()).then(|| {
            let mut b = f.clone();
            lpf3(
                &mut b,
                self.dt,
                SEQ_LPF_HZ,
                self.init_len_end,
                -self.omega_2_end,
                true,
            );
            b
        });
        lpf3(
            &mut f,
            self.dt,
            SEQ_LPF_HZ,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced supply that steps from 100 % at 50 Hz to 60 % at 30 Hz (a V/f step)
    /// has no negative sequence; the separation must not make one. Before it ran in the
    /// supply's frame and both ways around steps: 0.3 % of the voltage for 0.2 s.
    #[test]
    fn a_supply_step_makes_no_negative_sequence() {
        let p = ParamFile::reference_2p2kw();
        let dt = 0.5e-3;
        let vpk = p.supply.v_phase_peak();
        let mut d = Decimated {
            channels: crate::log::Channels {
                voltages: true,
                speed: false,
                encoder: false,
            },
            factor: 1,
            log_rate_hz: 1.0 / dt,
            ..Default::default()
        };
        let mut phase = 0.0f64;
        for k in 0..6000 {
            let t = k as f64 * dt;
            let (scale, f) = if t < 1.5 { (1.0, 50.0) } else { (0.6, 30.0) };
            let v = C64::from_polar(vpk * scale, phase);
            // A current lagging the voltage by 30 degrees.
            let i = C64::from_polar(5.0 * scale, phase - 0.5);
            d.t_s.push(t);
            d.v_ab.push([v.re as f32, v.im as f32]);
            d.i_ab.push([i.re as f32, i.im as f32]);
            d.i0.push(0.0);
            phase += 2.0 * std::f64::consts::PI * f * dt;
        }
        let prep = voltage_model_flux_frame(&d, &p);
        let worst = prep.v_neg.iter().map(|x| x.norm()).fold(0.0, f64::max);
        assert!(
            worst < 1e-3 * vpk,
            "|v_neg| up to {worst:.3} V of {vpk:.0} V"
        );
    }

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
