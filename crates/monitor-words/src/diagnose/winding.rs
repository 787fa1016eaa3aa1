//! The winding in words: the negative-sequence finding, why no phase is named, a baseline
//! at another operating point, the shorted-turn level.

use monitor_core::verdict::{Against, FindingSource};
use monitor_core::Phase;
use monitor_replay::{
    LevelBasis, OperatingPointSource, PhaseNotJudged, ShortedTurns, TurnReach, UnbalanceReport,
    Widened, WINDING_FAULT_PROBABILITY,
};

use crate::spelling::Spelling;
use monitor_replay::OptionField;

/// Where a reference angle comes from, in words.
pub fn operating_point_source(op: OperatingPointSource) -> &'static str {
    match op {
        OperatingPointSource::Voltages => "measured from the voltages",
        OperatingPointSource::Speed => "the model's at the measured speed",
        OperatingPointSource::CurrentMagnitude => "the model's at the current's magnitude",
        OperatingPointSource::AssumedRange => {
            "unknown operating point: no load to full load (the current's magnitude does not fit the parameter file)"
        }
    }
}

/// What a winding judgement's reference is, in words, for the text report.
pub fn describe_against(a: Against) -> &'static str {
    match a {
        Against::Commissioning => "against the commissioning window",
        Against::HealthyRuns => "against the healthy runs",
        Against::WithinTheLog => "against another stretch of the log",
        Against::ParameterFile | Against::Nothing => "with no healthy baseline",
    }
}

/// `shorted turns in phase c: about 30 % of the phase's turns (22-38 %), from the model (no
/// labels)`.
pub fn shorted_turns(t: &ShortedTurns) -> String {
    let by = match t.basis {
        LevelBasis::Physics => "from the model (no labels)",
        LevelBasis::Calibration => "from the calibration of labelled runs",
    };
    format!(
        "shorted turns in phase {}: about {:.0} % of the phase's turns ({:.0}-{:.0} %), {by}",
        t.phase.name(),
        100.0 * t.fraction,
        100.0 * t.low,
        100.0 * t.high
    )
}

/// The least change that names a phase, in words.
fn least_text(least: Option<f32>) -> String {
    match least {
        Some(l) => format!("least change {:.1} %", 100.0 * l),
        None => "no change names a phase with this spread".to_string(),
    }
}

/// A judged stretch `[from, to]` [s]: `2.0..4.5 s`.
fn at_text(at: [f64; 2]) -> String {
    format!("{:.1}..{:.1} s", at[0], at[1])
}

/// Why no phase is named (JSON `unbalance.phase_not_judged`).
pub fn phase_not_judged(w: &PhaseNotJudged, sp: &dyn Spelling) -> String {
    let head = match w {
        PhaseNotJudged::NoSteadyStretch { .. } => "cannot judge the phase",
        PhaseNotJudged::BetweenPhases { .. } => "which phase is uncertain",
        _ => "no phase",
    };
    format!("{head}: {}", reason_body(w, sp))
}

/// Why no phase is named, without its head (`no phase: `): the change, where it was read,
/// and what it is within.
fn reason_body(w: &PhaseNotJudged, sp: &dyn Spelling) -> String {
    match *w {
        PhaseNotJudged::NoSteadyStretch { windows, seconds } => format!(
            "no steady stretch of at least {windows} least-squares windows ({seconds:.2} s): the log is too short or its operating point never settled"
        ),
        PhaseNotJudged::BetweenPhases {
            change,
            at_s,
            short,
            phase,
            phase_probability,
            deviation_deg,
            towards,
            angle_sd_deg,
            reference_sd_deg,
            reference,
        } => format!(
            "the change ({:.1} % of I1 at {}) is likely a short ({short:.2}) but points {deviation_deg:.0} deg from phase {}'s centre (probability {phase_probability:.2}), towards phase {}, and its angle is uncertain by {angle_sd_deg:.0} deg (reference angle +/-{reference_sd_deg:.0} deg, {}, and the shorted loop's own)",
            100.0 * change,
            at_text(at_s),
            phase.name(),
            towards.name(),
            operating_point_source(reference)
        ),
        PhaseNotJudged::NoBaseline { change, at_s, least } => format!(
            "the negative sequence ({:.1} % of I1 at {}) is within what a healthy machine's own asymmetry may reach ({}) and there is no healthy baseline (give {} with healthy logs of this motor, or commission, to see smaller shorts)",
            100.0 * change,
            at_text(at_s),
            least_text(least),
            sp.hint(OptionField::Baseline, "")
        ),
        PhaseNotJudged::WithinTheLog {
            change,
            at_s,
            reference_s,
            least,
        } => format!(
            "the negative sequence changed by {:.1} % of I1 at {}{}, within what stretches of one healthy log differ by at their loads ({}), and neither stands clear of a healthy machine's own asymmetry",
            100.0 * change,
            at_text(at_s),
            reference_s.map_or(String::new(), |r| format!(
                " from the stretch at {:.1}..{:.1} s",
                r[0], r[1]
            )),
            least_text(least)
        ),
        PhaseNotJudged::WithinHealthyRuns { change, at_s, least } => format!(
            "the change of the negative sequence ({:.1} % of I1 at {}) is within what healthy runs differ by ({})",
            100.0 * change,
            at_text(at_s),
            least_text(least)
        ),
    }
}

