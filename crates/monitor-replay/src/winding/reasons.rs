//! Why the winding judgement names no phase ([`PhaseNotJudged`]), and that a baseline ran at
//! another operating point (the least change widened for it, [`Widened`]): typed values,
//! spelled at the door (`monitor_words`).

use super::probability::{External, PhaseJudged};
use super::{
    abs, Against, OperatingPointSource, SequenceSegment, OPERATING_SPEED_STEP, SEGMENT_I1_STEP,
};
use monitor_core::Phase;
use serde::Serialize;

/// A change of `I2/I1` below this is no asymmetry to speak of (the noise of 12-bit sensors):
/// no reason is given for naming no phase.
pub const BALANCED_RATIO: f32 = 0.005;

/// Why no phase is named (JSON `unbalance.phase_not_judged_reason`, `{"kind": ..}`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PhaseNotJudged {
    /// No steady stretch of at least `windows` least-squares windows (`seconds`): the log
    /// is too short or its operating point never settled.
    NoSteadyStretch {
        /// The least windows a stretch holds.
        windows: usize,
        /// Their length [s].
        seconds: f64,
    },
    /// A short is the more probable, but no one phase is: the change points between two
    /// phases' centres and its angle is uncertain.
    BetweenPhases {
        /// The change (fraction of `|I1|`).
        change: f32,
        /// The judged stretch `[from, to]` [s].
        at_s: [f64; 2],
        /// The probability of a short.
        short: f32,
        /// The most probable phase, and its probability.
        phase: Phase,
        /// See `phase`.
        phase_probability: f32,
        /// How far the change points from that phase's centre [deg].
        deviation_deg: f32,
        /// The phase it leans towards.
        towards: Phase,
        /// The change's angle uncertainty [deg].
        angle_sd_deg: f32,
        /// The reference angle's uncertainty [deg], and where it comes from.
        reference_sd_deg: f32,
        /// See `reference_sd_deg`.
        reference: OperatingPointSource,
    },
    /// The change is within what a healthy machine's own asymmetry may reach, and there is
    /// no healthy baseline.
    NoBaseline {
        /// The change (fraction of `|I1|`).
        change: f32,
        /// The judged stretch `[from, to]` [s].
        at_s: [f64; 2],
        /// The least change that names a phase (`None`: none does with this spread).
        least: Option<f32>,
    },
    /// Within what stretches of one healthy log differ by.
    WithinTheLog {
        /// The change (fraction of `|I1|`).
        change: f32,
        /// The judged stretch `[from, to]` [s].
        at_s: [f64; 2],
        /// The stretch it was judged against `[from, to]` [s].
        reference_s: Option<[f64; 2]>,
        /// The least change that names a phase.
        least: Option<f32>,
    },
    /// Within what healthy runs (or the commissioning window) differ by.
    WithinHealthyRuns {
        /// The change (fraction of `|I1|`).
        change: f32,
        /// The judged stretch `[from, to]` [s].
        at_s: [f64; 2],
        /// The least change that names a phase.
        least: Option<f32>,
    },
}

