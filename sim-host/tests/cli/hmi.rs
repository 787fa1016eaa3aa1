//! `sim-host hmi` run as a user runs it: plain text when stdout is not a terminal, the keys
//! in `--help` and docs/hmi.md, and a log replay that takes `diagnose`'s options. (The three
//! sources through the library: `src/hmi/tests.rs`; the screen: `src/cli/render/hmi.rs`; a real
//! terminal: `hmi_tmux.rs`.)

use monitor_testkit::text::verdict_line_of;

/// Stdout not a terminal: one status line per reading interval, the events, then exit 0
/// when standard input ends.
#[test]
fn plain_text_when_stdout_is_not_a_terminal() {
    let sample =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fw_status_sample.txt");
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["hmi", "--stdin", "--every", "0.1"])
        .pipe_stdin(&sample)
        .expect("stdin")
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let status: Vec<&str> = out.lines().filter(|l| l.contains(" rpm ")).collect();
    assert_eq!(status.len(), 5, "{out}");
    assert!(status[2].contains("commissioning 5 %"), "{out}");
    assert!(
        status[4].contains("○●●● FAULT") && status[4].contains("sig. b/bl p 1.00"),
        "{out}"
    );
    assert!(out.contains("> WARN ADC DMA overrun #1"), "{out}");
    // No escape sequences: plain text.
    assert!(!out.contains('\u{1b}'), "{out:?}");

    // The live simulation for two seconds of wall time.
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["hmi", "--duration", "2", "--every", "0.5"])
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.starts_with("live simulation: 3 hp reference motor"),
        "{out}"
    );
    assert!(
        out.lines().filter(|l| l.contains(" rpm ")).count() >= 2,
        "{out}"
    );
}

/// `hmi --help` teaches: examples and the key list; the HMI page's key list (docs/hmi.md) is the same.
#[test]
fn the_help_and_the_readme_list_the_keys() {
    let o = assert_cmd::Command::cargo_bin("sim-host")
        .expect("binary")
        .args(["hmi", "--help"])
        .output()
        .expect("runs");
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(help.contains("sim-host hmi LOG --params P.toml") && help.contains("--stdin"));
    let readme = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/hmi.md"),
    )
    .expect("docs/hmi.md");
    for line in sim_host::hmi::key_help().lines().skip(1) {
        assert!(help.contains(line), "--help lacks `{line}`");
        assert!(readme.contains(line), "docs/hmi.md lacks `{line}`");
    }
}

/// `hmi LOG` takes `diagnose`'s options through the same request (issue 64): `--load`,
/// `--baseline` and `--group` are accepted, the baseline's healthy runs are what the
/// verdict's winding is judged against, and a value `diagnose` refuses the HMI refuses with
/// the same one-line message.
#[test]
fn a_log_replay_takes_diagnoses_options_and_refuses_what_it_refuses() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let itsc = root.join("examples/recordings/itsc");
    let s = |p: &std::path::Path| p.display().to_string();
    let (log, params) = (
        s(&itsc.join("SC_A0_B0_C1_001.csv")),
        s(&itsc.join("baldor_0p75hp.toml")),
    );
    let (h1, h2) = (
        s(&itsc.join("SC_HLT_001.csv")),
        s(&itsc.join("SC_HLT_002.csv")),
    );
    let run = |cmd: &str, extra: &[&str]| {
        let mut args = vec![cmd.to_string()];
        if cmd == "hmi" {
            args.extend([log.clone(), "--params".into(), params.clone()]);
            args.extend(["--speed", "max", "--plain", "--every", "1"].map(String::from));
        } else {
            args.extend(["--params".into(), params.clone(), log.clone()]);
        }
        args.extend(extra.iter().map(|a| a.to_string()));
        assert_cmd::Command::cargo_bin("sim-host")
            .expect("binary")
            .args(&args)
            .timeout(std::time::Duration::from_secs(120))
            .output()
            .expect("runs")
    };
    // Accepted: the healthy runs are the reference, as diagnose says.
    let with = ["--load", "viscous", "--baseline"];
    let mut extra: Vec<&str> = with.to_vec();
    extra.extend([h1.as_str(), h2.as_str()]);
    let o = run("hmi", &extra);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        out.contains("> log analysed: verdict fault")
            && out.contains("> verdict: FAULT shorted turns in phase c")
            && out.contains("winding against healthy runs"),
        "{out}"
    );
    let d = run("diagnose", &extra);
    let line = verdict_line_of(&String::from_utf8_lossy(&d.stdout))
        .strip_prefix("verdict: ")
        .map(str::to_string)
        .expect("diagnose's verdict line");
    assert!(out.contains(&format!("> verdict: {line}")), "{line}\n{out}");
    // Without the baseline: judged against the log's own stretches.
    let o = run("hmi", &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && !out.contains("against healthy runs"),
        "{out}"
    );
    // Refused, with diagnose's words: a load the library does not know (clap's line), a
    // baseline that is the log itself and one that does not exist (the library's).
    let missing = s(&itsc.join("nosuch.csv"));
    for bad in [
        vec!["--load", "heavy"],
        vec!["--baseline", log.as_str()],
        vec!["--baseline", missing.as_str()],
        vec!["--commission", "4:2"],
        vec!["--group", "x"],
    ] {
        let h = run("hmi", &bad);
        let d = run("diagnose", &bad);
        assert!(!h.status.success() && !d.status.success(), "{bad:?}");
        let first = |o: &std::process::Output| {
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .next()
                .unwrap_or_default()
                .to_string()
        };
        assert_eq!(first(&h), first(&d), "{bad:?}");
        assert!(first(&h).contains(bad[0]), "{bad:?}: {}", first(&h));
        assert!(!first(&h).contains("Usage"), "{bad:?}: {}", first(&h));
    }
}
