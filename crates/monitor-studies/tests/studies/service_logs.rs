//! Service logs (issue 24): the load moves +-30 % every few seconds, the monitor is
//! commissioned over that range, and a fault arrives mid-log. Three motors: the 3 hp and
//! 2.2 kW reference machines and Krause, Wasynczuk and Sudhoff's 50 hp (37 kW) one, each
//! with every parametric fault (rs, rr, ls, lr) at +-50 %, rs and rr at +20 %, and every
//! sensor's gain (speed, current, voltage) at +-5 %.
//!
//! The bar: at the log's end the fault is named alone (probability >= 0.5, ahead of the
//! runner-up) with its size within 25 %, in at least 90 % of the cases; no other name (a
//! wrong fault, or the friction class b/bl) is ever given; the healthy logs name nothing.
//!
//! Each log is 52 s at 5 kHz ([`monitor_studies::service_profile::moving_load`]: the load steps
//! every 4 s, commissioned 2-24 s over five levels, 0.7 to 1.3 x Bl, the fault at 26 s,
//! then six more levels drawn from the seed). The seeds are the case's index plus 900 (not
//! tuned on). The whole table (51 logs, about 10 s on two cores in the test profile) runs
//! with `MONITOR_FULL_SWEEPS=1` (`.ci/run` runs it), with the hour-long log below; plain
//! `cargo test` runs a subset of seven on the 2.2 kW machine. Print the table with
//! `-- --nocapture`. Measured (docs/isolation.md, "Service logs"): 45 of 48 named alone
//! with their size, no wrong name, the healthy logs name nothing.

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_replay::{IsolationEvent, IsolationName, NameGiven, ReplayOptions};
use monitor_sim::FaultSpec;
use monitor_studies::experiment::simulate_and_replay;
use monitor_studies::service_profile::{moving_load, MOVING_COMMISSION};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Length of a service log [s] and its sample rate [Hz].
const DURATION_S: f64 = 52.0;
const RATE_HZ: f64 = 5000.0;
/// When the fault arrives [s]: mid-log, two seconds after the first post-commissioning
/// load step.
const FAULT_AT_S: f64 = 26.0;

/// Krause, Wasynczuk and Sudhoff's 50 hp, 460 V, 60 Hz, 4-pole machine (Analysis of
/// Electric Machinery and Drive Systems: Rs 0.087, Rr 0.228, Xls = Xlr 0.302, Xm 13.08
/// ohm at 60 Hz, J 1.662 kg m^2), in the paper's simplified-model structure (Ls = Lls + Lm,
/// Lr = Llr + Lm, the viscous load): Bl 0.9 N m s/rad, 160 N m (0.8 of its rated 198 N m)
/// at 1705 rpm, B a hundredth of it.
fn krause_50hp() -> ParamFile {
    let w = TAU * 60.0;
    let (xm, xl) = (13.08, 0.302);
    let mut p = ParamFile::reference_3hp();
    p.motor.rs_ohm = 0.087;
    p.motor.rr_ohm = 0.228;
    p.motor.lm_h = xm / w;
    p.motor.ls_h = (xm + xl) / w;
    p.motor.lr_h = (xm + xl) / w;
    p.motor.j_kgm2 = 1.662;
    p.motor.bl_nms = 0.9;
    p.motor.b_nms = 0.009;
    p.supply.v_ll_rms = 460.0;
    p
}

fn motors() -> Vec<(&'static str, ParamFile)> {
    vec![
        ("3 hp", ParamFile::reference_3hp()),
        ("2.2 kW", ParamFile::reference_2p2kw()),
        ("37 kW", krause_50hp()),
    ]
}

/// The faults of the bar, with their sizes.
fn faults() -> Vec<(Fault, f64)> {
    let mut v = Vec::new();
    for f in [Fault::Rs, Fault::Rr, Fault::Ls, Fault::Lr] {
        v.push((f, 0.5));
        v.push((f, -0.5));
    }
    v.push((Fault::Rs, 0.2));
    v.push((Fault::Rr, 0.2));
    for f in [
        Fault::SpeedSensor,
        Fault::CurrentSensor,
        Fault::VoltageSensor,
    ] {
        v.push((f, 0.05));
        v.push((f, -0.05));
    }
    v
}

