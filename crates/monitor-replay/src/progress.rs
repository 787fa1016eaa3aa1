//! The fraction of `diagnose`'s work done, for a progress bar: the rows that have reached
//! the data-quality stage against the rows the log holds (the reader's estimate), up to
//! [`READ_SHARE`]; the rest is the work after the last row (the verdict, the rotor's
//! spectrum, the sequence windows' judgement), and 1 only once the report is built.
//!
//! (The reader's own fraction is of the bytes read, which runs ahead of the rows handed
//! over by up to two batches of parsing blocks, 16 MB on two cores: a 30 MB log's bar
//! stood at 56 % and then jumped to done.)

use monitor_io::log::{Row, RowSink};
use std::ops::ControlFlow;

/// The share of the work that is reading and replaying the rows; the rest is the
/// conclusion after the last row.
pub(crate) const READ_SHARE: f64 = 0.95;

/// Least change of the fraction that is reported (the callback is called at most about
/// a thousand times).
const STEP: f64 = 0.001;

/// A progress callback that only moves forward, by [`STEP`] at least.
pub(crate) struct Forward<'a> {
    progress: &'a mut dyn FnMut(f64),
    shown: f64,
}

impl<'a> Forward<'a> {
    /// Nothing reported yet (the bar at 0).
    pub(crate) fn new(progress: &'a mut dyn FnMut(f64)) -> Self {
        Forward {
            progress,
            shown: 0.0,
        }
    }

    /// Reports `fraction` (0..1) if it is [`STEP`] beyond the last one reported, or 1.
    pub(crate) fn to(&mut self, fraction: f64) {
        let f = fraction.clamp(0.0, 1.0);
        if f >= self.shown + STEP || (f >= 1.0 && self.shown < 1.0) {
            self.shown = f;
            (self.progress)(f);
        }
    }
}

/// A [`RowSink`] in front of the data-quality stage that counts the rows handed to it and
/// moves the progress to `READ_SHARE * rows / expected` (held below [`READ_SHARE`] when the
/// estimate is short; a restarted read holds the bar until it passes it again).
pub(crate) struct CountedRows<'s, 'p> {
    sink: &'s mut dyn RowSink,
    progress: &'s mut Forward<'p>,
    rows: u64,
    expected: f64,
}

impl<'s, 'p> CountedRows<'s, 'p> {
    /// Counts the rows into `sink` against `expected` rows (the reader's estimate).
    pub(crate) fn new(
        sink: &'s mut dyn RowSink,
        progress: &'s mut Forward<'p>,
        expected: f64,
    ) -> Self {
        CountedRows {
            sink,
            progress,
            rows: 0,
            expected: expected.max(1.0),
        }
    }

    /// Moves the bar after `n` more rows.
    fn counted(&mut self, n: usize) {
        self.rows += n as u64;
        let read = (self.rows as f64 / self.expected).min(0.999);
        self.progress.to(READ_SHARE * read);
    }
}

impl RowSink for CountedRows<'_, '_> {
    fn row(&mut self, row: &Row) -> bool {
        let go_on = self.sink.row(row);
        self.counted(1);
        go_on
    }

    fn rows(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        let flow = self.sink.rows(rows);
        self.counted(match flow {
            ControlFlow::Break(k) => k + 1,
            ControlFlow::Continue(()) => rows.len(),
        });
        flow
    }

    fn restart(&mut self) {
        self.rows = 0;
        self.sink.restart();
    }

    fn blank_lines(&mut self, lines: u64) {
        self.sink.blank_lines(lines);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sink that takes every row.
    struct Take;
    impl RowSink for Take {
        fn row(&mut self, _: &Row) -> bool {
            true
        }
        fn restart(&mut self) {}
    }

    #[test]
    fn the_fraction_moves_forward_and_stops_short_of_the_conclusion() {
        let mut seen = Vec::new();
        let mut cb = |f| seen.push(f);
        let mut fwd = Forward::new(&mut cb);
        let rows = vec![Row::default(); 100];
        {
            let mut take = Take;
            // (An estimate 20 % short: the bar holds below the conclusion's share.)
            let mut c = CountedRows::new(&mut take, &mut fwd, 800.0);
            for _ in 0..5 {
                let _ = c.rows(&rows);
            }
            c.restart();
            for _ in 0..10 {
                let _ = c.rows(&rows);
            }
        }
        fwd.to(1.0);
        fwd.to(1.0);
        assert!(seen.windows(2).all(|w| w[0] < w[1]), "{seen:?}");
        assert_eq!(seen.iter().filter(|f| **f >= 1.0).count(), 1, "{seen:?}");
        assert!(seen[seen.len() - 2] < READ_SHARE, "{seen:?}");
    }
}
