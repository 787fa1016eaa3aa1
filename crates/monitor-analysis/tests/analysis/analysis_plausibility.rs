//! Plausibility of fitted values, identifiability of the base parameters, and the advice
//! `compare` gives when its worst windows are a start or a step (issue 10).
use crate::analysis_common;
use analysis_common::*;
use monitor_analysis::compare::NotIdentifiedWhy;
use monitor_analysis::effects::library;
use monitor_analysis::explain::SkipReason;
use monitor_analysis::explain::{ExplainReport, Standing, EXPLAINS_MIN};
use monitor_analysis::simplified_model::BaseParameter;
use monitor_analysis::transients::{Advice, Cover, NotProposed};
use monitor_analysis::unbalance::UnbalanceFinding;
use monitor_analysis::EffectId;
use monitor_core::EffectKind;
use monitor_sim::{LoadKind, LoadSpec, LoadStep, Scenario, SupplyStep};

/// A direct-on-line start from standstill, then steady running: 3 s at 5 kHz.
fn dol() -> Scenario {
    let mut s = Scenario::steady(3.0, 5000.0);
    s.sensors = sensors(1);
    s
}

#[test]
fn a_start_is_named_with_the_dynamics_effects_and_a_from() {
    let dir = tempfile::tempdir().unwrap();
    let p = motor("2p2");
    let log = write_log(dir.path(), "dol", &p, &dol(), false);
    let a = analyse(&log, &p, 0.0);
    let c = a.compare(&opts(&[])).unwrap().report;
    eprintln!("{:#?}", c.advice);
    let w = &c.worst_windows[0];
    assert_eq!(
        w.transient.as_ref().map(|t| t.kind.name()),
        Some("start"),
        "{w:?}"
    );
    let added = proposed(&c.advice);
    assert!(
        added.contains(&EffectKind::FluxDynamics.into())
            && added.contains(&EffectKind::CurrentDynamics.into()),
        "{:?}",
        c.advice
    );
    let from: f64 = c
        .advice
        .iter()
        .find_map(|a| match a {
            Advice::LeaveStartOut { from_s, .. } => Some(*from_s),
            _ => None,
        })
        .expect("a window past the start");
    assert!(from > 0.1 && from < 1.5, "{from}");
    // Past the suggested start the model fits, its values are plausible, no window is a
    // start, and the error falls by more than 5x.
    let b = analyse(&log, &p, from).compare(&opts(&[])).unwrap().report;
    assert!(
        b.worst_windows.iter().all(|w| w.transient.is_none()),
        "{:?}",
        b.worst_windows
    );
    assert!(b.advice.is_empty(), "{:?}", b.advice);
    assert!(b.plausible, "{:?}", b.implausible_because);
    assert!(
        b.normalized_rms_error < c.normalized_rms_error / 5.0,
        "{} -> {}",
        c.normalized_rms_error,
        b.normalized_rms_error
    );
    // Through the start, the paper's model fits an impossible Ra to absorb it.
    assert!(!c.plausible, "{:?}", c.base_parameters);
}

#[test]
fn inertia_is_not_identified_when_the_speed_never_changes() {
    let dir = tempfile::tempdir().unwrap();
    let p = motor("2p2");
    let steady = write_log(
        dir.path(),
        "steady",
        &p,
        &Scenario::steady(3.0, 5000.0),
        false,
    );
    let c = analyse(&steady, &p, 1.5)
        .compare(&opts(&[]))
        .unwrap()
        .report;
    eprintln!("{:#?}\n{:#?}", c.identifiability, c.not_identified);
    let j = c.identifiability.as_ref().unwrap();
    let jj = j
        .base
        .iter()
        .find(|b| b.parameter == BaseParameter::J)
        .unwrap();
    assert!(!jj.identified, "{j:?}");
    assert!(
        c.not_identified
            .iter()
            .any(|s| s.parameter == BaseParameter::J
                && matches!(s.because, NotIdentifiedWhy::SpeedConstant { .. })),
        "{:?}",
        c.not_identified
    );
    assert!(c.plausible, "{:?}", c.implausible_because);
    // Voltage steps move the speed: now J is identified.
    let mut s = Scenario::steady(4.0, 5000.0);
    s.supply.steps = vec![
        SupplyStep {
            t_s: 2.0,
            v_scale: Some(0.7),
            f_hz: Some(30.0),
        },
        SupplyStep {
            t_s: 3.0,
            v_scale: Some(1.0),
            f_hz: Some(50.0),
        },
    ];
    let stepped = write_log(dir.path(), "stepped", &p, &s, false);
    let c = analyse(&stepped, &p, 1.5)
        .compare(&opts(&["flux_dynamics", "current_dynamics"]))
        .unwrap()
        .report;
    eprintln!("{:#?}", c.identifiability);
    let j = c.identifiability.as_ref().unwrap();
    assert!(
        j.base
            .iter()
            .find(|b| b.parameter == BaseParameter::J)
            .unwrap()
            .identified,
        "{j:?}"
    );
}

