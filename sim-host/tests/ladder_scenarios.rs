//! The project's own hidden-effect scenarios (`examples/scenarios/effect_*.toml`) through
//! `simulate` and `explain --ladder`, as the README's user runs them: every hidden effect is
//! named along the ladder, its fitted size is the injected one where the scenario states it,
//! and the ladder ends within 2x the noise floor.
//!
//! `cargo test` runs the two scenarios whose effect shows only where the speed moves
//! (windage, Coulomb friction); `MONITOR_FULL_SWEEPS=1` runs all nine:
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test --release -p sim-host --test ladder_scenarios -- --nocapture
//! ```
use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The parameter file a scenario names in its header comment (`examples/params/X.toml`).
fn params_of(scenario: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scenario).unwrap();
    let at = text
        .find("examples/params/")
        .unwrap_or_else(|| panic!("{} names no parameter file", scenario.display()));
    let name: String = text[at..]
        .chars()
        .take_while(|c| !c.is_whitespace() && *c != ')')
        .collect();
    repo().join(name)
}

/// Simulates `effect_<effect>.toml` and runs the ladder on it: the JSON document.
fn ladder_on(effect: &str, dir: &Path) -> serde_json::Value {
    let scenario = repo().join(format!("examples/scenarios/effect_{effect}.toml"));
    let params = params_of(&scenario);
    let log = dir.join(format!("{effect}.csv"));
    Command::cargo_bin("sim-host")
        .unwrap()
        .args(["simulate", "--params"])
        .arg(&params)
        .arg("--scenario")
        .arg(&scenario)
        .arg("--out")
        .arg(&log)
        .assert()
        .success();
    let out = Command::cargo_bin("sim-host")
        .unwrap()
        .args(["explain", "--ladder", "--json", "--params"])
        .arg(&params)
        .arg(&log)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{effect}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The effect is named on a step of the ladder, which ends within 2x the noise floor on the
/// whole log or 5x below its start (the ladder's bar); `truth` (parameter, injected value)
/// is met within 10 % when given.
fn named(effect: &str, truth: Option<(&str, f64)>) {
    let dir = tempfile::tempdir().unwrap();
    let v = ladder_on(effect, dir.path());
    let steps = v["ladder"].as_array().unwrap();
    let added = |s: &serde_json::Value| -> Vec<String> {
        let a = s["added"].as_array().unwrap();
        a.iter().map(|e| e.as_str().unwrap().to_string()).collect()
    };
    let effects: Vec<Vec<String>> = steps.iter().map(added).collect();
    let step = steps
        .iter()
        .find(|s| added(s).iter().any(|e| e == effect))
        .unwrap_or_else(|| panic!("{effect} not named: the ladder added {effects:?}"));
    let last = steps.last().unwrap();
    let ratio = last["ratio_to_floor"].as_f64().unwrap();
    let start = v["start"]["error"].as_f64().unwrap();
    let fall = start / last["error"].as_f64().unwrap();
    assert!(
        ratio <= 2.0 || fall >= 5.0,
        "{effect}: ends at {ratio:.2}x the floor, {fall:.1}x below the start"
    );
    if let Some((p, x)) = truth {
        let fitted = step["fitted"]
            .as_object()
            .unwrap()
            .iter()
            .find(|(k, _)| k.ends_with(p))
            .map(|(_, f)| f["value"].as_f64().unwrap())
            .unwrap_or_else(|| panic!("{effect}: no fitted {p} in {:#}", step["fitted"]));
        assert!(
            (fitted - x).abs() <= 0.1 * x.abs(),
            "{effect}: {p} = {fitted}, injected {x}"
        );
    }
    println!(
        "{effect}: named ({effects:?}), ends at {ratio:.2}x the floor, {fall:.0}x below the start"
    );
}

fn full() -> bool {
    std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1")
}

/// A fan load (k w^2) beside the viscous load: named once the V/f step moves the speed.
#[test]
fn windage_is_named_with_its_size() {
    named("windage", Some(("k_nms2", 3.0e-4)));
}

/// Dry friction beside a load torque's steps: the start, where it is not yet turning,
/// tells it from a constant load.
#[test]
fn coulomb_friction_is_named_with_its_size() {
    named("coulomb_friction", Some(("torque_nm", 3.0)));
}

/// The other seven scenarios (full sweeps only: about two minutes in release).
#[test]
fn every_other_hidden_effect_is_named() {
    if !full() {
        return;
    }
    named("rotor_asymmetry", Some(("delta", 0.27)));
    for e in [
        "thermal_drift",
        "saturation",
        "iron_loss",
        "load_torque",
        "supply_unbalance",
        "phase_asymmetry",
    ] {
        named(e, None);
    }
}
