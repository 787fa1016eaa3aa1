//! Issue 65: a fleet log pattern that matches no file is an error naming the pattern (the
//! Python fleet's words), not a row blaming the motor table; a pattern that matches is
//! expanded in its folder.

use assert_cmd::Command;
use std::path::Path;

/// A motor table for `pump_*` logs of the motulator machine, in `dir`.
fn table(dir: &Path) -> std::path::PathBuf {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs");
    let params = examples.join("motulator_2p2kw_dol.toml");
    let t = dir.join("motors.toml");
    let text = format!(
        "[[motor]]\nname = \"pump\"\nparams = {:?}\nlogs = \"pump_*\"\n",
        params.display().to_string()
    );
    std::fs::write(&t, text).expect("write the table");
    t
}

#[test]
fn a_pattern_that_matches_no_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let motors = table(dir.path());
    let pattern = dir.path().join("logs").join("pump_*.csv");
    std::fs::create_dir(dir.path().join("logs")).expect("mkdir");
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("fleet")
        .arg(&motors)
        .arg(&pattern)
        .output()
        .expect("sim-host runs");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_eq!(
        e.trim_end(),
        format!(
            "error: logs: the pattern '{}' matches no file",
            pattern.display()
        )
    );
    assert!(!e.contains("motor table"), "{e}");
}

#[test]
fn a_pattern_that_matches_is_expanded_in_its_folder() {
    let dir = tempfile::tempdir().expect("temp dir");
    let motors = table(dir.path());
    let example =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs/motulator_2p2kw_dol.csv");
    std::fs::copy(&example, dir.path().join("pump_1.csv")).expect("copy");
    std::fs::write(dir.path().join("other.csv"), "t_s,ia_A,ib_A,ic_A\n").expect("write");
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("fleet")
        .arg(&motors)
        .arg(dir.path().join("pump_?.csv"))
        .arg("--json")
        .output()
        .expect("sim-host runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON rows");
    let rows = rows.as_array().expect("a list");
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(rows[0]["motor"], "pump", "{rows:?}");
    assert!(
        rows[0]["file"]
            .as_str()
            .is_some_and(|f| f.ends_with("pump_1.csv")),
        "{rows:?}"
    );
    assert!(rows[0]["error"].is_null(), "{rows:?}");
}
