//! The winding stage ([`WindingStage`]): per row it books the least-squares windows the
//! sequence stage closed, with what the monitor adds to them (whether commissioning was
//! learning over the whole window, the monitor's speed where it closed: [`WindowBook`]);
//! at the end it judges them ([`super::judgement`]) into the [`UnbalanceReport`].

use super::judgement::unbalance_report;
use super::level::TurnLevelOptions;
use super::{HealthyReference, UnbalanceReport};
use crate::options::ReplayOptions;
use crate::stage::{Finish, Stage};
use crate::windows::{SequenceWindow, WindowRow};
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use std::collections::VecDeque;

/// The least-squares windows with what the monitor adds to them: whether the commissioning
/// window's learning covered every sample, and the monitor's speed where the window closed.
#[derive(Debug, Clone, Default)]
pub(crate) struct WindowBook {
    /// The open window's samples were all offered while learning.
    learning: bool,
    /// Windows closed by the front, not yet booked.
    queue: VecDeque<Option<SequenceWindow>>,
    windows: Vec<SequenceWindow>,
}

impl WindowBook {
    /// An empty book.
    pub fn new() -> Self {
        WindowBook {
            learning: true,
            ..WindowBook::default()
        }
    }

    /// Queues one window the front closed (the other thread's end of [`WindowBook::take`]).
    pub fn queue(&mut self, w: Option<SequenceWindow>) {
        self.queue.push_back(w);
    }

    /// Books one row's step: `learning` whether the monitor was learning its commissioning
    /// window, `wr_rad_s` its electrical speed, both at the row before (where the log has a
    /// speed).
    #[inline]
    pub fn row(&mut self, r: WindowRow) {
        if r.closed_before {
            self.close(r.wr_rad_s);
        }
        self.learning &= r.learning;
        if r.closed_after {
            self.close(r.wr_rad_s);
        }
    }

    /// Ends the open window (the front closed it).
    pub fn close(&mut self, wr_rad_s: Option<f32>) {
        if let Some(mut w) = self.queue.pop_front().flatten() {
            w.learning = self.learning;
            w.wr_rad_s = wr_rad_s;
            self.windows.push(w);
        }
        self.learning = true;
    }

    /// The least-squares windows so far (the open one left out).
    pub fn windows(&self) -> &[SequenceWindow] {
        &self.windows
    }
}

/// The winding stage: the windows booked, and what they are judged with (configured once).
#[derive(Debug, Clone)]
pub(crate) struct WindingStage {
    book: WindowBook,
    params: ParamFile,
    /// The log has a speed for the monitor (the windows carry it).
    speed: bool,
    baseline: Option<HealthyReference>,
    level: TurnLevelOptions,
}

/// What the chain hands the winding at the end: whether the sequence stage closed its last
/// window at the end, with the monitor's speed then, and the windows it closed and did not
/// hand on yet.
pub(crate) struct WindingClosing {
    /// The windows closed and not yet handed on, in order.
    pub(crate) closed: Vec<Option<SequenceWindow>>,
    /// `Some(speed)` where the last window was closed at the end (the monitor's electrical
    /// speed then [rad/s], where the log has one).
    pub(crate) closed_last: Option<Option<f32>>,
}

impl WindingStage {
    /// The stage for `params`' machine (`speed`: the log has a speed for the monitor), as
    /// `opts` ask: judged against their healthy baseline where given, the level with their
    /// turn level.
    pub(crate) fn new(params: &ParamFile, speed: bool, opts: &ReplayOptions) -> Self {
        WindingStage {
            book: WindowBook::new(),
            params: *params,
            speed,
            baseline: opts.unbalance_baseline,
            level: opts.turn_level,
        }
    }

    /// Queues the windows the sequence stage closed, before the step of the row they closed
    /// at.
    #[inline]
    pub(crate) fn queue(&mut self, windows: impl Iterator<Item = Option<SequenceWindow>>) {
        for w in windows {
            self.book.queue(w);
        }
    }
}

impl Stage for WindingStage {
    type Input<'a> = WindowRow;
    type Output = ();

    #[inline]
    fn update(&mut self, _row: &Row, r: WindowRow) {
        self.book.row(r);
    }
}

impl Finish for WindingStage {
    type Closing<'a> = WindingClosing;
    type Finding = UnbalanceReport;

    fn finish(mut self, c: WindingClosing) -> UnbalanceReport {
        self.queue(c.closed.into_iter());
        if let Some(wr) = c.closed_last {
            self.book.close(wr);
        }
        unbalance_report(
            self.book.windows(),
            &self.params,
            self.speed,
            self.baseline,
            self.level,
        )
    }
}
