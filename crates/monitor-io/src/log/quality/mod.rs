//! The data-quality stage: every row of a log passes here before `diagnose`, `compare` or
//! `explain` sees it ([`QualityStage`], a [`RowSink`] in front of the command's own sink,
//! a [`CleanSink`]). It judges the log as a data-acquisition system wrote it, with gaps,
//! glitches and bad cells, across the whole log (not its first rows), and reports what it
//! found ([`DataQuality`], JSON key `data_quality`).
//!
//! **Time base.** The sample period is the median interval of the first [`HEAD_ROWS`]
//! rows ([`super::sample_rate_hz`], robust to dropped samples among them). The time unit
//! is chosen from the phase-a current: its zero crossings must repeat at about the supply
//! frequency; a log whose `t_s` is in milliseconds or microseconds is rescaled
//! ([`TimeUnit`]). Without alternating current (a log at standstill) the unit is seconds
//! unless seconds would give fewer than [`MIN_SAMPLES_PER_PERIOD`] samples per supply
//! period. Then each interval between rows is classified against the period `T`
//! (tolerance [`INTERVAL_TOLERANCE`]` T`):
//! - about `T`: a normal row;
//! - about `m T` (m >= 2) and at most [`MAX_BRIDGED_GAP_S`]: `m - 1` dropped samples, a
//!   short gap, bridged downstream with the real elapsed time (the core's estimators and
//!   the M/T speed advance over it; the analysis interpolates the working series across
//!   it);
//! - longer than [`MAX_BRIDGED_GAP_S`]: a long gap, the start of a new segment
//!   ([`SegmentBreak::Gap`]);
//! - zero or negative (a repeated or backward time): the row is dropped; a run of
//!   [`RATE_CHANGE_RUN`] such rows that are regular among themselves is a clock reset and
//!   starts a new segment;
//! - one row off the grid whose successor is back on it (`t[k+1] - t[k-1] = 2 T`): a
//!   timestamp glitch; its time is corrected to `t[k-1] + T`;
//! - anything else: an irregular interval, kept with its real time;
//! - [`RATE_CHANGE_RUN`] consecutive off-period intervals that agree within 5 %: a change
//!   of sample rate, a new segment at the new rate.
//!
//! Rows on the grid (one or `m` periods on) are put on a smoothed sample clock: the
//! clock advances by whole periods and moves [`CLOCK_GAIN`] of the way to each row's own
//! time, so timestamp jitter (a software clock) does not reach the estimators, and a
//! clock a little off the estimated period is followed. A row within [`CLOCK_EXACT`] of a
//! period of the clock, and every row off the grid, keeps its own time.
//!
//! **Cells.** A cell that is not finite or lies beyond [`CellLimits`] (far beyond what the
//! machine could draw or the supply could give) is bad ([`BadCells`]). The encoder count
//! is judged by its steps ([`encoder`]): counter wraps are undone, an unreadable count or
//! a jump no shaft can make is a bad cell, a re-zeroed counter is followed. A phase channel
//! frozen while the others alternate, or a whole set dead while the other set is live, is
//! bad too ([`stuck`]); duplicated channels and a reversed phase order withhold the verdict
//! ([`wiring`]). Consecutive rows
//! with bad cells form a glitch burst. The stage counts them and hands the rows on,
//! flagged: the monitor holds such samples out as the firmware does with impossible ADC
//! readings, the analysis drops them and bridges the hole like dropped samples.
//!
//! **Missing values**, one rule: an empty CSV cell, `NA`, `null`, `NaN` and `inf` are all
//! read as NaN ([`super::is_missing`]) and are bad cells alike. When at least
//! [`UNUSABLE_FRACTION`] of the rows have a bad cell, nothing is left to analyse: an error
//! names the channel with the most bad cells and what they are ([`LogError::NoValue`]).
//! Blank lines of a CSV are skipped and counted (`DataQuality::blank_lines`).
//!
//! **Supply frequency.** The median period of the phase-a current's zero crossings is
//! compared with the parameter file's supply frequency; a difference over
//! [`SUPPLY_MISMATCH`] is not trusted: the verdict is withheld, since the monitor's model
//! runs at the file's frequency (a V/f drive running below base speed also gives one).
//!
//! **Trust.** [`DataQuality::trusted`] is false when more than [`MAX_BAD_FRACTION`] of
//! the rows were dropped or held out, the timestamps are irregular on more than
//! [`MAX_BAD_FRACTION`] of the intervals, or more than [`MAX_DROPPED_FRACTION`] of the
//! samples are missing: the commands then withhold their verdict and say why.

