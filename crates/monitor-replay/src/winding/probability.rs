//! The probability of shorted turns in each phase for one log (module docs of [`super`],
//! steps 3 and 4): each stretch's reading against a healthy reference from outside the
//! log ([`judge_external`]), against another stretch of the log ([`judge_within`]), or
//! against nothing ([`judge_alone`]); the stretch that changed most decides.
//!
//! Within the log the two stretches `i` (the reference, the one that looks most healthy)
//! and `j` (the one that changed most from it) are judged together. Hypotheses, with their
//! priors: nothing shorted (1/2); a short in phase k in `j` only, in `i` only, or in both
//! (1/18 each). `I2/I1` of a healthy stretch is a healthy machine's own asymmetry (spread
//! [`NO_BASELINE_SPREAD`]); the change between the stretches scatters by
//! [`WITHIN_LOG_SPREAD`] each, their own standard errors, and what the load moves. A short
//! in both stretches reads as a short against nothing in `i`, and the change between them
//! is none, or its size grew or shrank. The probability of phase k sums its three
//! hypotheses.

use super::anchor::{Anchor, AngleAt};
pub(super) use super::reading::PhaseReading;
use super::{abs, pooled_change_sigma, Against, Complex32};
use monitor_core::sequence::{ln_no_short, ln_short, phase_posterior, PhasePosterior};
use monitor_core::Phase;

/// A healthy reference from outside the log: the `--baseline` runs or the commissioning
/// window.
#[derive(Debug, Clone, Copy)]
pub(super) struct External {
    /// Its `|I1|` [A, peak].
    pub i1: f32,
    /// Its electrical rotor speed [rad/s], where known.
    pub wr: Option<f32>,
    /// The model's `arg Z1` at its operating point, where known.
    pub z1_angle: Option<f32>,
    /// How many healthy runs it is the mean of (1 for the commissioning window).
    pub runs: u32,
    /// `sum |h_i - mean|^2` of their readings (0 for one).
    pub sum_sq_dev: f32,
    /// Which it is.
    pub against: Against,
}

/// What the reference's own negative sequence at a stretch's operating point is: its
/// winding part and the supply's part taken out of it.
pub(super) type ReferencePart<'a> = &'a dyn Fn(&PhaseReading) -> (Complex32, f32);

/// A stretch judged.
#[derive(Debug, Clone, Copy)]
pub(super) struct PhaseJudged {
    /// The stretch judged (the one that changed most).
    pub index: usize,
    /// The stretch it was judged against, within the log.
    pub reference: Option<usize>,
    /// Its change from the reference (fraction of `|I1|`).
    pub change: Complex32,
    /// The supply's part taken out of the stretch's reading.
    pub supply_ratio: f32,
    /// The change's spread (each component), and before the widening for another
    /// operating point.
    pub sigma: f32,
    /// See `sigma`.
    pub sigma_same_point: f32,
    /// The probabilities.
    pub posterior: PhasePosterior,
    /// What it was judged against.
    pub against: Against,
    /// The stretch's reading (its reference angle).
    pub reading: PhaseReading,
    /// Against an outside reference: how much the load changed `|I1|` from it (relative),
    /// the named short's own share taken out.
    pub load_i1_change: Option<f32>,
}

/// The posterior of `rd` against `anchor` (spread `same` at one operating point), each
/// hypothesis with its own account of another operating point ([`Anchor::ln_density`]);
/// with the spread under no short ([`Anchor::spread`]).
fn posterior_against(
    rd: &PhaseReading,
    anchor: &Anchor,
    same: f32,
    angle_at: AngleAt<'_>,
) -> (PhasePosterior, f32) {
    let model = rd.model();
    let none = anchor.ln_density(rd, same, None, angle_at, &|r, s| ln_no_short(rd.w, r, s));
    let ln_k = Phase::ALL.map(|p| {
        anchor.ln_density(rd, same, Some(p), angle_at, &|r, s| {
            ln_short(rd.w, r, p, &model, s)
        })
    });
    (
        PhasePosterior::from_ln(none, ln_k),
        anchor.spread(rd, same, None, angle_at),
    )
}

