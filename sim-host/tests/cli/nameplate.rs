//! `params from-nameplate`, the command: the written TOML loads and says where each value
//! comes from, a refused nameplate is one line naming the option, and the help teaches what
//! goes in, what comes out and how far off. (The estimate against six machines' published
//! circuits, the library's `monitor_io::nameplate`: `crates/monitor-io/tests/io/nameplate.rs`.)

use assert_cmd::Command;
use monitor_io::nameplate::{estimate, Connection, Nameplate, NemaDesign};
use monitor_io::params::ParamFile;

/// A nameplate that is fine: the small 0.37 kW machine's, as
/// `crates/monitor-io/tests/io/nameplate.rs` computes it from its circuit at rated power (its
/// `good()`; the same values, written out: the library's test holds the circuit model).
fn good() -> Nameplate {
    Nameplate {
        power_kw: 0.37,
        voltage_v: 400.0,
        current_a: 1.05,
        frequency_hz: 50.0,
        speed_rpm: 1375.0,
        power_factor: 0.69,
        efficiency: 0.736,
        poles: None,
        connection: Connection::Star,
        locked_rotor_ratio: None,
        design: NemaDesign::B,
    }
}

#[test]
fn the_written_toml_loads_and_says_where_each_value_comes_from() {
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("P.toml");
    let n = good();
    let num = |x: f64| x.to_string();
    let args = [
        "params".to_string(),
        "from-nameplate".into(),
        "--power-kw".into(),
        num(n.power_kw),
        "--voltage-v".into(),
        num(n.voltage_v),
        "--current-a".into(),
        num(n.current_a),
        "--frequency-hz".into(),
        num(n.frequency_hz),
        "--speed-rpm".into(),
        num(n.speed_rpm),
        "--power-factor".into(),
        num(n.power_factor),
        "--efficiency".into(),
        num(n.efficiency),
        "--out".into(),
        out.display().to_string(),
    ];
    let bin = || Command::cargo_bin("sim-host").expect("binary");
    let o = bin().args(&args).output().expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let p = ParamFile::load(&out).expect("loads and passes the checks");
    p.check().expect("equations' limits");
    let lib = estimate(&n).expect("estimate");
    assert!((p.motor.rs_ohm / lib.params.motor.rs_ohm - 1.0).abs() < 1e-3);
    assert_eq!(p.motor.poles, 4);
    let text = std::fs::read_to_string(&out).expect("read");
    for key in [
        "rs_ohm", "rr_ohm", "ls_h", "lr_h", "lm_h", "j_kgm2", "b_nms", "bl_nms",
    ] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("{key} missing:\n{text}"));
        assert!(
            line.contains(" # [") && line.contains("..") && line.contains("; "),
            "{line}"
        );
    }
    // Never over an existing file without --force; with it, atomically replaced.
    let o = bin().args(&args).output().expect("run");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--force") && err.trim().lines().count() == 1,
        "{err}"
    );
    let mut forced = args.to_vec();
    forced.push("--force".into());
    forced.push("--json".into());
    let o = bin().args(&forced).output().expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON document");
    let rs = &j["values"][0];
    assert_eq!(rs["key"], "motor.rs_ohm");
    assert!(rs["lo"].as_f64() <= rs["value"].as_f64() && rs["value"].as_f64() <= rs["hi"].as_f64());
    assert!(rs["source"].as_str().is_some_and(|s| !s.is_empty()));
    // A refused nameplate: one line on stderr naming the option, nothing on stdout.
    let mut bad = args[..args.len() - 2].to_vec();
    bad[15] = "1.2".into();
    let o = bin().args(&bad).output().expect("run");
    assert!(!o.status.success() && o.stdout.is_empty());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--efficiency") && err.trim().lines().count() == 1,
        "{err}"
    );
}

#[test]
fn the_help_teaches_what_goes_in_what_comes_out_and_how_far_off() {
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["params", "from-nameplate", "--help"])
        .output()
        .expect("run");
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for needle in [
        "nameplate gives",
        "How far off",
        "35 %",
        "refine it with a log of the healthy",
        "--json",
        "--locked-rotor-ratio",
        "  sim-host params from-nameplate ",
    ] {
        assert!(text.contains(needle), "{needle} missing:\n{text}");
    }
    // `sim-host --help` lists the group.
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .arg("--help")
        .output()
        .expect("run");
    assert!(String::from_utf8_lossy(&o.stdout).contains("params"));
}
