//! "healthy" only when something was judged, and the mistakes users make on their own
//! motor's path (the issue "healthy only when something was judged"): logs that are all
//! start or all transient, a current unit left out of `[columns]`, a speed channel in the
//! wrong unit, the parameter file and the log swapped.

use assert_cmd::Command;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf8")
}

fn run(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("sim-host")
        .expect("binary")
        .current_dir(repo())
        .args(args)
        .output()
        .expect("run")
}

fn json(args: &[&str]) -> Value {
    let o = run(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("json")
}

/// The first `rows` rows of the DAQ example (a direct-on-line start), with its header.
fn daq_head(dir: &Path, rows: usize) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("examples/logs/daq_2p2kw.csv")).expect("read");
    let p = dir.join(format!("head_{rows}.csv"));
    let head: Vec<&str> = text.lines().take(rows + 1).collect();
    std::fs::write(&p, head.join("\n") + "\n").expect("write");
    p
}

#[test]
fn no_command_says_healthy_where_no_lamp_was_judged() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = repo().join("examples/params/daq_2p2kw.toml");
    // All start (0.4 s of a direct-on-line start) and start plus a little running (1.2 s):
    // the lamps hold through the start, nothing is judged.
    for rows in [400, 1200] {
        let log = daq_head(dir.path(), rows);
        let d = json(&["diagnose", "--params", s(&params), s(&log), "--json"]);
        assert_eq!(
            d["verdict"], "could_not_judge",
            "{rows} rows: {}",
            d["verdict"]
        );
        let why = d["verdict_withheld_because"].to_string();
        assert!(
            why.contains("judged on only") || why.contains("never evaluated"),
            "{why}"
        );
    }
    // The whole example, judged on its settled running after the start: healthy (its load
    // step is a load move, not a fault).
    let whole = repo().join("examples/logs/daq_2p2kw.csv");
    let d = json(&["diagnose", "--params", s(&params), s(&whole), "--json"]);
    assert_eq!(d["verdict"], "healthy", "{}", d["verdict_withheld_because"]);
    // The demo's verdict is the same rule's: a fault named.
    let demo = json(&["demo", "--json"]);
    assert_eq!(demo["verdict"], "fault");
}

#[test]
fn identify_refuses_currents_in_ma_read_as_a_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tmp");
    // The DAQ example in the schema's names but its currents still in mA (the mapping's
    // units left out): a thousand times what the motor can draw.
    let schema = dir.path().join("schema.csv");
    let params = repo().join("examples/params/daq_2p2kw.toml");
    let o = run(&[
        "convert",
        "--params",
        s(&params),
        "examples/logs/daq_2p2kw.csv",
        s(&schema),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&schema).expect("read");
    let mut lines = text.lines();
    let header = lines.next().expect("header").to_string();
    let cols: Vec<&str> = header.split(',').collect();
    let idx: Vec<usize> = ["ia_A", "ib_A", "ic_A"]
        .iter()
        .map(|c| cols.iter().position(|h| h == c).expect("current column"))
        .collect();
    let mut out = header.clone() + "\n";
    for l in lines {
        let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
        for &k in &idx {
            f[k] = (f[k].parse::<f64>().expect("number") * 1000.0).to_string();
        }
        out += &(f.join(",") + "\n");
    }
    let ma = dir.path().join("ma.csv");
    std::fs::write(&ma, out).expect("write");
    let written = dir.path().join("identified.toml");
    let o = run(&[
        "identify",
        "--params",
        "examples/params/2p2kw.toml",
        s(&ma),
        "--out",
        s(&written),
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("mA") && e.lines().count() == 1, "{e}");
    assert!(!written.exists(), "a file was written");
    // The same log with the right file identifies (within the noise).
    let o = run(&[
        "identify",
        "--params",
        "examples/params/2p2kw.toml",
        s(&schema),
        "--out",
        s(&written),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(written.exists());
}

#[test]
fn a_speed_in_the_wrong_unit_is_a_finding_not_a_sensor_fault() {
    let dir = tempfile::tempdir().expect("tmp");
    let base =
        std::fs::read_to_string(repo().join("examples/params/daq_2p2kw.toml")).expect("read");
    let log = repo().join("examples/logs/daq_2p2kw.csv");
    // The Speed channel is in rpm; mapped as rad/s it reads 9.55 times too fast.
    let as_rad_s = dir.path().join("rad_s.toml");
    std::fs::write(
        &as_rad_s,
        base.replace(
            "wm_rad_s = { name = \"Speed\", unit = \"rpm\" }",
            "wm_rad_s = { name = \"Speed\", unit = \"rad/s\" }",
        ),
    )
    .expect("write");
    let o = run(&["diagnose", "--params", s(&as_rad_s), s(&log), "--json"]);
    let e = String::from_utf8_lossy(&o.stderr);
    if o.status.success() {
        let d: Value = serde_json::from_slice(&o.stdout).expect("json");
        assert_ne!(d["verdict"], "fault", "{d}");
        assert!(d["data_quality"]["speed_unit"].as_str().is_some(), "{d}");
    } else {
        // Beyond the sensor's range: refused with the unit to give.
        assert!(e.contains("unit = \"rpm\""), "{e}");
    }
    // A 4-pole machine's Speed in rad/s with the unit rpm: ten times too slow.
    let schema = dir.path().join("schema.csv");
    let o = run(&[
        "convert",
        "--params",
        s(&repo().join("examples/params/daq_2p2kw.toml")),
        s(&log),
        s(&schema),
    ]);
    assert!(o.status.success());
    let slow = dir.path().join("slow.toml");
    let plain = std::fs::read_to_string(repo().join("examples/params/2p2kw.toml")).expect("read");
    std::fs::write(
        &slow,
        format!("{plain}\n[columns]\nwm_rad_s = {{ name = \"wm_rad_s\", unit = \"rpm\" }}\n"),
    )
    .expect("write");
    let d = json(&[
        "diagnose",
        "--params",
        s(&slow),
        s(&schema),
        "--commission",
        "1:6.5",
        "--json",
    ]);
    assert_eq!(d["verdict"], "could_not_judge", "{}", d["verdict"]);
    let finding = d["data_quality"]["speed_unit"].as_str().expect("finding");
    assert!(finding.contains("given the unit rpm"), "{finding}");
    assert!(d["candidates"]
        .as_array()
        .is_none_or(|c| c.iter().all(|c| c["fault"] != "speed_sensor")));
}

#[test]
fn swapped_arguments_are_named() {
    let o = run(&[
        "diagnose",
        "--params",
        "examples/logs/daq_2p2kw.csv",
        "examples/params/daq_2p2kw.toml",
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("look swapped") && e.lines().count() == 1, "{e}");
}
