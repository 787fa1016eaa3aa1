//! The real `sim-host` binary: every command works, `--json` parses, and every bad input
//! gives a non-zero exit and a one-line message naming the problem.

use assert_cmd::Command;
use monitor_testkit::text::verdict_line_of;
use std::path::{Path, PathBuf};

fn bin() -> Command {
    Command::cargo_bin("sim-host").expect("binary")
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn json(args: &[&str]) -> serde_json::Value {
    let o = bin().args(args).output().expect("run");
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|e| panic!("{args:?}: stdout is not one JSON document: {e}"))
}

/// Runs a command that must fail; returns its one-line message.
fn fails(args: &[&str]) -> String {
    let o = bin().args(args).output().expect("run");
    assert!(!o.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
    assert_eq!(
        err.lines().count(),
        1,
        "{args:?}: message is not one line:\n{err}"
    );
    assert!(o.stdout.is_empty(), "{args:?}: wrote to stdout on failure");
    err
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

const PARAMS_3HP: &str = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";

#[test]
fn demo_names_the_injected_fault() {
    // The default run, a day in service: a load step and back (load moves, never a fault),
    // then Rs +50 % at 8.5 s, named with its size; the verdict says so.
    let j = json(&["demo", "--json"]);
    assert_eq!(j["story"], "service");
    assert_eq!(j["fault_injected"], "rs");
    assert_eq!(j["correct_fault_among_candidates"], true, "{}", j["named"]);
    assert_eq!(j["verdict"], "fault");
    let after = j["detected_after_s"].as_f64().expect("detected");
    assert!(after > 0.0 && after < 2.5, "detected {after} s after");
    let moves: Vec<f64> = j["events"]
        .as_array()
        .expect("events")
        .iter()
        .filter(|e| e["event"] == "load_moved")
        .map(|e| e["t_s"].as_f64().expect("t"))
        .collect();
    assert!(
        moves.len() == 2 && moves[0] > 5.0 && moves[1] > 6.5 && moves[1] < 8.5,
        "{moves:?}"
    );
    let o = bin().arg("demo").output().expect("run");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{text}");
    // No red FAULT before the fault; the amber MOVED state while the load had moved.
    let before: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.split(" s ")
                .next()
                .and_then(|t| t.trim().parse::<f64>().ok())
                .is_some_and(|t| t < 8.5)
        })
        .collect();
    assert!(before.iter().all(|l| !l.contains("FAULT")), "{text}");
    assert!(before.iter().any(|l| l.contains("MOVED")), "{text}");
    assert_eq!(text.matches("event: ").count(), 2, "{text}");
    let last = verdict_line_of(&text);
    assert!(last.starts_with("verdict: FAULT rs +"), "{last}");
    // The paper's case, one option away: Bl +50 % on its fixed viscous load, the amber
    // state with the friction class and the sentence why.
    let o = bin().args(["demo", "--paper"]).output().expect("run");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success()
            && text.contains("MOVED moved: b/bl +50 % | load (active current)")
            && text.contains("b/bl p 1.00 (b/bl +50 %)")
            && text.contains("a friction change is a load change"),
        "{text}"
    );
}

#[test]
fn table1_json_has_eighteen_rows() {
    let j = json(&["table1", "--json"]);
    let rows = j["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 18);
    for r in rows {
        assert!(r["fault"].is_string() && (r["change"] == 0.5 || r["change"] == -0.5));
        assert_eq!(r["signature"].as_array().map(|s| s.len()), Some(4));
    }
}

#[test]
fn simulate_then_diagnose_finds_the_fault() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = write(dir.path(), "p.toml", PARAMS_3HP);
    let sc = write(
        dir.path(),
        "s.toml",
        "duration_s = 8.0\nsample_rate_hz = 10000.0\n[[faults]]\nkind = \"lr\"\nat_s = 5.0\nchange = -0.5\n",
    );
    let csv = dir.path().join("d.csv");
    let j = json(&[
        "simulate",
        "--params",
        params.to_str().expect("utf8"),
        "--scenario",
        sc.to_str().expect("utf8"),
        "--out",
        csv.to_str().expect("utf8"),
        "--json",
    ]);
    assert_eq!(j["rows"], 80_000);
    let d = json(&[
        "diagnose",
        "--params",
        params.to_str().expect("utf8"),
        csv.to_str().expect("utf8"),
        "--commission",
        "2:4",
        "--json",
    ]);
    for k in ["r1", "r2", "r3", "r4"] {
        assert!(d["lamps"][k].is_boolean());
    }
    let t = d["first_detection_s"].as_f64().expect("detected");
    assert!(t > 5.0, "{t}");
    let names: Vec<&str> = d["candidates"]
        .as_array()
        .expect("list")
        .iter()
        .filter_map(|c| c["fault"].as_str())
        .collect();
    assert!(names.contains(&"lr"), "{names:?}");
    assert!(d["unbalance"]["negative_sequence_ratio"].is_number());
    assert!(d["unbalance"].get("suspect_phase").is_some());
}