mod block;
mod cells;
pub mod encoder;
mod finish;
mod report;
mod signals;
mod speed_unit;
pub mod stuck;
mod time_base;
pub mod wiring;

pub use cells::{BadCells, CellLimits};
pub use report::{ClippedChannel, DataQuality, NotJudged, RateChange};
pub(in crate::log) use time_base::median_positive;
pub use time_base::TimeUnit;

use super::{Column, LogError, Row, RowSink};
use std::ops::ControlFlow;
use time_base::time_base;

/// Rows whose intervals set the nominal sample period and time unit.
pub const HEAD_ROWS: usize = 2048;
/// An interval within this fraction of a period of `m T` counts as `m` periods.
pub const INTERVAL_TOLERANCE: f64 = 0.25;
/// Longest stretch of missing samples bridged [s]; longer gaps split the log into
/// segments. The same as the core's default `MonitorConfig::max_bridged_gap_s`.
pub const MAX_BRIDGED_GAP_S: f64 = 0.1;
/// Consecutive off-period intervals that, agreeing within 5 %, make a change of sample
/// rate (or, backward, a clock reset).
pub const RATE_CHANGE_RUN: usize = 64;
/// Samples per supply period below which no analysis is possible (the core's limit,
/// `MonitorConfig::validate`).
pub const MIN_SAMPLES_PER_PERIOD: f64 = 8.0;
/// Relative difference between the current's frequency and the parameter file's supply
/// frequency beyond which the log is not trusted (the verdict withheld).
pub const SUPPLY_MISMATCH: f64 = 0.05;
/// Fraction of rows dropped or held out (or of intervals irregular) beyond which no
/// verdict is given.
pub const MAX_BAD_FRACTION: f64 = 0.05;
/// Stretches of rows with unusable time beyond which their share counts against trust.
pub const MAX_DROP_RUNS: u64 = 3;
/// Fraction of the log's duration not judged (a stretch the command could not replay)
/// beyond which "healthy" is not said: a fault may hide there.
pub const MAX_NOT_JUDGED_FRACTION: f64 = 0.05;
/// Fraction of missing samples (bridged gaps) beyond which no verdict is given.
pub const MAX_DROPPED_FRACTION: f64 = 0.10;
/// Gain of the timestamp smoothing: each row on the grid moves the sample clock this
/// fraction of the way to its own time (a first-order loop: jitter falls by about
/// `sqrt(2 / gain)`, a clock off the estimated period by `e` lags `e / gain` periods).
pub const CLOCK_GAIN: f64 = 1.0 / 32.0;
/// Distance from the sample clock (fraction of a period) within which a row keeps its own
/// time: printed-time rounding, not jitter.
pub const CLOCK_EXACT: f64 = 0.01;
/// Timestamp jitter (RMS, fraction of a period) above which the report warns.
pub const JITTER_WARN: f64 = 0.02;
/// Entries kept in the lists of the report (long gaps, rate changes).
const LIST_CAP: usize = 20;

/// What the stage knows once it has seen the first rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeBase {
    /// Unit of the log's `t_s`.
    pub unit: TimeUnit,
    /// Nominal sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Time of the first row [s] (in seconds, after the unit).
    pub t0_s: f64,
}

/// Why a new segment starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentBreak {
    /// A gap longer than [`MAX_BRIDGED_GAP_S`] [s].
    Gap(f64),
    /// The sample rate changed to this [Hz].
    RateChange(f64),
    /// The time went back (the acquisition clock restarted).
    ClockReset,
}

