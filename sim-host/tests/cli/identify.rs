//! `sim-host identify`, the command: the motulator log (a simulator this project did not
//! write) from its nameplate estimate, bad input is one line, the help, and the command
//! never writes over its inputs. (The identification itself against six known circuits,
//! the library's `monitor_analysis::identify`: `crates/monitor-analysis/tests/analysis/identify.rs`.)

use assert_cmd::Command;
use monitor_analysis::identify::InverseGamma;
use monitor_io::nameplate::estimate;
use monitor_io::params::ParamFile;
use monitor_testkit::identify_machines::Machine;
use std::f64::consts::TAU;

/// `identify` on `args`; (status ok, stdout, stderr).
fn run(args: &[&str]) -> (bool, String, String) {
    let o = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(args)
        .output()
        .expect("runs");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

fn root(p: &str) -> String {
    format!("{}/../{p}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_motulator_log_from_its_nameplate_within_10_percent_and_the_file_says_where_from() {
    let dir = tempfile::tempdir().expect("tmp");
    let start = dir.path().join("start.toml");
    let out = dir.path().join("motor.toml");
    let log = root("examples/logs/motulator_2p2kw_dol.csv");
    // Its nameplate at rated power from the log's true circuit (examples/logs/README.md).
    let truth = ParamFile::load(std::path::Path::new(&root(
        "examples/logs/motulator_2p2kw_dol.toml",
    )))
    .expect("truth");
    let m = Machine {
        name: "motulator log",
        p_kw: 2.2,
        v_ll: 400.0,
        f_hz: 50.0,
        t: [3.7, 2.5, 0.0, 0.023, 0.245],
        j: 0.015,
    };
    assert_eq!(m.truth().motor.lr_h, truth.motor.lr_h);
    std::fs::write(
        &start,
        estimate(&m.nameplate()).expect("estimate").to_toml(),
    )
    .expect("write");
    let (ok, stdout, stderr) = run(&[
        "identify",
        "--params",
        start.to_str().unwrap(),
        &log,
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(ok, "{stderr}");
    let j: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON document");
    let est = &j["identification"]["estimates"];
    let truth4 = [3.7, 2.5, 0.023, 0.245];
    for (k, t) in truth4.iter().enumerate() {
        let v = est[k]["value"]
            .as_f64()
            .unwrap_or_else(|| panic!("{}", est[k]));
        eprintln!(
            "motulator log: {} {:+.2} %",
            est[k]["name"],
            100.0 * (v / t - 1.0)
        );
        assert!(
            (v / t - 1.0).abs() <= 0.10,
            "{}: {v} vs {t}",
            est[k]["name"]
        );
        let (lo, hi) = (
            est[k]["lo"].as_f64().unwrap(),
            est[k]["hi"].as_f64().unwrap(),
        );
        assert!(lo <= v && v <= hi);
    }
    // The split-free form: what the log determines, whatever the split (within 1 %).
    let g = &j["identification"]["inverse_gamma"];
    let [rs, rr, lls, llr, lm] = m.t;
    let t = InverseGamma::of_t_circuit(rs, rr, lls, llr, lm);
    for (key, truth) in [
        ("rs_ohm", t.rs_ohm),
        ("r_r_ohm", t.r_r_ohm),
        ("l_sigma_h", t.l_sigma_h),
        ("l_m_h", t.l_m_h),
    ] {
        let v = g[key].as_f64().unwrap_or_else(|| panic!("{key}: {g}"));
        eprintln!(
            "motulator log: inverse-Gamma {key} {:+.3} %",
            100.0 * (v / truth - 1.0)
        );
        assert!((v / truth - 1.0).abs() <= 0.01, "{key}: {v} vs {truth}");
    }
    // Lls and Llr apart: not identified, with the reason.
    let names: Vec<&str> = est
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e["name"].as_str())
        .collect();
    for split in ["Lls", "Llr"] {
        let e = est
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["name"] == split)
            .expect(split);
        assert!(
            e["value"].is_null()
                && e["not_identified_because"]
                    .as_str()
                    .unwrap()
                    .contains("cannot split"),
            "{names:?}"
        );
    }
    let written = ParamFile::load(&out).expect("the written file loads");
    assert!((written.motor.rs_ohm / 3.7 - 1.0).abs() < 0.1);
    let text = std::fs::read_to_string(&out).unwrap();
    for key in ["rs_ohm", "rr_ohm", "lm_h", "j_kgm2"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .expect(key);
        assert!(
            line.contains("# identified, 95 % interval [")
                || line.contains("# kept from the start file"),
            "{line}"
        );
    }
    // Never over an input, nor over an existing file without --force.
    for target in [start.to_str().unwrap(), log.as_str(), out.to_str().unwrap()] {
        let (ok, _, err) = run(&[
            "identify",
            "--params",
            start.to_str().unwrap(),
            &log,
            "--out",
            target,
        ]);
        assert!(!ok && err.trim().lines().count() == 1, "{err}");
        assert!(err.contains("refusing to overwrite"), "{err}");
    }
}

#[test]
fn bad_input_is_one_line_naming_the_problem() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = root("examples/logs/motulator_2p2kw_dol.toml");
    // A current-only log: no voltages to drive the model.
    let log = dir.path().join("current_only.csv");
    let mut text = String::from("t_s,ia_A,ib_A,ic_A\n");
    for k in 0..3000 {
        let t = k as f64 * 2e-4;
        let a = (TAU * 50.0 * t).sin();
        text.push_str(&format!("{t},{a},{},{}\n", -0.5 * a, -0.5 * a));
    }
    std::fs::write(&log, text).unwrap();
    let (ok, _, err) = run(&["identify", "--params", &params, log.to_str().unwrap()]);
    assert!(
        !ok && err.trim().lines().count() == 1 && err.contains("no voltages"),
        "{err}"
    );
    // A window too short.
    let csv = root("examples/logs/motulator_2p2kw_dol.csv");
    let (ok, _, err) = run(&[
        "identify", "--params", &params, &csv, "--from", "1", "--to", "1.05",
    ]);
    assert!(
        !ok && err.trim().lines().count() == 1 && err.contains("at least"),
        "{err}"
    );
    // A start file that is no machine.
    let bad = dir.path().join("bad.toml");
    let p = std::fs::read_to_string(&params)
        .unwrap()
        .replace("rr_ohm = 2.5", "rr_ohm = 0.0");
    std::fs::write(&bad, p).unwrap();
    let (ok, _, err) = run(&["identify", "--params", bad.to_str().unwrap(), &csv]);
    assert!(!ok && err.trim().lines().count() == 1, "{err}");
}

#[test]
fn the_help_teaches_what_the_log_must_hold_and_what_cannot_be_told() {
    let (ok, out, _) = run(&["identify", "--help"]);
    assert!(ok);
    // Read as prose: clap wraps the help at the terminal's width.
    let out = out.split_whitespace().collect::<Vec<_>>().join(" ");
    for needle in [
        "What the log must hold",
        "Lls and Llr apart",
        "not identified",
        "--out",
        "95 %",
        "params from-nameplate",
    ] {
        assert!(out.contains(needle), "{needle} missing:\n{out}");
    }
    let (_, out, _) = run(&["--help"]);
    assert!(out.contains("identify"));
}
