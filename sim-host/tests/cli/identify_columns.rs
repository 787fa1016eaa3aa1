//! Issue 65: `identify --out` leaves the start file's `[columns]` table (a DAQ's channel
//! names and units) out of the identified file, so that it reads logs with the standard
//! column names; `--keep-columns` keeps it.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `sim-host args...`, which must succeed: its stdout.
fn ok(args: &[&std::ffi::OsStr]) -> String {
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(args)
        .output()
        .expect("sim-host runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string()
}

/// Identifies the DAQ example (its start file maps the DAQ's columns) into `out`.
fn identify(out: &Path, keep: bool) -> String {
    let params = repo().join("examples/params/daq_2p2kw.toml");
    let log = repo().join("examples/logs/daq_2p2kw.csv");
    let mut args = vec![
        "identify".as_ref(),
        "--params".as_ref(),
        params.as_os_str(),
        log.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ];
    if keep {
        args.push("--keep-columns".as_ref());
    }
    ok(&args);
    std::fs::read_to_string(out).expect("the identified file")
}

#[test]
fn the_identified_file_reads_standard_logs_unless_the_columns_are_kept() {
    let start = std::fs::read_to_string(repo().join("examples/params/daq_2p2kw.toml"))
        .expect("the start file");
    assert!(
        start.contains("\n[columns]"),
        "the start file maps the DAQ's columns"
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let plain = dir.path().join("identified.toml");
    let text = identify(&plain, false);
    assert!(!text.contains("[columns]"), "{text}");
    assert!(
        text.contains("[motor]") && text.contains("[supply]"),
        "{text}"
    );
    // A log with the standard column names is read with it.
    let standard = repo().join("examples/logs/motulator_2p2kw_dol.csv");
    let d = ok(&[
        "diagnose".as_ref(),
        "--params".as_ref(),
        plain.as_os_str(),
        standard.as_os_str(),
        "--json".as_ref(),
    ]);
    let d: serde_json::Value = serde_json::from_str(&d).expect("JSON");
    assert_eq!(
        d["data_quality"]["rows_read"], 50_001,
        "{}",
        d["data_quality"]
    );
    // --keep-columns: the DAQ's table, as the start file has it.
    let kept = identify(&dir.path().join("kept.toml"), true);
    assert!(
        kept.contains("\n[columns]\n") && kept.contains("name = \"Ia\""),
        "{kept}"
    );
}
