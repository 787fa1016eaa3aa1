//! A reference at another operating point than the stretch judged against it (module docs
//! of [`super`], step 3): what the load moves of the reference's negative sequence.
//!
//! Without voltages a reference's `I2/I1 = R` is part the supply's unbalance, whose `I2`
//! stays while `I1` moves with the load, and part the machine's own asymmetry, which
//! moves with `I1` and keeps its ratio; the split is not known. At a stretch whose healthy
//! current is `I1_h` the reference reads `R_s (I1_R/I1_h) e^{jd} + (R - R_s)`, `d` the
//! model's turn of `arg Z1` between the two points where it knows them: somewhere on the
//! segment from `R` (all the machine's) to `R q e^{jd}` (all the supply's),
//! `q = |I1_R|/|I1_h|`. The density is the mean over [`SPLITS`] points of that segment,
//! each with the spread at one operating point and [`MOVE_MODEL_ERROR`] of the segment's
//! length for the model. With voltages the supply's part is out; what moves is the
//! model's error on it ([`SUPPLY_PART_UNCERTAINTY`]), in any direction.
//!
//! Under a short the loop itself draws `|1 + r|` of `I1` (Tallam; `|r|` from the reading,
//! `|(M - R)/(a^k - M)|`, its angle the reference angle): the healthy current at the
//! stretch is `I1/|1 + r|`, and only the rest of the change of `I1` is the load's. That
//! rest is evidence too: the load stayed (the rest within [`SAME_LOAD_CURRENT_SD`]) or it
//! moved (anywhere within a factor of [`LOAD_MOVE_RANGE`]), each as likely as the other
//! ([`Anchor::ln_current`]). So a stretch whose `|I1|` rose with its negative sequence
//! carries the short, not the one it is judged against.

use super::reading::PhaseReading;
use super::{abs, cdiv, Complex32};
use monitor_core::sequence::SUPPLY_PART_UNCERTAINTY;
use monitor_core::Phase;

/// Points along the segment of possible splits between the supply's part and the
/// machine's own.
pub const SPLITS: usize = 9;
/// Relative error of the model's account of the move (the turn `d` and the ratio `q`
/// near no load, where `arg Z1` turns fast with the load).
pub const MOVE_MODEL_ERROR: f32 = 0.3;

/// Spread of `ln |I1|` between two stretches at one load: the supply's voltage and the
/// shorted loop's share of the current beyond Tallam's (on the real recordings the loop
/// raises `|I1|` by up to 5 % more than `|1 + r|` at the reference angle).
pub const SAME_LOAD_CURRENT_SD: f32 = 0.03;
/// A load that moved changes `|I1|` by up to this factor either way.
pub const LOAD_MOVE_RANGE: f32 = 2.0;

/// The model's `arg Z1` at a stretch's operating point when it draws `|I1|` = the given
/// current [A, peak] (what a healthy machine would draw there), where known.
pub(super) type AngleAt<'a> = &'a dyn Fn(&PhaseReading, f32) -> Option<f32>;

/// What a stretch's change is taken from.
#[derive(Debug, Clone, Copy)]
pub(super) struct Anchor {
    /// The reference's reading (its winding part with voltages).
    pub w: Complex32,
    /// The supply's part taken out of it (0 without voltages).
    pub supply: f32,
    /// Both the reference and the stretch have voltages.
    pub voltages: bool,
    /// Its `|I1|` [A, peak].
    pub i1: f32,
    /// The model's `arg Z1` at its operating point, where known.
    pub z1: Option<f32>,
}

impl Anchor {
    /// `(I1_R/I1_h) e^{jd}` at stretch `rd` under no short (`None`) or a short in a phase
    /// (module docs).
    fn turn(&self, rd: &PhaseReading, short: Option<Phase>, angle_at: AngleAt<'_>) -> Complex32 {
        let q = self.current_ratio(rd, short);
        let i1_h = self.i1 / q;
        let d = match (self.z1, angle_at(rd, i1_h)) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        Complex32::new(q * d.cos(), q * d.sin())
    }

