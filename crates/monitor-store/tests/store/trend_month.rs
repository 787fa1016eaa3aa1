//! The simulated month (issue 53): a dozen motors of three sizes (the 3 hp and 2.2 kW
//! reference machines and Krause's 50 hp one, four of each), one 6 s log a day for 30 days,
//! the load moving from day to day (0.85 to 1.15 of the motor's Bl), the season warming and
//! cooling the windings by 20 K (a rise of 5 to 25 K above the parameter file's
//! temperature, a sine over the month, a phase of its own per motor). One motor has a
//! loosening connection (Rs +0.5 % a day from day 10: the simulator's parametric Rs fault),
//! one a growing short (the simulator's shorted-turn loop in phase a, 0.25 % of the turns a
//! day from day 15), the rest are healthy. Each day's logs are judged against the parameter
//! file, stored, and the trend is taken on the logs up to that day.
//!
//! The motors carry a winding temperature probe (the simulator's `t_winding_c` channel,
//! read without lag): the season's heating raises Rs as much as the loosening connection
//! does, and only a measured temperature tells them apart (the isolation's own reading of
//! the rise takes up part of an Rs change).
//!
//! Asserted (issue 53's bar): each faulty motor is trend-alarmed at least 5 days before the
//! first single log whose verdict is FAULT (or within the month where no log's verdict is
//! FAULT); no healthy motor raises a trend alarm on any day. Four more months, each with
//! its own noise, under `MONITOR_FULL_SWEEPS=1`. Set `MONITOR_MONTH_STORE=PATH` to keep the
//! month's store (the docs' plot: `sim-host trend --store PATH --plot ...`).

use monitor_testkit::small_motor;

use monitor_io::params::ParamFile;
use monitor_replay::ReplayOptions;
use monitor_sim::{EffectSpec, FaultSpec, LoadSpec, Scenario, SensorSpec};
use monitor_store::trend::{self, TrendOptions};
use monitor_store::{LogIdentity, Store, StoredRow};
use rayon::prelude::*;
use std::f64::consts::TAU;

const DAYS: u32 = 30;
/// 2026-11-01 00:00 UTC, the month's first day; each log at 06:00.
const START_S: i64 = 1_793_491_200 + 6 * 3600;

#[derive(Clone, Copy, PartialEq, Debug)]
enum Health {
    Healthy,
    Loosening,
    Short,
}

struct Motor {
    name: String,
    params: ParamFile,
    health: Health,
    phase: f64,
}

fn motors() -> Vec<Motor> {
    let sizes = [
        ("3hp", ParamFile::reference_3hp()),
        ("2p2kw", ParamFile::reference_2p2kw()),
        ("50hp", small_motor::krause_50hp()),
    ];
    let mut v = Vec::new();
    for k in 0..4 {
        for (s, (size, p)) in sizes.iter().enumerate() {
            let health = match (k, s) {
                (0, 0) => Health::Loosening,
                (0, 1) => Health::Short,
                _ => Health::Healthy,
            };
            v.push(Motor {
                name: format!("{size}_{k}"),
                params: *p,
                health,
                phase: 0.9 * f64::from(k) + 0.4 * s as f64,
            });
        }
    }
    v
}

/// The windings' rise above the parameter file's temperature on `day` [K]: 5 to 25 K.
fn season_rise_k(m: &Motor, day: u32) -> f64 {
    15.0 + 10.0 * (TAU * f64::from(day) / f64::from(DAYS) + m.phase).sin()
}

/// The day's load as a fraction of Bl: 0.85 to 1.15, moving from day to day.
fn load(m: &Motor, day: u32) -> f64 {
    1.0 + 0.15 * (2.3 * f64::from(day) + 3.0 * m.phase).sin()
}

fn day_log(m: &Motor, day: u32, seed: u64) -> Scenario {
    let p = &m.params;
    let mut sc = Scenario::steady(6.0, 4000.0);
    sc.seed = seed;
    sc.sensors = SensorSpec {
        temperature: Some(monitor_sim::TemperatureSpec {
            tau_s: 0.0,
            ..monitor_sim::TemperatureSpec::default()
        }),
        ..SensorSpec::default()
    };
    sc.load = LoadSpec {
        bl_nms: Some(p.motor.bl_nms * load(m, day)),
        ..LoadSpec::default()
    };
    let toml = format!(
        "name = \"thermal_drift\"\nrise_k = {}\ntau_s = 0.2\nat_s = 0.0\n",
        season_rise_k(m, day)
    );
    sc.effects
        .push(toml::from_str::<EffectSpec>(&toml).expect("effect"));
    match m.health {
        Health::Loosening if day > 10 => sc.faults.push(FaultSpec::parametric(
            monitor_core::Fault::Rs,
            0.0,
            0.005 * f64::from(day - 10),
        )),
        Health::Short if day >= 15 => sc.effects.push(EffectSpec::PhaseAsymmetry {
            phase: monitor_core::Phase::A,
            fraction: 0.0025 * f64::from(day - 14),
            fault_resistance_ohm: None,
        }),
        _ => {}
    }
    sc
}

