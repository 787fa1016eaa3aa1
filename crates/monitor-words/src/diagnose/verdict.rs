//! The verdict in words: its line, the lists of what was and was not judged, a named
//! fault with its size and phase.

use super::findings::{brief, summary};
use monitor_core::isolation::{MIN_FAULT_CHANGE, NOMINAL_UNCERTAINTY};
use monitor_core::verdict::{
    Against, FaultName, FindingSource, NamedFault, Rule, Size, Verdict, FAULT_CONFIDENCE,
};
use monitor_replay::{DiagnoseReport, FindingReport};

use crate::spelling::Spelling;

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

/// The other named findings beside the deciding one (`; also: ...`), or nothing.
fn also(decided: Option<&FindingReport>, findings: &[FindingReport]) -> String {
    let others: Vec<String> = findings
        .iter()
        .filter(|f| decided.is_none_or(|d| d.source() != f.source()))
        .filter_map(|f| {
            f.named().map(|n| {
                format!(
                    "{} {} (confidence {:.2})",
                    f.source().name(),
                    fault_text(n),
                    n.confidence
                )
            })
        })
        .collect();
    if others.is_empty() {
        String::new()
    } else {
        format!("; also named: {}", others.join("; "))
    }
}

/// How the verdict's words read a finding: its sentence and its brief phrase.
pub(super) struct Spelled<'a> {
    /// The finding's sentence.
    pub summary: &'a dyn Fn(&FindingReport) -> String,
    /// Its brief phrase.
    pub brief: &'a dyn Fn(&FindingReport) -> String,
}

/// The report's findings as `sp` spells them.
fn spelled_by<'a>(
    rep: &'a DiagnoseReport,
    sp: &'a dyn Spelling,
) -> (
    impl Fn(&FindingReport) -> String + 'a,
    impl Fn(&FindingReport) -> String + 'a,
) {
    (
        move |f: &FindingReport| summary(f, rep, sp),
        move |f: &FindingReport| brief(f, rep, sp),
    )
}

/// The fault-judging findings that were judged, as their brief phrases.
pub fn judged(rep: &DiagnoseReport, sp: &dyn Spelling) -> Vec<String> {
    let (_, b) = spelled_by(rep, sp);
    judged_of(&rep.findings, &b)
}

fn judged_of(findings: &[FindingReport], brief: &dyn Fn(&FindingReport) -> String) -> Vec<String> {
    findings
        .iter()
        .filter(|f| f.source().judges_faults() && !f.judged_nothing())
        .map(brief)
        .collect()
}

/// The fault-judging findings that could not be judged, with why.
pub fn not_judged(rep: &DiagnoseReport, sp: &dyn Spelling) -> Vec<String> {
    let (_, b) = spelled_by(rep, sp);
    not_judged_of(&rep.findings, &b)
}

fn not_judged_of(
    findings: &[FindingReport],
    brief: &dyn Fn(&FindingReport) -> String,
) -> Vec<String> {
    findings
        .iter()
        .filter(|f| f.source().judges_faults() && f.judged_nothing())
        .map(brief)
        .collect()
}

/// Why the verdict is not a FAULT or healthy (empty for those): the deciding finding's
/// sentence, then what could not be judged.
pub fn withheld_because(rep: &DiagnoseReport, sp: &dyn Spelling) -> Vec<String> {
    let (s, b) = spelled_by(rep, sp);
    let words = Spelled {
        summary: &s,
        brief: &b,
    };
    withheld_of(&decided(rep), &rep.findings, &words)
}

/// What the decision table concluded: the verdict, its rule, the finding it rests on.
pub(super) type Decided<'a> = (Verdict, Rule, Option<&'a FindingReport>);

/// The report's decision.
fn decided(rep: &DiagnoseReport) -> Decided<'_> {
    (rep.verdict, rep.verdict_rule, rep.verdict_finding.as_ref())
}

pub(super) fn withheld_of(
    d: &Decided<'_>,
    findings: &[FindingReport],
    w: &Spelled<'_>,
) -> Vec<String> {
    match d.0 {
        Verdict::Fault | Verdict::Healthy => Vec::new(),
        Verdict::Watching | Verdict::CouldNotJudge => {
            d.2.iter()
                .map(|f| (w.summary)(f))
                .chain(not_judged_of(findings, w.brief))
                .collect()
        }
    }
}

/// The verdict's line (after `verdict: `).
pub fn line(rep: &DiagnoseReport, sp: &dyn Spelling) -> String {
    let (s, b) = spelled_by(rep, sp);
    let words = Spelled {
        summary: &s,
        brief: &b,
    };
    line_of(&decided(rep), &rep.findings, &words)
}

/// The line of the decision `d` over `findings`, their words `w`.
pub(super) fn line_of(d: &Decided<'_>, findings: &[FindingReport], w: &Spelled<'_>) -> String {
    let (verdict, rule, by) = *d;
    let named = by.and_then(|f| f.named().map(|n| (f, n)));
    let not_judged = not_judged_of(findings, w.brief);
    let not = if not_judged.is_empty() {
        String::new()
    } else {
        format!("; not judged: {}", not_judged.join("; "))
    };
    match (verdict, rule, named) {
        (Verdict::Fault, _, Some((f, n))) => format!(
            "FAULT {} (confidence {:.2}; {} {}){}",
            fault_text(n),
            n.confidence,
            f.source().name(),
            against_text(f.source(), f.finding.against),
            also(Some(f), findings)
        ),
        (Verdict::Watching, Rule::Watching, Some((f, n))) => format!(
            "WATCHING {} ({}; {} {}){}",
            fault_text(n),
            why_watched(n, f.finding.against),
            f.source().name(),
            against_text(f.source(), f.finding.against),
            also(Some(f), findings)
        ),
        (Verdict::Watching, _, _) => format!(
            "WATCHING: {}{}",
            by.map_or("a change no single fault explains".to_string(), w.summary),
            also(by, findings)
        ),
        (Verdict::Healthy, _, _) => {
            format!("healthy: {}{not}", judged_of(findings, w.brief).join("; "))
        }
        (Verdict::CouldNotJudge, Rule::NothingJudged, _) => {
            format!("could not judge: {}", not_judged.join("; "))
        }
        (_, _, _) => format!("could not judge: {}", by.map_or(String::new(), w.summary)),
    }
}
