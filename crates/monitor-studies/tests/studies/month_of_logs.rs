//! A month of daily logs, in small (issue 48): each motor logged on four days of a month
//! whose season warms its windings from 11 to 30 K above the parameter file's temperature,
//! the load moving every 3 s (an unknown input), judged against the parameter file (not
//! commissioned). On one copy of each motor a connection loosens from day 10: Rs +0.5 % a
//! day (+10 % on day 30).
//!
//! Before: the loosening connection ended the month named `ls +30 %` to `ls +37 %` (the
//! wrong fault), and the healthy warm motors ended most logs with "a change ... that no
//! single fault explains", where heating explains it. Now: the loosening connection is
//! named `rs` or nothing, never another fault, at no time of any log; on the healthy warm
//! motors no fault is named and the isolation's report says heating explains the change
//! (`isolation.heating_explains`). The three motors: the 3 hp and 2.2 kW reference
//! machines and Krause's 50 hp one. Twenty-four 20 s logs at 4 kHz: about 5 s in the test
//! profile.

use monitor_testkit::small_motor;

use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, IsolationEvent, IsolationName, ReplayOptions};
use monitor_sim::{EffectSpec, FaultSpec, LoadSpec, LoadStep, Scenario, SensorSpec};
use rayon::prelude::*;

/// The days logged.
const DAYS: [u32; 4] = [3, 12, 21, 30];

/// The windings' rise above the parameter file's temperature on `day` [K]: the season
/// warms them from 10 K to 30 K over the month.
fn season_rise_k(day: u32) -> f64 {
    10.0 + 20.0 * f64::from(day) / 30.0
}

/// The loosening connection's Rs change on `day`: +0.5 % a day from day 10.
fn loosening(day: u32) -> f64 {
    0.005 * f64::from(day.saturating_sub(10))
}

/// The day's log of `p`: warm by the season from its start, the load moving every 3 s
/// between 0.7 and 1.3 of its Bl, Rs changed by `rs_change` (none when 0).
fn day_log(p: &ParamFile, day: u32, rs_change: f64, seed: u64) -> Scenario {
    let mut sc = Scenario::steady(20.0, 4000.0);
    sc.seed = seed;
    sc.sensors = SensorSpec::default();
    let levels = [1.0, 0.8, 1.2, 0.7, 1.3, 0.9, 1.1];
    let steps = (1..levels.len())
        .map(|k| LoadStep {
            t_s: 3.0 * k as f64,
            torque_nm: None,
            bl_scale: Some(levels[(k + day as usize) % levels.len()]),
        })
        .collect();
    sc.load = LoadSpec {
        bl_nms: Some(p.motor.bl_nms),
        steps,
        ..LoadSpec::default()
    };
    let toml = format!(
        "name = \"thermal_drift\"\nrise_k = {}\ntau_s = 0.2\nat_s = 0.0\n",
        season_rise_k(day)
    );
    sc.effects
        .push(toml::from_str::<EffectSpec>(&toml).expect("effect"));
    if rs_change > 0.0 {
        sc.faults.push(FaultSpec::parametric(
            monitor_core::Fault::Rs,
            0.0,
            rs_change,
        ));
    }
    sc
}

fn replay(p: &ParamFile, sc: &Scenario) -> DiagnoseReport {
    monitor_studies::experiment::simulate_and_replay(p, p, sc, ReplayOptions::default(), |_, _| {})
        .expect("runs")
        .finish()
}

/// Every name the report gives: at the end and on the way.
fn names(r: &DiagnoseReport) -> Vec<IsolationName> {
    let mut v: Vec<IsolationName> = r
        .isolation
        .events
        .iter()
        .filter_map(|e| match e {
            IsolationEvent::Named { name, .. } => Some(*name),
            IsolationEvent::LoadMoved { .. } => None,
        })
        .collect();
    v.extend(r.isolation.named);
    v
}

#[test]
fn a_month_of_warm_logs_reads_heating_and_a_loosening_connection_as_rs() {
    let motors = [
        ("3 hp", ParamFile::reference_3hp()),
        ("2.2 kW", ParamFile::reference_2p2kw()),
        ("50 hp", small_motor::krause_50hp()),
    ];
    let mut cases = Vec::new();
    for (m, (name, p)) in motors.iter().enumerate() {
        for day in DAYS {
            for loose in [false, true] {
                cases.push((
                    *name,
                    *p,
                    day,
                    loose,
                    4_800_000 + 100 * m as u64 + u64::from(day),
                ));
            }
        }
    }
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|&(name, p, day, loose, seed)| {
            let change = if loose { loosening(day) } else { 0.0 };
            let r = replay(&p, &day_log(&p, day, change, seed));
            let given = names(&r);
            let line = format!(
                "{name} day {day} ({:.0} K warm{}): {:?}, named {given:?}, heating explains {}, {:?}",
                season_rise_k(day),
                if change > 0.0 {
                    format!(", Rs +{:.1} %", 100.0 * change)
                } else {
                    String::new()
                },
                r.verdict,
                r.isolation.heating_explains,
                r.isolation.said
            );
            eprintln!("{line}");
            let rs = IsolationName::Fault(monitor_core::Fault::Rs);
            let ok = if change > 0.0 {
                given.iter().all(|n| *n == rs)
            } else {
                given.is_empty() && r.isolation.heating_explains
            };
            (!ok).then_some(line)
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}