/// The long runs are asked for (`MONITOR_FULL_SWEEPS=1`, as `.ci/run` does); says so when
/// they are skipped.
fn full_sweeps() -> bool {
    let on = std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1");
    if !on {
        eprintln!("skipped: set MONITOR_FULL_SWEEPS=1");
    }
    on
}

/// Every motor's healthy log and every fault of the bar: (motor index, fault).
fn every_case() -> Vec<(usize, Option<(Fault, f64)>)> {
    let mut cases = Vec::new();
    for m in 0..motors().len() {
        cases.push((m, None));
        for f in faults() {
            cases.push((m, Some(f)));
        }
    }
    cases
}

/// One service log's outcome.
struct CaseOutcome {
    motor: &'static str,
    fault: Option<(Fault, f64)>,
    /// What the isolation names at the log's end, and its size.
    named: Option<IsolationName>,
    size: Option<f32>,
    /// Every name given over the log, with its first time.
    given: Vec<NameGiven>,
    verdict: String,
    /// The learned spreads of the isolation's residuals.
    spread: [f32; 3],
}

impl CaseOutcome {
    /// Named alone at the end with the size within 25 %.
    fn right(&self) -> bool {
        let Some((f, change)) = self.fault else {
            return false;
        };
        self.named == Some(IsolationName::Fault(f))
            && self
                .size
                .is_some_and(|c| (f64::from(c) - change).abs() <= 0.25 * change.abs())
    }

    /// Names given that are not the fault's (any name on a healthy log).
    fn wrong(&self) -> Vec<NameGiven> {
        let own = self.fault.map(|(f, _)| IsolationName::Fault(f));
        self.given
            .iter()
            .filter(|g| Some(g.name) != own)
            .copied()
            .collect()
    }

    fn row(&self) -> String {
        let case = self.fault.map_or("healthy".to_string(), |(f, c)| {
            format!("{f} {:+.0} %", 100.0 * c)
        });
        let named = self.named.map_or("-".to_string(), |n| {
            format!(
                "{n} {}",
                self.size
                    .map_or(String::new(), |c| format!("{:+.1} %", 100.0 * c))
            )
        });
        let given: Vec<String> = self
            .given
            .iter()
            .map(|g| format!("{}@{:.1}", g.name, g.t_s))
            .collect();
        format!(
            "{:7} {:22} {:5} {:24} {:30} {:?} {}",
            self.motor,
            case,
            if self.fault.is_none() {
                if self.given.is_empty() {
                    "ok"
                } else {
                    "NAMED"
                }
            } else if self.right() {
                "ok"
            } else {
                "miss"
            },
            named,
            given.join(" "),
            self.spread.map(|x| (x * 1e5).round() / 1e5),
            self.verdict
        )
    }
}

/// The parameter file a user would write from a nameplate, off the machine: Rs +20 %, Rr
/// -20 %, Lm -5 % (the leakages kept).
fn nameplate_off(p: &ParamFile) -> ParamFile {
    let mut n = *p;
    n.motor.rs_ohm *= 1.2;
    n.motor.rr_ohm *= 0.8;
    let lm = 0.05 * n.motor.lm_h;
    n.motor.lm_h -= lm;
    n.motor.ls_h -= lm;
    n.motor.lr_h -= lm;
    n
}

