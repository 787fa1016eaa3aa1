//! No fault hides behind the gates: a step in the gain of a speed, current or voltage
//! reading that settles into a new steady state must end with a verdict or with "could
//! not judge", never with "healthy" while the residuals sit at many times their bands.
//!
//! Three motors (the 3 hp and 2.2 kW reference motors and a 0.37 kW machine of per-unit
//! values typical of its size, the one of `crates/monitor-io/tests/io/nameplate.rs`), each sensor's gain stepped
//! by -50, -5, +5, +20 and +50 % at 5 s of an 8 s log at 5 kHz, commissioned on the healthy
//! running over 1.5-4 s. Also: a speed-sensor gain step is not reported as a load or
//! voltage change (the operating point is judged without the speed-dependent d-q frame),
//! and healthy logs stay healthy.
//!
//! 45 faulty and 3 healthy 8 s replays: about 10 s in the test profile on 2 cores.

use monitor_testkit::small_motor;

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, ReplayOptions, Verdict};
use monitor_sim::{FaultSpec, Scenario, SensorSpec};
use monitor_studies::experiment::simulate_and_replay;
use rayon::prelude::*;

fn motors() -> Vec<(&'static str, ParamFile)> {
    small_motor::three_motors()
}

/// The replay's report of `p`'s machine with `fault` (a sensor gain step at 5 s) or none.
fn run(p: &ParamFile, fault: Option<(Fault, f64)>) -> DiagnoseReport {
    let mut sc = Scenario::steady(8.0, 5000.0);
    sc.sensors = SensorSpec::default();
    sc.seed = 11;
    if let Some((f, change)) = fault {
        sc.faults.push(FaultSpec::sensor_gain(f, 5.0, change));
    }
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(1.5, 4.0)),
        ..Default::default()
    };
    simulate_and_replay(p, p, &sc, opts, |_, _| {})
        .expect("runs")
        .finish()
}

const SENSORS: [Fault; 3] = [
    Fault::SpeedSensor,
    Fault::CurrentSensor,
    Fault::VoltageSensor,
];
const GAINS: [f64; 5] = [-0.5, -0.05, 0.05, 0.2, 0.5];

#[test]
fn a_sensor_gain_step_never_ends_healthy() {
    let cases: Vec<(&str, ParamFile, Fault, f64)> = motors()
        .into_iter()
        .flat_map(|(name, p)| {
            SENSORS
                .iter()
                .flat_map(move |f| GAINS.iter().map(move |g| (name, p, *f, *g)))
        })
        .collect();
    let results: Vec<(String, Verdict, String)> = cases
        .par_iter()
        .map(|(name, p, f, g)| {
            let r = run(p, Some((*f, *g)));
            let named = r
                .isolation
                .named
                .map_or("-".to_string(), |n| format!("{n:?}"));
            let line = format!(
                "{name} {f} {:+.0} %: {:?}, named {named} {:?}, first detection {:?}",
                100.0 * g,
                r.verdict,
                r.isolation.named_change,
                r.first_detection_s
            );
            eprintln!("{line}");
            (line, r.verdict, named)
        })
        .collect();
    let healthy: Vec<&String> = results
        .iter()
        .filter(|(_, v, _)| *v == Verdict::Healthy)
        .map(|(l, _, _)| l)
        .collect();
    let faults = results
        .iter()
        .filter(|(_, v, _)| *v == Verdict::Fault)
        .count();
    eprintln!(
        "{} cases: {faults} FAULT, {} could not judge, {} healthy",
        results.len(),
        results.len() - faults - healthy.len(),
        healthy.len()
    );
    assert!(
        healthy.is_empty(),
        "a sensor gain step ended healthy: {healthy:#?}"
    );
}

#[test]
fn a_speed_sensor_step_is_not_called_a_load_or_voltage_change() {
    for (name, p) in motors() {
        let r = run(&p, Some((Fault::SpeedSensor, 0.1)));
        let notes: Vec<String> = r
            .commissioning
            .outside_range
            .iter()
            .map(monitor_words::diagnose::note)
            .collect();
        eprintln!("{name}: {:?}, notes {notes:?}", r.verdict);
        assert!(
            notes.is_empty(),
            "{name}: the speed reading's gain moved no load and no voltage: {notes:?}"
        );
        assert_ne!(r.verdict, Verdict::Healthy, "{name}");
    }
}

#[test]
fn healthy_logs_stay_healthy() {
    for (name, p) in motors() {
        let r = run(&p, None);
        assert_eq!(
            r.verdict,
            Verdict::Healthy,
            "{name}: {:?}",
            r.verdict_finding
        );
        assert!(r.isolation.named.is_none(), "{name}: {:?}", r.isolation);
    }
}
