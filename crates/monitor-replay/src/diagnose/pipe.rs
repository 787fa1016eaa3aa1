//! The replay on a thread of its own: the reading thread runs the data-quality stage, the
//! glitch and clock handling before the replay ([`super::front::ReplaySink`]) and the
//! sequence analysis' filters ([`SequenceFront`], which need nothing but the rows); it
//! hands the rows with their sequence steps, in batches over a bounded channel, to the
//! monitor, the isolation and the bookkeeping on another thread ([`Replay::push_step`]).
//! The two run side by side on two cores (the parsing workers fill in the rest;
//! docs/performance.md, "diagnose of a 1 h log").
//!
//! The replay sees the same rows in the same order, with the same steps, as without the
//! thread ([`Replay::push`] runs the same two halves one after the other): the results are
//! the same, bit for bit. The replay's configuration at the time base is answered
//! synchronously (a configuration the core rejects stops the read at once, as without the
//! thread).

use super::front::Feeder;
use crate::error::ReplayError;
use crate::options::ReplayOptions;
use crate::replay::Replay;
use crate::sequences::{SequenceFront, SequenceStep};
use crate::windows::SequenceWindow;
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};

/// The replay's answer to [`Call::Begin`]: its sequence analysis, lent to the reading
/// thread (`None`: the replay could not be configured).
type Lent = Option<Box<SequenceFront>>;

/// Rows per batch (about 140 bytes each with its step).
const BATCH: usize = 4096;
/// Batches on their way at most (the reading thread waits beyond: bounded memory).
const IN_FLIGHT: usize = 4;

/// One call to the replay's thread other than a row.
enum Call {
    /// Configure the replay at this sample rate [Hz] (answered).
    Begin(f64),
    /// A window the sequence analysis closed ([`Replay::queue_window`]).
    Window(Option<SequenceWindow>),
    /// The acquisition clock was reset before the next row ([`Replay::clock_reset`]).
    ClockReset,
    /// Forget everything: the rows come again.
    Restart,
    /// The read is over: the sequence analysis as it ended ([`Replay::set_sequence_front`]).
    End(Box<SequenceFront>),
}

/// A batch of calls: the rows with their sequence steps side by side, and the other calls,
/// each after the rows of the batch before it (their number). Sent full, received in that
/// order, sent back empty (the memory reused).
struct Batch {
    rows: Vec<Row>,
    steps: Vec<SequenceStep>,
    calls: Vec<(usize, Call)>,
}

impl Batch {
    fn with_capacity(n: usize) -> Self {
        Batch {
            rows: Vec::with_capacity(n),
            steps: Vec::with_capacity(n),
            calls: Vec::new(),
        }
    }
}

/// The reading thread's end: a [`Feeder`] that runs the sequence analysis and batches the
/// calls (given to the read by [`on_own_thread`]).
pub(super) struct Pipe {
    tx: SyncSender<Batch>,
    /// Emptied batches coming back (their memory reused).
    back: Receiver<Batch>,
    /// The answer to [`Call::Begin`].
    began: Receiver<Lent>,
    batch: Batch,
    front: Option<SequenceFront>,
    /// The first row's time (the replay's time 0) [s].
    t0: Option<f64>,
    /// The other end is gone.
    closed: bool,
}

impl Pipe {
    /// Sends the batch.
    fn flush(&mut self) {
        if (self.batch.rows.is_empty() && self.batch.calls.is_empty()) || self.closed {
            return;
        }
        let next = self
            .back
            .try_recv()
            .unwrap_or_else(|_| Batch::with_capacity(BATCH));
        let full = std::mem::replace(&mut self.batch, next);
        self.closed = self.tx.send(full).is_err();
    }

    /// A call after the rows pushed so far.
    fn push(&mut self, c: Call) {
        self.batch.calls.push((self.batch.rows.len(), c));
    }

    /// The read is over: the sequence analysis goes to the replay, and every call is sent.
    fn end(&mut self) {
        if let Some(f) = self.front.take() {
            self.push(Call::End(Box::new(f)));
        }
        self.flush();
    }
}

impl Feeder for Pipe {
    fn begin(&mut self, rate_hz: f64) -> bool {
        // (The replay's thread answers with the sequence analysis it built, to run here; a
        // rate the replay refuses is no answer.)
        self.t0 = None;
        self.push(Call::Begin(rate_hz));
        self.flush();
        self.front = None;
        if !self.closed {
            self.front = self.began.recv().ok().flatten().map(|f| *f);
        }
        self.front.is_some()
    }

    fn row(&mut self, row: &Row) {
        let Some(front) = self.front.as_mut() else {
            return;
        };
        let t = row.t_s - *self.t0.get_or_insert(row.t_s);
        let step = front.track(row, t);
        while let Some(w) = self.front.as_mut().and_then(SequenceFront::take_closed) {
            self.push(Call::Window(w));
        }
        self.batch.rows.push(*row);
        self.batch.steps.push(step);
        if self.batch.rows.len() >= BATCH {
            self.flush();
        }
    }