fn judge(m: &Motor, day: u32, seed: u64) -> StoredRow {
    let sc = day_log(m, day, seed);
    let report = monitor_studies::experiment::simulate_and_replay(
        &m.params,
        &m.params,
        &sc,
        ReplayOptions::default(),
        |_, _| {},
    )
    .expect("runs")
    .finish();
    let doc = serde_json::to_value(&report).expect("json");
    let id = LogIdentity {
        motor: m.name.clone(),
        path: format!("month/{}/day{day:02}.csv", m.name),
        hash: monitor_store::content_hash(format!("{} {day} {seed}", m.name).as_bytes()),
        time_s: START_S + i64::from(day - 1) * 86_400,
    };
    StoredRow::from_diagnose(&id, &doc)
}

/// The first day on which the trend of the logs up to that day alarms for `motor`, with the
/// alarmed indicators.
fn first_alarm(rows: &[StoredRow], motor: &str) -> Option<(u32, Vec<String>)> {
    let opts = TrendOptions::default();
    (1..=DAYS).find_map(|day| {
        let upto: Vec<&StoredRow> = rows
            .iter()
            .filter(|r| r.str("motor") == Some(motor))
            .filter(|r| r.f64("log_time_s").unwrap() < (START_S + i64::from(day) * 86_400) as f64)
            .collect();
        let t = trend::motor_trend(motor, &upto, &opts);
        t.alarm.then(|| {
            (
                day,
                t.indicators
                    .iter()
                    .filter(|i| i.alarm)
                    .map(|i| format!("{}: {:?}", i.indicator, i.reason))
                    .collect(),
            )
        })
    })
}

/// |I2w|/|I1|'s days to its FAULT level as of `day` for `motor`: the whole window's line's
/// and the window's second half's (`days_to_fault`, `days_to_fault_recent`).
fn projection(rows: &[StoredRow], motor: &str, day: u32) -> (Option<f64>, Option<f64>) {
    let upto: Vec<&StoredRow> = rows
        .iter()
        .filter(|r| r.str("motor") == Some(motor))
        .filter(|r| r.f64("log_time_s").unwrap() < (START_S + i64::from(day) * 86_400) as f64)
        .collect();
    let t = trend::motor_trend(motor, &upto, &TrendOptions::default());
    t.indicators
        .iter()
        .find(|i| i.indicator == "i2_over_i1")
        .map_or((None, None), |i| (i.days_to_fault, i.days_to_fault_recent))
}

/// The days after `from` (to the month's end) on which the trend of the logs up to the day
/// does not alarm `motor`: none once an alarm is raised (it holds until the indicator is
/// back at the motor's reference; before issue 65 the loosening connection's alarm of day
/// 29 was gone on day 30).
fn dropped_after(rows: &[StoredRow], motor: &str, from: u32) -> Vec<u32> {
    let opts = TrendOptions::default();
    (from + 1..=DAYS)
        .filter(|day| {
            let upto: Vec<&StoredRow> = rows
                .iter()
                .filter(|r| r.str("motor") == Some(motor))
                .filter(|r| {
                    r.f64("log_time_s").unwrap() < (START_S + i64::from(*day) * 86_400) as f64
                })
                .collect();
            !trend::motor_trend(motor, &upto, &opts).alarm
        })
        .collect()
}

/// The month's verdicts and alarms: per motor, its health, the first FAULT verdict's day,
/// the first trend alarm's day with its indicators, |I2w|/|I1|'s projections on that
/// day ([`projection`]), and the later days the alarm was not held ([`dropped_after`]).
type Outcome = Vec<(
    String,
    Health,
    Option<u32>,
    Option<(u32, Vec<String>)>,
    (Option<f64>, Option<f64>),
    Vec<u32>,
)>;

