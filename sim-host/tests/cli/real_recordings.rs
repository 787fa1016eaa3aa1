//! Real recordings of a motor with shorted turns (the ITSC data set, MIT license:
//! `examples/recordings/itsc/`) through the command line: `diagnose --baseline` with two
//! healthy runs, with a folder of them, and with the log itself (refused). (The recordings
//! read and judged through the library, and the estimate on simulated logs:
//! `crates/monitor-replay/tests/replay/real_recordings.rs`.)

use std::path::{Path, PathBuf};

// (The same folder as `crates/monitor-replay/tests/replay/real_recordings.rs`'s, from this crate.)
fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/recordings/itsc")
}

/// The command line as a user runs it: `--baseline` with two files, with a folder of them,
/// and with the log itself (refused).
#[test]
fn the_command_takes_several_healthy_runs_or_a_folder() {
    let run = |extra: &[&str]| {
        let d = folder();
        let mut args = vec![
            "diagnose".to_string(),
            "--params".into(),
            d.join("baldor_0p75hp.toml").display().to_string(),
            d.join("SC_A0_B0_C2_001.csv").display().to_string(),
            "--json".into(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        assert_cmd::Command::cargo_bin("sim-host")
            .expect("binary") // ok: test
            .args(&args)
            .output()
            .expect("run") // ok: test
    };
    let d = folder();
    let h1 = d.join("SC_HLT_001.csv").display().to_string();
    let h2 = d.join("SC_HLT_002.csv").display().to_string();
    let files = run(&["--baseline", &h1, &h2]);
    assert!(
        files.status.success(),
        "{}",
        String::from_utf8_lossy(&files.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&files.stdout).expect("json"); // ok: test
    assert_eq!(v["unbalance"]["suspect_phase"], "c", "{}", v["unbalance"]);
    assert_eq!(v["unbalance"]["baseline_runs"], 2);
    assert!(v["unbalance"]["baseline_spread"].as_f64().is_some());
    // A folder of the same two runs gives the same answer.
    let tmp = tempfile::tempdir().expect("tempdir"); // ok: test
    for n in ["SC_HLT_001.csv", "SC_HLT_002.csv"] {
        std::fs::copy(d.join(n), tmp.path().join(n)).expect("copy"); // ok: test
    }
    let dir = run(&["--baseline", &tmp.path().display().to_string()]);
    let w: serde_json::Value = serde_json::from_slice(&dir.stdout).expect("json"); // ok: test
    assert_eq!(w["unbalance"], v["unbalance"]);
    // The log judged is no baseline of itself.
    let me = d.join("SC_A0_B0_C2_001.csv").display().to_string();
    let o = run(&["--baseline", &me]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("that is the log being judged"), "{e}");
    // An empty folder says so.
    let empty = tempfile::tempdir().expect("tempdir"); // ok: test
    let o = run(&["--baseline", &empty.path().display().to_string()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds no log"));
}
