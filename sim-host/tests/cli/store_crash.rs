//! The store survives a killed fleet run (issue 53): `sim-host fleet --store` is started as
//! a child on many logs and killed (SIGKILL) once some logs are stored; the store then
//! opens, holds only whole rows, and a second run stores every log exactly once (the ones
//! stored before the kill skipped, not judged again), its Parquet mirror the same rows.

use monitor_store::{Cell, Store, StoredRow, COLUMNS};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const LOGS: usize = 16;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_sim-host"))
}

/// One simulated log (10 s at 10 kHz, Parquet) copied to `LOGS` names: the same bytes at
/// another path is another log (its identity is its hash and its path).
fn logs(dir: &Path) -> Vec<PathBuf> {
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/3hp.toml");
    std::fs::copy(&params, dir.join("p.toml")).expect("params");
    let sc = dir.join("s.toml");
    std::fs::write(&sc, "duration_s = 10.0\nsample_rate_hz = 10000.0\n").expect("scenario");
    let first = dir.join("m_00.parquet");
    let ok = Command::new(bin())
        .args(["simulate", "--params"])
        .arg(dir.join("p.toml"))
        .arg("--scenario")
        .arg(&sc)
        .arg("--out")
        .arg(&first)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("simulate");
    assert!(ok.success());
    std::fs::write(
        dir.join("motors.toml"),
        "[[motor]]\nname = \"m\"\nparams = \"p.toml\"\nlogs = \"m_*\"\n",
    )
    .expect("table");
    (0..LOGS)
        .map(|i| {
            let p = dir.join(format!("m_{i:02}.parquet"));
            if i > 0 {
                std::fs::copy(&first, &p).expect("copy");
            }
            p
        })
        .collect()
}

fn fleet(dir: &Path, logs: &[PathBuf], store: &Path) -> Command {
    let mut c = Command::new(bin());
    c.arg("fleet")
        .arg(dir.join("motors.toml"))
        .args(logs)
        .arg("--store")
        .arg(store)
        .env("RAYON_NUM_THREADS", "2")
        .stdout(Stdio::null());
    c
}

fn stored(store: &Path) -> usize {
    Store::open_existing(store)
        .and_then(|s| s.rows(None, None))
        .map_or(0, |r| r.len())
}

/// A row is whole: its identity, verdict and the log's row count are there.
fn whole(r: &StoredRow) -> bool {
    ["log_id", "log_hash", "log_path", "motor", "day", "verdict"]
        .iter()
        .all(|c| r.str(c).is_some())
        && r.f64("rows") == Some(100_000.0)
        && r.cells.len() == COLUMNS.len()
}

/// The mirror's rows, keyed by log_id: each file's columns as cells.
fn mirror_rows(dir: &Path) -> Vec<(String, Vec<(String, Cell)>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            assert_eq!(
                p.extension().and_then(|x| x.to_str()),
                Some("parquet"),
                "{p:?}"
            );
            let r =
                SerializedFileReader::new(std::fs::File::open(&p).expect("open")).expect("parquet");
            let rows: Vec<_> = r.get_row_iter(None).expect("rows").collect();
            assert_eq!(rows.len(), 1, "{p:?}");
            let row = rows.into_iter().next().expect("row").expect("row");
            let cells: Vec<(String, Cell)> = row
                .get_column_iter()
                .map(|(n, f)| {
                    let c = match f {
                        Field::Null => Cell::Null,
                        Field::Long(v) => Cell::Int(*v),
                        Field::Double(v) => Cell::Real(*v),
                        Field::Str(s) => Cell::Text(s.clone()),
                        other => panic!("{n}: unexpected {other:?}"),
                    };
                    (n.clone(), c)
                })
                .collect();
            let id = cells
                .iter()
                .find(|(n, _)| n == "log_id")
                .and_then(|(_, c)| c.as_str().map(str::to_string))
                .expect("log_id");
            out.push((id, cells));
        }
    }
    out
}

#[test]
fn a_killed_fleet_run_loses_no_row_and_the_next_run_stores_each_log_once() {
    let dir = tempfile::tempdir().expect("tmp");
    let logs = logs(dir.path());
    let store = dir.path().join("history.db");
    // The first run, killed once at least one log is stored.
    let mut child = fleet(dir.path(), &logs, &store)
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    let started = Instant::now();
    while stored(&store) == 0 {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "nothing stored"
        );
        assert!(
            child.try_wait().expect("wait").is_none(),
            "the run ended first"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
    let s = Store::open_existing(&store).expect("the store opens after the kill");
    let before = s.rows(None, None).expect("rows");
    eprintln!("killed with {} of {LOGS} logs stored", before.len());
    assert!(
        !before.is_empty() && before.len() < LOGS,
        "{} stored",
        before.len()
    );
    assert!(before.iter().all(whole), "a half row");
    drop(s);
    // The second run: every log once, the ones stored skipped.
    let out = fleet(dir.path(), &logs, &store).output().expect("rerun");
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let skipped = err.matches("already stored, skipped").count();
    assert_eq!(skipped, before.len(), "{err}");
    let s = Store::open_existing(&store).expect("store");
    let rows = s.rows(None, None).expect("rows");
    assert_eq!(rows.len(), LOGS);
    assert!(rows.iter().all(whole));
    let mut ids: Vec<&str> = rows.iter().map(StoredRow::log_id).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), LOGS);
    for r in &before {
        assert!(rows.contains(r), "a row stored before the kill changed");
    }
    // The mirror: the same rows (each column but the partitions, value for value).
    let mirror = mirror_rows(&s.mirror_dir());
    assert_eq!(mirror.len(), LOGS);
    for (id, cells) in mirror {
        let r = rows.iter().find(|r| r.log_id() == id).expect("in SQLite");
        assert_eq!(cells.len(), COLUMNS.len() - 2);
        for (name, c) in cells {
            assert_eq!(&c, r.get(&name), "{id} {name}");
        }
    }
}
