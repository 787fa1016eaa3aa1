//! What stands between the data-quality stage and the replay ([`ReplaySink`]): glitch
//! bursts filled in along the rotation or held out, segments at another sample rate
//! resampled onto the monitor's clock, the replay's time carried on over a clock reset.
//! The rows it replays go to a [`Feeder`]: the replay on this thread ([`Direct`], with an
//! observer of every output) or the pipe to a replay on a thread of its own
//! (`super::pipe`).

use crate::error::ReplayError;
use crate::options::ReplayOptions;
use crate::replay::{Replay, ReplayObserver};
use crate::sampler::CLOCK_RESET_GAP_S;
use monitor_core::Abc;
use monitor_io::log::quality::{BadCells, CleanSink, SegmentBreak, TimeBase, MAX_BRIDGED_GAP_S};
use monitor_io::log::{Channels, Column, Row};
use monitor_io::params::ParamFile;
use std::ops::ControlFlow;

/// The replay behind the data-quality stage: configured when the stage knows the time
/// base; rows of segments at another sample rate are counted, not replayed (the monitor's
/// configuration follows from one rate). The rows it replays go to a [`Feeder`]: the
/// replay itself, or the pipe to the replay's thread.
pub(super) struct ReplaySink<'a, F: Feeder> {
    feeder: F,
    params: &'a ParamFile,
    /// The feeder took the time base (the replay is configured).
    began: bool,
    /// The first row replayed's time (the replay's time 0) [s].
    t0: Option<f64>,
    other_rate: bool,
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
    /// The last good row replayed, unless `fed_good` (then it is `last_fed`: the common
    /// case, one copy of the row kept instead of two).
    last_good: Option<Row>,
    fed_good: bool,
    /// Nothing held or pending: no segment at another rate, no burst, no clock reset (the
    /// common row's one test).
    quiet: bool,
    handled: Handled,
}

/// What [`ReplaySink`] did, for the report's actions.
#[derive(Debug, Clone, Default)]
pub(super) struct Handled {
    /// The monitor's sample rate (the time base's) [Hz].
    pub rate_hz: f64,
    /// Rows of segments at another rate resampled onto the monitor's clock.
    pub rows_other_rate: u64,
    /// Stretches of the log not judged, `(from, to, why)` [s of the replay's time].
    pub not_judged: Vec<(f64, f64, &'static str)>,
    /// Bursts of bad cells up to the longest gap bridged, and longer ones.
    pub short_bursts: u64,
    /// See `short_bursts`.
    pub long_bursts: u64,
    /// Rows of glitches filled in between their neighbours.
    pub filled_rows: u64,
}

impl<F: Feeder + ?Sized> Feeder for &mut F {
    fn begin(&mut self, rate_hz: f64) -> bool {
        (**self).begin(rate_hz)
    }
    fn row(&mut self, row: &Row) {
        (**self).row(row);
    }
    fn rows(&mut self, rows: &[Row]) {
        (**self).rows(rows);
    }
    fn clock_reset(&mut self) {
        (**self).clock_reset();
    }
    fn restart(&mut self) {
        (**self).restart();
    }
}

/// Where [`ReplaySink`] sends what it replays: a [`Replay`] on this thread ([`Direct`]), or
/// the pipe to one on a thread of its own ([`super::pipe`]).
pub(super) trait Feeder {
    /// The time base is known: configure the replay at `rate_hz`. False when it cannot be
    /// (the error is the feeder's to report).
    fn begin(&mut self, rate_hz: f64) -> bool;
    /// One row to replay, its time on the replay's clock.
    fn row(&mut self, row: &Row);
    /// Rows to replay, in order: [`Feeder::row`] of each in turn (by default).
    fn rows(&mut self, rows: &[Row]) {
        for r in rows {
            self.row(r);
        }
    }
    /// The acquisition clock was reset before the next row: the replay's encoder count goes
    /// on over the bridged time ([`Replay::clock_reset`]).
    fn clock_reset(&mut self);
    /// Forget everything: the rows come again from the first one.
    fn restart(&mut self);
}

/// The replay on this thread, with an optional observer of every output (the live HMI).
pub(super) struct Direct<'a, O: ReplayObserver + ?Sized> {
    params: &'a ParamFile,
    channels: Channels,
    opts: ReplayOptions,
    observer: Option<&'a mut O>,
    pub(super) replay: Option<Replay>,
    pub(super) error: Option<ReplayError>,
}

