//! The stage's path for a block of rows ([`RowSink::rows`]): the longest run of rows at
//! its head that are all the common row (one period after the last, on the sample clock
//! within [`CLOCK_EXACT`], no bad cell, no encoder count to follow, no phase channel's run
//! of equal readings as long as a stuck one's) is judged in one pass and handed on at once
//! ([`CleanSink::rows`]); any other row goes the row's own way ([`RowSink::row`]). The counts, the accumulators, the stuck
//! channels' runs and the rows handed on are those of the rows one by one, bit for bit.

use super::stuck::StuckTracker;
use super::{CleanSink, QualityStage, TimeUnit, CLOCK_EXACT, INTERVAL_TOLERANCE};
use crate::log::{Row, RowSink};
use std::ops::ControlFlow;

impl<S: CleanSink> QualityStage<'_, S> {
    /// [`RowSink::rows`] of the stage.
    pub(super) fn block(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        let mut done = 0;
        while let Some(rest) = rows.get(done..).filter(|r| !r.is_empty()) {
            let (n, stuck) = if self.base.is_some() && !self.stopped {
                self.common_run(rest)
            } else {
                (0, StuckTracker::default())
            };
            if n == 0 {
                if !self.row(&rest[0]) {
                    return ControlFlow::Break(done);
                }
                done += 1;
                continue;
            }
            if let ControlFlow::Break(k) = self.pass_common(&rest[..n], stuck) {
                return ControlFlow::Break(done + k);
            }
            done += n;
        }
        ControlFlow::Continue(())
    }

    /// The rows at the head of `rows` that are the common row, each after the one before
    /// (the first after the last row passed), and the stuck channels' runs after them;
    /// see the module documentation. Judged channel by channel on the rows staged
    /// ([`super::signals::Signals::stage`]).
    fn common_run(&mut self, rows: &[Row]) -> (usize, StuckTracker) {
        if self.pending.is_some() || self.burst.is_some() || self.q.time_unit != TimeUnit::S {
            return (0, self.stuck.clone());
        }
        let lim = self.limits;
        let staged = self.signals.stage(rows);
        let mut n = on_clock(staged.t, self.last_t, self.period);
        let first = if staged.has_v { 0 } else { 3 };
        for (k, xs) in staged.x.iter().enumerate().skip(first) {
            let max = if k < 3 { lim.v_max } else { lim.i_max };
            n = n.min(within(xs, max));
        }
        if let Some(wm) = staged.wm {
            n = n.min(within(wm, lim.wm_max));
        }
        let stuck = self.stuck.follow_columns(staged.x, staged.has_v, &mut n);
        (n, stuck)
    }

    /// Passes rows of a [`QualityStage::common_run`] on (`stuck`: the runs after them): the
    /// sink first (it may stop at one of them), then the stage's counts and accumulators
    /// for the rows it took.
    fn pass_common(&mut self, rows: &[Row], stuck: StuckTracker) -> ControlFlow<usize> {
        let flow = self.sink.rows(rows);
        let m = match flow {
            ControlFlow::Break(k) => k + 1,
            ControlFlow::Continue(()) => rows.len(),
        };
        let rows = rows.get(..m).unwrap_or(rows);
        if flow.is_continue() {
            self.stuck = stuck;
        } else {
            for r in rows {
                self.stuck.follow_unmarked(r);
            }
        }
        self.off_run.clear();
        self.off_run_counts = (0, 0);
        self.back_run.0 = 0;
        self.q.rows_read += m as u64;
        self.q.rows_passed += m as u64;
        self.dropping = false;
        let (mut last_t, mut sq) = (self.last_t, self.jitter.0);
        for r in rows {
            let err = r.t_s - (last_t + self.period);
            sq += err * err;
            last_t = r.t_s;
        }
        self.signals.take_staged(m);
        self.jitter = (sq, self.jitter.1 + m as u64);
        self.last_t = last_t;
        self.stopped = flow.is_break();
        flow
    }
}

/// The number of times at the head of `t` each one period after the one before (the first
/// after `last_t`) within [`INTERVAL_TOLERANCE`], and on the sample clock within
/// [`CLOCK_EXACT`] (the expressions of `ingest` and `emit_on_clock`; times in seconds).
fn on_clock(t: &[f64], last_t: f64, period: f64) -> usize {
    let (tol, exact) = (INTERVAL_TOLERANCE * period, CLOCK_EXACT * period);
    let ok = |prev: f64, t: f64| {
        ((t - prev - period).abs() <= tol) & ((t - (prev + period)).abs() <= exact)
    };
    let Some(&t0) = t.first() else {
        return 0;
    };
    if !ok(last_t, t0) {
        return 0;
    }
    let pairs = t.iter().zip(t.iter().skip(1));
    if pairs.clone().fold(true, |all, (&a, &b)| all & ok(a, b)) {
        return t.len();
    }
    pairs.take_while(|(&a, &b)| ok(a, b)).count() + 1
}

/// The number of readings at the head of `xs` within `max` (finite, `|x| <= max`: the
/// rule of [`BadCells::of`]).
fn within(xs: &[f64], max: f64) -> usize {
    let max = max.min(f64::MAX);
    if xs.iter().fold(true, |all, &x| all & (x.abs() <= max)) {
        return xs.len();
    }
    xs.iter().take_while(|&&x| x.abs() <= max).count()
}
