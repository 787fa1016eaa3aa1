//! A log through the data-quality stage and a [`Replay`]: what `sim-host diagnose` runs
//! ([`diagnose_file`]), the glitch bursts filled or held out, and the observer of every
//! output (the live HMI's log source).

use super::{pipe, DiagnoseReport, Replay, ReplayError, ReplayOptions, Verdict};
use crate::log::quality::{
    BadCells, CellLimits, CleanSink, DataQuality, NotJudged, QualityStage, SegmentBreak, TimeBase,
    MAX_BRIDGED_GAP_S, MAX_NOT_JUDGED_FRACTION,
};
use crate::log::{Channels, Column, LogError, LogFile, OpenOptions, Row, RowSink};
use crate::params::ParamFile;
use monitor_core::{Abc, MonitorOutput};
use std::path::Path;

/// A log replayed by [`diagnose_file`] or [`diagnose_rows`].
#[derive(Debug, Clone)]
pub struct Diagnosed {
    /// The report (`diagnose --json`), `data_quality` included.
    pub report: DiagnoseReport,
    /// The log's nominal sample rate (the data-quality stage's) [Hz].
    pub sample_rate_hz: f64,
}

/// Replays rows held in memory, through the data-quality stage, and returns the report.
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_rows(
    params: &ParamFile,
    channels: Channels,
    rows: &[Row],
    opts: ReplayOptions,
) -> Result<DiagnoseReport, ReplayError> {
    replay_through_quality(params, channels, "the log", opts, |stage| {
        for r in rows {
            if !stage.row(r) {
                break;
            }
        }
        Ok(())
    })
    .map(|d| d.report)
}

/// Streams a log file through the data-quality stage and the core (`sim-host
/// diagnose`): the stage's time base configures the monitor, and every row is replayed,
/// with bounded memory whatever the log's length.
///
/// # Errors
/// [`ReplayError::Log`] naming the file, line and column, or the stage's time-base
/// errors (a log without rows or sampled below 8 samples per supply period, with the rate
/// needed); [`ReplayError::Config`] when the core rejects the configuration;
/// [`ReplayError::IncompleteCommissioning`] for a window not learned without
/// `allow_incomplete`.
pub fn diagnose_file(
    params: &ParamFile,
    path: &Path,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    diagnose_log(params, &LogFile::open(path)?, opts, progress)
}

/// [`diagnose_file`] on a log already opened (any format, a TDMS group chosen:
/// [`LogFile::open_with`]).
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_log(
    params: &ParamFile,
    file: &LogFile,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    replay_through_quality(params, file.channels(), file.shown(), opts, |stage| {
        file.for_each_row(progress, stage).map(|_| ())
    })
}

/// Watches a replay row by row ([`diagnose_file_observed`]): the live HMI's log source.
pub trait ReplayObserver {
    /// The monitor's output after `row` (as the data-quality stage passed it on, glitches
    /// filled in); `replay` for its time base and thresholds ([`Replay::time_of`],
    /// [`Replay::threshold_bands`]).
    fn output(&mut self, row: &Row, out: &MonitorOutput, replay: &Replay);
    /// The replay starts again from the log's first row (the reader's fast path handed
    /// over to the exact reader): forget every output so far.
    fn restart(&mut self);
}

/// [`diagnose_file`] that hands every replayed row's output to `observer` as it goes, the
/// log opened with `open` (a TDMS group, the parameter file's `[columns]` mapping).
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_file_observed(
    params: &ParamFile,
    path: &Path,
    open: &OpenOptions,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
    observer: &mut dyn ReplayObserver,
) -> Result<Diagnosed, ReplayError> {
    let file = LogFile::open_with(path, open)?;
    replay_observed(
        params,
        file.channels(),
        file.shown(),
        opts,
        Some(observer),
        |stage| file.for_each_row(progress, stage).map(|_| ()),
    )
}

/// Runs `feed` into the data-quality stage in front of a replay; builds the report.
fn replay_through_quality(
    params: &ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    replay_observed(params, channels, shown, opts, None, feed)
}