#[test]
fn diagnose_runs_on_the_independent_motulator_log() {
    let data = repo().join("examples/logs");
    let (p, csv) = (
        data.join("motulator_2p2kw_dol.toml"),
        data.join("motulator_2p2kw_dol.csv"),
    );
    assert!(csv.exists(), "{} is part of the repository", csv.display());
    let d = json(&[
        "diagnose",
        "--params",
        p.to_str().expect("utf8"),
        csv.to_str().expect("utf8"),
        "--commission",
        "1.5:2.4",
        "--json",
    ]);
    // The 14.6 N m constant torque applied at 2.5 s is, to the paper's model, a load
    // friction (Bl) change: r2, r3, r4 light and B/Bl are named, r1 stays dark.
    assert_eq!(d["lamps"]["r1"], false);
    assert_eq!(d["lamps"]["r2"], true);
    let names: Vec<&str> = d["signature_candidates"]
        .as_array()
        .expect("list")
        .iter()
        .filter_map(|c| c["fault"].as_str())
        .collect();
    assert_eq!(names, vec!["b", "bl"]);
    // The isolation: the constant torque is no viscous-friction change (the file's Bl is
    // 0, so no Bl factor fits), so it names nothing rather than a wrong fault.
    for c in d["candidates"].as_array().expect("list") {
        assert!(c["probability"].as_f64().expect("p") < 0.5, "{c}");
    }
    assert_ne!(d["isolation"]["state"], "isolated");
    let t = d["first_detection_s"].as_f64().expect("detected");
    assert!(t > 2.5, "{t}");
    assert_eq!(d["unbalance"]["suspect_phase"], serde_json::Value::Null);
}

#[test]
fn diagnose_on_a_current_only_log_still_gives_the_unbalance() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = write(dir.path(), "p.toml", PARAMS_3HP);
    let sc = write(
        dir.path(),
        "s.toml",
        "duration_s = 4.0\nsample_rate_hz = 10000.0\n[[effects]]\nname = \"phase_asymmetry\"\nphase = \"b\"\nfraction = 0.05\n[sensors]\nvoltages = false\nspeed = false\nencoder = false\n",
    );
    let csv = dir.path().join("i.csv");
    json(&[
        "simulate",
        "--params",
        params.to_str().expect("utf8"),
        "--scenario",
        sc.to_str().expect("utf8"),
        "--out",
        csv.to_str().expect("utf8"),
        "--json",
    ]);
    let header = std::fs::read_to_string(&csv).expect("csv");
    assert!(
        header.starts_with("t_s,ia_A,ib_A,ic_A\n"),
        "{}",
        &header[..40]
    );
    let d = json(&[
        "diagnose",
        "--params",
        params.to_str().expect("utf8"),
        csv.to_str().expect("utf8"),
        "--json",
    ]);
    assert_eq!(d["unbalance"]["suspect_phase"], "b", "{}", d["unbalance"]);
    let skipped = d["skipped"].as_array().expect("skipped");
    assert!(
        skipped
            .iter()
            .any(|s| s.as_str().is_some_and(|s| s.contains("va_V"))),
        "{skipped:?}"
    );
}

