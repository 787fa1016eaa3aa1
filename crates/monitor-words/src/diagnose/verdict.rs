//! The verdict in words: its line, the lists of what was and was not judged, a named
//! fault with its size and phase.

use super::findings::{brief, summary};
pub use super::named::{against_text, fault_text, pct, why_watched};
use monitor_core::verdict::{Rule, Verdict};
use monitor_replay::{DiagnoseReport, FindingReport};

use crate::spelling::Spelling;

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