/// One service log of machine `p` (seed `seed`, `fault` at [`FAULT_AT_S`]), the monitor
/// told `nominal`.
fn run_with(
    motor: &'static str,
    p: &ParamFile,
    nominal: &ParamFile,
    fault: Option<(Fault, f64)>,
    seed: u64,
) -> CaseOutcome {
    let mut sc = moving_load(p, seed, DURATION_S, RATE_HZ);
    if let Some((f, change)) = fault {
        sc.faults.push(FaultSpec::at_change(f, FAULT_AT_S, change));
    }
    let opts = ReplayOptions {
        commission: Some(MOVING_COMMISSION),
        ..Default::default()
    };
    let replay = simulate_and_replay(p, nominal, &sc, opts, |_, _| {}).expect("runs");
    let given = replay.isolation_names().to_vec();
    let r = replay.finish();
    CaseOutcome {
        motor,
        fault,
        named: r.isolation.named,
        size: r.isolation.named_change,
        given,
        verdict: format!("{:?}", r.isolation.said)
            .chars()
            .take(110)
            .collect(),
        spread: r.isolation.spread,
    }
}

/// Runs the cases (motor index, fault) and prints the table; returns the outcomes. `off`:
/// the monitor is told [`nameplate_off`]'s parameters.
fn table(cases: &[(usize, Option<(Fault, f64)>)], off: bool) -> Vec<CaseOutcome> {
    let ms = motors();
    let out: Vec<CaseOutcome> = cases
        .par_iter()
        .enumerate()
        .map(|(k, &(m, fault))| {
            let (name, p) = &ms[m];
            let nominal = if off { nameplate_off(p) } else { *p };
            run_with(name, p, &nominal, fault, 900 + k as u64)
        })
        .collect();
    eprintln!(
        "{:7} {:22} {:5} {:24} {:30} verdict",
        "motor", "case", "", "named at the end", "names given@t_s"
    );
    for o in &out {
        eprintln!("{}", o.row());
    }
    let faulty: Vec<&CaseOutcome> = out.iter().filter(|o| o.fault.is_some()).collect();
    let right = faulty.iter().filter(|o| o.right()).count();
    let wrong = out.iter().filter(|o| !o.wrong().is_empty()).count();
    eprintln!(
        "named alone with the size within 25 %: {right} of {} ({:.0} %); logs with a wrong name: {wrong} of {}",
        faulty.len(),
        100.0 * right as f64 / faulty.len().max(1) as f64,
        out.len()
    );
    out
}

/// The bar's failures, in words.
fn bar_failures(out: &[CaseOutcome]) -> Vec<String> {
    let faulty = out.iter().filter(|o| o.fault.is_some()).count();
    let right = out.iter().filter(|o| o.right()).count();
    let mut bad: Vec<String> = out
        .iter()
        .filter(|o| !o.wrong().is_empty())
        .map(|o| format!("wrong name: {}", o.row()))
        .collect();
    if 10 * right < 9 * faulty {
        bad.push(format!("named alone: {right} of {faulty}, below 90 %"));
    }
    bad
}

#[test]
fn service_logs_of_the_2p2kw_motor_a_subset() {
    let cases: Vec<(usize, Option<(Fault, f64)>)> = [
        None,
        Some((Fault::Rs, 0.5)),
        Some((Fault::Rr, 0.2)),
        Some((Fault::Ls, -0.5)),
        Some((Fault::Lr, 0.5)),
        Some((Fault::SpeedSensor, 0.05)),
        Some((Fault::VoltageSensor, -0.05)),
    ]
    .into_iter()
    .map(|f| (1, f))
    .collect();
    let out = table(&cases, false);
    // No wrong name, the healthy log names nothing, and at least 5 of the 6 faults named
    // (measured: all but Rr +20 %, which this seed leaves shared with the speed sensor at
    // p 0.51 / 0.49).
    let wrong: Vec<String> = out
        .iter()
        .filter(|o| !o.wrong().is_empty())
        .map(CaseOutcome::row)
        .collect();
    assert!(wrong.is_empty(), "{wrong:#?}");
    let right = out.iter().filter(|o| o.right()).count();
    assert!(right >= 5, "{right} of 6 named");
}

#[test]
fn service_logs_of_three_motors_every_fault() {
    if !full_sweeps() {
        return;
    }
    let cases = every_case();
    let out = table(&cases, false);
    let bad = bar_failures(&out);
    assert!(bad.is_empty(), "{bad:#?}");
}

