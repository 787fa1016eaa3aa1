//! A named fault in words: its size, its phase, what it was judged against, and why it is
//! watched rather than a FAULT. The verdict's line and the findings' sentences both say a
//! fault this way.

use monitor_core::isolation::{MIN_FAULT_CHANGE, NOMINAL_UNCERTAINTY};
use monitor_core::verdict::{
    Against, FaultName, FindingSource, NamedFault, Size, FAULT_CONFIDENCE,
};

/// A relative change as the reports print it: `+50 %`, to a tenth of a per cent under 10 %.
pub fn pct(x: f32) -> String {
    let digits = usize::from(x.abs() < 0.095);
    format!("{:+.digits$} %", 100.0 * x)
}

/// The fault of `n` with its size and phase: `rs +50 %`, `current_sensor +20 % (phase b)`,
/// `shorted turns in phase c: the negative sequence changed by 12.5 % of I1`, `broken rotor
/// bars: the (1 - 2s) f sideband 41.0 dB below the supply line`.
pub fn fault_text(n: &NamedFault) -> String {
    let phase = n.phase.map(|p| p.name());
    match (n.fault, n.size) {
        (FaultName::ShortedTurns, size) => {
            let what = match size {
                Size::TurnsFraction(x) => format!("about {:.0} % of the phase's turns", 100.0 * x),
                Size::OfPositiveSequence(x) => {
                    format!("the negative sequence changed by {:.1} % of I1", 100.0 * x)
                }
                other => size_text(other),
            };
            match phase {
                Some(p) => format!("shorted turns in phase {p}: {what}"),
                None => format!("shorted turns: {what}"),
            }
        }
        (FaultName::BrokenBars, size) => {
            let band = match size {
                Size::DbBelowLine(db) => format!(
                    " ({})",
                    super::rotor::band_words(monitor_replay::band_of(-f64::from(db)))
                ),
                _ => String::new(),
            };
            format!("broken rotor bars: {}{band}", size_text(size))
        }
        (FaultName::Friction, size) => format!("b/bl {}", size_text(size)),
        (FaultName::Table1(f), size) => {
            let p = phase.map_or(String::new(), |p| format!(" (phase {p})"));
            format!("{} {}{p}", f.name(), size_text(size))
        }
    }
}

/// A size in words.
fn size_text(size: Size) -> String {
    match size {
        Size::Relative(x) => pct(x),
        Size::OfPositiveSequence(x) => format!("{:.1} % of I1", 100.0 * x),
        Size::TurnsFraction(x) => format!("{:.0} % of the turns", 100.0 * x),
        Size::DbBelowLine(db) => {
            format!("the (1 - 2s) f sideband {db:.1} dB below the supply line")
        }
    }
}

/// What a finding of `source` was judged against, in words.
pub fn against_text(source: FindingSource, a: Against) -> &'static str {
    match (a, source) {
        (Against::Commissioning, _) => "against commissioning",
        (Against::HealthyRuns, _) => "against healthy runs",
        (Against::WithinTheLog, FindingSource::Winding) => {
            "against the log's own stretches and a healthy machine's asymmetry"
        }
        (Against::WithinTheLog, _) => "against the log's own stretches",
        (Against::ParameterFile, _) => "against the parameter file",
        (Against::Nothing, FindingSource::Winding) => "against a healthy machine's own asymmetry",
        (Against::Nothing, FindingSource::Rotor) => "against the MCSA severity bands",
        (Against::Nothing, _) => "against physics alone",
    }
}

/// Why a name is watched rather than a FAULT (`confidence 0.39, below the 0.60 a FAULT
/// needs`): the verdict line's words, which `diagnose --report`'s banner says too.
pub fn why_watched(n: &NamedFault, against: Against) -> String {
    // (A confidence that is not a number is below it.)
    if n.confidence
        .partial_cmp(&FAULT_CONFIDENCE)
        .is_none_or(|o| o.is_lt())
    {
        return format!(
            "confidence {:.2}, below the {FAULT_CONFIDENCE:.2} a FAULT needs",
            n.confidence
        );
    }
    match n.size {
        _ if n.fault == FaultName::Friction => format!(
            "confidence {:.2}; the friction class: a load change moves it as a bearing's friction would, so it is watched, never a FAULT",
            n.confidence
        ),
        Size::Relative(_) if against == Against::ParameterFile => format!(
            "confidence {:.2}; within the parameter file's own uncertainty (+/-{:.0} %): commission to judge a change this small",
            n.confidence,
            100.0 * NOMINAL_UNCERTAINTY
        ),
        Size::Relative(_) => format!(
            "confidence {:.2}; below the {:.0} % a FAULT needs (what a parameter file's error and a few kelvin of heating move)",
            n.confidence,
            100.0 * MIN_FAULT_CHANGE
        ),
        Size::DbBelowLine(_) => format!(
            "confidence {:.2}; in the MCSA watch band, not yet a fault",
            n.confidence
        ),
        _ => format!("confidence {:.2}", n.confidence),
    }
}
