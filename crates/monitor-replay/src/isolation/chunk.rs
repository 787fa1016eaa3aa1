//! The rows the isolation's per-row work is done on at once ([`RowChunk`]): consecutive rows
//! with the same flags from the monitor's output, at most the core's block of
//! `decimation` samples (2.5 ms at 10 kHz).
//!
//! The isolation's operating point is the sequence analysis' positive-sequence vectors
//! through 2 Hz critically damped filters: over a core block they move by a few per cent
//! of a step at most, so the follower ([`monitor_core::isolation::Follower`]: its 0.1 s
//! blocks, its band of steadiness) and the load history behind the events' dates (its
//! 20 ms blocks) are given the block's mean point once, with the block's length, rather
//! than each row's point. The monitor's output changes once per core block (its slow
//! path), so the flags the isolation reads ([`RowFlags`]) are constant over a chunk; a
//! change ends the chunk early. What moves: a restart of the follower's average (a point
//! outside its band) is seen at the end of the chunk that left it, up to a block later,
//! and its 0.1 s blocks close on chunk ends.

use crate::stage::RowFlags;
use monitor_core::SteadyPoint;

/// Rows summed for the isolation (module docs).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct RowChunk {
    /// The sum of the rows' points.
    sum: SteadyPoint,
    /// Rows summed.
    rows: u32,
    /// The time of the first and of the last row [s].
    first_t: f64,
    last_t: f64,
    /// The rows' time steps summed [s].
    span_s: f64,
    /// The rows' flags (the same for every row of a chunk).
    flags: RowFlags,
}

/// A closed chunk: its mean point, first and last time [s], length [s] and flags.
#[derive(Debug, Clone, Copy)]
pub(super) struct Closed {
    pub(super) point: SteadyPoint,
    pub(super) first_t: f64,
    pub(super) last_t: f64,
    pub(super) span_s: f64,
    pub(super) flags: RowFlags,
}

impl RowChunk {
    /// Whether the row with `flags` belongs to another chunk than the rows summed.
    #[inline]
    pub(super) fn ends_before(&self, flags: RowFlags) -> bool {
        self.rows > 0 && self.flags != flags
    }

    /// Adds the row at `t` [s], `dt_s` after the previous one, with point `p` and `flags`;
    /// returns the number of rows summed.
    #[inline]
    pub(super) fn add(&mut self, t: f64, dt_s: f64, p: &SteadyPoint, flags: RowFlags) -> u32 {
        if self.rows == 0 {
            self.first_t = t;
            self.flags = flags;
        }
        self.sum.add_scaled(p, 1.0);
        self.rows += 1;
        self.last_t = t;
        self.span_s += dt_s;
        self.rows
    }

    /// The rows' time steps summed [s].
    #[inline]
    pub(super) fn span_s(&self) -> f64 {
        self.span_s
    }

    /// Ends the chunk: what it summed (`None` when empty), and an empty chunk.
    pub(super) fn close(&mut self) -> Option<Closed> {
        if self.rows == 0 {
            return None;
        }
        let mut point = self.sum;
        point.scale(1.0 / self.rows as f32);
        let closed = Closed {
            point,
            first_t: self.first_t,
            last_t: self.last_t,
            span_s: self.span_s,
            flags: self.flags,
        };
        *self = RowChunk::default();
        Some(closed)
    }
}
