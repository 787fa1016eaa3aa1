//! Issue 79, "a trend that alarms on what the logs show": ten dated copies of the real ITSC
//! bench's recordings (examples/recordings/itsc: a 0.75 hp motor, currents only, 1 kHz;
//! four healthy, then phase c's shorted turns growing from 10 % to 40 %), stored day by day
//! with `sim-host fleet --store` and read back with `sim-host trend`.
//!
//! Before: every log from the first short on said FAULT, and `trend` said "no alarm yet (10
//! logs; the operating-point fit needs 16)"; it printed and drew the parity residuals and
//! Rs beyond Rr, which logs without voltages cannot measure, as flat lines at zero. Now the
//! FAULT level on two logs in a row alarms whatever the fit needs (one FAULT log alone does
//! not), and an indicator no log measured is absent from the row (null), the table, the
//! JSON and the plot.

use assert_cmd::Command;
use monitor_store::{Store, StoredRow};
use std::path::{Path, PathBuf};

/// The bench's recordings, in the order of the days: four healthy runs (the two healthy
/// recordings twice), then phase c's shorts, 10 % of its turns to 40 %.
const LOGS: [&str; 10] = [
    "SC_HLT_001",
    "SC_HLT_002",
    "SC_HLT_001",
    "SC_HLT_002",
    "SC_A0_B0_C1_001",
    "SC_A0_B0_C1_002",
    "SC_A0_B0_C2_001",
    "SC_A0_B0_C2_002",
    "SC_A0_B0_C3_001",
    "SC_A0_B0_C4_001",
];

/// The indicators these logs cannot measure (no voltages: no isolation, no resistances).
const UNMEASURED: [&str; 4] = [
    "residual_d",
    "residual_q",
    "residual_t",
    "stator_excess_pct",
];

fn itsc() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/recordings/itsc")
}

fn sim_host() -> Command {
    Command::cargo_bin("sim-host").expect("sim-host")
}

/// The ten copies in `dir`, named by their day (`bench_20261101.csv`, ...), and the motor
/// table dating them by name.
fn setup(dir: &Path) -> (PathBuf, Vec<PathBuf>) {
    let logs: Vec<PathBuf> = LOGS
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let to = dir.join(format!("bench_202611{:02}.csv", k + 1));
            std::fs::copy(itsc().join(format!("{name}.csv")), &to).expect("copy");
            to
        })
        .collect();
    let table = dir.join("motors.toml");
    std::fs::write(
        &table,
        format!(
            "[[motor]]\nname = \"bench\"\nparams = \"{}\"\nlogs = \"bench_*\"\ntime_from_name = \"bench_%Y%m%d\"\n",
            itsc().join("baldor_0p75hp.toml").display()
        ),
    )
    .expect("table");
    (table, logs)
}

/// `sim-host fleet TABLE LOGS --store DB`.
fn store(table: &Path, logs: &[PathBuf], db: &Path) {
    let out = sim_host()
        .arg("fleet")
        .arg(table)
        .args(logs)
        .arg("--store")
        .arg(db)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `sim-host trend --store DB --json`'s one motor.
fn trend(db: &Path) -> serde_json::Value {
    let out = sim_host()
        .args(["trend", "--json", "--store"])
        .arg(db)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    doc["motors"][0].clone()
}

fn indicator<'a>(m: &'a serde_json::Value, column: &str) -> Option<&'a serde_json::Value> {
    m["indicators"]
        .as_array()
        .expect("indicators")
        .iter()
        .find(|i| i["indicator"] == column)
}

/// The stored rows, by day.
fn rows(db: &Path) -> Vec<StoredRow> {
    let mut rows = Store::open_existing(db)
        .and_then(|s| s.rows(None, None))
        .expect("the store");
    rows.sort_by_key(|r| r.str("day").unwrap_or_default().to_string());
    rows
}

