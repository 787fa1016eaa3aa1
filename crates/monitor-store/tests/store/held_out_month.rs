//! The held-out month (issue 65): three motors (the 3 hp and 2.2 kW reference machines and
//! Krause's 50 hp one), one 6 s log a day for 30 days, **no temperature channel**, the
//! windings 10 to 30 K warmer than the parameter file with the season, the load wandering
//! from day to day (a random walk between 0.85 and 1.15 of Bl, its own per motor), and one
//! motor's connection loosening (Rs +0.5 % a day from day 10: +10 % on day 30). Each day's
//! logs are judged against the parameter file, stored, and the trend is taken on the logs
//! up to that day. Unlike `trend_month.rs` (a probe on every winding, the season's and the
//! load's laws sines), nothing here was used to choose the trend's settings.
//!
//! Asserted (issue 65's bar), for the loosening connection on each of the three machines in
//! turn:
//! - the trend alarms it by day 25 and at least 5 days before the first single log whose
//!   verdict is FAULT, on the stator's resistance beyond the rotor's (Rs alone: not heating);
//! - once raised the alarm holds on every later day;
//! - the healthy motors raise no alarm on any day;
//! - every motor's first days (before the connection loosens) lie in the green band of the
//!   trend taken on day 30 (within `k` reference scatters of its reference) on the
//!   indicators that alarm here (|I2w|/|I1|, Rs beyond Rr), healthy motors' and the loosening
//!   one's alike;
//! - no single log names a fault other than Rs.

use monitor_io::params::ParamFile;
use monitor_replay::ReplayOptions;
use monitor_sim::{EffectSpec, FaultSpec, LoadSpec, Scenario};
use monitor_store::trend::{self, TrendOptions};
use monitor_store::{LogIdentity, Store, StoredRow};
use monitor_testkit::small_motor;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::f64::consts::TAU;

const DAYS: u32 = 30;
/// 2026-06-01 00:00 UTC; each log at 14:00.
const START_S: i64 = 1_780_272_000 + 14 * 3600;

struct Motor {
    name: &'static str,
    params: ParamFile,
    loosening: bool,
    /// The season's phase [rad].
    phase: f64,
    /// The day's load as a fraction of Bl, days 1..=30.
    loads: Vec<f64>,
}

/// A random walk of the load, kept within 0.85..1.15 of Bl.
fn wandering_load(seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut x: f64 = 1.0;
    (0..DAYS)
        .map(|_| {
            x = (x + rng.gen_range(-0.08..0.08)).clamp(0.85, 1.15);
            x
        })
        .collect()
}

fn motors(loosening: usize, seed: u64) -> Vec<Motor> {
    let machines = [
        ("3hp", ParamFile::reference_3hp()),
        ("2p2kw", ParamFile::reference_2p2kw()),
        ("50hp", small_motor::krause_50hp()),
    ];
    machines
        .into_iter()
        .enumerate()
        .map(|(k, (name, params))| Motor {
            name,
            params,
            loosening: k == loosening,
            phase: 1.3 + 2.1 * k as f64 + 0.7 * seed as f64,
            loads: wandering_load(seed * 10 + k as u64),
        })
        .collect()
}

/// The windings' rise above the parameter file's temperature on `day` [K]: 10 to 30 K.
fn rise_k(m: &Motor, day: u32) -> f64 {
    20.0 + 10.0 * (TAU * f64::from(day) / 33.0 + m.phase).sin()
}

fn day_log(m: &Motor, day: u32, seed: u64) -> Scenario {
    let p = &m.params;
    let mut sc = Scenario::steady(6.0, 5000.0);
    sc.seed = seed;
    sc.load = LoadSpec {
        bl_nms: Some(p.motor.bl_nms * m.loads[day as usize - 1]),
        ..LoadSpec::default()
    };
    let toml = format!(
        "name = \"thermal_drift\"\nrise_k = {}\ntau_s = 0.5\nat_s = 0.0\n",
        rise_k(m, day)
    );
    sc.effects
        .push(toml::from_str::<EffectSpec>(&toml).expect("effect"));
    if m.loosening && day > 10 {
        sc.faults.push(FaultSpec::parametric(
            monitor_core::Fault::Rs,
            0.0,
            0.005 * f64::from(day - 10),
        ));
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
        motor: m.name.to_string(),
        path: format!("held_out/{}/{day:02}.csv", m.name),
        hash: monitor_store::content_hash(format!("{} {day} {seed}", m.name).as_bytes()),
        time_s: START_S + i64::from(day - 1) * 86_400,
    };
    StoredRow::from_diagnose(&id, &doc)
}

/// Per day 1..=30: whether the trend of the motor's logs up to that day alarms, and the
/// alarmed indicators with their reasons ("stator_excess_pct: Slope { .. }").
fn alarms(rows: &[StoredRow], motor: &str) -> Vec<(bool, Vec<String>)> {
    (1..=DAYS)
        .map(|day| {
            let end = (START_S + i64::from(day) * 86_400) as f64;
            let upto: Vec<&StoredRow> = rows
                .iter()
                .filter(|r| r.str("motor") == Some(motor))
                .filter(|r| r.f64("log_time_s").is_some_and(|t| t < end))
                .collect();
            let t = trend::motor_trend(motor, &upto, &TrendOptions::default());
            let said = t.indicators.iter().filter(|i| i.alarm);
            let said = said.map(|i| format!("{}: {:?}", i.indicator, i.reason));
            (t.alarm, said.collect())
        })
        .collect()
}