    /// `ln` of the density of the change of `|I1|` that the short does not draw:
    /// `e = ln(I1_h/I1_R)`, the load stayed or moved (module docs).
    fn ln_current(&self, rd: &PhaseReading, short: Option<Phase>) -> f32 {
        let e = -self.current_ratio(rd, short).ln();
        if !e.is_finite() {
            return 0.0;
        }
        let sd = SAME_LOAD_CURRENT_SD;
        let stayed = (-(e * e) / (2.0 * sd * sd)).exp() / ((std::f32::consts::TAU).sqrt() * sd);
        let moved = if e.abs() <= LOAD_MOVE_RANGE.ln() {
            0.5 / LOAD_MOVE_RANGE.ln()
        } else {
            0.0
        };
        (0.5 * stayed + 0.5 * moved).max(1e-30).ln()
    }

    /// `I1_R/I1_h`: the reference's current over the healthy current at the stretch.
    pub fn current_ratio(&self, rd: &PhaseReading, short: Option<Phase>) -> f32 {
        // The loop's size from the reading, its angle the reference's: a hypothesis whose
        // phase does not fit the reading does not get a loop that turns I1 to fit.
        let loop_share = short.map_or(1.0, |p| {
            let turn = std::f32::consts::TAU / 3.0 * p.index() as f32;
            let r = abs(cdiv(
                rd.w - self.w,
                Complex32::new(turn.cos(), turn.sin()) - rd.w,
            ));
            let g = (1.0 + 2.0 * r * rd.op.0.cos() + r * r).sqrt();
            if g.is_finite() && g > 0.0 {
                g
            } else {
                1.0
            }
        });
        let i1_h = rd.i1 / loop_share;
        if i1_h > 0.0 && self.i1 > 0.0 {
            self.i1 / i1_h
        } else {
            1.0
        }
    }

    /// How far another operating point may move the reference (the length of the
    /// segment without voltages, the model's error on the supply's part with them).
    fn moved(&self, t: Complex32) -> f32 {
        let k = abs(Complex32::new(1.0 - t.re, -t.im));
        if self.voltages {
            SUPPLY_PART_UNCERTAINTY * self.supply * k
        } else {
            abs(self.w) * k
        }
    }

    /// The spread of `rd`'s change from this reference (`same`: at one operating point)
    /// with the move taken as a spread in any direction: the least change's and the
    /// sentence's.
    pub fn spread(
        &self,
        rd: &PhaseReading,
        same: f32,
        short: Option<Phase>,
        angle_at: AngleAt<'_>,
    ) -> f32 {
        same.hypot(self.moved(self.turn(rd, short, angle_at)))
    }

    /// `ln` of the density of `rd`'s reading under a hypothesis (`short`), given `f(R', s)`,
    /// its `ln` density about a reference `R'` with spread `s` at one operating point:
    /// averaged over where the reference may have moved, times the density of the change
    /// of `|I1|` the short does not draw (module docs).
    pub fn ln_density(
        &self,
        rd: &PhaseReading,
        same: f32,
        short: Option<Phase>,
        angle_at: AngleAt<'_>,
        f: &dyn Fn(Complex32, f32) -> f32,
    ) -> f32 {
        let t = self.turn(rd, short, angle_at);
        let current = self.ln_current(rd, short);
        if self.voltages {
            return current + f(self.w, same.hypot(self.moved(t)));
        }
        let w = self.w;
        let seg = w * t - w;
        let s = same.hypot(MOVE_MODEL_ERROR * abs(seg));
        let terms: [f32; SPLITS] = std::array::from_fn(|k| {
            let l = k as f32 / (SPLITS - 1) as f32;
            f(w + seg * l, s)
        });
        let m = terms.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        if !m.is_finite() {
            return m;
        }
        current + m + (terms.iter().map(|x| (x - m).exp()).sum::<f32>() / SPLITS as f32).ln()
    }
}
