//! The demo, `diagnose` and the HMI say the same state, fault and size for the same case
//! (issue 28): Rs +50 % is a FAULT `rs +5x %` on all three; Bl +50 % (to the paper's model
//! a load change) and a +30 % load step with no fault are the amber MOVED state with the
//! load's note, never a red FAULT; no probability is written as a bare percentage beside a
//! fault name. The demo injects faults only, so the load step is compared between `diagnose`
//! and the HMI.

use assert_cmd::Command;
use monitor_core::Fault;
use monitor_io::log::Log;
use monitor_io::params::ParamFile;
use monitor_sim::{simulate_to_vec, LoadStep, Scenario};
use monitor_studies::fault_signatures::{scenario, Protocol};
use monitor_testkit::text::verdict_line_of;
use sim_host::hmi::live::LiveSim;
use sim_host::hmi::{HmiState, Key, Source};
use std::path::Path;

/// The demo's protocol: commissioning 2-4 s, the fault at 5 s, 8 s in all.
fn protocol() -> Protocol {
    Protocol {
        duration_s: 8.0,
        fault_at_s: 5.0,
        ..Protocol::default()
    }
}

fn stdout(args: &[&str]) -> String {
    let out = Command::cargo_bin("sim-host")
        .expect("binary")
        .args(args)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf8")
}

/// The state column of the last timeline line (the text after the four lamps).
fn last_state(text: &str) -> String {
    let line = text
        .lines()
        .rfind(|l| l.contains(" s ") && l.chars().filter(|c| matches!(c, '●' | '○')).count() == 4)
        .unwrap_or_else(|| panic!("no timeline in\n{text}"));
    let after = line
        .rfind(['●', '○'])
        .map(|k| &line[k + '●'.len_utf8()..])
        .unwrap_or_default();
    after.trim().to_string()
}

/// The demo's last state.
fn demo(fault: &str) -> String {
    last_state(&stdout(&[
        "demo", "--paper", "--fault", fault, "--change", "0.5",
    ]))
}

/// `diagnose`'s last state on the demo's motor simulated with `sc`, commissioned 2-4 s.
fn diagnose(sc: &Scenario) -> String {
    diagnose_with(sc, &[])
}

/// [`diagnose`] with more command-line arguments (`--load viscous`).
fn diagnose_with(sc: &Scenario, more: &[&str]) -> String {
    let dir = tempfile::tempdir().expect("tmp");
    let params = ParamFile::reference_3hp();
    let p = dir.path().join("p.toml");
    std::fs::write(&p, params.to_toml_string()).expect("params");
    let rows = simulate_to_vec(&params, sc).expect("simulates");
    let csv = dir.path().join("d.csv");
    Log {
        channels: sc.sensors.channels(),
        rows,
    }
    .write(&csv)
    .expect("log");
    let mut args = vec![
        "diagnose",
        "--params",
        p.to_str().expect("utf8"),
        csv.to_str().expect("utf8"),
        "--commission",
        "2:4",
        "--timeline-step",
        "0.25",
    ];
    args.extend_from_slice(more);
    let text = stdout(&args);
    last_state(&text)
}

/// The HMI's plain status line after commissioning and then `keys` pressed, 3 s later.
fn hmi(keys: &[char]) -> String {
    let mut live = LiveSim::demo_motor().expect("reference motor");
    let mut state: HmiState = live.initial_state();
    let run = |live: &mut LiveSim, state: &mut HmiState, s: f64| {
        for _ in 0..(s / 0.25).round() as usize {
            live.advance(0.25, state);
        }
    };
    run(&mut live, &mut state, 1.5);
    assert!(live.key(Key::Char('c'), &mut state));
    run(&mut live, &mut state, 4.0);
    for k in keys {
        assert!(live.key(Key::Char(*k), &mut state));
    }
    run(&mut live, &mut state, 3.0);
    let line = state.status_line();
    // The status line: time, speed, four lamps, then the state.
    let k = line.rfind(['●', '○']).expect("lamps");
    let words: Vec<&str> = line[k + '●'.len_utf8()..].split_whitespace().collect();
    words.join(" ")
}

/// The named fault's size in per cent after `prefix` (`"FAULT rs "` -> 49 of `+49 %`).
fn size_after(state: &str, prefix: &str) -> Option<i32> {
    let rest = state.strip_prefix(prefix)?;
    let (num, _) = rest.split_once(" %")?;
    num.strip_prefix('+')?.parse().ok()
}

/// No fault name followed by an unsigned percentage (a probability as a size).
fn no_bare_percentage(state: &str) {
    let words: Vec<&str> = state.split_whitespace().collect();
    for w in words.windows(3) {
        let name = Fault::ALL.iter().any(|f| f.name() == w[0]) || w[0] == "b/bl";
        let unsigned = w[1].chars().all(|c| c.is_ascii_digit());
        assert!(
            !(name && unsigned && w[2] == "%"),
            "a bare percentage beside a fault: {state}"
        );
    }
}

