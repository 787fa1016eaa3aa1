//! Issue 65, "a trend a planner can trust": a log's time in the store comes from the log
//! itself (a time column of ISO 8601 text or epoch seconds, a TDMS `wf_start_time`), else
//! from its file name by the motor table's `time_from_name`, and only then from the file's
//! modification time, which the run says. Every log here is written now, so its file's
//! modification time is today: a log that lands on its own day (2026-11-03) took its time
//! from the log.

use monitor_store::{Store, StoredRow};
use std::path::{Path, PathBuf};
use std::process::Command;

/// 2026-11-03T06:00:00Z in seconds since 1970-01-01 (`date -u -d 2026-11-03T06:00:00Z
/// +%s`), the start every log here says it has.
const START: i64 = 1_793_685_600;
/// Its day.
const DAY: &str = "2026-11-03";

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs/motulator_2p2kw_dol")
}

/// The example log's lines (header first), its time column rewritten by `time`.
fn rewritten(time: &dyn Fn(f64) -> String) -> String {
    let text = std::fs::read_to_string(example().with_extension("csv")).expect("example");
    let mut out = String::with_capacity(text.len() * 2);
    for (i, line) in text.lines().enumerate() {
        let (t, rest) = line.split_once(',').expect("a CSV line");
        if i == 0 {
            out.push_str(&format!("Time,{rest}\n"));
        } else {
            let t: f64 = t.parse().expect("t_s");
            out.push_str(&format!("{},{rest}\n", time(t)));
        }
    }
    out
}

/// The example's parameter file with `columns` appended, and a motor table of motor
/// `pump` (logs `pump_*`, and `extra` lines) in `dir`.
fn setup(dir: &Path, columns: &str, extra: &str) -> PathBuf {
    let params = std::fs::read_to_string(example().with_extension("toml")).expect("params");
    std::fs::write(dir.join("p.toml"), format!("{params}\n{columns}")).expect("write");
    let t = dir.join("motors.toml");
    std::fs::write(
        &t,
        format!("[[motor]]\nname = \"pump\"\nparams = \"p.toml\"\nlogs = \"pump_*\"\n{extra}"),
    )
    .expect("table");
    t
}

/// Runs `sim-host fleet TABLE LOGS --store DIR/h.db`: the stored rows by file name, and
/// stderr.
fn fleet(dir: &Path, table: &Path, logs: &[PathBuf]) -> (Vec<StoredRow>, String) {
    let store = dir.join("h.db");
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .arg("fleet")
        .arg(table)
        .args(logs)
        .arg("--store")
        .arg(&store)
        .output()
        .expect("sim-host runs");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    let rows = Store::open_existing(&store)
        .and_then(|s| s.rows(None, None))
        .expect("the store");
    assert_eq!(rows.len(), logs.len(), "{err}");
    (rows, err)
}

fn row_of<'a>(rows: &'a [StoredRow], name: &str) -> &'a StoredRow {
    rows.iter()
        .find(|r| r.str("log_path").is_some_and(|p| p.ends_with(name)))
        .unwrap_or_else(|| panic!("no row of {name}"))
}

/// The UTC day of the file's modification time (today, for a file written now).
fn modified_day(p: &Path) -> String {
    let m = std::fs::metadata(p)
        .and_then(|m| m.modified())
        .expect("mtime");
    let s = m.duration_since(std::time::UNIX_EPOCH).expect("after 1970");
    monitor_store::utc_day(s.as_secs() as i64)
}

#[test]
fn iso_and_epoch_time_columns_put_the_logs_on_their_own_day() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let table = setup(
        d,
        "[columns]\nt_s = { name = \"Time\", unit = \"timestamp\" }\n",
        "",
    );
    // 06:00:00 + t, with an offset of +02:00 (08:00 local), and as epoch seconds.
    let iso = d.join("pump_iso.csv");
    std::fs::write(
        &iso,
        rewritten(&|t| format!("2026-11-03T08:00:{:09.6}+02:00", t)),
    )
    .expect("write");
    let epoch = d.join("pump_epoch.csv");
    std::fs::write(&epoch, rewritten(&|t| format!("{:.6}", START as f64 + t))).expect("write");
    assert_ne!(
        modified_day(&iso),
        DAY,
        "the test needs a file written on another day"
    );
    let (rows, err) = fleet(d, &table, &[iso, epoch]);
    for name in ["pump_iso.csv", "pump_epoch.csv"] {
        let r = row_of(&rows, name);
        assert_eq!(r.str("day"), Some(DAY), "{name}: {err}");
        assert_eq!(r.f64("log_time_s"), Some(START as f64), "{name}");
        assert_eq!(r.str("time_source"), Some("log"), "{name}");
        assert_eq!(r.f64("rows"), Some(50_001.0), "{name}: every row read");
    }
    assert!(!err.contains("modification time"), "{err}");
}