fn the_month(seed: u64) -> Outcome {
    let started = std::time::Instant::now();
    let motors = motors();
    let seed0 = seed;
    let cases: Vec<(usize, u32)> = (0..motors.len())
        .flat_map(|m| (1..=DAYS).map(move |d| (m, d)))
        .collect();
    let rows: Vec<StoredRow> = cases
        .par_iter()
        .map(|&(m, day)| judge(&motors[m], day, seed0 + 1000 * m as u64 + u64::from(day)))
        .collect();
    let dir = tempfile::tempdir().expect("tmp");
    let path = match std::env::var_os("MONITOR_MONTH_STORE") {
        Some(p) => std::path::PathBuf::from(p),
        None => dir.path().join("month.db"),
    };
    let mut store = Store::open(&path).expect("store");
    for r in &rows {
        store.append(r).expect("append");
    }
    let rows = store.rows(None, None).expect("rows");
    assert_eq!(rows.len(), motors.len() * DAYS as usize);
    let mut out = Vec::new();
    for m in &motors {
        let mine: Vec<&StoredRow> = rows
            .iter()
            .filter(|r| r.str("motor") == Some(&m.name))
            .collect();
        let first_fault = mine
            .iter()
            .position(|r| r.str("verdict") == Some("fault"))
            .map(|i| i as u32 + 1);
        let alarm = first_alarm(&rows, &m.name);
        eprintln!(
            "{} ({:?}): first FAULT verdict on day {:?}, first trend alarm on day {:?}",
            m.name,
            m.health,
            first_fault,
            alarm.as_ref().map(|a| a.0)
        );
        for s in alarm.iter().flat_map(|a| a.1.iter()) {
            eprintln!("    {s}");
        }
        let projected = alarm
            .as_ref()
            .map_or((None, None), |a| projection(&rows, &m.name, a.0));
        let dropped = alarm
            .as_ref()
            .map_or(Vec::new(), |a| dropped_after(&rows, &m.name, a.0));
        out.push((
            m.name.clone(),
            m.health,
            first_fault,
            alarm,
            projected,
            dropped,
        ));
    }
    eprintln!("the month: {:.1} s", started.elapsed().as_secs_f64());
    out
}

/// Whether `alarm` came at least 5 days before the first FAULT verdict (or within the
/// month where no verdict was FAULT).
fn early(alarm: &Option<(u32, Vec<String>)>, fault: Option<u32>) -> bool {
    match (alarm, fault) {
        (Some((a, _)), Some(f)) => a + 5 <= f,
        (Some(_), None) => true,
        (None, _) => false,
    }
}

/// Issue 53's bar on one month: each faulty motor alarmed early, no healthy motor alarmed,
/// the short on its negative sequence.
fn check(month: &Outcome) -> Vec<String> {
    let mut bad: Vec<String> = month
        .iter()
        .filter(|m| match m.1 {
            Health::Healthy => m.3.is_some(),
            _ => !early(&m.3, m.2),
        })
        .map(|m| format!("{} ({:?}): alarm {:?}, FAULT {:?}", m.0, m.1, m.3, m.2))
        .collect();
    for m in month.iter().filter(|m| !m.5.is_empty()) {
        bad.push(format!(
            "{}: alarmed on day {:?}, not on the later days {:?}",
            m.0,
            m.3.as_ref().map(|a| a.0),
            m.5
        ));
    }
    let on_i2 = |a: &Option<(u32, Vec<String>)>| {
        a.as_ref()
            .is_some_and(|a| a.1.iter().any(|s| s.starts_with("i2_over_i1")))
    };
    if !month.iter().any(|m| m.1 == Health::Short && on_i2(&m.3)) {
        bad.push("the short is not alarmed on |I2w|/|I1|".into());
    }
    // The short began inside the window and grows: the second half's slope must project
    // the FAULT verdict's day better than the whole window's line.
    for m in month.iter().filter(|m| m.1 == Health::Short) {
        if let (Some((a, _)), Some(f), (Some(whole), Some(recent))) = (&m.3, m.2, m.4) {
            let miss = |d: f64| (f64::from(*a) + d - f64::from(f)).abs();
            if miss(recent) >= miss(whole) {
                bad.push(format!(
                    "{}: the recent slope projects FAULT in {recent:.1} days, the window {whole:.1}, \
                     on day {a} with FAULT on day {f}",
                    m.0
                ));
            }
        } else if on_i2(&m.3) {
            bad.push(format!(
                "{}: no recent projection at the alarm: {:?}",
                m.0, m.4
            ));
        }
    }
    bad
}

#[test]
fn a_month_of_daily_logs_alarms_each_fault_early_and_no_healthy_motor() {
    let bad = check(&the_month(5_300_000));
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Four more months, each with its own noise (`MONITOR_FULL_SWEEPS=1`, about 20 s).
#[test]
fn four_more_months_of_noise_meet_the_same_bar() {
    if std::env::var("MONITOR_FULL_SWEEPS").map_or(true, |v| v != "1") {
        eprintln!("four more months: skipped (MONITOR_FULL_SWEEPS=1 runs them)");
        return;
    }
    let bad: Vec<String> = (1..=4)
        .flat_map(|k| {
            check(&the_month(k))
                .into_iter()
                .map(move |b| format!("seed {k}: {b}"))
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}
