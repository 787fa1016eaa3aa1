//! Plausibility of fitted values, identifiability of the base parameters, and the advice
//! `compare` gives when its worst windows are a start or a step (issue 10).
mod analysis_common;
use analysis_common::*;
use sim_host::analysis::simplified_model::BaseParameter;
use sim_host::sim::{Scenario, SupplyStep};

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
    assert!(c.advice[0].contains("flux_dynamics") && c.advice[0].contains("current_dynamics"));
    let from: f64 = c
        .advice
        .iter()
        .find_map(|a| a.split("--from ").nth(1))
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .expect("a --from suggestion");
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
            .any(|s| s.starts_with("j_kgm2 is not identified: the speed never changes")),
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
/// whatever it ranks, an implausible candidate is never ahead of a plausible one.
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
        assert!(ex.unexplained, "{which}: {}", ex.verdict);
    }
}
