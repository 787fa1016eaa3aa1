//! Issue 65: Ctrl-C (SIGINT) during `diagnose` ends it with status 130 and one line on
//! stderr saying what was stopped and that nothing was written; nothing on stdout.
//!
//! The log is a named pipe no one writes to: the replay waits on it for as long as the test
//! likes, so the signal always arrives mid-replay, whatever the machine's speed.

use std::process::Command;
use std::time::{Duration, Instant};

#[test]
fn sigint_during_diagnose_says_what_was_stopped_and_exits_130() {
    let dir = tempfile::tempdir().expect("temp dir");
    let log = dir.path().join("long.csv");
    let made = Command::new("mkfifo")
        .arg(&log)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo");
    let params =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/3hp.toml");
    let child = Command::new(assert_cmd::cargo::cargo_bin("sim-host"))
        .arg("diagnose")
        .arg("--params")
        .arg(&params)
        .arg(&log)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("sim-host starts");
    // Time to start and reach the log (it then waits on the pipe).
    std::thread::sleep(Duration::from_millis(1500));
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success(), "kill -INT");
    let started = Instant::now();
    let out = child.wait_with_output().expect("sim-host ends");
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "it ended at once"
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("interrupted by SIGINT")
            && stderr.contains(&format!("diagnose of {} stopped", log.display()))
            && stderr.contains("nothing was written"),
        "{stderr}"
    );
}