#[test]
fn rs_plus_50_is_the_same_fault_and_size_on_the_three() {
    let proto = protocol();
    let states = [
        ("demo", demo("rs")),
        (
            "diagnose",
            diagnose(&scenario(Some((Fault::Rs, 0.5)), &proto)),
        ),
        ("hmi", hmi(&['1'])),
    ];
    for (who, s) in &states {
        no_bare_percentage(s);
        let size =
            size_after(s, "FAULT rs ").unwrap_or_else(|| panic!("{who}: not `FAULT rs +N %`: {s}"));
        assert!((40..=60).contains(&size), "{who}: rs {size:+} %: {s}");
    }
}

/// The paper's fixed viscous load (the demo and `diagnose --load viscous`): a Bl change is
/// the fault b/bl, shown in the amber state. With the load an unknown input (`diagnose`'s
/// default, and the live HMI's: a load step of 10-40 % is never a FAULT there, issue 48) the
/// same change is a load move: amber, without a name.
#[test]
fn bl_plus_50_is_the_amber_state_with_the_friction_class_on_the_three() {
    let proto = protocol();
    let sc = scenario(Some((Fault::Bl, 0.5)), &proto);
    for (who, unknown) in [("diagnose", diagnose(&sc)), ("hmi", hmi(&['6']))] {
        assert!(
            unknown.starts_with("MOVED operating point moved") && !unknown.contains("b/bl"),
            "{who} with the load unknown: {unknown}"
        );
        assert!(!unknown.contains("FAULT"), "{who}: a red FAULT: {unknown}");
    }
    let states = [
        ("demo", demo("bl")),
        ("diagnose", diagnose_with(&sc, &["--load", "viscous"])),
    ];
    for (who, s) in &states {
        no_bare_percentage(s);
        assert!(!s.contains("FAULT"), "{who}: a red FAULT: {s}");
        let size = size_after(s, "MOVED moved: b/bl ")
            .unwrap_or_else(|| panic!("{who}: not `MOVED moved: b/bl +N %`: {s}"));
        assert!((40..=60).contains(&size), "{who}: b/bl {size:+} %: {s}");
        assert!(s.contains("load (active current)"), "{who}: no note: {s}");
    }
}

#[test]
fn a_load_step_without_a_fault_is_the_amber_state_in_diagnose_and_the_hmi() {
    let mut sc = scenario(None, &protocol());
    sc.load.steps.push(LoadStep {
        t_s: 5.0,
        torque_nm: None,
        bl_scale: Some(1.3),
    });
    // Three `+` presses: the load x1.3.
    let states = [("diagnose", diagnose(&sc)), ("hmi", hmi(&['+', '+', '+']))];
    for (who, s) in &states {
        no_bare_percentage(s);
        assert!(
            s.starts_with("MOVED") && s.contains("load (active current)") && s.contains("above"),
            "{who}: not the amber state with the load's note: {s}"
        );
        assert!(!s.contains("FAULT"), "{who}: {s}");
    }
}

/// `diagnose` never prints a bare "verdict: FAULT" beside "final lamps: none" and
/// "candidates: none" (the README's simulated 3 hp log with load steps and its window): it
/// says what the verdict rests on.
#[test]
fn a_fault_verdict_beside_dark_lamps_says_why() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let p = repo.join("examples/params/3hp.toml");
    let sc = repo.join("examples/scenarios/healthy_3hp.toml");
    let dir = tempfile::tempdir().expect("tmp");
    let csv = dir.path().join("run.csv");
    let path = |p: &Path| p.to_str().expect("utf8").to_string();
    stdout(&[
        "simulate",
        "--params",
        &path(&p),
        "--scenario",
        &path(&sc),
        "--out",
        &path(&csv),
    ]);
    let text = stdout(&[
        "diagnose",
        "--params",
        &path(&p),
        &path(&csv),
        "--commission",
        "2:3.5",
    ]);
    let dark = text.contains("\nfinal lamps: none\n") && text.contains("\ncandidates: none\n");
    let verdict = verdict_line_of(&text);
    let verdict = verdict.as_str();
    assert!(
        !(dark && verdict == "verdict: FAULT"),
        "a bare FAULT beside dark lamps and no candidate:\n{text}"
    );
    if dark && verdict.starts_with("verdict: FAULT") {
        assert!(verdict.contains("the lamps lit at "), "{verdict}");
    }
    // The log is healthy: its lamps lit only while the load stood 50 % above the
    // commissioned range, the isolation read that as the load's move (the stator-voltage
    // equations fit), and the lamps are dark at the end, back in the commissioned range:
    // healthy, and the verdict says what the lamps lit for.
    assert!(
        verdict.starts_with("verdict: healthy") && verdict.contains("lamps lit for a load move"),
        "{verdict}"
    );
}
