//! Issue 65: one cell of text (`abc`) in a current column of a CSV log no longer aborts
//! `diagnose`: the cell is a bad cell like NaN, counted in `data_quality.bad_cells`, and the
//! rest of the log gets the same verdict as the clean log.

use assert_cmd::Command;
use std::path::Path;

/// `diagnose --json` of `log` with the motulator machine's parameter file.
fn diagnose(log: &Path) -> serde_json::Value {
    let params =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs/motulator_2p2kw_dol.toml");
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("diagnose")
        .arg("--params")
        .arg(&params)
        .arg(log)
        .arg("--json")
        .output()
        .expect("sim-host runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document")
}

#[test]
fn a_text_cell_is_held_out_and_counted_and_the_rest_is_judged() {
    let example =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/logs/motulator_2p2kw_dol.csv");
    let text = std::fs::read_to_string(&example).expect("the example log");
    // Line 30000 (3 s, steady running): its ib_A (the 6th field) becomes text.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut fields: Vec<String> = lines[29_999].split(',').map(str::to_string).collect();
    fields[5] = "abc".to_string();
    lines[29_999] = fields.join(",");
    let dir = tempfile::tempdir().expect("temp dir");
    let log = dir.path().join("with_text.csv");
    std::fs::write(&log, lines.join("\n") + "\n").expect("write");
    let clean = diagnose(&example);
    let got = diagnose(&log);
    let q = &got["data_quality"];
    assert_eq!(q["bad_cells"]["ib_A"], 1, "{q}");
    assert_eq!(q["bad_rows"], 1, "{q}");
    assert_eq!(q["rows_read"], clean["data_quality"]["rows_read"], "{q}");
    assert_eq!(got["verdict"], clean["verdict"]);
}