/// Receives the rows the stage passes: times in seconds, in order, each row's bad cells
/// flagged.
pub trait CleanSink {
    /// Called once, before the first row. Return false to stop.
    fn begin(&mut self, base: &TimeBase) -> bool;
    /// One row (time strictly after the previous row's within a segment). Return false
    /// to stop.
    fn row(&mut self, row: &Row, bad: BadCells) -> bool;
    /// Rows with no bad cell, in order: [`ControlFlow::Break`] with the index of the row
    /// that asked to stop. The same as [`CleanSink::row`] of each in turn, which it is by
    /// default.
    fn rows(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        match rows.iter().position(|r| !self.row(r, BadCells::default())) {
            Some(k) => ControlFlow::Break(k),
            None => ControlFlow::Continue(()),
        }
    }
    /// The next row starts a new segment. Return false to stop.
    fn new_segment(&mut self, why: SegmentBreak) -> bool;
    /// Forget everything: the rows come again from the first one.
    fn restart(&mut self);
}

/// The stage as a [`RowSink`] in front of a [`CleanSink`]; see the module documentation.
/// After the read, [`QualityStage::finish`] gives the report.
pub struct QualityStage<'a, S: CleanSink> {
    sink: &'a mut S,
    limits: CellLimits,
    shown: String,
    head: Vec<Row>,
    base: Option<TimeBase>,
    period: f64,
    last_t: f64,
    pending: Option<Row>,
    off_run: Vec<f64>,
    off_run_counts: (u64, u64),
    back_run: (usize, f64),
    burst: Option<(f64, f64)>,
    /// The clipping count, the wiring check, the current's zero crossings and the speed
    /// channel's median over synchronous ([`speed_unit`]).
    signals: signals::Signals,
    encoder: encoder::EncoderTrack,
    stuck: stuck::StuckTracker,
    jitter: (f64, u64),
    dropping: bool,
    /// Bad cells per column: [not finite, finite but beyond the limits].
    cells_out: [[u64; 2]; Column::COUNT],
    q: DataQuality,
    error: Option<LogError>,
    stopped: bool,
}

/// Fraction of the rows with a bad cell at and above which nothing is left to analyse: the
/// channel to blame is named ([`LogError::NoValue`]).
pub const UNUSABLE_FRACTION: f64 = 0.99;

impl<'a, S: CleanSink> QualityStage<'a, S> {
    /// A stage for the log shown as `shown` in messages, judging cells against `limits`.
    pub fn new(sink: &'a mut S, limits: CellLimits, shown: &str) -> Self {
        QualityStage {
            sink,
            limits,
            shown: shown.to_string(),
            head: Vec::new(),
            base: None,
            period: 0.0,
            last_t: f64::NEG_INFINITY,
            pending: None,
            off_run: Vec::new(),
            off_run_counts: (0, 0),
            back_run: (0, f64::NAN),
            burst: None,
            signals: signals::Signals::new(limits.sync_rad_s),
            encoder: encoder::EncoderTrack::new(limits.wm_max),
            stuck: stuck::StuckTracker::default(),
            jitter: (0.0, 0),
            dropping: false,
            cells_out: [[0; 2]; Column::COUNT],
            q: DataQuality::default(),
            error: None,
            stopped: false,
        }
    }

    /// Sets the time base from the rows held and passes them on.
    fn start(&mut self) {
        let (unit, period) = match time_base(&self.head, self.limits.supply_hz, &self.shown) {
            Ok(b) => b,
            Err(e) => {
                self.error = Some(e);
                self.stopped = true;
                return;
            }
        };
        let t0 = self
            .head
            .iter()
            .map(|r| r.t_s * unit.seconds())
            .find(|t| t.is_finite())
            .unwrap_or(0.0);
        let base = TimeBase {
            unit,
            sample_rate_hz: 1.0 / period,
            t0_s: t0,
        };
        self.base = Some(base);
        self.period = period;
        self.stuck = stuck::StuckTracker::new(period, self.limits.supply_hz);
        self.q.time_unit = unit;
        self.q.sample_rate_hz = base.sample_rate_hz;
        self.q.segments = 1;
        if !self.sink.begin(&base) {
            self.stopped = true;
            return;
        }
        let head = std::mem::take(&mut self.head);
        self.q.rows_read = 0;
        for r in &head {
            if !self.ingest(r) {
                self.stopped = true;
                return;
            }
        }
    }

