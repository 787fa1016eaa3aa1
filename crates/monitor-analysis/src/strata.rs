//! The log's strata: runs of samples of one kind (the start up to its settling, a supply or
//! speed transient, a load move, a steady stretch). The ladder's held-back split cuts each
//! into alternating windows (`explain::ladder`), and the leftover says how much of the
//! model's error each holds ([`crate::leftover`]).

use crate::prep::Prepared;
use crate::simplified_model::MachineConstants;
use crate::transients;
use serde::Serialize;

/// The kinds of stretch [`strata`] tells apart (JSON: `start`, `transient`, `load_move`,
/// `steady`, the names the ladder's split reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StratumKind {
    /// The start, from the first sample up to its settling.
    Start,
    /// A supply (voltage or frequency) or speed transient.
    Transient,
    /// A load move: the active current's mean moves.
    LoadMove,
    /// A steady stretch.
    Steady,
}

impl StratumKind {
    /// The name the ladder's `split` reports.
    pub fn name(self) -> &'static str {
        match self {
            StratumKind::Start => "start",
            StratumKind::Transient => "transient",
            StratumKind::LoadMove => "load_move",
            StratumKind::Steady => "steady",
        }
    }
}

/// A load move: the active current's 50 ms mean moves by more than this share of its
/// median magnitude within [`LOAD_LOOK_S`].
const LOAD_MOVE_MIN: f64 = 0.1;
/// How far back a load move is looked for [s] (and how long after it a stretch stays one).
const LOAD_LOOK_S: f64 = 0.3;

/// The samples of a log whose active current `iq` (sampled every `dt` s) is in a load move:
/// its 50 ms mean differs by more than [`LOAD_MOVE_MIN`] of its median magnitude over the log (at least 2 % of its peak) from the
/// mean [`LOAD_LOOK_S`] before (the look-back span is part of the move).
pub(crate) fn load_moves(iq: &[f64], dt: f64) -> Vec<bool> {
    let len = iq.len();
    let dt = dt.max(1e-9);
    let w = ((0.05 / dt).round() as usize).max(1);
    let look = ((LOAD_LOOK_S / dt).round() as usize).max(1);
    let mut cum = Vec::with_capacity(len + 1);
    cum.push(0.0);
    for &x in iq {
        let last = cum.last().copied().unwrap_or(0.0);
        cum.push(last + x);
    }
    let mean = |a: usize, b: usize| (cum[b] - cum[a]) / (b - a).max(1) as f64;
    // The scale: the median magnitude of the active current (a start's inrush, a few per
    // cent of a log, does not move it), at least 2 % of its peak (a log at no load).
    let mut mags: Vec<f64> = iq
        .iter()
        .map(|x| x.abs())
        .filter(|x| x.is_finite())
        .collect();
    // The median by selection (the value a sort puts in the middle, without the sort: a long
    // log's strata are cut for compare's leftover too).
    let peak = mags.iter().copied().fold(0.0f64, f64::max);
    let mid = mags.len() / 2;
    let median = if mags.is_empty() {
        0.0
    } else {
        *mags.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let range = median.max(0.02 * peak).max(1e-9);
    let mut moved = vec![false; len];
    for k in (w + look)..len {
        let now = mean(k + 1 - w, k + 1);
        let before = mean(k + 1 - w - look, k + 1 - look);
        if (now - before).abs() > LOAD_MOVE_MIN * range {
            for m in moved.iter_mut().take(k + 1).skip(k + 1 - look) {
                *m = true;
            }
        }
    }
    moved
}

/// Runs of equal kinds in `kinds`, as `(kind, first, end)` sample ranges.
pub(crate) fn runs(
    kinds: impl IntoIterator<Item = StratumKind>,
) -> Vec<(StratumKind, usize, usize)> {
    let mut out: Vec<(StratumKind, usize, usize)> = Vec::new();
    for (k, c) in kinds.into_iter().enumerate() {
        match out.last_mut() {
            Some((last, _, end)) if *last == c => *end = k + 1,
            _ => out.push((c, k, k + 1)),
        }
    }
    out
}

/// The log's strata: runs of samples of one kind (the start up to its settling, a supply or
/// speed transient, a load move, a steady stretch), as `(kind, first, end)` sample ranges.
pub(crate) fn strata(d: &Prepared, n: &MachineConstants) -> Vec<(StratumKind, usize, usize)> {
    let input = transients::input_transients(d, n);
    let start_until = transients::start_end_s(d).map(|te| te + transients::settling_s(n));
    let moved = load_moves(&d.iq, d.dt_s);
    runs((0..d.len()).map(|k| {
        if start_until.is_some_and(|u| d.t_s[k] <= u) {
            StratumKind::Start
        } else if input.get(k).copied().unwrap_or(false) {
            StratumKind::Transient
        } else if moved.get(k).copied().unwrap_or(false) {
            StratumKind::LoadMove
        } else {
            StratumKind::Steady
        }
    }))
}