/// Every stretch against an outside reference; the one whose change stands out most from
/// its spread at one operating point is judged.
pub(super) fn judge_external(
    readings: &[PhaseReading],
    ext: &External,
    part: ReferencePart<'_>,
    angle_at: AngleAt<'_>,
) -> Option<PhaseJudged> {
    let (rd, anchor, same, _) = readings
        .iter()
        .map(|rd| {
            let (w_ref, supply_ref) = part(rd);
            let anchor = Anchor {
                w: w_ref,
                supply: supply_ref,
                voltages: rd.voltages,
                i1: ext.i1,
                z1: ext.z1_angle,
            };
            let change = pooled_change_sigma(rd.run_sigma(), ext.runs, ext.sum_sq_dev);
            let same = change.hypot(rd.sem);
            (rd, anchor, same, abs(rd.w - w_ref) / same.max(1e-6))
        })
        .max_by(|a, b| a.3.total_cmp(&b.3))?;
    let (posterior, sigma) = posterior_against(rd, &anchor, same, angle_at);
    let q = anchor.current_ratio(rd, posterior.named().map(|n| n.0));
    Some(PhaseJudged {
        load_i1_change: Some(1.0 / q - 1.0),
        index: rd.index,
        reference: None,
        change: (rd.w - anchor.w),
        supply_ratio: rd.supply,
        sigma,
        sigma_same_point: same,
        posterior,
        against: ext.against,
        reading: *rd,
    })
}

/// One stretch against nothing: `R = 0`, a healthy machine's own asymmetry the spread.
pub(super) fn judge_alone(rd: &PhaseReading) -> PhaseJudged {
    let sigma = rd.alone_sigma();
    PhaseJudged {
        index: rd.index,
        reference: None,
        change: rd.w,
        supply_ratio: rd.supply,
        sigma,
        sigma_same_point: sigma,
        posterior: phase_posterior(rd.w, Complex32::new(0.0, 0.0), sigma, &rd.model()),
        against: Against::Nothing,
        reading: *rd,
        load_i1_change: None,
    }
}

/// The spread of the change between two stretches of one log at one operating point.
fn pair_same(i: &PhaseReading, j: &PhaseReading) -> f32 {
    let w = i.within_sigma().max(j.within_sigma());
    (2.0 * w * w + i.sem * i.sem + j.sem * j.sem).sqrt()
}

/// Stretch `r` as the reference of another.
fn anchor_of(r: &PhaseReading, other: &PhaseReading) -> Anchor {
    Anchor {
        w: r.w,
        supply: r.supply,
        voltages: r.voltages && other.voltages,
        i1: r.i1,
        z1: r.z1_angle,
    }
}

/// The log's stretches against each other (module docs): `None` for fewer than two.
pub(super) fn judge_within(
    readings: &[PhaseReading],
    angle_at: AngleAt<'_>,
) -> Option<PhaseJudged> {
    let i = readings
        .iter()
        .min_by(|a, b| abs(a.w).total_cmp(&abs(b.w)))?;
    let j = readings
        .iter()
        .filter(|r| r.index != i.index)
        .max_by(|a, b| {
            let z = |x: &PhaseReading| abs(x.w - i.w) / pair_same(i, x).max(1e-6);
            z(a).total_cmp(&z(b))
        })?;
    Some(Pair::judge(i, j, pair_same(i, j), angle_at).judged())
}

/// The two stretches' hypotheses (module docs), as `ln` of prior times likelihood.
struct Pair<'a> {
    i: &'a PhaseReading,
    j: &'a PhaseReading,
    /// The spread of the change at one operating point, and under no short.
    same_point: f32,
    /// See `same_point`.
    sw: f32,
    none: f32,
    /// Per phase: the short in `j` only, in `i` only, in both.
    short: [[f32; 3]; 3],
}

