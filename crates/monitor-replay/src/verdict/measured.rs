//! The findings of the analyses that judge a report of their own: the winding's negative
//! sequence, the rotor's sidebands, the data quality and the sensors' impossible readings
//! (the lamps' and the operating point's are in [`super::findings`]).

use super::FindingReport;
use crate::winding::{BaselineSource, UnbalanceReport};
use monitor_core::verdict::{Against, FaultName, FindingSource, NamedFault, Size, State};
use monitor_core::SensorFlags;
use monitor_io::log::quality::{DataQuality, MAX_NOT_JUDGED_FRACTION};

/// What the winding was judged against, and the brief phrase (`winding against 2 healthy
/// runs`).
fn winding_against(u: &UnbalanceReport) -> (Against, String) {
    let against = u.judged_against.unwrap_or(match u.baseline {
        Some(BaselineSource::File) => Against::HealthyRuns,
        Some(BaselineSource::Commissioning) => Against::Commissioning,
        None => Against::Nothing,
    });
    let brief = if u.baseline_runs > 0 && against == Against::HealthyRuns {
        format!(
            "winding against {} healthy run{}",
            u.baseline_runs,
            if u.baseline_runs == 1 { "" } else { "s" }
        )
    } else {
        format!(
            "winding {}",
            super::words::against_text(FindingSource::Winding, against)
        )
    };
    (against, brief)
}

/// The winding's finding from the negative-sequence report: shorted turns named with the
/// phase's calibrated probability where a phase is more probable than no short (a FAULT
/// from 0.5 on), clear where no short is the more probable, unavailable without a steady
/// stretch.
pub(crate) fn winding_finding(u: &UnbalanceReport) -> FindingReport {
    let (against, brief) = winding_against(u);
    let of = |state, summary: String| {
        FindingReport::new(
            FindingSource::Winding,
            state,
            against,
            summary,
            brief.clone(),
        )
    };
    let widened = u
        .least_change_widened
        .as_ref()
        .map_or(String::new(), |w| format!("; {w}"));
    let change = format!(
        "the negative sequence changed by {:.1} % of I1 (least change {:.1} %){widened}",
        100.0 * u.winding_ratio,
        100.0 * u.least_change
    );
    let short = |phase, confidence| {
        State::Named(NamedFault {
            fault: FaultName::ShortedTurns,
            size: winding_size(u),
            phase: Some(phase),
            confidence,
        })
    };
    if let Some(p) = u.suspect_phase {
        // With the level where one was sized: "shorted turns in phase c: about 30 % of the
        // phase's turns (22-38 %), from ...; the negative sequence changed by ...".
        let said = u.shorted_turns.map_or_else(
            || format!("shorted turns in phase {}: {change}", p.name()),
            |t| format!("{}; {change}", t.sentence()),
        );
        return of(short(p, u.phase_confidence), said);
    }
    if u.judged_segment.is_none() {
        return winding_unavailable(u, against);
    }
    let why = u
        .phase_not_judged
        .as_ref()
        .map_or(String::new(), |w| format!(" ({w})"));
    if let Some((p, prob)) = watched_phase(&u.phase_probabilities) {
        // Not named (no short is the most probable), but a short too probable to call the
        // winding clear: watched, never healthy.
        return of(
            short(p, prob),
            format!(
                "a short in phase {} is not ruled out (probability {prob:.2}, no short {:.2}): {change}{why}",
                p.name(),
                u.phase_probabilities.no_short
            ),
        );
    }
    of(State::Clear, format!("no shorted turns: {change}{why}"))
}

/// The winding finding's size: the shorted fraction of the phase's turns where one was
/// sized (`unbalance.shorted_turns`), else the change of the negative sequence.
fn winding_size(u: &UnbalanceReport) -> Size {
    u.shorted_turns
        .map_or(Size::OfPositiveSequence(u.winding_ratio), |t| {
            Size::TurnsFraction(t.fraction)
        })
}

/// The winding's finding where no steady stretch was judged: unavailable, with the reason.
fn winding_unavailable(u: &UnbalanceReport, against: Against) -> FindingReport {
    let why = u
        .phase_not_judged
        .clone()
        .unwrap_or_else(|| "no steady stretch".to_string());
    let brief = format!("winding: {why}");
    FindingReport::new(
        FindingSource::Winding,
        State::Unavailable,
        against,
        why,
        brief,
    )
}

/// The least probability of a short in one phase at which the winding is not clear
/// ([`winding_finding`]): a short in a phase at 1 in 5 is worth watching.
pub const WINDING_WATCH_PROBABILITY: f32 = 0.2;