#[test]
fn the_bench_s_shorts_alarm_by_the_second_fault_log_and_not_on_the_first() {
    let dir = tempfile::tempdir().expect("tmp");
    let (table, logs) = setup(dir.path());
    let db = dir.path().join("h.db");
    // The premise: the healthy runs are not FAULT, every short is (what the logs show).
    store(&table, &logs[..5], &db);
    let verdicts: Vec<String> = rows(&db)
        .iter()
        .map(|r| r.str("verdict").unwrap_or_default().to_string())
        .collect();
    assert!(
        verdicts[..4].iter().all(|v| v != "fault") && verdicts[4] == "fault",
        "{verdicts:?}"
    );
    // One FAULT log: no alarm by itself.
    let m = trend(&db);
    assert_eq!(m["alarm"], false, "{:#}", m["indicators"]);
    let i2 = indicator(&m, "i2_over_i1").expect("i2_over_i1");
    assert_eq!(i2["reason"]["kind"], "fault_level_not_confirmed", "{i2:#}");

    // The second FAULT log raises the alarm, with 6 logs where the fit needs 16.
    store(&table, &logs[5..6], &db);
    let m = trend(&db);
    assert_eq!(m["alarm"], true, "{:#}", m["indicators"]);
    let i2 = indicator(&m, "i2_over_i1").expect("i2_over_i1");
    assert_eq!(i2["alarm"], true);
    assert_eq!(i2["operating_point_fitted"], false);
    assert_eq!(i2["alarm_since"], "2026-11-06");
    assert_eq!(i2["reason"]["kind"], "fault_level_in_a_row", "{i2:#}");
    assert_eq!(i2["reason"]["logs"], 2);
    assert_eq!(i2["reason"]["first_day"], "2026-11-05");
    let s = i2["sentence"].as_str().expect("sentence");
    assert!(s.contains("TREND ALARM"), "{s}");

    // All ten: every short is at the FAULT level, the alarm stands on the six.
    store(&table, &logs[6..], &db);
    let m = trend(&db);
    assert_eq!(m["alarm"], true);
    let i2 = indicator(&m, "i2_over_i1").expect("i2_over_i1");
    assert_eq!(i2["reason"]["kind"], "fault_level_in_a_row", "{i2:#}");
    assert_eq!(i2["reason"]["logs"], 6);
    assert_eq!(i2["alarm_since"], "2026-11-06");
}

#[test]
fn what_the_logs_cannot_measure_is_absent_not_zero() {
    let dir = tempfile::tempdir().expect("tmp");
    let (table, logs) = setup(dir.path());
    let db = dir.path().join("h.db");
    store(&table, &logs, &db);
    // The store: null in SQLite ...
    let stored = rows(&db);
    assert_eq!(stored.len(), 10);
    for r in &stored {
        for c in UNMEASURED.iter().chain(&["deviation_sigma"]) {
            assert_eq!(r.f64(c), None, "{c} of {}", r.log_id());
        }
        assert!(r.f64("i2_over_i1").is_some(), "{}", r.log_id());
    }
    // ... and in the Parquet mirror.
    let mut files = Vec::new();
    let mut dirs = vec![PathBuf::from(format!("{}.parquet", db.display()))];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).expect("mirror") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "parquet") {
                files.push(p);
            }
        }
    }
    assert_eq!(files.len(), 10, "{files:?}");
    for f in &files {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        use parquet::record::Field;
        let reader = SerializedFileReader::new(std::fs::File::open(f).expect("open"))
            .expect("a Parquet file");
        for row in reader.get_row_iter(None).expect("rows") {
            let row = row.expect("a row");
            for (name, field) in row.get_column_iter() {
                if UNMEASURED.contains(&name.as_str()) {
                    assert_eq!(field, &Field::Null, "{name} in {}", f.display());
                }
                if name == "i2_over_i1" {
                    assert!(matches!(field, Field::Double(_)), "{field:?}");
                }
            }
        }
    }
    // The trend: neither in the JSON nor in the table nor in the plot.
    let m = trend(&db);
    for c in UNMEASURED {
        assert!(indicator(&m, c).is_none(), "{c}: {:#}", m["indicators"]);
    }
    assert!(indicator(&m, "i2_over_i1").is_some());
    let svg = dir.path().join("bench.svg");
    let out = sim_host()
        .args(["trend", "--motor", "bench", "--store"])
        .arg(&db)
        .arg("--plot")
        .arg(&svg)
        .output()
        .expect("runs");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for c in UNMEASURED {
        assert!(!text.contains(c), "{c} in the table:\n{text}");
    }
    assert!(text.contains("i2_over_i1"), "{text}");
    let svg = std::fs::read_to_string(&svg).expect("svg");
    assert!(svg.contains("|I2w|/|I1|"), "the negative sequence's panel");
    for title in ["e_d [", "e_q [", "e_T [", "Rs beyond Rr ["] {
        assert!(!svg.contains(title), "a panel {title} in the plot");
    }
}