/// The points of days 1-10 of `motor` outside the green band of the trend taken on day 30
/// (more than `k` reference scatters from the reference centre), per indicator.
fn first_days_out_of_green(rows: &[StoredRow], motor: &str) -> Vec<String> {
    let mine: Vec<&StoredRow> = rows
        .iter()
        .filter(|r| r.str("motor") == Some(motor))
        .collect();
    let opts = TrendOptions::default();
    let t = trend::motor_trend(motor, &mine, &opts);
    let day10 = (START_S + 10 * 86_400) as f64 / 86_400.0;
    let mut bad = Vec::new();
    // The indicators that alarm here: without a temperature channel the residuals are
    // shown, not alarmed, and their normalisation on the isolation's rise leaves a few of
    // the first days 3-4 scatters out (printed, not asserted); the sideband is not drawn.
    let alarming = ["i2_over_i1", "stator_excess_pct"];
    for i in &t.indicators {
        let (Some(c), Some(s)) = (i.reference_centre, i.reference_scatter) else {
            continue;
        };
        let out = i
            .series
            .iter()
            .filter(|p| p.t_days < day10 && ((p.normalised - c) / s).abs() > opts.k_scatter)
            .count();
        if out > 0 && !alarming.contains(&i.indicator.as_str()) {
            eprintln!("{motor}: {out} of its first 10 days' {} outside the green band (shown, not alarmed)", i.indicator);
        } else if out > 0 {
            bad.push(format!(
                "{motor}: {out} of its first 10 days' {} outside the green band",
                i.indicator
            ));
        }
    }
    bad
}

/// The month with the loosening connection on machine `loosening`; what broke the bar.
fn month(loosening: usize, seed: u64) -> Vec<String> {
    let motors = motors(loosening, seed);
    let cases: Vec<(usize, u32)> = (0..motors.len())
        .flat_map(|m| (1..=DAYS).map(move |d| (m, d)))
        .collect();
    let judged: Vec<StoredRow> = cases
        .par_iter()
        .map(|&(m, d)| judge(&motors[m], d, seed * 1000 + 100 * m as u64 + u64::from(d)))
        .collect();
    let dir = tempfile::tempdir().expect("tmp");
    let mut store = Store::open(&dir.path().join("held_out.db")).expect("store");
    for r in &judged {
        store.append(r).expect("append");
    }
    let rows = store.rows(None, None).expect("rows");
    let mut bad = Vec::new();
    for r in &rows {
        for col in ["fault", "isolation_named"] {
            if let Some(f) = r.str(col).filter(|f| *f != "rs") {
                bad.push(format!("{}: a single log's {col} is {f}", r.log_id()));
            }
        }
    }
    for m in &motors {
        bad.extend(first_days_out_of_green(&rows, m.name));
        let days = alarms(&rows, m.name);
        let first_alarm = days.iter().position(|d| d.0).map(|i| i as u32 + 1);
        let first_fault = rows
            .iter()
            .filter(|r| r.str("motor") == Some(m.name))
            .position(|r| r.str("verdict") == Some("fault"))
            .map(|i| i as u32 + 1);
        eprintln!(
            "seed {seed}, {} (loosening: {}): first trend alarm on day {first_alarm:?}, \
             first FAULT verdict on day {first_fault:?}",
            m.name, m.loosening
        );
        if let Some(a) = first_alarm {
            for s in &days[a as usize - 1].1 {
                eprintln!("    {s}");
            }
        }
        if !m.loosening {
            if let Some(a) = first_alarm {
                bad.push(format!(
                    "{}: healthy, alarmed on day {a}: {:?}",
                    m.name,
                    days[a as usize - 1].1
                ));
            }
            continue;
        }
        let Some(a) = first_alarm else {
            bad.push(format!(
                "{}: the loosening connection is never alarmed",
                m.name
            ));
            continue;
        };
        if a > 25 || first_fault.is_some_and(|f| a + 5 > f) {
            bad.push(format!(
                "{}: alarm on day {a}, FAULT verdict on day {first_fault:?}",
                m.name
            ));
        }
        if let Some(gone) = days[a as usize..].iter().position(|d| !d.0) {
            bad.push(format!(
                "{}: the alarm of day {a} is gone on day {}",
                m.name,
                a + 1 + gone as u32
            ));
        }
        if !days[a as usize - 1]
            .1
            .iter()
            .any(|s| s.starts_with("stator_excess_pct:"))
        {
            bad.push(format!(
                "{}: alarmed, but not on Rs beyond Rr: {:?}",
                m.name,
                days[a as usize - 1].1
            ));
        }
    }
    bad
}

#[test]
fn a_loosening_connection_is_alarmed_early_on_each_machine_and_no_healthy_motor() {
    let bad: Vec<String> = (0..3).flat_map(|k| month(k, 1 + k as u64)).collect();
    assert!(bad.is_empty(), "{bad:#?}");
}