    /// One raw row (time in the log's unit). The common row, one period after the last
    /// with nothing held, goes straight on.
    #[inline]
    fn ingest(&mut self, r: &Row) -> bool {
        self.q.rows_read += 1;
        let t = r.t_s * self.q.time_unit.seconds();
        let d = t - self.last_t;
        if self.pending.is_none() && (d - self.period).abs() <= INTERVAL_TOLERANCE * self.period {
            // (Never the first row, whose `d` is infinite, nor a time not finite.)
            self.off_run.clear();
            self.off_run_counts = (0, 0);
            self.back_run.0 = 0;
            return self.emit_on_clock(r, t, 1.0);
        }
        self.ingest_other(r, t)
    }

    /// [`QualityStage::ingest`] of a row at `t` [s] after one held, off the period, or the
    /// first.
    #[cold]
    fn ingest_other(&mut self, r: &Row, t: f64) -> bool {
        if !t.is_finite() {
            self.q.non_finite_times += 1;
            self.note_dropped();
            return true;
        }
        if self.last_t == f64::NEG_INFINITY {
            return self.emit(r, t);
        }
        if let Some(p) = self.pending.take() {
            let tol = INTERVAL_TOLERANCE * self.period;
            if (t - self.last_t - 2.0 * self.period).abs() <= tol {
                // p was one glitched timestamp between two rows on the grid.
                self.q.timestamp_glitches += 1;
                if !self.emit(&p, self.last_t + self.period) {
                    return false;
                }
            } else if !self.settle(p) {
                return false;
            }
        }
        let d = t - self.last_t;
        if (d - self.period).abs() <= INTERVAL_TOLERANCE * self.period {
            self.off_run.clear();
            self.off_run_counts = (0, 0);
            self.back_run.0 = 0;
            return self.emit_on_clock(r, t, 1.0);
        }
        self.pending = Some(Row { t_s: t, ..*r });
        true
    }

    /// A row whose interval is off the period and is not a single glitch: classify it.
    fn settle(&mut self, p: Row) -> bool {
        let d = p.t_s - self.last_t;
        if d <= 0.0 {
            return self.backward(p);
        }
        self.back_run.0 = 0;
        if d > MAX_BRIDGED_GAP_S {
            self.q.long_gaps += 1;
            if self.q.long_gap_spans.len() < LIST_CAP {
                let t0 = self.base.map_or(0.0, |b| b.t0_s);
                self.q.long_gap_spans.push([self.last_t - t0, p.t_s - t0]);
            }
            self.off_run.clear();
            self.off_run_counts = (0, 0);
            return self.new_segment(SegmentBreak::Gap(d)) && self.emit(&p, p.t_s);
        }
        let m = (d / self.period).round();
        if m >= 2.0 && (d - m * self.period).abs() <= INTERVAL_TOLERANCE * self.period {
            self.q.dropped_samples += m as u64 - 1;
            self.q.gaps_bridged += 1;
            self.q.longest_bridged_gap_s = self.q.longest_bridged_gap_s.max(d - self.period);
            self.off_run_counts.0 += 1;
        } else {
            self.q.irregular_intervals += 1;
            self.off_run_counts.1 += 1;
        }
        self.off_run.push(d);
        if self.off_run.len() >= RATE_CHANGE_RUN && !self.rate_change(p.t_s) {
            return false;
        }
        if m >= 2.0 && (d - m * self.period).abs() <= INTERVAL_TOLERANCE * self.period {
            self.emit_on_clock(&p, p.t_s, m)
        } else {
            self.emit(&p, p.t_s)
        }
    }