/// That the reference ran at another operating point, and the least change widened for it
/// (JSON `unbalance.least_change_widened`).
pub fn widened(w: &Widened) -> String {
    let mut how = Vec::new();
    if let Some(d) = w.i1_change {
        how.push(format!(
            "|I1| {:.0} % {}{}",
            100.0 * d.abs(),
            if d > 0.0 { "higher" } else { "lower" },
            if w.beyond_short {
                " beyond the short's own share"
            } else {
                ""
            }
        ));
    }
    if let Some(d) = w.speed_change_rad_s {
        how.push(format!(
            "speed {:.1} rad/s {}",
            d.abs(),
            if d > 0.0 { "higher" } else { "lower" }
        ));
    }
    let what = match w.reference {
        Against::Commissioning => "the commissioning window",
        _ => "the baseline",
    };
    let [from, to] = w.least_pct;
    // Two decimals where one would not show the widening; none worth a word at two.
    let digits = if (to - from) < 0.05 { 2 } else { 1 };
    if (to - from).is_nan() || to - from < 0.005 {
        return format!(
            "{what} ran at another operating point than the judged stretch ({}), which the least change {from:.digits$} % already covers",
            how.join(", "),
        );
    }
    format!(
        "{what} ran at another operating point than the judged stretch ({}): the least change widened from {from:.digits$} % to {to:.digits$} % (the negative sequence a healthy motor has moves with the load)",
        how.join(", "),
    )
}

/// The share of the turns a short a crew would act on holds: a reach above it says the log
/// cannot show such a short.
pub const CREW_SHORT: f32 = 0.1;

/// How large a short the log could hide, in a crew's units: `no short of more than 35 % of
/// the turns (a 10 % short would be below what this log shows)`.
pub fn reach(r: &TurnReach) -> String {
    let by = match r.basis {
        LevelBasis::Physics => "",
        LevelBasis::Calibration => ", by the calibration of labelled runs",
    };
    let below = if r.high > CREW_SHORT {
        format!(
            "; a {:.0} % short would be below what this log shows",
            100.0 * CREW_SHORT
        )
    } else {
        String::new()
    };
    format!(
        "no short of more than {:.0} % of the turns{by}{below}",
        (100.0 * r.high).ceil()
    )
}

/// A negative-sequence ratio `|I2|/|I1|` as a measurement (`12.50 %`), or, above 100 %,
/// why it is none: the negative sequence is the larger, so the currents turn backwards
/// against the sequence judged (two channels exchanged, the data-quality finding says
/// which), which no unbalance of a running motor makes.
pub fn sequence_ratio(ratio: f32) -> String {
    if ratio.is_finite() && ratio <= 1.0 {
        format!("{:.2} %", 100.0 * ratio)
    } else {
        "not measured (the negative sequence exceeds the positive: the phase order is reversed, wiring, not an unbalance)".to_string()
    }
}

/// The suspect phase as the unbalance line gives it: `c (probability 0.72)`, `c, watched
/// (probability 0.39, below the 0.50 a FAULT needs)`, or `none`.
pub fn suspect(u: &UnbalanceReport) -> String {
    if let Some(p) = u.suspect_phase {
        return if u.phase_confidence >= WINDING_FAULT_PROBABILITY {
            format!("{} (probability {:.2})", p.name(), u.phase_confidence)
        } else {
            format!(
                "{}, watched (probability {:.2}, below the {WINDING_FAULT_PROBABILITY:.2} a FAULT needs)",
                p.name(),
                u.phase_confidence
            )
        };
    }
    match watched(u) {
        Some((p, prob)) => format!(
            "{}, watched (probability {prob:.2}, below the {WINDING_FAULT_PROBABILITY:.2} a FAULT needs; no short {:.2})",
            p.name(),
            u.phase_probabilities.no_short
        ),
        None => "none".to_string(),
    }
}

