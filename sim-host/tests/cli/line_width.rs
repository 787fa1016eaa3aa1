//! Issue 86, item 7: readable at a glance. No text line of any command's output over the
//! shipped examples is longer than 160 characters (a list one item a line); the ladder's
//! `found:` line ran 924-1 259 characters, explain's `model's error:` 800, a healthy
//! recording's verdict 666, the trend's alarm 425. stdout and stderr, text outputs (the
//! JSON documents and the fleet's CSV are data, not lines a crew reads). About 10 s in the
//! test profile.

use assert_cmd::Command;
use monitor_testkit::text::help_subcommands as commands;
use std::path::{Path, PathBuf};

const WIDTH: usize = 160;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace") // ok: test
        .to_path_buf()
}

/// The lines of `sim-host args` (stdout, then stderr; stderr alone for the fleet, whose
/// stdout is its CSV) longer than [`WIDTH`] characters.
fn long_lines(args: &[&str]) -> Vec<String> {
    let data = args.first() == Some(&"fleet");
    let out = Command::cargo_bin("sim-host")
        .expect("binary") // ok: test
        .current_dir(repo())
        .args(args)
        .output()
        .expect("runs"); // ok: test
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = if data { Vec::new() } else { out.stdout };
    [stdout, out.stderr]
        .iter()
        .flat_map(|b| {
            String::from_utf8_lossy(b)
                .lines()
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .filter(|l| l.chars().count() > WIDTH)
        .collect()
}

#[test]
fn no_output_line_is_longer_than_160_characters() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let d = dir.path();
    let p = |name: &str| d.join(name).to_str().expect("utf8").to_string(); // ok: test
    let (store, id, a, b) = (
        p("h.db"),
        p("id.toml"),
        p("pump_1_20261101_0600.csv"),
        p("pump_1_20261102_0600.csv"),
    );
    for (log, seed) in [(&a, "1"), (&b, "2")] {
        let run = Command::cargo_bin("sim-host")
            .expect("binary") // ok: test
            .current_dir(repo())
            .args([
                "simulate",
                "--params",
                "examples/params/2p2kw.toml",
                "--scenario",
            ])
            .args([
                "examples/scenarios/fault_rs_2p2kw.toml",
                "--out",
                log,
                "--seed",
                seed,
            ])
            .output()
            .expect("simulates"); // ok: test
        assert!(run.status.success());
    }
    let motors = p("motors.toml");
    let params = repo().join("examples/params/2p2kw.toml");
    std::fs::write(
        &motors,
        format!(
            "[[motor]]\nname = \"pump_1\"\nparams = \"{}\"\nlogs = \"pump_1_*\"\ntime_from_name = \"pump_1_%Y%m%d_%H%M\"\n",
            params.display()
        ),
    )
    .expect("motor table"); // ok: test
    let m = "examples/logs/motulator_2p2kw_dol.toml";
    let l = "examples/logs/motulator_2p2kw_dol.csv";
    let itsc = "examples/recordings/itsc/baldor_0p75hp.toml";
    let runs: Vec<Vec<&str>> = vec![
        vec!["diagnose", "--params", m, l],
        vec!["diagnose", "--params", m, l, "--commission", "1.5:2.4"],
        vec![
            "diagnose",
            "--params",
            "examples/params/daq_2p2kw.toml",
            "examples/logs/daq_2p2kw.csv",
        ],
        vec![
            "diagnose",
            "--params",
            itsc,
            "examples/recordings/itsc/SC_A0_B0_C1_001.csv",
            "--parallel-paths",
            "2",
        ],
        vec![
            "diagnose",
            "--params",
            itsc,
            "examples/recordings/itsc/SC_HLT_001.csv",
        ],
        vec![
            "diagnose",
            "--params",
            "examples/params/2p2kw.toml",
            &a,
            "--commission",
            "1.5:4.5",
        ],
        vec!["explain", "--params", m, l, "--from", "0.8"],
        vec![
            "compare",
            "--params",
            m,
            l,
            "--from",
            "0.8",
            "--effects",
            "load_torque",
        ],
        vec![
            "identify",
            "--params",
            "examples/params/daq_2p2kw.toml",
            "examples/logs/daq_2p2kw.csv",
            "--out",
            &id,
        ],
        vec!["demo"],
        vec!["table1"],
        vec!["fleet", &motors, &a, &b, "--store", &store],
        vec!["trend", "--store", &store],
        vec!["trend", "--store", &store, "--motor", "pump_1"],
    ];
    let mut long = Vec::new();
    for args in &runs {
        long.extend(
            long_lines(args)
                .into_iter()
                .map(|l| format!("{args:?}: {l}")),
        );
    }
    assert!(
        long.is_empty(),
        "{} lines over {WIDTH}:\n{}",
        long.len(),
        long.join("\n")
    );
}

/// Every `--help` (the top, each command's, each subcommand's) keeps within [`WIDTH`]: clap
/// wraps it at 160 columns where the output is no terminal, at the terminal's width (at
/// most 160) where it is one. Before, a command's long description was one line of up to
/// 900 characters.
#[test]
fn no_help_line_is_longer_than_160_characters() {
    let help = |args: &[&str]| -> String {
        let out = Command::cargo_bin("sim-host")
            .expect("binary") // ok: test
            .args(args)
            .arg("--help")
            .output()
            .expect("runs"); // ok: test
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let top = help(&[]);
    let mut texts = vec![(String::new(), top.clone())];
    for c in commands(&top) {
        let t = help(&[&c]);
        for sub in commands(&t) {
            texts.push((format!("{c} {sub}"), help(&[&c, &sub])));
        }
        texts.push((c, t));
    }
    assert!(texts.len() >= 15, "{} help texts", texts.len());
    let long: Vec<String> = texts
        .iter()
        .flat_map(|(c, t)| {
            t.lines()
                .filter(|l| l.chars().count() > WIDTH)
                .map(move |l| format!("`{c} --help`: {l}"))
        })
        .collect();
    assert!(long.is_empty(), "{}", long.join("\n"));
}