#[test]
fn bad_csv_inputs_give_one_line_errors_naming_the_problem() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = write(dir.path(), "p.toml", PARAMS_3HP);
    let p = params.to_str().expect("utf8");
    let missing = write(
        dir.path(),
        "missing.csv",
        "t_s,va_V,vb_V,vc_V,ia_A,ib_A,wm_rad_s\n0,1,2,3,4,5,6\n",
    );
    let e = fails(&["diagnose", "--params", p, missing.to_str().expect("utf8")]);
    assert!(e.contains("ic_A") && e.contains("missing column"), "{e}");
    // LF, and the same from a Windows editor (CRLF): the same line number.
    for (name, eol) in [("nonnum.csv", "\n"), ("crlf.csv", "\r\n")] {
        // (Text in the time column: a row that cannot be placed. Text in a measured
        // column is a bad cell, tests/cli/text_cells.rs.)
        let text = ["t_s,ia_A,ib_A,ic_A", "0,1,2,-3", "0.0001x,1,2,-3", ""].join(eol);
        let bad = write(dir.path(), name, &text);
        let e = fails(&["diagnose", "--params", p, bad.to_str().expect("utf8")]);
        assert!(
            e.contains("t_s") && e.contains("line 3") && e.contains("not a number"),
            "{name}: {e}"
        );
    }
    // A good CRLF log reads.
    let mut good = String::from("t_s,ia_A,ib_A,ic_A\r\n");
    for k in 0..2000 {
        let t = k as f64 * 1e-4;
        let w = 2.0 * std::f64::consts::PI * 60.0 * t;
        let i = |ph: f64| 10.0 * (w - ph).cos();
        let tp = 2.0 * std::f64::consts::PI / 3.0;
        good += &format!("{t},{},{},{}\r\n", i(0.0), i(tp), i(-tp));
    }
    let good = write(dir.path(), "good_crlf.csv", &good);
    let v = json(&[
        "diagnose",
        "--params",
        p,
        good.to_str().expect("utf8"),
        "--json",
    ]);
    assert!(v.get("unbalance").is_some(), "{v}");
    let backwards = write(
        dir.path(),
        "back.csv",
        "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n0.0001,1,2,-3\n0.00005,1,2,-3\n",
    );
    // A time that goes back is no longer fatal: the data-quality stage drops the row,
    // counts it and warns.
    let o = bin()
        .args([
            "diagnose",
            "--params",
            p,
            backwards.to_str().expect("utf8"),
            "--json",
        ])
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(v["data_quality"]["repeated_or_backward_rows"], 1, "{v}");
    assert_eq!(v["rows"], 2, "{v}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("warning: 1 rows dropped"), "{err}");
    let e = fails(&["diagnose", "--params", p, "no/such/file.csv"]);
    assert!(e.contains("no/such/file.csv"), "{e}");
    let e = fails(&[
        "diagnose",
        "--params",
        p,
        missing.to_str().expect("utf8"),
        "--commission",
        "4:2",
    ]);
    assert!(e.contains("START"), "{e}");
}

#[test]
fn bad_toml_inputs_give_one_line_errors_naming_the_key() {
    let dir = tempfile::tempdir().expect("tmp");
    let csv = write(
        dir.path(),
        "ok.csv",
        "t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n0.0001,1,2,-3\n",
    );
    // An unknown key and a missing key in the parameter file, each named.
    for (name, text, key) in [
        ("u.toml", PARAMS_3HP.replace("rs_ohm", "rs_ohms"), "rs_ohms"),
        (
            "m.toml",
            PARAMS_3HP.replace("j_kgm2 = 0.089\n", ""),
            "j_kgm2",
        ),
    ] {
        let p = write(dir.path(), name, &text);
        let e = fails(&[
            "diagnose",
            "--params",
            p.to_str().expect("utf8"),
            csv.to_str().expect("utf8"),
        ]);
        assert!(e.contains(key), "{e}");
    }
    let params = write(dir.path(), "p.toml", PARAMS_3HP);
    let sc = write(
        dir.path(),
        "s.toml",
        "duration_s = 1.0\nsample_rate_hz = 10000.0\nseeed = 3\n",
    );
    let out = dir.path().join("o.csv");
    let e = fails(&[
        "simulate",
        "--params",
        params.to_str().expect("utf8"),
        "--scenario",
        sc.to_str().expect("utf8"),
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert!(e.contains("seeed"), "{e}");
    assert!(!out.exists(), "a failed run must not leave an output");
    let sc2 = write(dir.path(), "s2.toml", "sample_rate_hz = 10000.0\n");
    let e = fails(&[
        "simulate",
        "--params",
        params.to_str().expect("utf8"),
        "--scenario",
        sc2.to_str().expect("utf8"),
        "--out",
        out.to_str().expect("utf8"),
    ]);
    assert!(e.contains("duration_s"), "{e}");
}

#[test]
fn every_command_has_a_help_that_teaches() {
    for cmd in [
        "demo",
        "simulate",
        "diagnose",
        "table1",
        "compare",
        "explain",
        "bench",
        "hmi",
        "params from-nameplate",
        "trend",
    ] {
        let o = bin()
            .args(cmd.split(' ').chain(["--help"]))
            .output()
            .expect("run");
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{cmd} --help failed");
        // Every command but the interactive HMI has a JSON output.
        assert!(
            cmd == "hmi" || text.contains("--json"),
            "{cmd} --help does not mention --json"
        );
        // An indented example line (the usage line alone does not teach; a doc comment on
        // the clap variant once hid every command's long help behind one short line).
        assert!(
            text.lines()
                .any(|l| l.starts_with("  sim-host ") || l.starts_with("  cargo ")),
            "{cmd} --help shows no example command line:\n{text}"
        );
    }
}