    /// Emits a row at `t` [s], `m` periods after the last one, on the smoothed sample
    /// clock: its time moves the clock [`CLOCK_GAIN`] of the way to its own. A row within
    /// [`CLOCK_EXACT`] of a period of the clock keeps its own time (a clean log passes
    /// unchanged, to the last bit).
    #[inline]
    fn emit_on_clock(&mut self, r: &Row, t: f64, m: f64) -> bool {
        let predicted = self.last_t + m * self.period;
        let err = t - predicted;
        self.jitter.0 += err * err;
        self.jitter.1 += 1;
        if err.abs() <= CLOCK_EXACT * self.period {
            return self.pass(r, t);
        }
        self.emit(r, predicted + CLOCK_GAIN * err)
    }

    /// After [`RATE_CHANGE_RUN`] off-period intervals: if they agree, the rate changed.
    fn rate_change(&mut self, t: f64) -> bool {
        let mut run = std::mem::take(&mut self.off_run);
        let counts = std::mem::take(&mut self.off_run_counts);
        let Some(med) = median_positive(&mut run) else {
            return true;
        };
        if !run.iter().all(|d| (d / med - 1.0).abs() <= 0.05) {
            return true;
        }
        // Not drops nor irregular intervals: the new period.
        self.q.dropped_samples -= self.q.dropped_samples.min(counts.0);
        self.q.gaps_bridged -= self.q.gaps_bridged.min(counts.0);
        self.q.irregular_intervals -= self.q.irregular_intervals.min(counts.1);
        self.period = med;
        self.stuck = stuck::StuckTracker::new(med, self.limits.supply_hz);
        if self.q.rate_changes.len() < LIST_CAP {
            let t0 = self.base.map_or(0.0, |b| b.t0_s);
            self.q.rate_changes.push(RateChange {
                at_s: t - t0 - med * run.len() as f64,
                rate_hz: 1.0 / med,
            });
        }
        self.new_segment(SegmentBreak::RateChange(1.0 / med))
    }

    /// A row whose time repeats or goes back: dropped, unless a run of them is regular
    /// among itself (the clock restarted).
    fn backward(&mut self, p: Row) -> bool {
        let (n, prev) = self.back_run;
        let regular = (p.t_s - prev - self.period).abs() <= INTERVAL_TOLERANCE * self.period;
        self.back_run = (if regular { n + 1 } else { 0 }, p.t_s);
        self.q.repeated_or_backward_rows += 1;
        self.note_dropped();
        if self.back_run.0 + 1 < RATE_CHANGE_RUN {
            return true;
        }
        self.q.repeated_or_backward_rows -= RATE_CHANGE_RUN as u64 - 1;
        self.q.clock_resets += 1;
        self.back_run.0 = 0;
        self.off_run.clear();
        self.off_run_counts = (0, 0);
        self.encoder.restart();
        self.new_segment(SegmentBreak::ClockReset) && self.emit(&p, p.t_s)
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        self.q.segments += 1;
        self.signals.interrupt();
        self.sink.new_segment(why)
    }

    /// Passes a row on at `t_s` [s]: cells judged (the encoder count made continuous,
    /// see [`encoder`]), bursts tracked, the good rows counted by the accumulators
    /// ([`signals`]). The row goes on as it came when neither its time nor its count
    /// changed.
    #[inline(never)]
    fn emit(&mut self, r: &Row, t_s: f64) -> bool {
        self.pass(r, t_s)
    }

