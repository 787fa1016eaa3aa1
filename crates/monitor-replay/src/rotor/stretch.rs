//! The steady stretch the rotor is judged on: the record cut into chunks of [`CHUNK_S`],
//! each with its mean slip (where the log has a speed) and its mean current magnitude,
//! and the longest run of chunks whose slip (or, without a speed, whose current) stays
//! within the steadiness tolerance of the run's mean; never across a gap.

use super::baseband::Block;
use super::{LOAD_STEADY, MIN_SLIP, SLIP_STEADY};
use std::ops::Range;

/// Chunk length [s]: the slip's steadiness is judged on means over this long (a 2 s f
/// ripple of a broken bar or a load's ripple averages out in part, a load move does not).
pub const CHUNK_S: f64 = 0.2;

/// One chunk of the record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Chunk {
    /// Its blocks.
    pub first: usize,
    /// See `first` (one past the last).
    pub end: usize,
    /// The first chunk after a gap (or the record's first).
    pub after_gap: bool,
    /// Mean slip `1 - Np wm / w_supply`; NaN where a block has no speed.
    pub slip: f64,
    /// Mean |I| of the demodulated current [A, peak].
    pub load: f64,
}

/// The record's chunks (`block_s` a block's length [s], `np` the pole pairs): about
/// [`CHUNK_S`] long, never across a time jump of more than 1.5 blocks.
pub(super) fn chunks(blocks: &[Block], block_s: f64, np: f64) -> Vec<Chunk> {
    let per_chunk = ((CHUNK_S / block_s).round() as usize).max(1);
    let mut out = Vec::new();
    let mut first = 0;
    let mut after_gap = true;
    for k in 1..=blocks.len() {
        let gap = blocks
            .get(k)
            .zip(blocks.get(k.wrapping_sub(1)))
            .is_some_and(|(b, a)| b.t_s - a.t_s > 1.5 * block_s);
        if k - first == per_chunk || gap || k == blocks.len() {
            if k - first == per_chunk {
                out.push(chunk_of(blocks, first..k, after_gap, np));
                after_gap = false;
            }
            first = k;
        }
        if gap {
            after_gap = true;
        }
    }
    out
}

/// The chunk of `blocks[r]`.
fn chunk_of(blocks: &[Block], r: Range<usize>, after_gap: bool, np: f64) -> Chunk {
    let n = r.len().max(1) as f64;
    let seg = blocks.get(r.clone()).unwrap_or(&[]);
    let slip = seg
        .iter()
        .map(|b| 1.0 - np * f64::from(b.wm) / f64::from(b.w_supply))
        .sum::<f64>()
        / n;
    let load = seg
        .iter()
        .map(|b| f64::from(b.z[0]).hypot(f64::from(b.z[1])))
        .sum::<f64>()
        / n;
    Chunk {
        first: r.start,
        end: r.end,
        after_gap,
        slip,
        load,
    }
}

/// Whether chunk value `v` belongs to a run of mean `mean`: the slip within
/// [`SLIP_STEADY`] of the run's (at least of [`MIN_SLIP`]), the current within
/// [`LOAD_STEADY`] of it.
fn steady(v: f64, mean: f64, by_slip: bool) -> bool {
    let tol = if by_slip {
        SLIP_STEADY * mean.abs().max(MIN_SLIP)
    } else {
        LOAD_STEADY * mean.abs()
    };
    v.is_finite() && (v - mean).abs() <= tol
}

/// The longest run of steady chunks (the latest of equally long ones), by the slip where
/// `by_slip`, else by the current; `None` when no chunk has a finite value.
pub(super) fn longest_run(chunks: &[Chunk], by_slip: bool) -> Option<Range<usize>> {
    let value = |c: &Chunk| if by_slip { c.slip } else { c.load };
    let mut best: Option<Range<usize>> = None;
    let mut keep = |r: Range<usize>| {
        if !r.is_empty() && best.as_ref().is_none_or(|b| r.len() >= b.len()) {
            best = Some(r);
        }
    };
    let mut start = 0;
    let mut sum = 0.0;
    for (k, c) in chunks.iter().enumerate() {
        let v = value(c);
        let joins = k > start && !c.after_gap && steady(v, sum / (k - start) as f64, by_slip);
        if joins {
            sum += v;
            continue;
        }
        if k > start {
            keep(start..k);
        }
        // A chunk without a value starts no run.
        start = if v.is_finite() { k } else { k + 1 };
        sum = if v.is_finite() { v } else { 0.0 };
    }
    if chunks.len() > start {
        keep(start..chunks.len());
    }
    best
}
