//! The replay on a thread of its own: the data-quality stage (on the reading thread) hands
//! what it passes on to a [`CleanSink`] on another thread, in batches over a bounded
//! channel, so that the stage and the replay run side by side on two cores (the parsing
//! workers fill in the rest; docs/performance.md, "diagnose of a 1 h log").
//!
//! The sink sees the same calls in the same order as without the thread: the replay's
//! results are the same, bit for bit. [`CleanSink::begin`] is answered synchronously (a
//! sink that cannot be configured stops the read at once, as without the thread). A sink
//! that asks to stop later ([`CleanSink::row`] or [`CleanSink::new_segment`] returning
//! false) stops the stage at the next batch: up to [`BATCH`] rows more are read and
//! dropped (the replay's sink never asks that).

use crate::log::quality::{BadCells, CleanSink, SegmentBreak, TimeBase};
use crate::log::Row;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};

/// Calls per batch (about 110 bytes each).
const BATCH: usize = 4096;
/// Batches on their way at most (the reading thread waits beyond: bounded memory).
const IN_FLIGHT: usize = 4;

/// One call of the [`CleanSink`] interface.
enum Call {
    Begin(TimeBase),
    Row(Row, BadCells),
    Segment(SegmentBreak),
    Restart,
}

/// The reading thread's end: a [`CleanSink`] that batches the calls (given to the read by
/// [`on_own_thread`]).
pub(super) struct Pipe<'s> {
    tx: SyncSender<Vec<Call>>,
    /// Emptied batches coming back (their memory reused).
    back: Receiver<Vec<Call>>,
    /// The answer to [`CleanSink::begin`].
    began: Receiver<bool>,
    batch: Vec<Call>,
    /// Set by the other end when its sink asked to stop.
    stop: &'s AtomicBool,
}

impl Pipe<'_> {
    /// Sends the batch; false when the other end asked to stop or is gone.
    fn flush(&mut self) -> bool {
        if !self.batch.is_empty() {
            let next = self
                .back
                .try_recv()
                .unwrap_or_else(|_| Vec::with_capacity(BATCH));
            let full = std::mem::replace(&mut self.batch, next);
            if self.tx.send(full).is_err() {
                return false;
            }
        }
        !self.stop.load(Ordering::Relaxed)
    }

    fn push(&mut self, c: Call) -> bool {
        self.batch.push(c);
        self.batch.len() < BATCH || self.flush()
    }
}

impl CleanSink for Pipe<'_> {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.batch.push(Call::Begin(*base));
        self.flush() && self.began.recv().unwrap_or(false)
    }

    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        self.push(Call::Row(*row, bad))
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        self.push(Call::Segment(why))
    }

    fn restart(&mut self) {
        self.push(Call::Restart);
    }
}

/// The other thread's end: hands every call to `sink` in order, none after the sink asked
/// to stop (the stage would not have passed them on).
fn receive<S: CleanSink>(
    sink: &mut S,
    rx: Receiver<Vec<Call>>,
    back: Sender<Vec<Call>>,
    began: Sender<bool>,
    stop: &AtomicBool,
) {
    let mut stopped = false;
    for mut batch in rx {
        for c in batch.drain(..) {
            let go = match c {
                Call::Begin(base) => {
                    let ok = !stopped && sink.begin(&base);
                    // (The reading thread waits for this answer.)
                    let _ = began.send(ok);
                    ok
                }
                _ if stopped => false,
                Call::Row(row, bad) => sink.row(&row, bad),
                Call::Segment(why) => sink.new_segment(why),
                Call::Restart => {
                    sink.restart();
                    true
                }
            };
            if !go && !stopped {
                stopped = true;
                stop.store(true, Ordering::Relaxed);
            }
        }
        // (The reading thread may be gone already.)
        let _ = back.send(batch);
    }
}