/// On a healthy steady log every refitted value is in range, and `explain` claims nothing;
/// whatever it ranks, an implausible candidate is never ahead of a plausible one, and no
/// line names a winding phase (a healthy machine's negative sequence is no shorted turn).
#[test]
fn healthy_refits_are_plausible_and_implausible_fits_rank_last() {
    let dir = tempfile::tempdir().unwrap();
    for which in ["2p2", "3hp"] {
        let truth = motor(which);
        let nominal = perturbed(&truth, 0.05);
        let log = write_log(dir.path(), which, &truth, &scenario(which, None, 1), false);
        let a = analyse(&log, &nominal, settle_s(which));
        let c = a.compare(&opts(&[])).unwrap().report;
        assert!(c.plausible, "{which}: {:?}", c.implausible_because);
        let ex = a.explain(&opts(&[]), &|_| {}).unwrap().report;
        let first_implausible = ex.ranking.iter().position(|c| !c.plausible);
        if let Some(i) = first_implausible {
            assert!(
                ex.ranking[i..].iter().all(|c| !c.plausible),
                "{which}: {:?}",
                ex.ranking
            );
        }
        assert!(ex.unexplained, "{which}: {:?}", ex.conclusion);
        assert_standings(which, &ex);
        assert_names_no_winding(which, &ex);
    }
}

/// A healthy machine on a supply whose own negative sequence moves (the supply-unbalance
/// scenario: a 2 % unbalanced supply, swept by a variac): the currents' negative sequence
/// is the supply's, and `explain` names no winding, neither in its unbalance line nor in
/// the fitted `phase_asymmetry`'s sentence (which named the phase of any fitted `c`, 0.7 %
/// on the balanced motulator log, before).
#[test]
fn a_healthy_motor_on_an_unbalanced_supply_names_no_winding() {
    let dir = tempfile::tempdir().unwrap();
    let truth = motor("2p2");
    let s = scenario("2p2", Some("supply_unbalance"), 1);
    let log = write_log(dir.path(), "unb", &truth, &s, false);
    let a = analyse(&log, &perturbed(&truth, 0.05), settle_s("2p2"));
    let ex = a.explain(&opts(&[]), &|_| {}).unwrap().report;
    assert!(
        ex.unbalance.negative_sequence_ratio > 0.05,
        "the supply's unbalance must show: {:?}",
        ex.unbalance
    );
    assert_names_no_winding("2p2 on an unbalanced supply", &ex);
    assert_standings("2p2 on an unbalanced supply", &ex);
}

/// No phase named: no suspect phase, no sentence saying a phase's winding differs.
fn assert_names_no_winding(case: &str, ex: &ExplainReport) {
    assert_eq!(
        ex.unbalance.suspect_phase, None,
        "{case}: {:?}",
        ex.unbalance
    );
    assert!(
        !matches!(ex.unbalance.finding, UnbalanceFinding::Winding { .. }),
        "{case}: {:?}",
        ex.unbalance.finding
    );
    for l in ex.ranking.iter().map(|c| &c.summary) {
        assert!(!l.contains("winding differs"), "{case}: {l}");
        for p in ["a", "b", "c"] {
            assert!(!l.contains(&format!("phase {p} ")), "{case}: {l}");
        }
    }
}

