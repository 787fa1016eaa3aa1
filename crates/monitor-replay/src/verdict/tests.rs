//! The verdict's words: its line says what the deciding finding says, and the lists split
//! what was judged from what was not.

use super::*;
use monitor_core::verdict::FaultName;
use monitor_core::Fault;

fn named(
    source: FindingSource,
    fault: FaultName,
    size: Size,
    p: f32,
    against: Against,
) -> FindingReport {
    FindingReport::new(
        source,
        State::Named(NamedFault {
            fault,
            size,
            phase: Some(Phase::C),
            confidence: p,
        }),
        against,
        format!("{} named", source.name()),
        format!("{} {}", source.name(), words::against_text(source, against)),
    )
}

fn plain(source: FindingSource, state: State, brief: &str) -> FindingReport {
    FindingReport::new(
        source,
        state,
        Against::Commissioning,
        format!("{} sentence", source.name()),
        brief.to_string(),
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
    let c = conclude(&f);
    assert_eq!(c.verdict, Verdict::Fault);
    assert!(
        c.line.starts_with("FAULT shorted turns in phase c"),
        "{}",
        c.line
    );
    assert!(
        c.line.contains("12.5 % of I1") && c.line.contains("0.72"),
        "{}",
        c.line
    );
    assert!(c.withheld_because.is_empty());
    assert_eq!(
        c.not_judged,
        vec!["residuals: need the voltages".to_string()]
    );
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
    let c = conclude(&f);
    assert_eq!(c.verdict, Verdict::Healthy);
    assert_eq!(
        c.line,
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
    let c = conclude(&f);
    assert_eq!(c.verdict, Verdict::Watching);
    assert!(c.line.starts_with("WATCHING rr +3.0 %"), "{}", c.line);
    assert!(c.line.contains("below the 5 %"), "{}", c.line);
    assert_eq!(c.withheld_because, vec!["residuals named".to_string()]);
    let weak = [named(
        FindingSource::Residuals,
        FaultName::Table1(Fault::Rr),
        Size::Relative(0.3),
        0.3,
        Against::Commissioning,
    )];
    let c = conclude(&weak);
    assert!(
        c.line.contains("confidence 0.30, below the 0.50"),
        "{}",
        c.line
    );
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
    let c = conclude(&f);
    assert_eq!(c.verdict, Verdict::CouldNotJudge);
    assert_eq!(c.line, "could not judge: data_quality sentence");
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
    let c = conclude(&f);
    assert!(c.line.starts_with("FAULT rs +50 % (phase c)"), "{}", c.line);
    assert!(
        c.line.contains("also named: winding shorted turns"),
        "{}",
        c.line
    );
}

#[test]
fn findings_serialise_with_their_name_size_unit_and_confidence() {
    let f = named(
        FindingSource::Rotor,
        FaultName::BrokenBars,
        Size::DbBelowLine(41.0),
        0.8,
        Against::Nothing,
    );
    let v = serde_json::to_value(&f).expect("serialises"); // ok: test
    assert_eq!(v["source"], "rotor");
    assert_eq!(v["state"], "named");
    assert_eq!(v["fault"], "broken_bars");
    assert_eq!(v["size_unit"], "db_below_line");
    assert_eq!(v["size"], 41.0);
    assert_eq!(v["against"], "nothing");
    let p = plain(FindingSource::Residuals, State::OutOfRange, "x");
    let v = serde_json::to_value(&p).expect("serialises"); // ok: test
    assert_eq!(v["state"], "out_of_range");
    assert!(v["fault"].is_null() && v["confidence"].is_null());
}

#[test]
fn put_replaces_the_finding_of_a_source() {
    let mut f = vec![plain(FindingSource::Residuals, State::Clear, "a")];
    put(&mut f, plain(FindingSource::DataQuality, State::Clear, "b"));
    put(
        &mut f,
        plain(FindingSource::Residuals, State::Unexplained, "c"),
    );
    assert_eq!(f.len(), 2);
    assert_eq!(f[0].brief, "c");
}
