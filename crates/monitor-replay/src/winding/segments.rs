//! The steady stretches of the negative sequence (module docs of [`super`], step 1): the
//! least-squares windows grouped by a greedy pass that starts a new stretch where the
//! negative sequence, the zero sequence or `|I1|` steps, then a pass that joins
//! neighbouring pieces whose means agree (a fault current that wobbles, broken into
//! pieces by the first pass, is one stretch again).

use super::{
    abs, cdiv, Complex32, SequenceSegment, MAX_UNSTEADY_INSIDE, MIN_SEGMENT_WINDOWS,
    SEGMENT_I1_STEP, SEGMENT_STEP_MIN, SEGMENT_STEP_REL, SEGMENT_VOLTAGE_STEP_MIN,
};
use crate::windows::SequenceWindow;
use num_complex::Complex64;

/// A window's features that a segment holds still: `I2/I1`, `I0/I1` and, with voltages,
/// `V2/V1`, `V0/V1` (a sensor's gain step moves the zero sequences, a winding or the
/// supply the negative ones).
fn features(w: &SequenceWindow) -> [Complex32; 4] {
    let p = w.i.positive();
    let v = w.v.map_or([Complex32::new(0.0, 0.0); 2], |v| {
        let p = v.positive();
        [cdiv(v.negative(), p), cdiv(v.zero(), p)]
    });
    [cdiv(w.i.negative(), p), cdiv(w.i.zero(), p), v[0], v[1]]
}

/// Running sums of a segment's [`features`] and `|I1|`, so that each new window is judged
/// against the segment's means in constant time (a steady hour at 60 Hz is 21 600 windows:
/// recomputing the means for each window was quadratic).
#[derive(Default, Clone, Copy)]
struct SegmentSums {
    features: [Complex64; 4],
    i1: f32,
    n: u32,
}

impl SegmentSums {
    fn add(&mut self, w: &SequenceWindow) {
        for (s, f) in self.features.iter_mut().zip(features(w)) {
            *s += Complex64::new(f64::from(f.re), f64::from(f.im));
        }
        self.i1 += abs(w.i.positive());
        self.n += 1;
    }

    fn join(&mut self, o: &SegmentSums) {
        for (s, f) in self.features.iter_mut().zip(o.features) {
            *s += f;
        }
        self.i1 += o.i1;
        self.n += o.n;
    }

    fn of(w: &SequenceWindow) -> Self {
        let mut s = SegmentSums::default();
        s.add(w);
        s
    }

    /// The means: the features and `|I1|`.
    fn means(&self) -> ([Complex32; 4], f32) {
        let n = f64::from(self.n.max(1));
        (
            self.features
                .map(|s| Complex32::new((s.re / n) as f32, (s.im / n) as f32)),
            self.i1 / self.n.max(1) as f32,
        )
    }

    /// Whether features `f` with `|I1|` `i1` lie outside the segment. Each feature's
    /// tolerance is its floor or [`SEGMENT_STEP_REL`] of its mean's size; the current's
    /// zero sequence and `|I1|` also get that share of the negative sequence's size (a
    /// shorted loop's current moves all three: a fault current that wobbles moves them
    /// together).
    fn departs_at(&self, f: [Complex32; 4], i1: f32) -> bool {
        let (m, i1_mean) = self.means();
        let i2 = abs(m[0]);
        let moved = (0..4).any(|k| {
            let (fk, mk) = (f[k], m[k]);
            let (floor, scale) = match k {
                0 => (SEGMENT_STEP_MIN, i2),
                1 => (SEGMENT_STEP_MIN, abs(mk).max(i2)),
                _ => (SEGMENT_VOLTAGE_STEP_MIN, abs(mk)),
            };
            abs(fk - mk) > floor.max(SEGMENT_STEP_REL * scale)
        });
        let i1_tol = SEGMENT_I1_STEP.max(SEGMENT_STEP_REL * i2);
        moved || (i1 - i1_mean).abs() > i1_tol * i1_mean
    }