    fn rows(&mut self, rows: &[Row]) {
        let mut rest = rows;
        while !rest.is_empty() {
            let Some(front) = self.front.as_mut() else {
                return;
            };
            let room = BATCH.saturating_sub(self.batch.rows.len()).max(1);
            let (now, later) = rest.split_at(room.min(rest.len()));
            let t0 = *self.t0.get_or_insert(now[0].t_s);
            let b = &mut self.batch;
            let before = b.rows.len();
            for (k, row) in now.iter().enumerate() {
                let step = front.track(row, row.t_s - t0);
                // (A window closed before the row: a call after the rows before it.)
                while let Some(w) = front.take_closed() {
                    b.calls.push((before + k, Call::Window(w)));
                }
                b.steps.push(step);
                // (Row by row: the copy of a whole block is a byte loop to the profilers.)
                b.rows.push(*row);
            }
            if self.batch.rows.len() >= BATCH {
                self.flush();
            }
            rest = later;
        }
    }

    fn clock_reset(&mut self) {
        self.push(Call::ClockReset);
    }

    fn restart(&mut self) {
        self.front = None;
        self.t0 = None;
        self.push(Call::Restart);
    }
}

/// The replay's thread's end: the replay, configured at [`Call::Begin`].
struct Back<'a> {
    params: &'a ParamFile,
    channels: Channels,
    opts: ReplayOptions,
    replay: Option<Replay>,
    error: Option<ReplayError>,
}

impl Back<'_> {
    /// One call; `began` gets the answer to [`Call::Begin`].
    fn call(&mut self, c: Call, began: &Sender<Lent>) {
        match c {
            Call::Begin(rate) => {
                match Replay::new(self.params, self.channels, rate, self.opts) {
                    Ok(r) => self.replay = Some(r),
                    Err(e) => self.error = Some(e),
                }
                // (The reading thread waits for this answer: the sequence analysis to run.)
                let lent = self.replay.as_mut().and_then(Replay::lend_sequence_front);
                let _ = began.send(lent.map(Box::new));
            }
            Call::Restart => {
                self.replay = None;
                self.error = None;
            }
            c => {
                let Some(r) = self.replay.as_mut() else {
                    return;
                };
                match c {
                    Call::Window(w) => r.queue_window(w),
                    Call::ClockReset => r.clock_reset(),
                    Call::End(front) => r.set_sequence_front(*front),
                    Call::Begin(_) | Call::Restart => {}
                }
            }
        }
    }

    /// Rows with their steps, in order.
    fn rows(&mut self, rows: &[Row], steps: &[SequenceStep]) {
        if let Some(r) = self.replay.as_mut() {
            for (row, step) in rows.iter().zip(steps) {
                r.push_step(row, step);
            }
        }
    }
}

/// Receives every batch and hands it to `back` in order (each call after the rows before
/// it), returning the emptied batches.
fn receive(back: &mut Back<'_>, rx: Receiver<Batch>, empty: Sender<Batch>, began: Sender<Lent>) {
    for mut batch in rx {
        let mut from = 0;
        for (at, c) in batch.calls.drain(..) {
            let to = at.clamp(from, batch.rows.len());
            back.rows(
                batch.rows.get(from..to).unwrap_or_default(),
                batch.steps.get(from..to).unwrap_or_default(),
            );
            from = to;
            back.call(c, &began);
        }
        back.rows(
            batch.rows.get(from..).unwrap_or_default(),
            batch.steps.get(from..).unwrap_or_default(),
        );
        batch.rows.clear();
        batch.steps.clear();
        // (The reading thread may be gone already.)
        let _ = empty.send(batch);
    }
}

/// Runs `read` on this thread with a [`Pipe`] whose rows reach a replay of a log of
/// `params`' machine with `channels` on a thread of its own (module docs); returns `read`'s
/// result once the replay has had every row, and the replay (`None` when it was never
/// configured) or the error configuring it.
pub(super) fn on_own_thread<R>(
    params: &ParamFile,
    channels: Channels,
    opts: ReplayOptions,
    read: impl FnOnce(&mut Pipe) -> R,
) -> (R, Result<Option<Replay>, ReplayError>) {
    let (tx, rx) = sync_channel(IN_FLIGHT);
    let (empty_tx, empty_rx) = channel();
    let (began_tx, began_rx) = channel();
    let mut back = Back {
        params,
        channels,
        opts,
        replay: None,
        error: None,
    };
    let r = std::thread::scope(|s| {
        let b = &mut back;
        s.spawn(move || receive(b, rx, empty_tx, began_tx));
        let mut pipe = Pipe {
            tx,
            back: empty_rx,
            began: began_rx,
            batch: Batch::with_capacity(BATCH),
            front: None,
            t0: None,
            closed: false,
        };
        let r = read(&mut pipe);
        pipe.end();
        // (Dropping the pipe closes the channel: the thread ends after the last batch,
        // and the scope waits for it.)
        drop(pipe);
        r
    });
    let replay = match back.error {
        Some(e) => Err(e),
        None => Ok(back.replay),
    };
    (r, replay)
}
