//! The decision table row by row, its precedence, and its guarantees.

use super::*;
use crate::isolation::NOMINAL_UNCERTAINTY;

fn named(
    source: FindingSource,
    fault: FaultName,
    size: Size,
    confidence: f32,
    against: Against,
) -> Finding {
    Finding::new(
        source,
        State::Named(NamedFault {
            fault,
            size,
            phase: None,
            confidence,
        }),
        against,
    )
}

fn rs(change: f32, confidence: f32, against: Against) -> Finding {
    named(
        FindingSource::Residuals,
        FaultName::Table1(Fault::Rs),
        Size::Relative(change),
        confidence,
        against,
    )
}

fn turns(confidence: f32) -> Finding {
    Finding {
        state: State::Named(NamedFault {
            fault: FaultName::ShortedTurns,
            size: Size::OfPositiveSequence(0.12),
            phase: Some(Phase::C),
            confidence,
        }),
        ..Finding::new(FindingSource::Winding, State::NotJudged, Against::Nothing)
    }
}

fn state(source: FindingSource, state: State) -> Finding {
    Finding::new(source, state, Against::Commissioning)
}

#[test]
fn a_fault_needs_a_name_a_size_that_stands_clear_and_even_odds() {
    let c = Against::Commissioning;
    let d = decide(&[rs(0.5, 0.9, c)]);
    assert_eq!(
        (d.verdict, d.rule, d.by),
        (Verdict::Fault, Rule::Named, Some(0))
    );
    // Just below even odds: watched, not a FAULT.
    assert_eq!(decide(&[rs(0.5, 0.49, c)]).verdict, Verdict::Watching);
    assert_eq!(
        decide(&[rs(0.5, FAULT_CONFIDENCE, c)]).verdict,
        Verdict::Fault
    );
    // Too small to send a crew for.
    assert_eq!(decide(&[rs(0.049, 0.99, c)]).verdict, Verdict::Watching);
    assert_eq!(decide(&[rs(-0.05, 0.99, c)]).verdict, Verdict::Fault);
    // Not a number: never a FAULT.
    assert_eq!(decide(&[rs(f32::NAN, 0.99, c)]).verdict, Verdict::Watching);
    assert_eq!(decide(&[rs(0.5, f32::NAN, c)]).verdict, Verdict::Watching);
}

#[test]
fn the_friction_class_is_watched_never_a_fault() {
    let friction = named(
        FindingSource::Residuals,
        FaultName::Friction,
        Size::Relative(0.5),
        1.0,
        Against::Commissioning,
    );
    let d = decide(&[friction]);
    assert_eq!((d.verdict, d.rule), (Verdict::Watching, Rule::Watching));
    assert_eq!(FaultName::Friction.name(), "b/bl");
}

#[test]
fn against_the_nominal_file_a_name_must_stand_clear_of_the_files_uncertainty() {
    let f = Against::ParameterFile;
    let within = NOMINAL_UNCERTAINTY - 0.01;
    assert_eq!(decide(&[rs(within, 0.99, f)]).verdict, Verdict::Watching);
    assert_eq!(
        decide(&[rs(NOMINAL_UNCERTAINTY + 0.01, 0.99, f)]).verdict,
        Verdict::Fault
    );
    // The same size against commissioning is a FAULT.
    assert_eq!(
        decide(&[rs(within, 0.99, Against::Commissioning)]).verdict,
        Verdict::Fault
    );
}

#[test]
fn the_rotor_is_a_fault_from_the_cracked_bar_band_on() {
    let bars = |db: f32, p: f32| {
        named(
            FindingSource::Rotor,
            FaultName::BrokenBars,
            Size::DbBelowLine(db),
            p,
            Against::Nothing,
        )
    };
    assert_eq!(decide(&[bars(45.0, 0.8)]).verdict, Verdict::Fault);
    assert_eq!(decide(&[bars(ROTOR_FAULT_DB, 0.8)]).verdict, Verdict::Fault);
    // The watch band (48-54 dB) is watched whatever the confidence.
    assert_eq!(decide(&[bars(50.0, 0.9)]).verdict, Verdict::Watching);
}

