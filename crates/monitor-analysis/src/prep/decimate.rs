//! Stage 1 of [`super`]: stream a log through the data-quality stage and block-average it
//! to the working rate.

use super::{ReadOptions, C64, MAX_WORK_SAMPLES, TARGET_RATE_HZ};
use monitor_core::frames::{clarke, zero_sequence, Abc};
use monitor_io::log::quality::{
    BadCells, CellLimits, CleanSink, DataQuality, QualityStage, SegmentBreak, TimeBase,
    MAX_BRIDGED_GAP_S,
};
use monitor_io::log::{Channels, LogError, LogFile, Row};
use monitor_io::params::ParamFile;
use std::path::Path;

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

/// Streams a log through the data-quality stage ([`monitor_io::log::quality`]) and
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
/// or the sample rate needed), or [`LogError::NoUsableRows`] (with what held them out) when the time window holds fewer
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
        let why = if !quality.not_trusted_because.is_empty() {
            quality.not_trusted_because.join("; ")
        } else if quality.bad_rows > 0 {
            format!(
                "{} of {} rows held out for bad cells",
                quality.bad_rows, quality.rows_read
            )
        } else {
            format!("{} rows in the log", quality.rows_read)
        };
        return Err(LogError::NoUsableRows {
            path: path.display().to_string(),
            why,
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
        let (ta, tb) = (src.t_s[j], src.t_s[j + 1]);
        if (g - ta).abs() > 0.5 * tw && (tb - g).abs() > 0.5 * tw {
            bridged += tw;
        }
        push_between(&mut out, &src, j, g);
    }
    *d = out;
    bridged
}

/// A stored vector sample as a complex number.
fn c64(x: [f32; 2]) -> C64 {
    C64::new(f64::from(x[0]), f64::from(x[1]))
}

/// The rotation rate [rad/s] of `src`'s reference vector (the voltage, the current for a
/// current-only log) at sample `j`: its phase step between the samples `j - 1` and `j`
/// (0 and 1 at the start); 0 where a sample is zero.
fn rotation_at(src: &Decimated, j: usize) -> f64 {
    let reference = if src.v_ab.len() == src.t_s.len() {
        &src.v_ab
    } else {
        &src.i_ab
    };
    let (p, q) = if j >= 1 { (j - 1, j) } else { (0, 1) };
    let (a, b) = (c64(reference[p]), c64(reference[q]));
    let dt = src.t_s[q] - src.t_s[p];
    if a.norm() * b.norm() > 0.0 && dt > 0.0 {
        (b * a.conj()).arg() / dt
    } else {
        0.0
    }
}

/// Appends to `out` the grid point at time `g` between `src`'s samples `j` and `j + 1`:
/// the vectors turned to `g` along the local rotation from each side and weighted
/// linearly, the scalars interpolated linearly ([`regrid`]).
fn push_between(out: &mut Decimated, src: &Decimated, j: usize, g: f64) {
    let n_src = src.t_s.len();
    let b = j + 1;
    let (ta, tb) = (src.t_s[j], src.t_s[b]);
    let w = if tb > ta {
        ((g - ta) / (tb - ta)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let omega = rotation_at(src, j);
    let turn = |x: &[[f32; 2]]| {
        let pa = c64(x[j]) * C64::from_polar(1.0, omega * (g - ta));
        let pb = c64(x[b]) * C64::from_polar(1.0, omega * (g - tb));
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
