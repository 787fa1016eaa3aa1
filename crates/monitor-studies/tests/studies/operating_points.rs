//! Evidence across operating points: on the 3 hp motor at rated load an Ls change moves the
//! residuals where an Rr change and a small speed-sensor error do, so one operating point
//! cannot name it (`isolation.rs`, beside it, lists it as not separable there). Once the log holds
//! two or three load levels 30-50 % apart after the fault, the joint fit over them (the
//! stator-voltage equations only: the load as an unknown input) names it with its size. A
//! healthy log with the same load steps names nothing, and a fault one point already names
//! keeps its name.
//!
//! 14 s logs at 5 kHz, commissioned 2-4 s at rated load, the fault at 4.5 s, the viscous
//! load stepped to 0.7 at 8 s and 0.5 at 11 s: about 2 s in the test profile.

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, IsolationName, ReplayOptions, Verdict};
use monitor_sim::{FaultSpec, LoadStep, Scenario, SensorSpec};
use monitor_studies::experiment::simulate_and_replay;
use rayon::prelude::*;

fn run(fault: Option<(Fault, f64)>, steps: bool) -> DiagnoseReport {
    let p = ParamFile::reference_3hp();
    let mut sc = Scenario::steady(14.0, 5000.0);
    sc.sensors = SensorSpec::default();
    sc.seed = 21;
    if steps {
        sc.load.steps = [(8.0, 0.7), (11.0, 0.5)]
            .map(|(t_s, k)| LoadStep {
                t_s,
                torque_nm: None,
                bl_scale: Some(k),
            })
            .to_vec();
    }
    if let Some((f, change)) = fault {
        sc.faults.push(FaultSpec::at_change(f, 4.5, change));
    }
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
        ..Default::default()
    };
    simulate_and_replay(&p, &p, &sc, opts, |_, _| {})
        .expect("runs")
        .finish()
}

#[test]
fn ls_on_the_3hp_motor_is_named_once_the_load_has_moved() {
    let named = std::sync::atomic::AtomicUsize::new(0);
    let bad: Vec<String> = [0.5, -0.5]
        .par_iter()
        .flat_map(|&change| {
            let one = run(Some((Fault::Ls, change)), false);
            let many = run(Some((Fault::Ls, change)), true);
            eprintln!(
                "ls {change:+}: one load level: named {:?}; three: named {:?} {:?}: {:?} rise {:?}, candidates {:?}",
                one.isolation.named,
                many.isolation.named,
                many.isolation.named_change,
                many.isolation.said,
                many.isolation.winding_rise_k,
                many.candidates
                    .iter()
                    .map(|c| (c.fault, c.probability, c.change))
                    .collect::<Vec<_>>()
            );
            let mut bad = Vec::new();
            if one.isolation.named.is_some() {
                bad.push(format!(
                    "ls {change:+} named at one level: {:?}",
                    one.isolation.named
                ));
            }
            let size_ok = many
                .isolation
                .named_change
                .is_some_and(|c| (f64::from(c) - change).abs() <= 0.1 * change.abs());
            // Over three levels: named with its size, or (the calibrated probability below
            // the name's 0.9, issue 48) not named; never another fault.
            let right = many.isolation.named == Some(IsolationName::Fault(Fault::Ls)) && size_ok;
            if right {
                named.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            } else if many.isolation.named.is_some() {
                bad.push(format!(
                    "ls {change:+} over three levels: {:?} {:?}",
                    many.isolation.named, many.isolation.named_change
                ));
            }
            bad
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
    // At least one of the two is named from the three levels (ls +50 %: p 0.91).
    assert!(named.into_inner() >= 1, "neither ls +50 % nor -50 % named");
}

#[test]
fn load_steps_alone_name_nothing_and_a_named_fault_keeps_its_name() {
    // The load steps alone: no fault (the friction class b/bl is how the paper's model
    // reads a load change, shown as the amber MOVED state), and no FAULT verdict.
    let healthy = run(None, true);
    eprintln!(
        "healthy with load steps: {:?}, {:?}",
        healthy.verdict, healthy.isolation.named
    );
    assert!(
        !matches!(healthy.isolation.named, Some(IsolationName::Fault(_))),
        "{:?}",
        healthy.isolation
    );
    assert_ne!(healthy.verdict, Verdict::Fault);
    for (f, change) in [
        (Fault::Rr, 0.3),
        (Fault::Rs, 0.5),
        (Fault::SpeedSensor, 0.05),
    ] {
        let r = run(Some((f, change)), true);
        eprintln!(
            "{f} {change:+} with load steps: {:?} {:?}",
            r.isolation.named, r.isolation.named_change
        );
        assert_eq!(r.isolation.named, Some(IsolationName::Fault(f)), "{f}");
        let c = f64::from(r.isolation.named_change.unwrap_or(f32::NAN));
        assert!((c - change).abs() <= 0.15 * change.abs(), "{f}: {c}");
    }
}