/// The same service logs with the parameter file off the machine as a nameplate's would be
/// (Rs +20 %, Rr -20 %, Lm -5 %: [`nameplate_off`]), commissioned over the load range as
/// before. The bar here is honesty: no wrong name at any time, and the healthy logs name
/// nothing; how many faults are still named alone is printed (docs/isolation.md, "Service
/// logs").
#[test]
fn service_logs_with_a_nameplate_that_is_off_name_nothing_wrong() {
    if !full_sweeps() {
        return;
    }
    let cases = every_case();
    let out = table(&cases, true);
    let wrong: Vec<String> = out
        .iter()
        .filter(|o| !o.wrong().is_empty())
        .map(CaseOutcome::row)
        .collect();
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// An hour of the 2.2 kW machine at 2 kHz (the log was 10 kHz; 2 kHz keeps the
/// isolation's 0.1 s blocks and the 2 Hz sequence filters as they are, at a fifth of the
/// cost): commissioned over 60-500 s at the file's load, the viscous load stepped to 0.7,
/// 1.2 and 0.9 x Bl at 10, 25 and 40 min, and Rr +20 % at 50 min. The fault is named with
/// its size after 50 min; nothing is named before it: with the load an unknown input (the
/// replay's default) each load step is a load move, listed as an event with its time. About 10 s in the test profile; with `MONITOR_FULL_SWEEPS=1`.
#[test]
fn an_hour_with_load_steps_and_a_rotor_fault_at_50_min() {
    if !full_sweeps() {
        return;
    }
    let p = ParamFile::reference_2p2kw();
    let mut sc = monitor_sim::Scenario::steady(3600.0, 2000.0);
    sc.sensors = monitor_sim::SensorSpec::default();
    sc.seed = 77;
    sc.load.steps = [(600.0, 0.7), (1500.0, 1.2), (2400.0, 0.9)]
        .map(|(t_s, k)| monitor_sim::LoadStep {
            t_s,
            torque_nm: None,
            bl_scale: Some(k),
        })
        .to_vec();
    sc.faults.push(FaultSpec::at_change(Fault::Rr, 3000.0, 0.2));
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(60.0, 500.0)),
        ..Default::default()
    };
    let replay = simulate_and_replay(&p, &p, &sc, opts, |_, _| {}).expect("runs");
    let given = replay.isolation_names().to_vec();
    let r = replay.finish();
    eprintln!(
        "names given: {given:?}\nnamed at the end: {:?} {:?}\nverdict: {:?}\n{}",
        r.isolation.named,
        r.isolation.named_change,
        r.isolation.said,
        serde_json::to_string(&r.verdict).unwrap_or_default()
    );
    // The load is an unknown input (the replay's default): the load steps are load moves,
    // never names, not even the friction class b/bl (the paper's model's reading of a load
    // change). Only Rr is named, after the fault.
    assert!(
        given
            .iter()
            .all(|g| g.name == IsolationName::Fault(Fault::Rr) && g.t_s >= 3000.0),
        "{given:?}"
    );
    // Each load step is reported as a load move within a few seconds of it (the steady
    // average after it: settling and half a second of averaging).
    let moves: Vec<f64> = r
        .isolation
        .events
        .iter()
        .filter_map(|e| match e {
            IsolationEvent::LoadMoved { t_s, .. } => Some(*t_s),
            IsolationEvent::Named { .. } => None,
        })
        .collect();
    eprintln!("load moves at {moves:?}");
    // Each listed where it began (within 0.2 s of its step).
    for step in [600.0, 1500.0, 2400.0] {
        assert!(
            moves.iter().any(|t| (*t - step).abs() <= 0.2),
            "no load move listed at the step at {step} s: {moves:?}"
        );
    }
    assert!(
        moves.len() <= 6,
        "load moves without a load step: {moves:?}"
    );
    assert_eq!(r.isolation.named, Some(IsolationName::Fault(Fault::Rr)));
    let size = f64::from(r.isolation.named_change.unwrap_or(f32::NAN));
    assert!((size - 0.2).abs() <= 0.25 * 0.2, "size {size}");
}
