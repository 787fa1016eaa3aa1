//! The verdict's words: its line says what the deciding finding says, and the lists split
//! what was judged from what was not (the findings' own sentences stand in as `<source>
//! sentence`, their brief phrases as given).

use super::verdict::{line_of, withheld_of, Decided, Spelled};
use monitor_core::verdict::{
    decide, Against, FaultName, Finding, FindingSource, NamedFault, Size, State,
};
use monitor_core::{Fault, Phase};
use monitor_replay::{Detail, FindingReport, Rule, Verdict};

fn named(
    source: FindingSource,
    fault: FaultName,
    size: Size,
    p: f32,
    against: Against,
) -> (FindingReport, String) {
    let f = FindingReport::new(
        source,
        State::Named(NamedFault {
            fault,
            size,
            phase: Some(Phase::C),
            confidence: p,
        }),
        against,
        Detail::Isolation,
    );
    let brief = format!(
        "{} {}",
        source.name(),
        super::verdict::against_text(source, against)
    );
    (f, brief)
}

fn plain(source: FindingSource, state: State, brief: &str) -> (FindingReport, String) {
    (
        FindingReport::new(source, state, Against::Commissioning, Detail::Steady),
        brief.to_string(),
    )
}

/// The verdict's line and withheld reasons of `cases` (each finding with its brief).
fn conclude(cases: &[(FindingReport, String)]) -> (Verdict, String, Vec<String>, Vec<String>) {
    let findings: Vec<FindingReport> = cases.iter().map(|c| c.0.clone()).collect();
    let core: Vec<Finding> = findings.iter().map(|f| f.finding).collect();
    let d = decide(&core);
    let by = d.by.and_then(|k| findings.get(k));
    let brief_of = |f: &FindingReport| {
        cases
            .iter()
            .find(|c| c.0.source() == f.source())
            .map_or(String::new(), |c| c.1.clone())
    };
    let summary = |f: &FindingReport| match f.finding.state {
        State::Named(_) => format!("{} named", f.source().name()),
        _ => format!("{} sentence", f.source().name()),
    };
    let w = Spelled {
        summary: &summary,
        brief: &brief_of,
    };
    let decided: Decided<'_> = (d.verdict, d.rule, by);
    let not_judged: Vec<String> = findings
        .iter()
        .filter(|f| f.source().judges_faults() && f.judged_nothing())
        .map(brief_of)
        .collect();
    (
        d.verdict,
        line_of(&decided, &findings, &w),
        withheld_of(&decided, &findings, &w),
        not_judged,
    )
}

#[test]
fn a_fault_line_names_the_fault_its_size_phase_and_confidence() {
    let f = [
        named(
            FindingSource::Winding,
            FaultName::ShortedTurns,
            Size::OfPositiveSequence(0.125),
            0.72,
            Against::WithinTheLog,
        ),
        plain(
            FindingSource::Residuals,
            State::NotJudged,
            "residuals: need the voltages",
        ),
    ];
    let (verdict, line, withheld, not_judged) = conclude(&f);
    assert_eq!(verdict, Verdict::Fault);
    assert!(line.starts_with("FAULT shorted turns in phase c"), "{line}");
    assert!(
        line.contains("12.5 % of I1") && line.contains("0.72"),
        "{line}"
    );
    assert!(withheld.is_empty());
    assert_eq!(not_judged, vec!["residuals: need the voltages".to_string()]);
}

#[test]
fn a_healthy_line_says_what_was_judged_and_what_was_not() {
    let f = [
        plain(
            FindingSource::Residuals,
            State::Clear,
            "residuals against commissioning",
        ),
        plain(
            FindingSource::Winding,
            State::Clear,
            "winding against 2 healthy runs",
        ),
        plain(
            FindingSource::Rotor,
            State::Unavailable,
            "rotor: the slip is too small",
        ),
        plain(
            FindingSource::OperatingPoint,
            State::Clear,
            "operating point",
        ),
    ];
    let (verdict, line, _, _) = conclude(&f);
    assert_eq!(verdict, Verdict::Healthy);
    assert_eq!(
        line,
        "healthy: residuals against commissioning; winding against 2 healthy runs; not judged: rotor: the slip is too small"
    );
}

#[test]
fn a_watched_name_says_why_it_is_no_fault() {
    let f = [named(
        FindingSource::Residuals,
        FaultName::Table1(Fault::Rr),
        Size::Relative(0.03),
        0.9,
        Against::Commissioning,
    )];
    let (verdict, line, withheld, _) = conclude(&f);
    assert_eq!(verdict, Verdict::Watching);
    assert!(line.starts_with("WATCHING rr +3.0 %"), "{line}");
    assert!(line.contains("below the 5 %"), "{line}");
    assert_eq!(withheld, vec!["residuals named".to_string()]);
    let weak = [named(
        FindingSource::Residuals,
        FaultName::Table1(Fault::Rr),
        Size::Relative(0.3),
        0.3,
        Against::Commissioning,
    )];
    let (_, line, _, _) = conclude(&weak);
    assert!(line.contains("confidence 0.30, below the 0.50"), "{line}");
}

#[test]
fn could_not_judge_gives_the_deciding_reason_and_other_names_are_listed() {
    let f = [
        plain(
            FindingSource::DataQuality,
            State::Unexplained,
            "data quality",
        ),
        named(
            FindingSource::Winding,
            FaultName::ShortedTurns,
            Size::OfPositiveSequence(0.05),
            0.2,
            Against::Nothing,
        ),
    ];
    let (verdict, line, _, _) = conclude(&f);
    assert_eq!(verdict, Verdict::CouldNotJudge);
    assert_eq!(line, "could not judge: data_quality sentence");
    // A FAULT lists the others that were named.
    let f = [
        named(
            FindingSource::Residuals,
            FaultName::Table1(Fault::Rs),
            Size::Relative(0.5),
            0.95,
            Against::Commissioning,
        ),
        named(
            FindingSource::Winding,
            FaultName::ShortedTurns,
            Size::OfPositiveSequence(0.05),
            0.2,
            Against::Nothing,
        ),
    ];
    let (_, line, _, _) = conclude(&f);
    assert!(line.starts_with("FAULT rs +50 % (phase c)"), "{line}");
    assert!(line.contains("also named: winding shorted turns"), "{line}");
    assert_eq!(Rule::Named, decide(&[f[0].0.finding]).rule);
}

#[test]
fn the_reach_says_what_size_of_short_a_log_can_show() {
    use monitor_replay::{LevelBasis, TurnReach};
    let r = |high: f32| TurnReach {
        fraction: 0.8 * high,
        high,
        basis: LevelBasis::Physics,
        least_change: 0.05,
    };
    assert_eq!(
        super::reach(&r(0.354)),
        "no short of more than 36 % of the turns; a 10 % short would be below what this log shows"
    );
    assert_eq!(
        super::reach(&r(0.08)),
        "no short of more than 8 % of the turns"
    );
}