/// `explain`'s standings: a rank only for a plausible fit that explains at least
/// `EXPLAINS_MIN` (ranks 1, 2, ... first, in order); every fit below it and plausible in
/// `no_effect`; an implausible fit never ranked, after every plausible one, and its sentence
/// says it is not physical (never a reading of its values).
fn assert_standings(case: &str, ex: &ExplainReport) {
    let mut next = 1;
    for (i, c) in ex.ranking.iter().enumerate() {
        let counts = c.plausible && c.explained_fraction >= EXPLAINS_MIN;
        assert_eq!(
            c.rank.is_some(),
            counts,
            "{case}: {:?} {:?}",
            c.effect,
            c.rank
        );
        if let Some(k) = c.rank {
            assert_eq!((k, i + 1), (next, next), "{case}: {:?}", c.effect);
            assert_eq!(c.standing, Standing::Candidate, "{case}");
            next += 1;
        }
        if !c.plausible {
            assert_eq!(c.standing, Standing::NotPlausible, "{case}: {:?}", c.effect);
            assert!(
                c.summary.starts_with("not physical"),
                "{case}: {}",
                c.summary
            );
            assert!(!c.summary.contains("K of heating"), "{case}: {}", c.summary);
        }
    }
    let no_effect: Vec<EffectId> = ex
        .ranking
        .iter()
        .filter(|c| c.plausible && c.explained_fraction < EXPLAINS_MIN)
        .map(|c| c.effect)
        .collect();
    assert_eq!(ex.no_effect, no_effect, "{case}");
    assert!(
        ex.ranking
            .iter()
            .filter(|c| c.explained_fraction == 0.0)
            .all(|c| c.rank.is_none()),
        "{case}: a candidate that explains nothing is ranked"
    );
}

/// The motulator log (a start and a load step, no commissioning): many fits there are not
/// physical (400 K of heating in 0.2 s, a negative core loss, a negative-sequence admittance
/// at its bound), none of them is ranked or read as a value; and no dimensionless value
/// prints with a unit "1" (`y_re = 5.00 1` before).
#[test]
fn the_motulator_logs_implausible_fits_stand_apart_and_print_no_unit_one() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/logs");
    let p = monitor_io::params::ParamFile::load(&root.join("motulator_2p2kw_dol.toml")).unwrap();
    let a = analyse(&root.join("motulator_2p2kw_dol.csv"), &p, 0.0);
    let ex = a.explain(&opts(&[]), &|_| {}).unwrap().report;
    assert_standings("motulator", &ex);
    assert_names_no_winding("motulator", &ex);
    let implausible: Vec<_> = ex.ranking.iter().filter(|c| !c.plausible).collect();
    assert!(implausible.len() >= 3, "{:?}", ex.ranking);
    let texts = ex
        .ranking
        .iter()
        .flat_map(|c| std::iter::once(&c.summary).chain(&c.implausible_because));
    for t in texts {
        assert!(!prints_unit_one(t), "{t}");
    }
}

/// True when `text` writes a number followed by the unit `1` (`5.00 1`, `3.00 1 (`).
fn prints_unit_one(text: &str) -> bool {
    let w: Vec<&str> = text.split_whitespace().collect();
    w.windows(2).any(|p| {
        let unit = p[1].trim_end_matches([')', ';', ',', ':']);
        let number = p[0]
            .trim_start_matches('(')
            .split("..")
            .last()
            .unwrap_or("");
        unit == "1" && number.parse::<f64>().is_ok()
    })
}

/// Every declared parameter of the library, dimensionless ones included, words a value out
/// of its range with its unit, and a dimensionless one without any.
#[test]
fn out_of_range_values_print_their_unit_and_no_unit_one() {
    let mut dimensionless = 0;
    for e in library() {
        for p in e.parameters() {
            let fit = p.fit(1.0, (-1e9, 1e9), 1.0, 1.0);
            let far = if p.range.1.is_finite() {
                p.range.1.abs() * 10.0 + 10.0
            } else {
                p.range.0 - 10.0
            };
            let Some(why) = fit.implausible_because(far) else {
                continue;
            };
            assert!(!prints_unit_one(&why), "{}: {why}", e.kind());
            if p.unit == "1" {
                dimensionless += 1;
            } else {
                assert!(
                    why.contains(&format!(" {} ", p.unit)),
                    "{}: {why}",
                    e.kind()
                );
            }
        }
    }
    assert!(
        dimensionless >= 5,
        "{dimensionless} dimensionless parameters checked"
    );
    assert!(prints_unit_one(
        "y_re = 5.00 1 is outside 0.300..3.00 1 (x)"
    ));
}