/// `ln(e^a + e^b + ...)`.
fn ln_sum(xs: &[f32]) -> f32 {
    let m = xs.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    if !m.is_finite() {
        return m;
    }
    m + xs.iter().map(|x| (x - m).exp()).sum::<f32>().ln()
}

impl<'a> Pair<'a> {
    /// The hypotheses of stretch `j` against stretch `i`, their change scattering by
    /// `same_point` at one operating point.
    fn judge(
        i: &'a PhaseReading,
        j: &'a PhaseReading,
        same_point: f32,
        angle_at: AngleAt<'_>,
    ) -> Self {
        let zero = Complex32::new(0.0, 0.0);
        let (hi, hj) = (i.alone_sigma(), j.alone_sigma());
        let healthy_i = ln_no_short(i.w, zero, hi);
        let healthy_j = ln_no_short(j.w, zero, hj);
        let (from_i, from_j) = (anchor_of(i, j), anchor_of(j, i));
        let sw = from_i.spread(j, same_point, None, angle_at);
        let same = from_i.ln_density(j, same_point, None, angle_at, &|r, s| {
            ln_no_short(j.w, r, s)
        });
        let prior = (1.0f32 / 18.0).ln();
        let (mi, mj) = (i.model(), j.model());
        let short = Phase::ALL.map(|p| {
            let in_j = from_i.ln_density(j, same_point, Some(p), angle_at, &|r, s| {
                ln_short(j.w, r, p, &mj, s)
            });
            let in_i = from_j.ln_density(i, same_point, Some(p), angle_at, &|r, s| {
                ln_short(i.w, r, p, &mi, s)
            });
            let both = ln_short(i.w, zero, p, &mi, hi)
                + ln_sum(&[0.5f32.ln() + same, 0.25f32.ln() + in_j, 0.25f32.ln() + in_i]);
            [
                prior + healthy_i + in_j,
                prior + healthy_j + in_i,
                prior + both,
            ]
        });
        Pair {
            i,
            j,
            same_point,
            sw,
            none: 0.5f32.ln() + healthy_i + same,
            short,
        }
    }

    /// The judgement: the probabilities, and the stretch and change the named phase
    /// rests on (the short in `j`, in `i`, or in both: then `i` against nothing).
    fn judged(&self) -> PhaseJudged {
        let posterior = PhasePosterior::normalised(self.none, self.short.map(|s| ln_sum(&s)));
        // The hypothesis the named phase rests on; with none named, the change between
        // the two stretches.
        let which = posterior.named().map_or(0, |(phase, _)| {
            self.short.get(phase.index()).map_or(0, |s| {
                (0..3).fold(0, |b, k| if s[k] > s[b] { k } else { b })
            })
        });
        let (i, j) = (self.i, self.j);
        let (index, reference, change, sigma, against) = match which {
            0 => (
                j,
                Some(i.index),
                (j.w - i.w),
                self.sw,
                Against::WithinTheLog,
            ),
            1 => (
                i,
                Some(j.index),
                (i.w - j.w),
                self.sw,
                Against::WithinTheLog,
            ),
            _ => (i, None, i.w, i.alone_sigma(), Against::Nothing),
        };
        PhaseJudged {
            index: index.index,
            reference,
            change,
            supply_ratio: index.supply,
            sigma,
            sigma_same_point: if which == 2 { sigma } else { self.same_point },
            posterior,
            against,
            reading: *index,
            load_i1_change: None,
        }
    }
}

impl PhaseJudged {
    /// The least change that names a phase at [`super::WINDING_FAULT_PROBABILITY`] with the
    /// spread `sigma` at the judged stretch's reference angle (`None` when none does).
    pub(super) fn least_change_at(&self, sigma: f32) -> Option<f32> {
        monitor_core::sequence::least_change(
            sigma,
            &self.reading.model(),
            super::WINDING_FAULT_PROBABILITY,
        )
    }
}
