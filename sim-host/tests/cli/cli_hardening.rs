//! The real binary under hostile conditions (issue 8): a reader that goes away, a full disk
//! on stdout, Ctrl-C in the middle of a run, outputs that are inputs by another name, the
//! umask, scenarios that would run for days, and parameter files no machine has. Each
//! failure is one line on stderr and never a panic; no input is ever changed.

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_sim-host");

const PARAMS_3HP: &str = "[motor]\nrs_ohm = 0.435\nrr_ohm = 0.816\nls_h = 0.0713\nlr_h = 0.0713\nlm_h = 0.0693\npoles = 4\nj_kgm2 = 0.089\nb_nms = 0.002\nbl_nms = 0.045\n[supply]\nv_ll_rms = 220.0\nf_hz = 60.0\n";

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf8 path")
}

/// Waits for `child` at most `limit`; a child still running then is killed and the test
/// fails (a run the old code would not have stopped).
fn wait_at_most(mut child: std::process::Child, limit: Duration) -> Output {
    let t0 = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return child.wait_with_output().expect("output");
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs the binary to the end (at most a minute).
fn run(args: &[&str]) -> Output {
    let child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    wait_at_most(child, Duration::from_secs(60))
}

/// Runs a command that must fail; returns its stderr, checked to be one line and no panic.
fn refused(args: &[&str]) -> String {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
    assert!(!o.status.success(), "{args:?} should fail");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line:\n{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// `simulate --params P --scenario S --out O`.
fn simulate<'a>(params: &'a Path, scenario: &'a Path, out: &'a Path) -> [&'a str; 7] {
    let (p, sc, o) = (s(params), s(scenario), s(out));
    ["simulate", "--params", p, "--scenario", sc, "--out", o]
}

/// A healthy 3 hp log of `secs` seconds at 2 kHz written by `simulate` into `dir`.
fn small_log(dir: &Path, name: &str, secs: f64) -> (PathBuf, PathBuf) {
    let params = write(dir, "motor.toml", PARAMS_3HP);
    let sc = write(
        dir,
        "short.toml",
        &format!("duration_s = {secs}\nsample_rate_hz = 2000.0\n"),
    );
    let log = dir.join(name);
    let o = run(&simulate(&params, &sc, &log));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (params, log)
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_reader_that_goes_away_ends_the_run_quietly() {
    let dir = tempfile::tempdir().expect("tmp");
    let (params, log) = small_log(dir.path(), "run.csv", 1.0);
    let (p, l) = (s(&params), s(&log));
    for args in [
        vec!["demo"],
        vec!["demo", "--json"],
        vec!["table1", "--json"],
        vec!["diagnose", "--params", p, l],
        vec!["diagnose", "--params", p, l, "--json"],
        vec!["compare", "--params", p, l],
        vec!["compare", "--params", p, l, "--json"],
        vec!["explain", "--params", p, l],
        vec!["explain", "--params", p, l, "--json"],
    ] {
        let mut child = Command::new(BIN)
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn");
        // `| head -c 0`: the reader closes before the first byte is written.
        drop(child.stdout.take());
        let o = wait_at_most(child, Duration::from_secs(60));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
        assert!(err.trim().is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn a_full_disk_on_stdout_is_one_line_and_status_1() {
    for args in [["demo", "--json"], ["demo", "--fault=rs"]] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full (Linux)");
        let o = Command::new(BIN)
            .args(args)
            .stdout(full)
            .stderr(Stdio::piped())
            .output()
            .expect("run");
        let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("cannot write to standard output") && err.contains("No space left"),
            "{err}"
        );
    }
}

/// Starts a long `simulate` into `dir/out.csv`, waits until its temporary file is being
/// written, sends `signal` and returns the result.
fn interrupt_simulate(dir: &Path, signal: &str) -> Output {
    let params = write(dir, "motor.toml", PARAMS_3HP);
    // 1000 s at 10 kHz: 1e7 rows, about 0.9 GB, a few seconds of work.
    let sc = write(
        dir,
        "long.toml",
        "duration_s = 1000.0\nsample_rate_hz = 10000.0\n",
    );
    let out = dir.join("out.csv");
    let child = Command::new(BIN)
        .args(["simulate", "--params", s(&params), "--scenario", s(&sc)])
        .args(["--out", s(&out)])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let t0 = Instant::now();
    let writing = || {
        std::fs::read_dir(dir).expect("dir").any(|e| {
            let e = e.expect("entry");
            e.file_name().to_string_lossy().ends_with(".tmp")
                && e.metadata().is_ok_and(|m| m.len() > 1_000_000)
        })
    };
    while !writing() {
        assert!(t0.elapsed() < Duration::from_secs(30), "no temporary file");
        std::thread::sleep(Duration::from_millis(10));
    }
    let ok = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(ok.success());
    wait_at_most(child, Duration::from_secs(30))
}

#[test]
fn ctrl_c_or_sigterm_during_simulate_leaves_no_output_and_no_temporary_file() {
    for (signal, status) in [("-INT", 130), ("-TERM", 143)] {
        let dir = tempfile::tempdir().expect("tmp");
        let o = interrupt_simulate(dir.path(), signal);
        let err = String::from_utf8_lossy(&o.stderr).trim().to_string();
        assert_eq!(o.status.code(), Some(status), "{signal}: {err}");
        assert!(
            err.contains("interrupted") && err.lines().count() == 1,
            "{err}"
        );
        // Only the two inputs remain: no out.csv, no hidden .sim-host-*.tmp.
        assert_eq!(names(dir.path()), ["long.toml", "motor.toml"], "{signal}");
    }
}

/// Runs the binary under `umask`; returns its output.
fn run_with_umask(umask: &str, args: &[&str]) -> Output {
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!("umask {umask} && exec \"$0\" \"$@\""))
        .arg(BIN)
        .args(args)
        .output()
        .expect("sh");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).expect("metadata").permissions().mode() & 0o777
}

#[test]
fn outputs_get_the_mode_of_any_new_file() {
    let dir = tempfile::tempdir().expect("tmp");
    let (params, log) = small_log(dir.path(), "first.csv", 1.5);
    let sc = dir.path().join("short.toml");
    for (umask, want) in [("022", 0o644), ("077", 0o600), ("002", 0o664)] {
        let out = dir.path().join(format!("u{umask}.csv"));
        run_with_umask(umask, &simulate(&params, &sc, &out));
        assert_eq!(mode(&out), want, "umask {umask}");
    }
    // The report page and the charts (SVG via the atomic writer, PNG via the plotter).
    let report = dir.path().join("report");
    run_with_umask(
        "022",
        &[
            "compare",
            "--params",
            s(&params),
            s(&log),
            "--report",
            s(&report),
        ],
    );
    for f in ["report.html", "overlay_iqs.svg", "overlay_iqs.png"] {
        assert_eq!(mode(&report.join(f)), 0o644, "{f}");
    }
    // Nothing but the report and the charts is left in the folder.
    assert!(names(&report).iter().all(|n| !n.starts_with('.')));
}

#[test]
fn an_input_under_a_name_the_command_writes_is_refused_and_unchanged() {
    let dir = tempfile::tempdir().expect("tmp");
    let (params, log) = small_log(dir.path(), "run.csv", 1.5);
    let before = std::fs::read(&log).expect("read");
    let plots = dir.path().join("plots");
    std::fs::create_dir(&plots).expect("mkdir");
    // The log hard-linked under a chart name of `compare` and of `explain`, and under the
    // report page's name: the same file by another path.
    for (cmd, flag, name) in [
        ("compare", "--plot", "error_spectrum.png"),
        ("compare", "--report", "report.html"),
        ("explain", "--plot", "before_after_error.svg"),
    ] {
        let link = plots.join(name);
        std::fs::hard_link(&log, &link).expect("hard link");
        let e = refused(&[cmd, "--params", s(&params), s(&log), flag, s(&plots)]);
        assert!(
            e.contains("refusing to overwrite") && e.contains(name),
            "{e}"
        );
        std::fs::remove_file(&link).expect("rm");
    }
    // The log itself stored under a chart name and analysed from there.
    let inside = plots.join("overlay_iqs.svg");
    std::fs::copy(&log, &inside).expect("copy");
    let e = refused(&[
        "compare",
        "--params",
        s(&params),
        s(&inside),
        "--plot",
        s(&plots),
    ]);
    assert!(e.contains("refusing to overwrite"), "{e}");
    assert_eq!(std::fs::read(&inside).expect("read"), before);
    // `simulate --out` hard-linked to the parameter file.
    let sc = dir.path().join("short.toml");
    let link = dir.path().join("out.csv");
    std::fs::hard_link(&params, &link).expect("hard link");
    let e = refused(&simulate(&params, &sc, &link));
    assert!(e.contains("refusing to overwrite"), "{e}");
    assert_eq!(std::fs::read_to_string(&params).expect("read"), PARAMS_3HP);
    assert_eq!(std::fs::read(&log).expect("read"), before);
    assert_eq!(names(&plots), ["overlay_iqs.svg"]);
}

#[test]
fn scenarios_that_would_run_for_days_are_refused_before_writing() {
    let dir = tempfile::tempdir().expect("tmp");
    let params = write(dir.path(), "motor.toml", PARAMS_3HP);
    let out = dir.path().join("out.csv");
    for (name, text, needles) in [
        // 8e5 s at 10 kHz: 8e9 rows, hundreds of GB.
        (
            "long.toml",
            "duration_s = 8e5\nsample_rate_hz = 10000.0\n",
            &["duration_s", "GB", "--force"][..],
        ),
        (
            "fast.toml",
            "duration_s = 1.0\nsample_rate_hz = 1e9\n",
            &["sample_rate_hz", "1..=1000000 Hz"][..],
        ),
        (
            "tiny_step.toml",
            "duration_s = 1.0\nsample_rate_hz = 10000.0\nmax_step_s = 1e-12\n",
            &["max_step_s", "1e-7..=1e-4 s"][..],
        ),
        // 1000 s at 1 kHz with the finest step: 1e6 rows but 1e10 steps.
        (
            "slow.toml",
            "duration_s = 1000.0\nsample_rate_hz = 1000.0\nmax_step_s = 1e-7\n",
            &["steps", "max_step_s", "--force"][..],
        ),
    ] {
        let sc = write(dir.path(), name, text);
        let e = refused(&simulate(&params, &sc, &out));
        for n in needles {
            assert!(e.contains(n), "{name}: no '{n}' in {e}");
        }
    }
    assert!(!out.exists());
    assert!(names(dir.path()).iter().all(|n| !n.ends_with(".tmp")));
}

#[test]
fn parameter_files_no_machine_has_are_refused_naming_key_value_and_range() {
    let dir = tempfile::tempdir().expect("tmp");
    for (from, to, needles) in [
        (
            "rs_ohm = 0.435",
            "rs_ohm = 1e9",
            ["motor.rs_ohm", "1.000e9", "plausible"],
        ),
        (
            "poles = 4",
            "poles = 1000",
            ["motor.poles", "1000", "2..=24"],
        ),
        (
            "j_kgm2 = 0.089",
            "j_kgm2 = 1e-12",
            ["motor.j_kgm2", "1.000e-12", "plausible"],
        ),
        (
            "lr_h = 0.0713",
            "lr_h = = 0.0713",
            ["line 5", "column 8", "motor.toml"],
        ),
    ] {
        let p = write(dir.path(), "motor.toml", &PARAMS_3HP.replace(from, to));
        let e = refused(&["table1", "--params", s(&p)]);
        for n in needles {
            assert!(e.contains(n), "{to}: no '{n}' in {e}");
        }
    }
}

#[test]
fn nan_and_negative_arguments_are_refused_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (params, log) = small_log(dir.path(), "a.csv", 0.5);
    let (p, l) = (s(&params), s(&log));
    for (args, name) in [
        (vec!["compare", "--params", p, l, "--from", "-5"], "--from"),
        (vec!["compare", "--params", p, l, "--from", "nan"], "--from"),
        (vec!["explain", "--params", p, l, "--to", "inf"], "--to"),
        (
            vec!["diagnose", "--params", p, l, "--timeline-step", "0"],
            "--timeline-step",
        ),
        (
            vec!["hmi", l, "--params", p, "--duration", "nan"],
            "--duration",
        ),
        (vec!["bench", "--repeat", "0"], "--repeat"),
        // A missing required argument is named, not only "required arguments".
        (vec!["diagnose", l], "--params"),
    ] {
        let err = refused(&args);
        assert!(err.contains(name), "{args:?}: {err}");
    }
}