/// The most probable shorted phase and its probability, where it has
/// [`WINDING_WATCH_PROBABILITY`] or more.
fn watched_phase(pp: &crate::winding::PhaseProbabilities) -> Option<(monitor_core::Phase, f32)> {
    use monitor_core::Phase;
    [(Phase::A, pp.a), (Phase::B, pp.b), (Phase::C, pp.c)]
        .into_iter()
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .filter(|(_, p)| *p >= WINDING_WATCH_PROBABILITY)
}

/// The rotor's finding from the current spectrum (MCSA): broken bars named from the band "a
/// cracked bar or a high-resistance joint likely" on (48 dB or less below the supply line,
/// `monitor_core::verdict::ROTOR_FAULT_DB`), with the spectrum's confidence; quieter
/// sidebands ("no sign", and the "watch" band, which practice trends rather than acts on)
/// are judged clear, with their level; a record the spectrum could not read is unavailable.
pub(crate) fn rotor_finding(r: &crate::rotor::RotorReport) -> FindingReport {
    use crate::rotor::RotorBand;
    let of = |state, summary: String, brief: String| {
        FindingReport::new(
            FindingSource::Rotor,
            state,
            Against::Nothing,
            summary,
            brief,
        )
    };
    let (Some(level), Some(band), true) = (r.level_db, r.band, r.judged) else {
        let why = r
            .cannot_judge_because
            .clone()
            .unwrap_or_else(|| "the sidebands were not read".to_string());
        return of(State::Unavailable, why.clone(), format!("rotor: {why}"));
    };
    let below = -level as f32;
    let brief = format!("rotor sidebands {below:.0} dB below the supply line");
    match band {
        RotorBand::NoSign | RotorBand::Watch => {
            let brief = if band == RotorBand::Watch {
                format!("{brief} (the watch band: trend it)")
            } else {
                brief
            };
            of(State::Clear, r.sentence.clone(), brief)
        }
        _ => {
            let named = NamedFault {
                fault: FaultName::BrokenBars,
                size: Size::DbBelowLine(below),
                phase: None,
                confidence: r.confidence.unwrap_or(0.0) as f32,
            };
            of(State::Named(named), r.sentence.clone(), brief)
        }
    }
}

/// The data-quality finding: what the stage does not trust, the stretches not judged, and
/// the sensors' readings no machine gives at the end (`sensors`, the core's flags).
pub(crate) fn data_quality_finding(q: &DataQuality, sensors: SensorFlags) -> FindingReport {
    let of = |state, summary: String| {
        FindingReport::new(
            FindingSource::DataQuality,
            state,
            Against::Nothing,
            summary,
            "data quality".to_string(),
        )
    };
    if !q.trusted {
        return of(
            State::Unexplained,
            format!("data quality: {}", q.not_trusted_because.join("; ")),
        );
    }
    let unjudged: f64 = q.not_judged.iter().map(|n| n.to_s - n.from_s).sum();
    if unjudged > MAX_NOT_JUDGED_FRACTION * q.duration_s.max(f64::MIN_POSITIVE) {
        return of(
            State::Unexplained,
            format!(
                "{unjudged:.2} s of the {:.2} s log could not be judged (over {:.0} %): {}",
                q.duration_s,
                100.0 * MAX_NOT_JUDGED_FRACTION,
                q.not_judged
                    .iter()
                    .map(|n| format!("{:.2}..{:.2} s, {}", n.from_s, n.to_s, n.why))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        );
    }
    if let Some(s) = sensor_flag_finding(sensors) {
        return s;
    }
    of(State::Clear, format!("data quality: {}", q.summary()))
}

/// The core's sensor flags at the end of a replay as a data-quality finding (readings no
/// machine gives: a sensor or its wiring, not the motor); `None` with no flag set.
pub(crate) fn sensor_flag_finding(s: SensorFlags) -> Option<FindingReport> {
    let which: Vec<&str> = [
        (s.current, "current"),
        (s.voltage, "voltage"),
        (s.speed, "speed (encoder)"),
    ]
    .into_iter()
    .filter_map(|(on, w)| on.then_some(w))
    .collect();
    (!which.is_empty()).then(|| {
        FindingReport::new(
            FindingSource::DataQuality,
            State::Unexplained,
            Against::Nothing,
            format!(
                "the {} sensor readings at the end of the log are impossible for any machine (not a number, saturated, phases not summing to zero, or an encoder jump): check the sensors and their wiring; the motor cannot be judged from them",
                which.join(" and ")
            ),
            "data quality".to_string(),
        )
    })
}