impl<'a, O: ReplayObserver + ?Sized> Direct<'a, O> {
    /// A replay of a log of `params`' machine with `channels`, configured at the time base.
    pub(super) fn new(
        params: &'a ParamFile,
        channels: Channels,
        opts: ReplayOptions,
        observer: Option<&'a mut O>,
    ) -> Self {
        Direct {
            params,
            channels,
            opts,
            observer,
            replay: None,
            error: None,
        }
    }
}

impl<O: ReplayObserver + ?Sized> Feeder for Direct<'_, O> {
    fn begin(&mut self, rate_hz: f64) -> bool {
        match Replay::new(self.params, self.channels, rate_hz, self.opts) {
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

    fn row(&mut self, row: &Row) {
        let Some(r) = self.replay.as_mut() else {
            return;
        };
        let out = r.push(row);
        if let Some(o) = self.observer.as_deref_mut() {
            o.output(&r.as_monitor_sees(row), &out, r);
        }
    }

    fn clock_reset(&mut self) {
        if let Some(r) = self.replay.as_mut() {
            r.clock_reset();
        }
    }

    fn restart(&mut self) {
        if let Some(o) = self.observer.as_deref_mut() {
            o.restart();
        }
        self.replay = None;
        self.error = None;
    }
}

/// Glitches spanning (with their good neighbours) at most this fraction of a supply
/// period are filled in between the neighbours: a quarter period keeps the phase step
/// between them unambiguous.
const FILL_PERIODS: f64 = 0.25;

impl<'a, F: Feeder> ReplaySink<'a, F> {
    /// The sink in front of `feeder` for a log of `params`' machine.
    pub(super) fn new(params: &'a ParamFile, feeder: F) -> Self {
        ReplaySink {
            feeder,
            params,
            began: false,
            t0: None,
            other_rate: false,
            restarts: 0,
            burst: Vec::new(),
            burst_forwarded: false,
            other_rate_hz: 0.0,
            last_fed: None,
            resample_from: None,
            clock_reset_pending: false,
            time_offset: 0.0,
            last_good: None,
            fed_good: false,
            quiet: true,
            handled: Handled::default(),
        }
    }

    /// The feeder and what the sink did, once the read is over.
    pub(super) fn into_parts(self) -> (F, Handled) {
        (self.feeder, self.handled)
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

impl<F: Feeder> ReplaySink<'_, F> {
    /// Replays one row: after a clock reset its time is moved on to follow the last row's
    /// by [`CLOCK_RESET_GAP_S`] (the replay's time never goes back).
    #[inline]
    fn feed(&mut self, row: &Row) {
        if !self.began {
            return;
        }
        if std::mem::take(&mut self.fed_good) {
            self.last_good = self.last_fed;
        }
        if std::mem::take(&mut self.clock_reset_pending) {
            if let Some(last) = self.last_fed {
                self.time_offset = last.t_s + self.time_offset + CLOCK_RESET_GAP_S - row.t_s;
                self.feeder.clock_reset();
            }
        }
        self.replay(row);
    }

    /// Hands a row on at its time plus the offset (the row as it came when that is its
    /// own time, bit for bit).
    #[inline]
    fn replay(&mut self, row: &Row) {
        self.last_fed = Some(*row);
        let t = row.t_s + self.time_offset;
        self.t0.get_or_insert(t);
        if t.to_bits() == row.t_s.to_bits() {
            self.feeder.row(row);
        } else {
            self.feeder.row(&Row { t_s: t, ..*row });
        }
    }

    /// The last good row replayed.
    fn last_good(&self) -> Option<Row> {
        if self.fed_good {
            self.last_fed
        } else {
            self.last_good
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
        self.handled.rows_other_rate += 1;
        let dt = 1.0 / self.handled.rate_hz;
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
        // (The replay's time: from its first row, or that of the first row to come.)
        let t = if self.began {
            t - self.t0.unwrap_or(t)
        } else {
            t
        };
        match self.handled.not_judged.last_mut() {
            Some(last) if last.2 == why && t - last.1 <= MAX_BRIDGED_GAP_S => last.1 = t,
            _ => self.handled.not_judged.push((t, t, why)),
        }
    }
}

impl<F: Feeder> ReplaySink<'_, F> {
    /// [`CleanSink::row`] of a row with bad cells, of a segment at another rate, or after
    /// rows held or a clock reset.
    #[cold]
    fn row_other(&mut self, row: &Row, bad: BadCells) -> bool {
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
            if self.burst.len() as f64 <= MAX_BRIDGED_GAP_S * self.handled.rate_hz {
                return true;
            }
            self.burst_forwarded = true;
            if !encoder_only(bad) {
                self.handled.long_bursts += 1;
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
            self.handled.short_bursts += 1;
            // A glitch of a few samples is filled in between its good neighbours (the
            // monitor would otherwise lose the whole block it falls in); a longer one is
            // left out, a gap the monitor bridges.
            let short = |a: &Row| (row.t_s - a.t_s) * self.params.supply.f_hz <= FILL_PERIODS;
            if let Some(a) = self.last_good().filter(short) {
                let burst = std::mem::take(&mut self.burst);
                for (b, _) in &burst {
                    self.feed(&between(&a, &row, b.t_s));
                }
                self.handled.filled_rows += burst.len() as u64;
            }
        }
        self.burst.clear();
        self.burst_forwarded = false;
        self.feed(&row);
        self.fed_good = true;
        true
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

impl<F: Feeder> CleanSink for ReplaySink<'_, F> {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.handled.rate_hz = base.sample_rate_hz;
        self.t0 = None;
        self.began = self.feeder.begin(base.sample_rate_hz);
        self.began
    }

    #[inline(always)]
    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        if !self.began {
            return true;
        }
        if bad.any() || !self.quiet {
            let go = self.row_other(row, bad);
            self.quiet = !(self.other_rate
                || self.burst_forwarded
                || !self.burst.is_empty()
                || self.clock_reset_pending);
            return go;
        }
        // A good row with nothing held: replayed as it is.
        self.replay(row);
        self.fed_good = true;
        true
    }

    fn rows(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        let off = self.time_offset;
        let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
            return ControlFlow::Continue(());
        };
        if !self.began {
            return ControlFlow::Continue(());
        }
        if !self.quiet
            || rows
                .iter()
                .any(|r| (r.t_s + off).to_bits() != r.t_s.to_bits())
        {
            for r in rows {
                self.row(r, BadCells::default());
            }
            return ControlFlow::Continue(());
        }
        // Good rows with nothing held, each at its own time: replayed as they are
        // ([`ReplaySink::replay`] of each).
        self.t0.get_or_insert(first.t_s + off);
        self.last_fed = Some(*last);
        self.feeder.rows(rows);
        self.fed_good = true;
        ControlFlow::Continue(())
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        match why {
            SegmentBreak::RateChange(r) => {
                let other = (r / self.handled.rate_hz - 1.0).abs() > 0.02;
                if other && !self.other_rate {
                    let dt = 1.0 / self.handled.rate_hz;
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
        self.quiet = !(self.other_rate || self.clock_reset_pending) && self.quiet;
        true
    }

    fn restart(&mut self) {
        self.feeder.restart();
        self.began = false;
        self.t0 = None;
        // (The rate stays: the time base is set again at the next begin.)
        self.handled = Handled {
            rate_hz: self.handled.rate_hz,
            ..Handled::default()
        };
        self.other_rate = false;
        self.restarts = 0;
        self.burst.clear();
        self.burst_forwarded = false;
        self.other_rate_hz = 0.0;
        self.last_fed = None;
        self.resample_from = None;
        self.clock_reset_pending = false;
        self.time_offset = 0.0;
        self.last_good = None;
        self.fed_good = false;
        self.quiet = true;
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