    /// [`QualityStage::emit`] in line (the common row's path).
    #[inline(always)]
    fn pass(&mut self, r: &Row, t_s: f64) -> bool {
        self.last_t = t_s;
        self.dropping = false;
        self.q.rows_passed += 1;
        let mut bad = BadCells::of(r, &self.limits);
        let mut enc = r.enc_count;
        if let Some(raw) = r.enc_count {
            match self.encoder.check(raw, t_s) {
                encoder::EncoderCell::Good(c) => enc = Some(c),
                encoder::EncoderCell::Bad => bad.set(Column::Encoder),
            }
        }
        let before = bad;
        self.stuck.check_flagged(r, &mut bad);
        if bad != before {
            self.count_stuck(before, bad);
        }
        if bad.any() {
            self.bad_row(r, t_s, bad);
        } else {
            if self.burst.is_some() {
                self.end_burst();
            }
            self.signals.push(r, t_s);
        }
        if t_s.to_bits() == r.t_s.to_bits() && enc == r.enc_count {
            self.sink.row(r, bad)
        } else {
            self.sink.row(
                &Row {
                    t_s,
                    enc_count: enc,
                    ..*r
                },
                bad,
            )
        }
    }

    /// Counts the cells the stuck tracker marked (`before`: the row's bad cells without).
    #[cold]
    fn count_stuck(&mut self, before: BadCells, bad: BadCells) {
        for c in Column::ALL {
            if bad.has(c) && !before.has(c) {
                *self.q.stuck_cells.entry(c.name().to_string()).or_insert(0) += 1;
            }
        }
    }

    /// A row with bad cells, passed on at `t_s`: its good cells counted for the clipping,
    /// the bad ones by column and kind, the burst it belongs to; the wiring check's
    /// sequence broken.
    #[cold]
    fn bad_row(&mut self, r: &Row, t_s: f64, bad: BadCells) {
        self.signals.bad_row(r, |c| !bad.has(c));
        self.q.bad_rows += 1;
        for c in Column::ALL {
            if bad.has(c) {
                *self.q.bad_cells.entry(c.name().to_string()).or_insert(0) += 1;
                let x = r.value(c).unwrap_or(f64::NAN);
                let (finite, beyond) = (x.is_finite(), self.limits.beyond(c, x));
                self.cells_out[c as usize][0] += u64::from(!finite);
                self.cells_out[c as usize][1] += u64::from(finite && beyond);
            }
        }
        let start = self.burst.map_or(t_s, |b| b.0);
        self.burst = Some((start, t_s));
    }

    /// A row dropped for its time: counts the stretches of them.
    fn note_dropped(&mut self) {
        if !self.dropping {
            self.dropping = true;
            self.q.time_drop_runs += 1;
        }
    }

    #[cold]
    fn end_burst(&mut self) {
        if let Some((a, b)) = self.burst.take() {
            let length = b - a + self.period;
            self.q.glitch_bursts += 1;
            self.q.longest_burst_s = self.q.longest_burst_s.max(length);
            if length <= MAX_BRIDGED_GAP_S {
                self.q.rows_in_short_bursts += (length / self.period).round() as u64;
            }
        }
    }
}

impl<S: CleanSink> RowSink for QualityStage<'_, S> {
    fn row(&mut self, row: &Row) -> bool {
        if self.stopped {
            return false;
        }
        if self.base.is_some() {
            let go = self.ingest(row);
            self.stopped = !go;
            return go;
        }
        self.head.push(*row);
        if self.head.len() >= HEAD_ROWS {
            self.start();
        }
        !self.stopped
    }

    fn rows(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        self.block(rows)
    }

    fn restart(&mut self) {
        self.sink.restart();
        self.head.clear();
        self.base = None;
        self.last_t = f64::NEG_INFINITY;
        self.pending = None;
        self.off_run.clear();
        self.off_run_counts = (0, 0);
        self.back_run = (0, f64::NAN);
        self.burst = None;
        self.signals = signals::Signals::new(self.limits.sync_rad_s);
        self.encoder = encoder::EncoderTrack::new(self.limits.wm_max);
        self.stuck = stuck::StuckTracker::default();
        self.jitter = (0.0, 0);
        self.dropping = false;
        self.cells_out = [[0; 2]; Column::COUNT];
        self.q = DataQuality::default();
        self.error = None;
        self.stopped = false;
    }

    fn blank_lines(&mut self, lines: u64) {
        self.q.blank_lines = lines;
    }
}

#[cfg(test)]
mod tests;