/// What the winding was judged against, as the verdict's lists say it (`winding against 2
/// healthy runs`).
pub fn brief(u: &UnbalanceReport, against: Against, sp: &dyn Spelling) -> String {
    if u.judged_segment.is_none() {
        return format!("winding: {}", unavailable(u, sp));
    }
    let judged = if u.baseline_runs > 0 && against == Against::HealthyRuns {
        format!(
            "winding against {} healthy run{}",
            u.baseline_runs,
            if u.baseline_runs == 1 { "" } else { "s" }
        )
    } else {
        format!(
            "winding {}",
            super::named::against_text(FindingSource::Winding, against)
        )
    };
    match u.shorted_turns_reach.filter(|_| watched(u).is_none()) {
        Some(r) => format!("{judged} ({})", reach(&r)),
        None => judged,
    }
}

/// Why the winding could not be judged at all.
fn unavailable(u: &UnbalanceReport, sp: &dyn Spelling) -> String {
    u.phase_not_judged.as_ref().map_or_else(
        || "no steady stretch".to_string(),
        |w| phase_not_judged(w, sp),
    )
}

/// The winding finding's sentence from the negative-sequence report: the phase named with
/// its level, a short not ruled out, no shorted turns, or why nothing was judged.
pub fn summary(u: &UnbalanceReport, sp: &dyn Spelling) -> String {
    if u.judged_segment.is_none() && u.suspect_phase.is_none() {
        return unavailable(u, sp);
    }
    let widened = u
        .least_change_widened
        .as_ref()
        .map_or(String::new(), |w| format!("; {}", widened(w)));
    let change = format!(
        "the negative sequence changed by {:.1} % of I1 (least change {:.1} %){widened}",
        100.0 * u.winding_ratio,
        100.0 * u.least_change
    );
    if let Some(p) = u.suspect_phase {
        return u.shorted_turns.map_or_else(
            || format!("shorted turns in phase {}: {change}", p.name()),
            |t| format!("{}; {change}", shorted_turns(&t)),
        );
    }
    let why = u
        .phase_not_judged
        .as_ref()
        .map_or(String::new(), |w| format!(" ({})", phase_not_judged(w, sp)));
    if let Some((p, prob)) = watched(u) {
        return format!(
            "a short in phase {} is not ruled out (probability {prob:.2}, below the {WINDING_FAULT_PROBABILITY:.2} a FAULT needs; no short {:.2}): {change}{why}",
            p.name(),
            u.phase_probabilities.no_short
        );
    }
    // Clear: the reach, then why no phase is named (the change and the least change that
    // would name one), each said once.
    let said = match &u.phase_not_judged {
        Some(w) => format!("{}{widened}", reason_body(w, sp)),
        None => change,
    };
    match &u.shorted_turns_reach {
        Some(r) => format!("{}: {said}", reach(r)),
        None => format!("no shorted turns seen: {said}"),
    }
}

/// The phase the winding finding watches, where a short there is too probable to call the
/// winding clear.
fn watched(u: &UnbalanceReport) -> Option<(Phase, f32)> {
    monitor_replay::watched_phase(&u.phase_probabilities)
}

/// The winding's line of the text report (after `winding: `): a named phase with what it
/// was judged against and its reference angle, else the winding finding's sentence; `None`
/// where nothing was judged and nothing is to say.
pub fn line(u: &UnbalanceReport, sp: &dyn Spelling) -> Option<String> {
    let Some(p) = u.suspect_phase else {
        return (u.judged_segment.is_some() || u.phase_not_judged.is_some())
            .then(|| summary(u, sp));
    };
    let against = match (u.judged_against, u.baseline_runs) {
        (Some(Against::HealthyRuns), 1) => "against 1 healthy run".to_string(),
        (Some(Against::HealthyRuns), n) => format!(
            "against the mean of {n} healthy runs (their spread {:.1} %)",
            100.0 * u.baseline_spread.unwrap_or(0.0)
        ),
        (Some(Against::WithinTheLog), _) => u
            .reference_segment
            .and_then(|k| u.segments.get(k))
            .map_or(describe_against(Against::WithinTheLog).to_string(), |r| {
                format!(
                    "against the stretch at {:.1}..{:.1} s of the log",
                    r.from_s, r.to_s
                )
            }),
        (Some(a), _) => describe_against(a).to_string(),
        (None, _) => "with no healthy baseline".to_string(),
    };
    let reference = u.operating_point.map(|o| {
        format!(
            "reference angle {:.0} +/- {:.0} deg, {}",
            u.correction_deg,
            u.correction_uncertainty_deg,
            operating_point_source(o)
        )
    });
    Some(format!(
        "shorted turns in phase {} (probability {:.2}): the negative sequence changed by {:.1} % of I1 {against}, least change {:.1} %; {}",
        p.name(),
        u.phase_confidence,
        100.0 * u.winding_ratio,
        100.0 * u.least_change,
        reference.unwrap_or_default()
    ))
}
