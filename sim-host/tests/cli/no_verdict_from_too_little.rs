//! No verdict from too little (issue 40), two of the inputs a user found:
//!
//! - **A size that says nothing.** On a 50 hp motor (Krause's values, 5 kHz, the paper's
//!   viscous load, `--angle pll --load viscous --commission 3:4.5`) the machine's own
//!   friction B rises 50 % at 5 s. B is 1 % of B + Bl on this machine, so the friction class
//!   moves by 0.5 %: a real change the commissioned lamps see, far too small to send a crew
//!   for. It used to end in `verdict: FAULT` with "current_sensor +0 %". Now: no FAULT (the
//!   verdict is `watching` with the size), no sentence of the unknown-input load model under
//!   `--load viscous`, and no event printed as "+0 %".
//! - **A window too short to judge.** `compare` and `explain` over the last 10 ms of a 10 s
//!   log (0.6 supply periods) are refused in one line that gives the window's length and
//!   the least length needed, instead of a normalised error and a ranking.
//!
//! One 10 s simulation at 5 kHz and nine runs of the binary: about 3 s in the test profile.

use assert_cmd::Command;
use serde_json::Value;
use std::path::Path;

/// A 50 hp, 460 V, 60 Hz motor (Krause's 50 hp machine's per-phase values).
const PARAMS_50HP: &str = "[motor]\nrs_ohm = 0.087\nrr_ohm = 0.228\nls_h = 0.03549685747426239\nlr_h = 0.03549685747426239\nlm_h = 0.03469577759403319\npoles = 4\nj_kgm2 = 1.662\nb_nms = 0.009\nbl_nms = 0.9\n[supply]\nv_ll_rms = 460.0\nf_hz = 60.0\n";

/// The machine's friction B +50 % at 5 s under the paper's viscous load, 10 s at 5 kHz.
const SCENARIO: &str = "duration_s = 10.0\nsample_rate_hz = 5000.0\nseed = 3\n[load]\nkind = \"viscous\"\n[[faults]]\nkind = \"b\"\nat_s = 5.0\nchange = 0.5\n";

fn sim_host(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("sim-host")
        .expect("the binary") // ok: test
        .args(args)
        .output()
        .expect("runs") // ok: test
}

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path") // ok: test
}

/// The parameter file and the simulated log in `dir`.
fn log(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let params = dir.join("50hp.toml");
    let scenario = dir.join("b.toml");
    let log = dir.join("b.csv");
    std::fs::write(&params, PARAMS_50HP).expect("write"); // ok: test
    std::fs::write(&scenario, SCENARIO).expect("write"); // ok: test
    let o = sim_host(&[
        "simulate",
        "--params",
        s(&params),
        "--scenario",
        s(&scenario),
        "--out",
        s(&log),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (params, log)
}

#[test]
fn a_change_too_small_to_matter_is_watched_not_a_fault() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let (params, log) = log(dir.path());
    let args = [
        "diagnose",
        "--params",
        s(&params),
        s(&log),
        "--angle",
        "pll",
        "--load",
        "viscous",
        "--commission",
        "3:4.5",
    ];
    let o = sim_host(&[&args[..], &["--json"]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let d: Value = serde_json::from_slice(&o.stdout).expect("JSON"); // ok: test
    let iso = &d["isolation"];
    eprintln!(
        "verdict {}, named {} {}, because {}",
        d["verdict"], iso["named"], iso["named_change"], d["verdict_withheld_because"]
    );
    // The lamps do see the change (it is real), ...
    assert!(d["first_detection_s"].as_f64().is_some(), "{d}");
    // ... but it is no FAULT: a name below 5 % (or the friction class, which a load change
    // moves as much) is watched, with its size.
    assert_ne!(d["verdict"], "fault", "{d}");
    if let Some(c) = iso["named_change"].as_f64() {
        assert!(c.abs() < 0.05, "{iso}");
        assert_eq!(d["verdict"], "watching", "{d}");
        assert!(
            d["verdict_line"]
                .as_str()
                .is_some_and(|l| l.starts_with("WATCHING")),
            "{d}"
        );
    }
    // Every name and candidate carries a size that is not zero.
    for c in d["candidates"].as_array().into_iter().flatten() {
        let change = c["change"].as_f64().unwrap_or(1.0);
        assert!(change.abs() > 1e-4, "a candidate of no size: {c}");
    }
    // The load reading said is the one used.
    let sentence = iso["verdict"].as_str().unwrap_or_default();
    assert!(!sentence.contains("unknown input"), "{sentence}");
    // The text report gives small sizes to a tenth of a per cent.
    let text = sim_host(&args);
    let out = String::from_utf8_lossy(&text.stdout);
    assert!(
        !out.contains("+0 %") && !out.contains("-0 %"),
        "a size printed as zero:\n{out}"
    );
}

/// The same log in `--angle pll` as a user runs it (issue 48 listed "a 50 hp B +50 % in
/// `--angle pll` names current_sensor at p 0.76"): with the load an unknown input and with
/// the paper's viscous load, commissioned and not, no sensor is named at any time and no
/// sensor is a candidate at probability 0.5 or more (the friction class, or a load move, is
/// the reading).
#[test]
fn a_friction_change_names_no_sensor_in_pll() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let (params, log) = log(dir.path());
    let variants: [&[&str]; 4] = [
        &["--commission", "3:4.5"],
        &["--commission", "3:4.5", "--load", "viscous"],
        &[],
        &["--load", "viscous"],
    ];
    let sensors = ["current_sensor", "voltage_sensor", "speed_sensor"];
    for extra in variants {
        let mut args = vec![
            "diagnose",
            "--params",
            s(&params),
            s(&log),
            "--angle",
            "pll",
        ];
        args.extend_from_slice(extra);
        args.push("--json");
        let o = sim_host(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let d: Value = serde_json::from_slice(&o.stdout).expect("JSON"); // ok: test
        let iso = &d["isolation"];
        eprintln!(
            "{extra:?}: verdict {}, named {} ({}), candidates {}",
            d["verdict"], iso["named"], iso["named_probability"], d["candidates"]
        );
        let named: Vec<&str> = iso["events"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|e| e["name"].as_str())
            .chain(iso["named"].as_str())
            .collect();
        assert!(
            !named.iter().any(|n| sensors.contains(n)),
            "{extra:?}: a sensor named: {named:?}"
        );
        for c in d["candidates"].as_array().into_iter().flatten() {
            let strong = c["probability"].as_f64().unwrap_or(0.0) >= 0.5;
            let sensor = c["fault"].as_str().is_some_and(|f| sensors.contains(&f));
            assert!(!(strong && sensor), "{extra:?}: {c}");
        }
    }
}

#[test]
fn compare_and_explain_refuse_a_window_too_short_to_judge() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let (params, log) = log(dir.path());
    for command in ["compare", "explain"] {
        let o = sim_host(&[command, "--params", s(&params), s(&log), "--from", "9.99"]);
        let err = String::from_utf8_lossy(&o.stderr);
        eprintln!("{command}: {err}");
        assert!(!o.status.success(), "{command} judged 10 ms");
        assert!(o.stdout.is_empty(), "{command} printed a result");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        assert!(
            err.contains("0.010 s") && err.contains("at least") && err.contains("supply periods"),
            "{command}: {err}"
        );
    }
    // The same commands over the last 2 s run.
    for command in ["compare", "explain"] {
        let o = sim_host(&[command, "--params", s(&params), s(&log), "--from", "8"]);
        assert!(
            o.status.success(),
            "{command}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}
