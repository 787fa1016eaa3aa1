//! The winding judgement's sentences: why no phase is named, and that a baseline ran at
//! another operating point (the least change widened for it).

use super::probability::{External, PhaseJudged};
use super::{abs, Against, SequenceSegment, OPERATING_SPEED_STEP, SEGMENT_I1_STEP};
use monitor_core::Phase;

/// A change of `I2/I1` below this is no asymmetry to speak of (the noise of 12-bit sensors):
/// no reason is given for naming no phase.
pub const BALANCED_RATIO: f32 = 0.005;

/// Why the judged stretch names no phase, in a sentence; `None` when it names one, or when
/// the change is below [`BALANCED_RATIO`] (nothing to judge). `seg` is the judged stretch,
/// `reference` the stretch it was judged against within the log, `least` the least change
/// that names a phase (fraction of `|I1|`; `None`: none does), `words` the words its
/// advice names a field in.
pub(super) fn not_named(
    j: &PhaseJudged,
    seg: &SequenceSegment,
    reference: Option<&SequenceSegment>,
    least: Option<f32>,
    words: crate::words::Words,
) -> Option<String> {
    let p = j.posterior;
    if p.named().is_some() {
        return None;
    }
    let change = 100.0 * abs(j.change);
    let at = format!("{:.1}..{:.1} s", seg.from_s, seg.to_s);
    let (phase, best) = p.most_probable();
    if p.short() > p.no_short && least.is_none_or(|l| abs(j.change) >= l) {
        // A short is the more probable, but no one phase is.
        let dev = deviation_deg(j, phase);
        let u = j.reading.model().angle_sd_rad.to_degrees();
        return Some(format!(
            "cannot judge the phase: the change ({change:.1} % of I1 at {at}) is likely a short ({:.2}) but points {dev:.0} deg from phase {}'s centre (probability {best:.2}), towards phase {}, and its angle is uncertain by {u:.0} deg (reference angle +/-{:.0} deg, {}, and the shorted loop's own)",
            p.short(),
            phase.name(),
            neighbour(j, phase).name(),
            j.reading.op.1.to_degrees(),
            j.reading.op.3.describe()
        ));
    }
    if abs(j.change) < BALANCED_RATIO {
        return None;
    }
    let least = match least {
        Some(l) => format!("least change {:.1} %", 100.0 * l),
        None => "no change names a phase with this spread".to_string(),
    };
    Some(match j.against {
        Against::Nothing | Against::ParameterFile => format!(
            "cannot judge the phase: the negative sequence ({change:.1} % of I1 at {at}) is within what a healthy machine's own asymmetry may reach ({least}) and there is no healthy baseline (give {} with healthy logs of this motor, or commission)",
            words.hint(crate::words::OptionField::Baseline, "")
        ),
        Against::WithinTheLog => {
            let from = reference.map_or(String::new(), |r| {
                format!(" from the stretch at {:.1}..{:.1} s", r.from_s, r.to_s)
            });
            format!(
                "no phase: the negative sequence changed by {change:.1} % of I1 at {at}{from}, within what stretches of one healthy log differ by at their loads ({least}), and neither stands clear of a healthy machine's own asymmetry"
            )
        }
        Against::HealthyRuns | Against::Commissioning => format!(
            "no phase: the change of the negative sequence ({change:.1} % of I1 at {at}) is within what healthy runs differ by ({least})"
        ),
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

/// The sentence that the outside reference `ext` ran at another operating point than the
/// judged stretch (`|I1|`, the named short's own share taken out, beyond
/// [`SEGMENT_I1_STEP`], or the speed beyond [`OPERATING_SPEED_STEP`]) and the least change
/// was widened for it; `None` at the same point. `pole_pairs` turns the electrical speed
/// into the shaft's.
pub(super) fn widened(j: &PhaseJudged, ext: &External, pole_pairs: f32) -> Option<String> {
    let rd = &j.reading;
    let i1 = j.load_i1_change.filter(|d| d.is_finite());
    let speed = rd.wr.zip(ext.wr).map(|(a, b)| a - b);
    let i1_moved = i1.filter(|d| d.abs() > SEGMENT_I1_STEP);
    let speed_moved = speed.filter(|d| d.abs() > OPERATING_SPEED_STEP * rd.we);
    if i1_moved.is_none() && speed_moved.is_none() {
        return None;
    }
    let mut how = Vec::new();
    if let Some(d) = i1 {
        how.push(format!(
            "|I1| {:.0} % {}{}",
            100.0 * d.abs(),
            if d > 0.0 { "higher" } else { "lower" },
            if j.posterior.named().is_some() {
                " beyond the short's own share"
            } else {
                ""
            }
        ));
    }
    if let Some(d) = speed {
        how.push(format!(
            "speed {:.1} rad/s {}",
            d.abs() / pole_pairs,
            if d > 0.0 { "higher" } else { "lower" }
        ));
    }
    let what = match ext.against {
        Against::Commissioning => "the commissioning window",
        _ => "the baseline",
    };
    let pct = |s: f32| j.least_change_at(s).map_or(f32::INFINITY, |l| 100.0 * l);
    let (from, to) = (pct(j.sigma_same_point), pct(j.sigma));
    // Two decimals where one would not show the widening; none worth a word at two.
    let digits = if (to - from) < 0.05 { 2 } else { 1 };
    if (to - from).is_nan() || to - from < 0.005 {
        return Some(format!(
            "{what} ran at another operating point than the judged stretch ({}), which the least change {from:.digits$} % already covers",
            how.join(", "),
        ));
    }
    Some(format!(
        "{what} ran at another operating point than the judged stretch ({}): the least change widened from {from:.digits$} % to {to:.digits$} % (the negative sequence a healthy motor has moves with the load)",
        how.join(", "),
    ))
}