#[test]
fn a_tdms_wf_start_time_is_the_logs_time() {
    use tdms_rs::{PropertyValue, TdmsWriter};
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let table = setup(d, "", "");
    let text = std::fs::read_to_string(example().with_extension("csv")).expect("example");
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for line in lines {
        for (c, x) in cols.iter_mut().zip(line.split(',')) {
            c.push(x.parse().expect("a number"));
        }
    }
    let log = d.join("pump_1.tdms");
    let mut w = TdmsWriter::create(&log).expect("create");
    let mut g = w.add_group("log").expect("group");
    for (name, vals) in names.iter().zip(&cols) {
        let mut ch = g.add_channel::<f64>(name.as_str()).expect("channel");
        ch.write(vals).expect("write");
        if name == "ia_A" {
            // Seconds since 1904-01-01 UTC (2 082 844 800 s before 1970) and a quarter
            // second as a fraction of 2^64.
            let t = (START + 2_082_844_800, 1u64 << 62);
            ch.add_property("wf_start_time", PropertyValue::TimeStamp(t))
                .expect("property");
        }
    }
    drop(g);
    w.close().expect("close");
    let (rows, err) = fleet(d, &table, std::slice::from_ref(&log));
    let r = row_of(&rows, "pump_1.tdms");
    assert_eq!(r.str("day"), Some(DAY), "{err}");
    assert_eq!(r.f64("log_time_s"), Some(START as f64));
    assert_eq!(r.str("time_source"), Some("tdms"));
}

#[test]
fn a_date_in_the_file_name_and_the_names_that_lack_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let table = setup(d, "", "time_from_name = \"pump_%Y%m%d_%H%M\"\n");
    let named = d.join("pump_20261103_0600.csv");
    let other = d.join("pump_latest.csv");
    std::fs::copy(example().with_extension("csv"), &named).expect("copy");
    std::fs::copy(example().with_extension("csv"), &other).expect("copy");
    let (rows, err) = fleet(d, &table, &[named, other.clone()]);
    let r = row_of(&rows, "pump_20261103_0600.csv");
    assert_eq!(r.str("day"), Some(DAY), "{err}");
    assert_eq!(r.f64("log_time_s"), Some(START as f64));
    assert_eq!(r.str("time_source"), Some("file_name"));
    let o = row_of(&rows, "pump_latest.csv");
    assert_eq!(o.str("time_source"), Some("modified"));
    assert_eq!(o.str("day"), Some(modified_day(&other).as_str()));
    // The name that does not match is said, once, and so is its fallback.
    let said: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("do not match time_from_name"))
        .collect();
    assert_eq!(said.len(), 1, "{err}");
    assert!(
        said[0].contains("motor pump: the names of 1 log(s)"),
        "{err}"
    );
    assert!(
        err.lines()
            .any(|l| l
                .starts_with("warning: the times of 1 log(s) are their files' modification times")),
        "{err}"
    );
}

#[test]
fn logs_whose_times_all_are_one_days_modification_times_are_warned_of() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let table = setup(d, "", "");
    let logs: Vec<PathBuf> = ["pump_a.csv", "pump_b.csv"]
        .iter()
        .map(|n| {
            let p = d.join(n);
            std::fs::copy(example().with_extension("csv"), &p).expect("copy");
            p
        })
        .collect();
    let day = modified_day(&logs[0]);
    let (rows, err) = fleet(d, &table, &logs);
    assert!(rows
        .iter()
        .all(|r| r.str("time_source") == Some("modified")));
    let loud = format!(
        "WARNING: motor pump: the times of 2 logs are their files' modification times and all fall on {day}: copy logs with `cp -p`, give the log a time column, or set `time_from_name` in the motor table"
    );
    assert!(err.contains(&loud), "{err}");
    assert_eq!(err.matches("modification times").count(), 1, "{err}");
    // The trend says it again, before its table.
    let trend = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(["trend", "--store"])
        .arg(d.join("h.db"))
        .output()
        .expect("sim-host runs");
    let said = String::from_utf8_lossy(&trend.stderr);
    assert!(trend.status.success() && said.contains(&loud), "{said}");
}

#[test]
fn a_timestamp_column_without_one_time_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let table = setup(
        d,
        "[columns]\nt_s = { name = \"Time\", unit = \"timestamp\" }\n",
        "",
    );
    let log = d.join("pump_bad.csv");
    std::fs::write(&log, rewritten(&|_| "soon".to_string())).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .arg("fleet")
        .arg(&table)
        .arg(&log)
        .arg("--json")
        .output()
        .expect("sim-host runs");
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON rows");
    let e = rows[0]["error"].as_str().unwrap_or_default();
    assert!(e.contains("column 'Time' holds no time: 'soon'"), "{rows}");
}

#[test]
fn a_time_cell_that_is_no_time_is_a_bad_cell_held_out_and_counted() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    setup(
        d,
        "[columns]\nt_s = { name = \"Time\", unit = \"timestamp\" }\n",
        "",
    );
    let log = d.join("pump_one_bad.csv");
    // Row 1000 (t = 0.0999 s) has text for its time; every other row is ISO 8601 text.
    let bad_at = 999.0e-4;
    let text = rewritten(&|t| {
        if (t - bad_at).abs() < 1e-9 {
            "#VALUE!".to_string()
        } else {
            format!("2026-11-03T06:00:{t:09.6}Z")
        }
    });
    std::fs::write(&log, text).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(["diagnose", "--params"])
        .arg(d.join("p.toml"))
        .arg(&log)
        .arg("--json")
        .output()
        .expect("sim-host runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let q = &doc["data_quality"];
    assert_eq!(q["rows_read"], 50_001, "{q}");
    assert_eq!(q["non_finite_times"], 1, "{q}");
}