/// `compare`'s advice on the dynamics effects and `explain`'s `skipped` come from one rule
/// (`analysis::transients::not_proposed`): on the same log, every dynamics effect `explain`
/// skips for what the span lacks is in the advice with the same words; one it skips only
/// because an effect it needs first is missing from the model is advised together with
/// that effect (issue 62: `cross_coupling_dynamics` with `d_axis_dynamics`, the full-order
/// machine; judged against the model alone it was dropped from the advice and nothing
/// proposed it later); every other one the advice adds is one `explain` fitted. On the
/// motulator log (a start and a load step), a simulated start, and simulated load steps
/// without a start that move the speed fast (the advice adds the dynamics, and `explain`
/// fits them; a log whose speed moves little skips them with the reason:
/// `analysis_effects`' `dynamics_effects_need_an_input_transient`).
#[test]
fn compare_advice_and_explain_skipped_agree() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/logs");
    let motulator =
        monitor_io::params::ParamFile::load(&root.join("motulator_2p2kw_dol.toml")).unwrap();
    let p = motor("2p2");
    let dol_log = write_log(dir.path(), "dol", &p, &dol(), false);
    // Load steps of 1.3x the rated torque every 0.4 s from 2.5 s (the speed moves by 6 %
    // of synchronous speed): compare's worst windows are speed changes.
    let t3 = motor("3hp");
    let mut step = Scenario::steady(6.0, 4000.0);
    step.sensors = sensors(1);
    step.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(2.0),
        bl_nms: None,
        steps: (0..9)
            .map(|i| LoadStep {
                t_s: 2.5 + 0.4 * f64::from(i),
                torque_nm: Some(if i % 2 == 0 { 18.0 } else { 2.0 }),
                bl_scale: None,
            })
            .collect(),
    };
    let step_log = write_log(dir.path(), "step", &t3, &step, false);
    let cases = [
        (
            "motulator",
            analyse(&root.join("motulator_2p2kw_dol.csv"), &motulator, 0.0),
            true,
        ),
        ("start", analyse(&dol_log, &p, 0.0), true),
        (
            "load steps",
            analyse(&step_log, &t3, settle_s("3hp")),
            false,
        ),
    ];
    for (case, a, start) in cases {
        // The load steps of 16 N m, more than the 3 hp motor's rated torque, move the speed
        // by several per cent of synchronous speed within a few ms: a transient the
        // dynamics act on (`transients::speed_transient`), as a start is.
        assert!(
            monitor_analysis::transients::speed_transient(&a.data, &a.constants),
            "{case}: the speed moves fast"
        );
        let c = a.compare(&opts(&[])).unwrap().report;
        let ex = a.explain(&opts(&[]), &|_| {}).unwrap().report;
        let skipped: Vec<(EffectId, Option<&NotProposed>)> = ex
            .skipped
            .iter()
            .filter(|s| s.effect.is_dynamics())
            .map(|s| match &s.because {
                SkipReason::NotProposed { why } => (s.effect, Some(why)),
                _ => (s.effect, None),
            })
            .collect();
        let held: Vec<(EffectId, Option<&NotProposed>)> = c
            .advice
            .iter()
            .filter_map(|a| match a {
                Advice::NotProposed { effect, why } => Some((*effect, Some(why))),
                _ => None,
            })
            .collect();
        let added = proposed(&c.advice);
        eprintln!("{case}: advice {:#?}\nskipped {skipped:#?}", c.advice);
        assert!(
            !c.advice.is_empty(),
            "{case}: the worst windows are transients"
        );
        // Skipped only for what it needs first, and advised with it.
        let with_its_needs = |s: &(EffectId, Option<&NotProposed>)| {
            added.contains(&s.0)
                && matches!(s.1, Some(NotProposed::Requires(needs))
                    if needs.iter().any(|r| *r != s.0 && added.contains(r)))
        };
        let for_the_span: Vec<(EffectId, Option<&NotProposed>)> = skipped
            .iter()
            .filter(|s| !with_its_needs(s))
            .copied()
            .collect();
        assert_eq!(held, for_the_span, "{case}: the same reasons");
        for k in &added {
            let fitted = ex.ranking.iter().any(|r| r.effect == *k);
            let needs = skipped.iter().any(|s| with_its_needs(s) && s.0 == *k);
            assert!(
                fitted != needs,
                "{case}: compare adds {k}: explain must fit it, or skip it only for what the advice adds with it"
            );
        }
        if start {
            // The full-order machine: all four dynamics effects advised on a start.
            assert_eq!(added.len(), 4, "{case}: {added:?}");
        }
        assert!(!added.is_empty(), "{case}: {added:?}");
    }
}

/// The dynamics effects `compare`'s advice adds (its first advice, on the transients).
fn proposed(advice: &[Advice]) -> Vec<EffectId> {
    match advice.first() {
        Some(Advice::Transients {
            cover: Cover::Add { proposed, .. },
            ..
        }) => proposed.clone(),
        _ => Vec::new(),
    }
}