    /// Whether window `w` lies outside the segment.
    fn departs(&self, w: &SequenceWindow) -> bool {
        self.departs_at(features(w), abs(w.i.positive()))
    }
}

/// A run of windows the greedy pass kept together, and whether a run of unsteady windows
/// (a run-up, a ramp) separates it from the one before (then they never join).
struct Piece<'a> {
    ws: Vec<&'a SequenceWindow>,
    sums: SegmentSums,
    apart: bool,
}

/// Ends the piece `cur` (kept when it holds a window) and starts the next, `apart_next`
/// when unsteady running separates them.
fn close<'a>(cur: &mut Piece<'a>, pieces: &mut Vec<Piece<'a>>, apart_next: bool) {
    let next = Piece {
        ws: Vec::new(),
        sums: SegmentSums::default(),
        apart: apart_next,
    };
    let done = std::mem::replace(cur, next);
    if done.ws.is_empty() {
        cur.apart |= done.apart;
    } else {
        pieces.push(done);
    }
}

/// The steady segments of `windows` (module docs of [`super`], step 1). A step must hold
/// for two windows: one window out of line (a burst of noise) is left out of its segment,
/// two in a row start the next one. Neighbouring pieces whose means agree are then
/// joined ([`join_pieces`]); a segment counts from [`MIN_SEGMENT_WINDOWS`] windows on.
pub fn segments(windows: &[SequenceWindow]) -> Vec<SequenceSegment> {
    let mut pieces: Vec<Piece> = Vec::new();
    let mut cur = Piece {
        ws: Vec::new(),
        sums: SegmentSums::default(),
        apart: true,
    };
    let (mut pending, mut unsteady) = (None::<&SequenceWindow>, 0usize);
    for w in windows {
        if !w.steady {
            // One or two unsteady windows (a PLL disturbance, a burst of bad samples) are
            // left out of the segment; more end it (a run-up, a ramp).
            unsteady += 1;
            if unsteady > MAX_UNSTEADY_INSIDE {
                close(&mut cur, &mut pieces, true);
                pending = None;
            }
            continue;
        }
        unsteady = 0;
        if cur.ws.is_empty() || !cur.sums.departs(w) {
            pending = None;
            cur.ws.push(w);
            cur.sums.add(w);
            continue;
        }
        match pending.take() {
            None => pending = Some(w),
            Some(p) => {
                close(&mut cur, &mut pieces, false);
                // The first window after a step may straddle it: it starts the new segment
                // only when the second agrees with it.
                if !SegmentSums::of(p).departs(w) {
                    cur.ws.push(p);
                    cur.sums.add(p);
                }
                cur.ws.push(w);
                cur.sums.add(w);
            }
        }
    }
    close(&mut cur, &mut pieces, true);
    join_pieces(&mut pieces);
    pieces
        .iter()
        .filter(|p| p.ws.len() >= MIN_SEGMENT_WINDOWS)
        .map(|p| super::segment_of(&p.ws))
        .collect()
}

/// Joins neighbouring pieces (not kept apart by unsteady running) whose means agree: the
/// smaller piece's means within the larger's tolerances ([`SegmentSums::departs_at`]).
/// Repeated until nothing joins; pieces shorter than a segment join too, so that a
/// stretch the first pass cut into short pieces is not lost.
fn join_pieces(pieces: &mut Vec<Piece<'_>>) {
    loop {
        let mut joined = false;
        let mut k = 0;
        while k + 1 < pieces.len() {
            let agree = match (pieces.get(k), pieces.get(k + 1)) {
                (Some(a), Some(b)) if !b.apart => {
                    let (big, small) = if a.ws.len() >= b.ws.len() {
                        (a, b)
                    } else {
                        (b, a)
                    };
                    let (f, i1) = small.sums.means();
                    !big.sums.departs_at(f, i1)
                }
                _ => false,
            };
            if agree {
                let b = pieces.remove(k + 1);
                if let Some(a) = pieces.get_mut(k) {
                    a.ws.extend(b.ws);
                    a.sums.join(&b.sums);
                }
                joined = true;
            } else {
                k += 1;
            }
        }
        if !joined {
            break;
        }
    }
}