/// Why the judged stretch names no phase; `None` when it names one, or when the change is
/// below [`BALANCED_RATIO`] (nothing to judge). `seg` is the judged stretch, `reference`
/// the stretch it was judged against within the log, `least` the least change that names a
/// phase (fraction of `|I1|`; `None`: none does).
pub(super) fn not_named(
    j: &PhaseJudged,
    seg: &SequenceSegment,
    reference: Option<&SequenceSegment>,
    least: Option<f32>,
) -> Option<PhaseNotJudged> {
    let p = j.posterior;
    if p.named().is_some() {
        return None;
    }
    let change = abs(j.change);
    let at_s = [seg.from_s, seg.to_s];
    let (phase, best) = p.most_probable();
    if p.short() > p.no_short && least.is_none_or(|l| change >= l) {
        // A short is the more probable, but no one phase is.
        return Some(PhaseNotJudged::BetweenPhases {
            change,
            at_s,
            short: p.short(),
            phase,
            phase_probability: best,
            deviation_deg: deviation_deg(j, phase),
            towards: neighbour(j, phase),
            angle_sd_deg: j.reading.model().angle_sd_rad.to_degrees(),
            reference_sd_deg: j.reading.op.1.to_degrees(),
            reference: j.reading.op.3,
        });
    }
    if change < BALANCED_RATIO {
        return None;
    }
    Some(match j.against {
        Against::Nothing | Against::ParameterFile => PhaseNotJudged::NoBaseline {
            change,
            at_s,
            least,
        },
        Against::WithinTheLog => PhaseNotJudged::WithinTheLog {
            change,
            at_s,
            reference_s: reference.map(|r| [r.from_s, r.to_s]),
            least,
        },
        Against::HealthyRuns | Against::Commissioning => PhaseNotJudged::WithinHealthyRuns {
            change,
            at_s,
            least,
        },
    })
}

/// How far the change's angle lies from `phase`'s sector centre [deg].
fn deviation_deg(j: &PhaseJudged, phase: Phase) -> f32 {
    let third = std::f32::consts::TAU / 3.0;
    let centre = j.reading.op.0 + phase.index() as f32 * third;
    let ang = j.change.im.atan2(j.change.re);
    monitor_core::frames::wrap_angle(ang - centre)
        .abs()
        .to_degrees()
}

/// The phase on the other side of `phase`'s sector border nearest the change.
fn neighbour(j: &PhaseJudged, phase: Phase) -> Phase {
    let third = std::f32::consts::TAU / 3.0;
    let centre = j.reading.op.0 + phase.index() as f32 * third;
    let ang = j.change.im.atan2(j.change.re);
    let side = monitor_core::frames::wrap_angle(ang - centre);
    Phase::from_turns(phase.index() as i32 + if side > 0.0 { 1 } else { -1 })
}

/// That the outside reference ran at another operating point than the judged stretch, and
/// the least change was widened for it (JSON `unbalance.least_change_widened_by`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Widened {
    /// What the reference is (`commissioning`, or `healthy_runs`: the baseline).
    pub reference: Against,
    /// `|I1|`'s relative change from the reference (the named short's own share taken out
    /// where `beyond_short`).
    pub i1_change: Option<f32>,
    /// A phase was named: `i1_change` is beyond the short's own share.
    pub beyond_short: bool,
    /// The shaft speed's change from the reference [rad/s, mechanical].
    pub speed_change_rad_s: Option<f32>,
    /// The least change at one operating point and as widened [%] (infinite: none).
    pub least_pct: [f32; 2],
}

/// That the outside reference `ext` ran at another operating point than the judged stretch
/// (`|I1|`, the named short's own share taken out, beyond [`SEGMENT_I1_STEP`], or the speed
/// beyond [`OPERATING_SPEED_STEP`]) and the least change was widened for it; `None` at the
/// same point. `pole_pairs` turns the electrical speed into the shaft's.
pub(super) fn widened(j: &PhaseJudged, ext: &External, pole_pairs: f32) -> Option<Widened> {
    let rd = &j.reading;
    let i1 = j.load_i1_change.filter(|d| d.is_finite());
    let speed = rd.wr.zip(ext.wr).map(|(a, b)| a - b);
    let i1_moved = i1.filter(|d| d.abs() > SEGMENT_I1_STEP);
    let speed_moved = speed.filter(|d| d.abs() > OPERATING_SPEED_STEP * rd.we);
    if i1_moved.is_none() && speed_moved.is_none() {
        return None;
    }
    let pct = |s: f32| j.least_change_at(s).map_or(f32::INFINITY, |l| 100.0 * l);
    Some(Widened {
        reference: ext.against,
        i1_change: i1,
        beyond_short: j.posterior.named().is_some(),
        speed_change_rad_s: speed.map(|d| d / pole_pairs),
        least_pct: [pct(j.sigma_same_point), pct(j.sigma)],
    })
}