#[test]
fn a_confident_name_wins_over_every_reason_not_to_judge() {
    // "could not judge" beside a finding at >= 0.5 would contradict the report.
    let others = [
        state(FindingSource::DataQuality, State::Unexplained),
        Finding::new(
            FindingSource::ParameterFit,
            State::Unexplained,
            Against::ParameterFile,
        ),
        state(FindingSource::Residuals, State::NotJudged),
        state(FindingSource::OperatingPoint, State::OutOfRange),
    ];
    let mut findings = others.to_vec();
    findings.push(turns(0.7));
    let d = decide(&findings);
    assert_eq!((d.verdict, d.by), (Verdict::Fault, Some(others.len())));
}

#[test]
fn bad_data_and_a_misfit_file_come_before_watching_and_healthy() {
    let weak = rs(0.2, 0.3, Against::Commissioning);
    let data = state(FindingSource::DataQuality, State::Unexplained);
    let file = Finding::new(
        FindingSource::ParameterFit,
        State::Unexplained,
        Against::ParameterFile,
    );
    let clear = state(FindingSource::Residuals, State::Clear);
    let d = decide(&[clear, weak, data]);
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::DataUntrusted)
    );
    let d = decide(&[clear, weak, file]);
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::FileMisfit)
    );
    // Never "healthy" under a file that does not fit.
    assert_eq!(decide(&[clear, file]).verdict, Verdict::CouldNotJudge);
}

#[test]
fn an_unexplained_change_is_watched_never_healthy() {
    let d = decide(&[
        state(FindingSource::Winding, State::Clear),
        state(FindingSource::Residuals, State::Unexplained),
    ]);
    assert_eq!(
        (d.verdict, d.rule, d.by),
        (Verdict::Watching, Rule::Unexplained, Some(1))
    );
    // A weak name comes before an unexplained change (it says more).
    let d = decide(&[
        state(FindingSource::Residuals, State::Unexplained),
        turns(0.3),
    ]);
    assert_eq!(
        (d.verdict, d.rule, d.by),
        (Verdict::Watching, Rule::Watching, Some(1))
    );
}

#[test]
fn lamps_outside_the_range_judged_are_not_judged_and_explained_lamps_are_healthy() {
    let d = decide(&[
        state(FindingSource::Residuals, State::OutOfRange),
        state(FindingSource::Winding, State::Clear),
    ]);
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::OutOfRange)
    );
    let d = decide(&[
        state(FindingSource::Residuals, State::Explained),
        state(FindingSource::OperatingPoint, State::Explained),
    ]);
    assert_eq!((d.verdict, d.rule), (Verdict::Healthy, Rule::Healthy));
}

#[test]
fn healthy_needs_a_fault_analysis_that_was_judged() {
    // The conditions alone (data, file, operating point) judge no fault.
    let d = decide(&[
        state(FindingSource::DataQuality, State::Clear),
        state(FindingSource::OperatingPoint, State::Clear),
        state(FindingSource::Residuals, State::NotJudged),
    ]);
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::NothingJudged)
    );
    assert_eq!(decide(&[]).rule, Rule::NothingJudged);
    let d = decide(&[state(FindingSource::Rotor, State::Clear)]);
    assert_eq!(d.verdict, Verdict::Healthy);
    // A missing channel leaves the others to judge; an analysis the log kept from judging
    // (the end unsettled with the residuals far off) leaves no verdict of healthy.
    let clear_winding = state(FindingSource::Winding, State::Clear);
    let d = decide(&[
        clear_winding,
        state(FindingSource::Residuals, State::Unavailable),
    ]);
    assert_eq!(d.verdict, Verdict::Healthy);
    let d = decide(&[
        clear_winding,
        state(FindingSource::Residuals, State::NotJudged),
    ]);
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::NothingJudged)
    );
}