/// [`replay_through_quality`] with an optional observer of every output. Without one,
/// the replay runs on a thread of its own beside the data-quality stage ([`pipe`]: the
/// same results, on two cores).
fn replay_observed<'a>(
    params: &'a ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    observer: Option<&'a mut dyn ReplayObserver>,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    match observer {
        None => {
            let mut sink = ReplaySink::<NoObserver>::new(params, channels, opts, None);
            let (read, quality) =
                pipe::on_own_thread(&mut sink, |p| through_quality(p, params, shown, feed));
            conclude(sink, read, quality, shown, opts)
        }
        Some(o) => {
            let mut sink = ReplaySink::new(params, channels, opts, Some(o));
            let (read, quality) = through_quality(&mut sink, params, shown, feed);
            conclude(sink, read, quality, shown, opts)
        }
    }
}

/// Runs `feed` into the data-quality stage in front of `clean`: the read's result and
/// the stage's report.
fn through_quality<S: CleanSink>(
    clean: &mut S,
    params: &ParamFile,
    shown: &str,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> (Result<(), LogError>, Result<DataQuality, LogError>) {
    let mut stage = QualityStage::new(clean, CellLimits::for_params(params), shown);
    let read = feed(&mut stage);
    (read, stage.finish())
}

/// The report of a replay whose rows have all been read.
fn conclude<O: ReplayObserver + ?Sized>(
    mut sink: ReplaySink<'_, O>,
    read: Result<(), LogError>,
    quality: Result<DataQuality, LogError>,
    shown: &str,
    opts: ReplayOptions,
) -> Result<Diagnosed, ReplayError> {
    if let Some(e) = sink.error.take() {
        return Err(e);
    }
    read?;
    let mut quality = quality?;
    let Some(replay) = sink.replay.take() else {
        return Err(ReplayError::Option(format!("{shown}: no rows to replay")));
    };
    if replay.commissioning_incomplete() && !opts.allow_incomplete {
        let mut why = replay.commission.why_incomplete().unwrap_or_default();
        // What the data-quality stage distrusts is often why nothing was learned (swapped
        // channels, a dead sensor): say it in the same line.
        if !quality.trusted {
            why = format!(
                "{why}; data quality: {}",
                quality.not_trusted_because.join("; ")
            );
        }
        return Err(ReplayError::IncompleteCommissioning { why });
    }
    let can_residuals = replay.monitor.is_some();
    let mut report = replay.finish();
    describe_actions(&mut quality, can_residuals, &sink);
    withhold_healthy_over_unjudged(&mut report, &quality);
    if !quality.trusted {
        report.verdict = Verdict::CouldNotJudge;
        report.verdict_withheld_because.extend(
            quality
                .not_trusted_because
                .iter()
                .map(|w| format!("data quality: {w}")),
        );
    }
    report.data_quality = quality;
    Ok(Diagnosed {
        report,
        sample_rate_hz: sink.rate_hz,
    })
}

/// What `diagnose` did about what the stage found, in the report's `actions`.
fn describe_actions<O: ReplayObserver + ?Sized>(
    q: &mut DataQuality,
    monitor: bool,
    sink: &ReplaySink<'_, O>,
) {
    let who = if monitor {
        "the monitor"
    } else {
        "the unbalance analysis"
    };
    if q.gaps_bridged > 0 {
        q.actions.push(format!(
            "short gaps: {who} advanced its estimators over the real elapsed time"
        ));
    }
    if q.long_gaps > 0 || q.clock_resets > 0 {
        q.actions.push(format!(
            "long gaps and clock resets: {who} restarted its estimators and settled again"
        ));
    }
    if sink.short_bursts > 0 {
        q.actions.push(format!(
            "{} bursts of bad cells up to {MAX_BRIDGED_GAP_S} s: {} rows of glitches within a quarter supply period filled in between their neighbours along the rotation, the longer bursts left out and bridged like gaps",
            sink.short_bursts, sink.filled_rows
        ));
    }
    if sink.long_bursts > 0 {
        q.actions.push(format!(
            "{} bursts of bad cells longer than {MAX_BRIDGED_GAP_S} s: given to {who}, which holds them out and flags the sensor",
            sink.long_bursts
        ));
    }
    if q.repeated_or_backward_rows + q.non_finite_times > 0 {
        q.actions
            .push("rows with a repeated, backward or unreadable time: dropped".to_string());
    }
    if sink.rows_other_rate > 0 {
        q.actions.push(format!(
            "{} rows at another sample rate resampled onto the monitor's {:.0} Hz clock (interpolated along the rotation)",
            sink.rows_other_rate, sink.rate_hz
        ));
    }
    if q.clock_resets > 0 {
        q.actions.push(format!(
            "after each clock reset the replay's time goes on from the last row's plus {CLOCK_RESET_GAP_S} s (the times reported are the replay's)"
        ));
    }
    q.not_judged = sink
        .not_judged
        .iter()
        .map(|&(from_s, to_s, why)| NotJudged {
            from_s,
            to_s,
            why: why.to_string(),
        })
        .collect();
    for n in &q.not_judged {
        q.warnings.push(format!(
            "{:.2}..{:.2} s not judged: {}",
            n.from_s, n.to_s, n.why
        ));
    }
}

/// A "healthy" verdict is withheld when more than [`MAX_NOT_JUDGED_FRACTION`] of the log
/// was not judged: a fault may hide there (a fault found elsewhere stands).
fn withhold_healthy_over_unjudged(report: &mut DiagnoseReport, q: &DataQuality) {
    let unjudged: f64 = q.not_judged.iter().map(|n| n.to_s - n.from_s).sum();
    if report.verdict == Verdict::Healthy
        && unjudged > MAX_NOT_JUDGED_FRACTION * q.duration_s.max(f64::MIN_POSITIVE)
    {
        report.verdict = Verdict::CouldNotJudge;
        report.verdict_withheld_because.push(format!(
            "{unjudged:.2} s of the {:.2} s log could not be judged (over {:.0} %): {}",
            q.duration_s,
            100.0 * MAX_NOT_JUDGED_FRACTION,
            q.not_judged
                .iter()
                .map(|n| format!("{:.2}..{:.2} s, {}", n.from_s, n.to_s, n.why))
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
}

/// The replay behind the data-quality stage: configured when the stage knows the time
/// base; rows of segments at another sample rate are counted, not replayed (the monitor's
/// configuration follows from one rate).
struct ReplaySink<'a, O: ReplayObserver + ?Sized> {
    observer: Option<&'a mut O>,
    params: &'a ParamFile,
    channels: Channels,
    opts: ReplayOptions,
    replay: Option<Replay>,
    rate_hz: f64,
    other_rate: bool,
    rows_other_rate: u64,
    restarts: u64,
    burst: Vec<(Row, BadCells)>,
    burst_forwarded: bool,
    /// The rate of the segment at another rate [Hz].
    other_rate_hz: f64,
    /// The last row replayed (its own time, before any clock-reset offset), where the
    /// resampling of a segment at another rate starts.
    last_fed: Option<Row>,
    /// The row the resampling interpolates from, and the next time on the monitor's clock
    /// [s].
    resample_from: Option<(Row, f64)>,
    /// A clock reset was seen: the next row replayed sets [`ReplaySink::time_offset`].
    clock_reset_pending: bool,
    /// Added to every row's time after a clock reset, so the replay's time goes on [s].
    time_offset: f64,
    /// Added to every row's encoder count after a clock reset: the turn over the bridged
    /// time.
    enc_offset: i64,
    /// Stretches of the log not judged, `(from, to, why)` [s of the replay's time].
    not_judged: Vec<(f64, f64, &'static str)>,
    short_bursts: u64,
    long_bursts: u64,
    last_good: Option<Row>,
    filled_rows: u64,
    error: Option<ReplayError>,
}

/// Glitches spanning (with their good neighbours) at most this fraction of a supply
/// period are filled in between the neighbours: a quarter period keeps the phase step
/// between them unambiguous.
const FILL_PERIODS: f64 = 0.25;

impl<'a, O: ReplayObserver + ?Sized> ReplaySink<'a, O> {
    fn new(
        params: &'a ParamFile,
        channels: Channels,
        opts: ReplayOptions,
        observer: Option<&'a mut O>,
    ) -> Self {
        ReplaySink {
            observer,
            params,
            channels,
            opts,
            replay: None,
            rate_hz: 0.0,
            other_rate: false,
            rows_other_rate: 0,
            restarts: 0,
            burst: Vec::new(),
            burst_forwarded: false,
            other_rate_hz: 0.0,
            last_fed: None,
            resample_from: None,
            clock_reset_pending: false,
            time_offset: 0.0,
            enc_offset: 0,
            not_judged: Vec::new(),
            short_bursts: 0,
            long_bursts: 0,
            last_good: None,
            filled_rows: 0,
            error: None,
        }
    }
}

/// True when the only bad cell is the encoder count.
fn encoder_only(bad: BadCells) -> bool {
    Column::ALL
        .iter()
        .all(|&c| !bad.has(c) || c == Column::Encoder)
}

/// Samples per supply period below which a segment at another rate is not resampled onto
/// the monitor's clock (not judged).
const MIN_RESAMPLE_PER_PERIOD: f64 = 20.0;
/// Time the replay puts between the segments around a clock reset [s]: a long gap, after
/// which the monitor restarts its estimators and settles.
const CLOCK_RESET_GAP_S: f64 = 2.0 * MAX_BRIDGED_GAP_S;

impl<O: ReplayObserver + ?Sized> ReplaySink<'_, O> {
    /// Replays one row: after a clock reset its time is moved on to follow the last row's
    /// by [`CLOCK_RESET_GAP_S`] (the replay's time never goes back).
    fn feed(&mut self, row: &Row) {
        let Some(r) = self.replay.as_mut() else {
            return;
        };
        if std::mem::take(&mut self.clock_reset_pending) {
            if let Some(last) = self.last_fed {
                self.time_offset = last.t_s + self.time_offset + CLOCK_RESET_GAP_S - row.t_s;
                // The shaft turned on over the bridged time at the last speed (the count
                // handed on by the data-quality stage continues with no step).
                let w = r
                    .monitor()
                    .map_or(0.0, |m| f64::from(m.output().speed_rad_s));
                let turned = w * CLOCK_RESET_GAP_S / std::f64::consts::TAU;
                self.enc_offset = self
                    .enc_offset
                    .wrapping_add((turned * f64::from(super::COUNTS_PER_REV)).round() as i64);
            }
        }
        self.last_fed = Some(*row);
        let shifted = Row {
            t_s: row.t_s + self.time_offset,
            enc_count: row.enc_count.map(|c| c.wrapping_add(self.enc_offset)),
            ..*row
        };
        let out = r.push(&shifted);
        if let Some(o) = self.observer.as_deref_mut() {
            o.output(&shifted, &out, r);
        }
    }

    /// A row with bad cells given to the monitor, which holds them out and flags the
    /// sensor; a row whose only bad cell is the encoder count (no speed channel to take
    /// over) is not judged: a count the log cannot carry is no reading of the shaft.
    fn forward_bad(&mut self, row: &Row, bad: BadCells) {
        if encoder_only(bad) {
            self.note_not_judged(row, "the encoder count is unreadable or jumps");
        } else {
            self.feed(row);
        }
    }

    /// Where the encoder count is bad and the speed channel good, the speed channel takes
    /// over (the sampler keeps the count continuous across the switch).
    fn speed_from_tachometer(&self, row: &Row, mut bad: BadCells) -> (Row, BadCells) {
        let mut row = *row;
        if bad.has(Column::Encoder) && row.wm_rad_s.is_some() && !bad.has(Column::Speed) {
            row.enc_count = None;
            bad.clear(Column::Encoder);
        }
        (row, bad)
    }

    /// A row of a segment at another sample rate: resampled onto the monitor's clock
    /// (interpolated along the rotation from the row before, [`between`]) where the
    /// segment has at least [`MIN_RESAMPLE_PER_PERIOD`] samples per supply period and the
    /// two rows lie within [`FILL_PERIODS`]; else not judged.
    fn resample(&mut self, row: &Row, bad: BadCells) {
        let f = self.params.supply.f_hz;
        if self.other_rate_hz < MIN_RESAMPLE_PER_PERIOD * f {
            self.note_not_judged(
                row,
                "sampled too coarsely to resample onto the monitor's rate",
            );
            return;
        }
        if bad.any() {
            // Held out; the interpolation spans it when short.
            return;
        }
        self.rows_other_rate += 1;
        let dt = 1.0 / self.rate_hz;
        match self
            .resample_from
            .filter(|a| (row.t_s - a.0.t_s) * f <= FILL_PERIODS)
        {
            Some((a, mut t)) => {
                while t <= row.t_s + 1e-6 * dt {
                    self.feed(&between(&a, row, t));
                    t += dt;
                }
                self.resample_from = Some((*row, t));
            }
            None => {
                self.feed(row);
                self.resample_from = Some((*row, row.t_s + dt));
            }
        }
    }

    /// Records `row` as not judged, `why`, extending the last stretch when it continues.
    fn note_not_judged(&mut self, row: &Row, why: &'static str) {
        let t = row.t_s + self.time_offset;
        let t = self
            .replay
            .as_ref()
            .map_or(t, |r| r.time_of(&Row { t_s: t, ..*row }));
        match self.not_judged.last_mut() {
            Some(last) if last.2 == why && t - last.1 <= MAX_BRIDGED_GAP_S => last.1 = t,
            _ => self.not_judged.push((t, t, why)),
        }
    }
}

/// The observer of a replay without one (no value exists): the replay's sink can then
/// move to a thread of its own.
enum NoObserver {}

impl ReplayObserver for NoObserver {
    fn output(&mut self, _: &Row, _: &MonitorOutput, _: &Replay) {
        match *self {}
    }
    fn restart(&mut self) {
        match *self {}
    }
}

/// The row at `t` between rows `a` and `b`. The voltage and current space vectors turn
/// from `a`'s to `b`'s along the rotation (angle and magnitude interpolated linearly,
/// exact for a steady balanced set, where a straight line in abc would cut the circle's
/// chord), the zero sequence, the speed and the encoder count (rounded) along a line.
fn between(a: &Row, b: &Row, t: f64) -> Row {
    use monitor_core::frames::{clarke, inverse_clarke, zero_sequence, AlphaBeta};
    use nalgebra::Complex;
    let w = if b.t_s > a.t_s {
        ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mix = |x: f64, y: f64| x + w * (y - x);
    let turn = |x: [f64; 3], y: [f64; 3]| {
        let (p, q) = (clarke(Abc::from_array(x)), clarke(Abc::from_array(y)));
        let (zp, zq) = (Complex::new(p.alpha, p.beta), Complex::new(q.alpha, q.beta));
        let step = (zq * zp.conj()).arg();
        let z = Complex::from_polar(mix(zp.norm(), zq.norm()), zp.arg() + w * step);
        let x0 = mix(
            zero_sequence(Abc::from_array(x)),
            zero_sequence(Abc::from_array(y)),
        );
        inverse_clarke(
            AlphaBeta {
                alpha: z.re,
                beta: z.im,
            },
            x0,
        )
        .to_array()
    };
    Row {
        t_s: t,
        v_abc: a.v_abc.zip(b.v_abc).map(|(x, y)| turn(x, y)),
        i_abc: turn(a.i_abc, b.i_abc),
        wm_rad_s: a.wm_rad_s.zip(b.wm_rad_s).map(|(x, y)| mix(x, y)),
        enc_count: a
            .enc_count
            .zip(b.enc_count)
            .map(|(x, y)| x + (w * (y - x) as f64).round() as i64),
        t_winding_c: a.t_winding_c.zip(b.t_winding_c).map(|(x, y)| mix(x, y)),
    }
}

impl<O: ReplayObserver + ?Sized> CleanSink for ReplaySink<'_, O> {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.rate_hz = base.sample_rate_hz;
        match Replay::new(self.params, self.channels, base.sample_rate_hz, self.opts) {
            Ok(r) => {
                self.replay = Some(r);
                true
            }
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        if self.replay.is_none() {
            return true;
        }
        let (row, bad) = self.speed_from_tachometer(row, bad);
        if self.other_rate {
            self.resample(&row, bad);
            return true;
        }
        if bad.any() && !self.burst_forwarded {
            // A glitch burst is held until it ends (dropped: the monitor bridges it like a
            // gap) or outlasts the longest gap bridged (a sensor that has failed: the rows
            // go to the monitor, which holds them out and flags the sensor).
            self.burst.push((row, bad));
            if self.burst.len() as f64 <= MAX_BRIDGED_GAP_S * self.rate_hz {
                return true;
            }
            self.burst_forwarded = true;
            if !encoder_only(bad) {
                self.long_bursts += 1;
            }
            let burst = std::mem::take(&mut self.burst);
            for (b, why) in &burst {
                self.forward_bad(b, *why);
            }
            return true;
        }
        if bad.any() {
            self.forward_bad(&row, bad);
            return true;
        }
        if !self.burst.is_empty() && !self.burst_forwarded {
            self.short_bursts += 1;
            // A glitch of a few samples is filled in between its good neighbours (the
            // monitor would otherwise lose the whole block it falls in); a longer one is
            // left out, a gap the monitor bridges.
            let short = |a: &Row| (row.t_s - a.t_s) * self.params.supply.f_hz <= FILL_PERIODS;
            if let Some(a) = self.last_good.filter(short) {
                let burst = std::mem::take(&mut self.burst);
                for (b, _) in &burst {
                    self.feed(&between(&a, &row, b.t_s));
                }
                self.filled_rows += burst.len() as u64;
            }
        }
        self.burst.clear();
        self.burst_forwarded = false;
        self.last_good = Some(row);
        self.feed(&row);
        true
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        match why {
            SegmentBreak::RateChange(r) => {
                let other = (r / self.rate_hz - 1.0).abs() > 0.02;
                if other && !self.other_rate {
                    let dt = 1.0 / self.rate_hz;
                    self.resample_from = self.last_fed.map(|l| (l, l.t_s + dt));
                }
                self.other_rate = other;
                self.other_rate_hz = r;
            }
            SegmentBreak::Gap(_) => self.restarts += 1,
            SegmentBreak::ClockReset => {
                self.restarts += 1;
                self.clock_reset_pending = true;
            }
        }
        true
    }

    fn restart(&mut self) {
        if let Some(o) = self.observer.as_deref_mut() {
            o.restart();
        }
        self.replay = None;
        self.other_rate = false;
        self.rows_other_rate = 0;
        self.restarts = 0;
        self.burst.clear();
        self.burst_forwarded = false;
        self.other_rate_hz = 0.0;
        self.last_fed = None;
        self.resample_from = None;
        self.clock_reset_pending = false;
        self.time_offset = 0.0;
        self.enc_offset = 0;
        self.not_judged.clear();
        self.short_bursts = 0;
        self.long_bursts = 0;
        self.last_good = None;
        self.filled_rows = 0;
        self.error = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced 50 Hz set (300 V, 10 A lagging 0.4 rad) with a zero sequence, at `t`.
    fn row(t: f64) -> Row {
        let w = std::f64::consts::TAU * 50.0 * t;
        let set = |amp: f64, lag: f64| {
            [0.0, 1.0, 2.0].map(|k| amp * (w - lag - k * std::f64::consts::TAU / 3.0).cos() + 0.5)
        };
        Row {
            t_s: t,
            v_abc: Some(set(300.0, 0.0)),
            i_abc: set(10.0, 0.4),
            wm_rad_s: Some(150.0 + 10.0 * t),
            enc_count: Some((100_000.0 * t) as i64),
            t_winding_c: None,
        }
    }

    #[test]
    fn a_glitch_is_filled_along_the_rotation() {
        // A fifth of a period between the neighbours (4 ms at 50 Hz, four samples at 1 kHz):
        // a straight line in abc would miss by (omega h)^2 / 8 = 20 % of the amplitude.
        let (a, b) = (row(0.010), row(0.014));
        for t in [0.011, 0.012, 0.013] {
            let f = between(&a, &b, t);
            let truth = row(t);
            for (x, y) in f.i_abc.iter().zip(truth.i_abc) {
                assert!((x - y).abs() < 1e-9, "{t}: {x} vs {y}");
            }
            let (fv, tv) = (f.v_abc.unwrap_or_default(), truth.v_abc.unwrap_or_default()); // ok: test
            for (x, y) in fv.iter().zip(tv) {
                assert!((x - y).abs() < 1e-7, "{t}: {x} vs {y}");
            }
            assert!((f.wm_rad_s.unwrap_or(0.0) - (150.0 + 10.0 * t)).abs() < 1e-9);
        }
    }
}
