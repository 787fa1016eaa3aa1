//! The findings of the analyses that judge a report of their own: the winding's negative
//! sequence, the rotor's sidebands, the data quality and the sensors' impossible readings
//! (the lamps' and the operating point's are in [`super::findings`]).

use super::{Detail, FindingReport};
use crate::winding::{BaselineSource, UnbalanceReport};
use monitor_core::verdict::{Against, FaultName, FindingSource, NamedFault, Size, State};
use monitor_core::SensorFlags;
use monitor_io::log::quality::{DataQuality, MAX_NOT_JUDGED_FRACTION};

/// What the winding was judged against.
pub fn winding_against(u: &UnbalanceReport) -> Against {
    u.judged_against.unwrap_or(match u.baseline {
        Some(BaselineSource::File) => Against::HealthyRuns,
        Some(BaselineSource::Commissioning) => Against::Commissioning,
        None => Against::Nothing,
    })
}

/// The winding's finding from the negative-sequence report: shorted turns named with the
/// phase's calibrated probability where a phase is more probable than no short (a FAULT
/// from 0.5 on), or watched where a short in a phase is too probable to call the winding
/// clear ([`WINDING_WATCH_PROBABILITY`]); clear where no short is the more probable;
/// unavailable without a steady stretch.
pub(crate) fn winding_finding(u: &UnbalanceReport) -> FindingReport {
    let against = winding_against(u);
    let of = |state| FindingReport::new(FindingSource::Winding, state, against, Detail::Winding);
    let short = |phase, confidence| {
        State::Named(NamedFault {
            fault: FaultName::ShortedTurns,
            size: winding_size(u),
            phase: Some(phase),
            confidence,
        })
    };
    if let Some(p) = u.suspect_phase {
        return of(short(p, u.phase_confidence));
    }
    if u.judged_segment.is_none() {
        return of(State::Unavailable);
    }
    if let Some((p, prob)) = watched_phase(&u.phase_probabilities) {
        // Not named (no short is the most probable), but a short too probable to call the
        // winding clear: watched, never healthy.
        return of(short(p, prob));
    }
    of(State::Clear)
}

/// The winding finding's size: the shorted fraction of the phase's turns where one was
/// sized (`unbalance.shorted_turns`), else the change of the negative sequence.
fn winding_size(u: &UnbalanceReport) -> Size {
    u.shorted_turns
        .map_or(Size::OfPositiveSequence(u.winding_ratio), |t| {
            Size::TurnsFraction(t.fraction)
        })
}

/// The least probability of a short in one phase at which the winding is not clear
/// ([`winding_finding`]): a short in a phase at 1 in 5 is worth watching.
pub const WINDING_WATCH_PROBABILITY: f32 = 0.2;

/// The most probable shorted phase and its probability, where it has
/// [`WINDING_WATCH_PROBABILITY`] or more.
pub fn watched_phase(
    pp: &crate::winding::PhaseProbabilities,
) -> Option<(monitor_core::Phase, f32)> {
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
    let of =
        |state| FindingReport::new(FindingSource::Rotor, state, Against::Nothing, Detail::Rotor);
    let (Some(level), Some(band), true) = (r.level_db, r.band, r.judged) else {
        return of(State::Unavailable);
    };
    let below = -level as f32;
    match band {
        RotorBand::NoSign | RotorBand::Watch => of(State::Clear),
        _ => of(State::Named(NamedFault {
            fault: FaultName::BrokenBars,
            size: Size::DbBelowLine(below),
            phase: None,
            confidence: r.confidence.unwrap_or(0.0) as f32,
        })),
    }
}

/// The data-quality finding: what the stage does not trust, the stretches not judged, and
/// the sensors' readings no machine gives at the end (`sensors`, the core's flags).
pub(crate) fn data_quality_finding(q: &DataQuality, sensors: SensorFlags) -> FindingReport {
    let of = |state, detail| {
        FindingReport::new(FindingSource::DataQuality, state, Against::Nothing, detail)
    };
    if !q.trusted {
        return of(State::Unexplained, Detail::DataNotTrusted);
    }
    let unjudged: f64 = q.not_judged.iter().map(|n| n.to_s - n.from_s).sum();
    if unjudged > MAX_NOT_JUDGED_FRACTION * q.duration_s.max(f64::MIN_POSITIVE) {
        return of(
            State::Unexplained,
            Detail::DataNotJudged {
                unjudged_s: unjudged,
                duration_s: q.duration_s,
            },
        );
    }
    if let Some(s) = sensor_flag_finding(sensors) {
        return s;
    }
    of(State::Clear, Detail::DataClean)
}

/// The core's sensor flags at the end of a replay as a data-quality finding (readings no
/// machine gives: a sensor or its wiring, not the motor); `None` with no flag set.
pub(crate) fn sensor_flag_finding(s: SensorFlags) -> Option<FindingReport> {
    (s.current || s.voltage || s.speed).then(|| {
        FindingReport::new(
            FindingSource::DataQuality,
            State::Unexplained,
            Against::Nothing,
            Detail::ImpossibleReadings {
                current: s.current,
                voltage: s.voltage,
                speed: s.speed,
            },
        )
    })
}