#[test]
fn two_confident_names_the_more_confident_wins_and_ties_go_by_source() {
    let c = Against::Commissioning;
    let d = decide(&[rs(0.5, 0.6, c), turns(0.8)]);
    assert_eq!(d.by, Some(1));
    let d = decide(&[rs(0.5, 0.9, c), turns(0.8)]);
    assert_eq!(d.by, Some(0));
    // Equal confidence: the winding (a one-phase fault the balanced model cannot see).
    let d = decide(&[rs(0.5, 0.8, c), turns(0.8)]);
    assert_eq!(d.by, Some(1));
}

#[test]
fn the_verdict_does_not_depend_on_the_order_of_the_findings() {
    let c = Against::Commissioning;
    let sets: [&[Finding]; 3] = [
        &[
            rs(0.5, 0.6, c),
            turns(0.8),
            state(FindingSource::DataQuality, State::Clear),
        ],
        &[
            state(FindingSource::Residuals, State::Unexplained),
            turns(0.2),
        ],
        &[
            state(FindingSource::OperatingPoint, State::OutOfRange),
            state(FindingSource::Rotor, State::Clear),
        ],
    ];
    for set in sets {
        let d = decide(set);
        let mut rev = set.to_vec();
        rev.reverse();
        let r = decide(&rev);
        assert_eq!((d.verdict, d.rule), (r.verdict, r.rule));
        // The same finding decides.
        assert_eq!(d.by.map(|k| set[k]), r.by.map(|k| rev[k]));
    }
}

#[test]
fn names_round_trip() {
    for v in [
        Verdict::Fault,
        Verdict::Watching,
        Verdict::Healthy,
        Verdict::CouldNotJudge,
    ] {
        assert_eq!(Verdict::from_name(v.name()), Some(v));
    }
    assert_eq!(Verdict::from_name("FAULT"), None);
    assert_eq!(FaultName::Table1(Fault::SpeedSensor).name(), "speed_sensor");
    assert_eq!(FaultName::ShortedTurns.name(), "shorted_turns");
}

fn glance_rs(change: f32, p: f32) -> Option<NamedFault> {
    Some(NamedFault {
        fault: FaultName::Table1(Fault::Rs),
        size: Size::Relative(change),
        phase: None,
        confidence: p,
    })
}

#[test]
fn a_glance_is_judged_by_the_same_table() {
    let commissioned = Glance {
        lamps_lit: true,
        commissioned: true,
        ..Glance::default()
    };
    // Lamps with nothing named: watched, never a FAULT (a FAULT needs a name).
    assert_eq!(commissioned.decide().verdict, Verdict::Watching);
    let named = Glance {
        named: glance_rs(0.5, 0.9),
        ..commissioned
    };
    assert_eq!(named.decide().verdict, Verdict::Fault);
    // NamedFault below the lamps' thresholds against a learned baseline: still a FAULT.
    let quiet = Glance {
        lamps_lit: false,
        ..named
    };
    assert_eq!(quiet.decide().verdict, Verdict::Fault);
    // A load move: amber, never a FAULT.
    let moved = Glance {
        moved: true,
        ..commissioned
    };
    assert_eq!(moved.decide().verdict, Verdict::Healthy);
    // Against the nominal values: a name within the file's uncertainty is no judgement.
    let nominal = Glance {
        commissioned: false,
        named: glance_rs(0.2, 0.9),
        ..commissioned
    };
    let d = nominal.decide();
    assert_eq!(
        (d.verdict, d.rule),
        (Verdict::CouldNotJudge, Rule::FileMisfit)
    );
    let nominal_big = Glance {
        named: glance_rs(0.5, 0.9),
        ..nominal
    };
    assert_eq!(nominal_big.decide().verdict, Verdict::Fault);
    // Impossible readings: the data, not the motor.
    let sensor = Glance {
        sensor_fault: true,
        ..commissioned
    };
    assert_eq!(sensor.decide().rule, Rule::DataUntrusted);
    // Nothing lit, nothing named: healthy.
    assert_eq!(
        Glance {
            commissioned: true,
            ..Glance::default()
        }
        .decide()
        .verdict,
        Verdict::Healthy
    );
}