/// Runs `read` on this thread with a [`Pipe`] whose calls reach `sink` on a thread of its
/// own (module docs); returns `read`'s result once `sink` has had every call.
pub(super) fn on_own_thread<S, R>(sink: &mut S, read: impl FnOnce(&mut Pipe<'_>) -> R) -> R
where
    S: CleanSink + Send,
{
    let stop = AtomicBool::new(false);
    let (tx, rx) = sync_channel(IN_FLIGHT);
    let (back_tx, back) = channel();
    let (began_tx, began) = channel();
    std::thread::scope(|s| {
        let stop = &stop;
        s.spawn(move || receive(sink, rx, back_tx, began_tx, stop));
        let mut pipe = Pipe {
            tx,
            back,
            began,
            batch: Vec::with_capacity(BATCH),
            stop,
        };
        let r = read(&mut pipe);
        pipe.flush();
        // (Dropping the pipe closes the channel: the thread ends after the last batch,
        // and the scope waits for it.)
        drop(pipe);
        r
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::quality::TimeUnit;

    /// Records every call; refuses to begin or stops after `stop_after` rows when asked.
    #[derive(Default)]
    struct Recorder {
        calls: Vec<String>,
        refuse_begin: bool,
        stop_after: Option<usize>,
        rows: usize,
    }

    impl CleanSink for Recorder {
        fn begin(&mut self, base: &TimeBase) -> bool {
            self.calls.push(format!("begin {}", base.sample_rate_hz));
            !self.refuse_begin
        }
        fn row(&mut self, row: &Row, bad: BadCells) -> bool {
            self.rows += 1;
            self.calls.push(format!("row {} {}", row.t_s, bad.any()));
            self.stop_after.is_none_or(|n| self.rows < n)
        }
        fn new_segment(&mut self, why: SegmentBreak) -> bool {
            self.calls.push(format!("segment {why:?}"));
            true
        }
        fn restart(&mut self) {
            self.calls.push("restart".to_string());
        }
    }

    fn row(t: f64) -> Row {
        Row {
            t_s: t,
            v_abc: None,
            i_abc: [t, -t, 0.0],
            wm_rad_s: None,
            enc_count: None,
            t_winding_c: None,
        }
    }

    /// Feeds `n` rows (a segment break and a restart among them) into `sink`; the answers
    /// of the calls, and whether the feed ran to its end.
    fn feed(sink: &mut dyn CleanSink, n: usize) -> (Vec<bool>, bool) {
        let base = TimeBase {
            unit: TimeUnit::S,
            sample_rate_hz: 1000.0,
            t0_s: 0.0,
        };
        let mut answers = vec![sink.begin(&base)];
        if !answers[0] {
            return (answers, false);
        }
        for k in 0..n {
            if k == 5000 {
                answers.push(sink.new_segment(SegmentBreak::Gap(2.0)));
            }
            if k == 7000 {
                sink.restart();
            }
            if !sink.row(&row(k as f64), BadCells::default()) {
                return (answers, false);
            }
        }
        (answers, true)
    }

    #[test]
    fn the_sink_gets_the_same_calls_in_the_same_order() {
        for n in [0, 1, BATCH - 1, BATCH, 3 * BATCH + 17] {
            let mut direct = Recorder::default();
            let d = feed(&mut direct, n);
            let mut piped = Recorder::default();
            let p = on_own_thread(&mut piped, |pipe| feed(pipe, n));
            assert_eq!(d, p, "{n} rows");
            assert_eq!(direct.calls, piped.calls, "{n} rows");
        }
    }

    #[test]
    fn a_refused_begin_stops_at_once_and_a_stop_within_a_batch() {
        let mut piped = Recorder {
            refuse_begin: true,
            ..Recorder::default()
        };
        let (answers, ran) = on_own_thread(&mut piped, |pipe| feed(pipe, 100));
        assert_eq!((answers, ran), (vec![false], false));
        assert_eq!(piped.calls.len(), 1);
        // A stop asked at row 10: the reading side learns it at the next batch and the
        // sink gets no row after the tenth.
        let mut piped = Recorder {
            stop_after: Some(10),
            ..Recorder::default()
        };
        let (_, ran) = on_own_thread(&mut piped, |pipe| feed(pipe, 10 * BATCH));
        assert!(!ran);
        assert_eq!(piped.rows, 10);
    }
}
