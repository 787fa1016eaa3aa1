//! The project's own hidden-effect scenarios (`examples/scenarios/effect_*.toml`) through
//! `simulate` and `explain --ladder`, as the README's user runs them: every hidden effect is
//! named along the ladder, its fitted size is the injected one where the scenario states it,
//! and the ladder ends within 2x the noise floor.
//!
//! `cargo test` runs the two scenarios whose effect shows only where the speed moves
//! (windage, Coulomb friction); `MONITOR_FULL_SWEEPS=1` runs all nine, and a long log at a
//! low rate (40 s at 2 kHz of a small machine warming, with its control), and a supply
//! that sags beside a stator that warms (told apart by the measured voltages):
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test --release -p sim-host --test cli ladder_scenarios:: -- --nocapture
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
fn ladder_on_scenario(effect: &str, dir: &Path) -> serde_json::Value {
    let scenario = repo().join(format!("examples/scenarios/effect_{effect}.toml"));
    let params = params_of(&scenario);
    let log = dir.join(format!("{effect}.csv"));
    simulate_and_climb(&params, &scenario, &log, "0")
}

/// `simulate` of `scenario` on the machine of `params` into `log`, then `explain --ladder
/// --json` on it from `from` s: the JSON document.
fn simulate_and_climb(params: &Path, scenario: &Path, log: &Path, from: &str) -> serde_json::Value {
    simulate(params, scenario, log);
    let ladder = ["explain", "--ladder", "--json", "--from", from, "--params"];
    run_json(&ladder, params, log, scenario)
}

/// `simulate` of `scenario` on the machine of `params` into `log`.
fn simulate(params: &Path, scenario: &Path, log: &Path) {
    Command::cargo_bin("sim-host")
        .unwrap()
        .args(["simulate", "--params"])
        .arg(params)
        .arg("--scenario")
        .arg(scenario)
        .arg("--out")
        .arg(log)
        .assert()
        .success();
}

/// `sim-host <args> <params> <log>` (the arguments end with `--params`): its JSON document;
/// a failure names `scenario`.
fn run_json(args: &[&str], params: &Path, log: &Path, scenario: &Path) -> serde_json::Value {
    let out = Command::cargo_bin("sim-host")
        .unwrap()
        .args(args)
        .arg(params)
        .arg(log)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}: {}",
        scenario.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The effect is named on a step of the ladder, which ends within 2x the noise floor on the
/// whole log or 5x below its start (the ladder's bar); `truth` (parameter, injected value)
/// is met within 10 % when given.
fn named(effect: &str, truth: Option<(&str, f64)>) {
    let dir = tempfile::tempdir().unwrap();
    let v = ladder_on_scenario(effect, dir.path());
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
    // The found line states the values of the step that named the effect (issue 87,
    // item 4: one story), not the final refit's, which may trade with the base.
    let found = v["summary"].as_str().unwrap();
    let said = step["summary"].as_str().unwrap();
    if found.contains(&format!("{effect}: ")) {
        assert!(
            said.split("; ")
                .any(|d| found.contains(&format!("{effect}: {d}"))),
            "{effect}: the found line does not state the step's values\n  step: {said}\n  found: {found}"
        );
    }
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

/// The long low-rate log's scenario: a machine started direct-on-line on its viscous
/// load, 40 s at 2 kHz (80 000 samples), variac steps through the run, a 12-bit current
/// sensor of range `i_range_a` with `noise_i` A of noise; `warming`: both windings warm by
/// 50 K with a 15 s time constant.
fn long_scenario(warming: bool, i_range_a: f64, noise_i: f64) -> String {
    let mut s = format!(
        r#"duration_s = 40.0
sample_rate_hz = 2000.0
seed = 5

[supply]
steps = [{{ t_s = 12.0, v_scale = 0.9 }}, {{ t_s = 13.5, v_scale = 1.0 }}, {{ t_s = 26.0, v_scale = 1.05 }}, {{ t_s = 27.5, v_scale = 1.0 }}]

[load]
kind = "viscous"

[sensors]
adc_bits = 12
v_range_v = 400.0
i_range_a = {i_range_a}
noise_v = 0.5
noise_i = {noise_i}
encoder = false
"#
    );
    if warming {
        s.push_str(
            "\n[[effects]]\nname = \"thermal_drift\"\nrise_k = 50.0\ntau_s = 15.0\nrotor = true\n",
        );
    }
    s
}

/// A long log of [`long_scenario`] on the machine of `machine` (the file the simulator and
/// the analysis read), the ladder's JSON from `from` s on.
struct LongLog<'a> {
    machine: monitor_io::params::ParamFile,
    i_range_a: f64,
    noise_i: f64,
    from: &'a str,
}

/// The 0.37 kW machine (`monitor_testkit::small_motor`, a 2.1 ms stator transient), from
/// 0.3 s on: the span `compare` advises, this machine reaching its speed in 30 ms, a start
/// the library's model does not follow (docs/model-vs-measurement.md).
fn small_long() -> LongLog<'static> {
    LongLog {
        machine: monitor_testkit::small_motor::small_0p37kw(),
        i_range_a: 10.0,
        noise_i: 0.002,
        from: "0.3",
    }
}

/// The ladder's JSON on the 0.37 kW machine's long log ([`small_long`]).
fn ladder_on_long_log(warming: bool, dir: &Path) -> serde_json::Value {
    ladder_on(&small_long(), warming, dir)
}

/// Simulates the long log of `l` (warming or not) into `dir` and runs the ladder on it
/// from `l.from`: the JSON document.
fn ladder_on(l: &LongLog<'_>, warming: bool, dir: &Path) -> serde_json::Value {
    let params = dir.join("machine.toml");
    let scenario = dir.join("long.toml");
    let log = dir.join("long.csv");
    std::fs::write(&params, l.machine.to_toml_string()).unwrap();
    std::fs::write(&scenario, long_scenario(warming, l.i_range_a, l.noise_i)).unwrap();
    simulate_and_climb(&params, &scenario, &log, l.from)
}

/// A long log at a low rate (issue 87): 40 s at 2 kHz of a small machine warming by 50 K.
/// The fit keeps the log's own rate, which the machine's 2.1 ms stator transient needs (at
/// 1 kHz its dynamics were refused and the ladder stopped at 11x the floor, "nothing
/// plausible helps", warming or not): the drift is named with both windings' rise within
/// 25 % of the injected 50 K beside the machine's dynamics, the chosen model refitted on
/// the whole log ends within 1.2x the floor, and the same log without the warming names no
/// drift. Full sweeps only (two ladders of 80 000 samples).
#[test]
fn a_long_low_rate_log_names_its_warming_and_its_control_stays_clean() {
    if !full() {
        return;
    }
    let finals = |v: &serde_json::Value| -> Vec<String> {
        v["final_effects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap().to_string())
            .collect()
    };
    let dir = tempfile::tempdir().unwrap();
    let v = ladder_on_long_log(true, dir.path());
    let fin = &v["final_fit"];
    let drift = fin["fitted"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["effect"] == "thermal_drift")
        .unwrap_or_else(|| panic!("no drift named: {:?}", finals(&v)));
    assert_rise_near(drift, 50.0);
    let dynamics = finals(&v).iter().any(|e| e.ends_with("_dynamics"));
    assert!(dynamics, "the dynamics refused: {:?}", finals(&v));
    let end = fin["ratio_to_floor"].as_f64().unwrap();
    assert!(end <= 1.2, "the warming log ends at {end:.2}x the floor");
    let c = ladder_on_long_log(false, dir.path());
    let named = finals(&c);
    assert!(
        named.iter().all(|e| e.ends_with("_dynamics")),
        "the control names {named:?}"
    );
    let end = c["final_fit"]["ratio_to_floor"].as_f64().unwrap();
    assert!(end <= 1.2, "the control ends at {end:.2}x the floor");
}

/// The drift `drift` (a fitted effect of the JSON) rose within 25 % of `injected` K in
/// both windings: one rise for both (`rise_k`), or the stator's and the rotor's apart.
fn assert_rise_near(drift: &serde_json::Value, injected: f64) {
    let p = &drift["parameters"];
    let names: &[&str] = if p.get("rise_k").is_some() {
        &["rise_k"]
    } else {
        &["stator_rise_k", "rotor_rise_k"]
    };
    for n in names {
        let rise = p[n]["value"].as_f64().unwrap();
        assert!(
            (rise - injected).abs() <= 0.25 * injected,
            "{n} {rise:.1} K, injected {injected} K"
        );
    }
}

/// The stopping rule weighs the log's length (issue 87): 40 s at 60 Hz of the 3 hp machine
/// (2 400 supply periods) warming by 50 K ends at 1.04x the floor with the dynamics alone,
/// inside the 1.12x band of a short log, where the ladder said "nothing is left to
/// explain" and never tried the drift. Its band is now 1.03x, and the drift is named: one
/// rise for both windings (the log does not tell them apart), judged at its values
/// corrected for the voltages' noise (SIMEX, the base refitted around them) against its own
/// noise floor, the rise within 25 % of the 50 K injected and the chosen model within the
/// band of its floor. The same log without the warming still stops at the floor with the
/// dynamics only. Full sweeps only (two ladders of 80 000 samples).
///
/// Before: the fitted values (stator +193 K) were refused as not physical; with the test
/// read at the log's rate they passed by passing less of the voltages' noise (1.16x their
/// own floor, more error beyond the noise than without the drift); at the SIMEX values of
/// the two windings apart the drift removed 5 % of the error beyond the floor (the test
/// asks 10 %).
#[test]
fn a_long_log_names_its_drift_below_the_short_logs_band() {
    if !full() {
        return;
    }
    let three_hp = LongLog {
        machine: monitor_io::params::ParamFile::reference_3hp(),
        i_range_a: 200.0,
        noise_i: 0.05,
        from: "0",
    };
    let dir = tempfile::tempdir().unwrap();
    let finals = |v: &serde_json::Value| -> Vec<String> {
        v["final_effects"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap().to_string())
            .collect()
    };
    let v = ladder_on(&three_hp, true, dir.path());
    let band = v["test_rule"]["floor_band"].as_f64().unwrap();
    assert!(band < 1.05, "band {band}");
    assert_eq!(v["stop"], "noise_floor", "{}", v["stopped_because"]);
    let fin = &v["final_fit"];
    let drift = fin["fitted"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["effect"] == "thermal_drift")
        .unwrap_or_else(|| panic!("no drift named: {:?}", finals(&v)));
    assert_rise_near(drift, 50.0);
    let end = fin["ratio_to_floor"].as_f64().unwrap();
    assert!(end <= band, "the warming log ends at {end:.3}x the floor");
    let c = ladder_on(&three_hp, false, dir.path());
    assert_eq!(c["stop"], "noise_floor", "{}", c["stopped_because"]);
    let named = finals(&c);
    assert!(
        named.iter().all(|e| e.ends_with("_dynamics")),
        "the control names {named:?}"
    );
}

/// The 3 hp machine's long log ([`long_scenario`], 40 s at 2 kHz, 0.5 V of voltage noise):
/// `compare` with the machine's dynamics and a thermal drift, as a user asks whether the
/// motor warmed. The noise of the voltages the model is driven by biases a fitted rise
/// upwards (a larger resistance passes less of it to the currents): the fit alone read
/// 112 K for the 50 K injected, and 75 K on the same log without any warming. Corrected
/// by SIMEX (refits with more noise added, extrapolated to none): the rise within 25 % of
/// the 50 K, and the control's below a third of it. Runs in `cargo test` (two logs of
/// 80 000 rows, a compare each: about 3 s).
#[test]
fn the_voltages_noise_does_not_warm_the_motor() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("machine.toml");
    let machine = monitor_io::params::ParamFile::reference_3hp();
    std::fs::write(&params, machine.to_toml_string()).unwrap();
    let rise = |warming: bool| -> f64 {
        let scenario = dir.path().join(format!("long_{warming}.toml"));
        let log = dir.path().join(format!("long_{warming}.csv"));
        std::fs::write(&scenario, long_scenario(warming, 200.0, 0.05)).unwrap();
        simulate(&params, &scenario, &log);
        let effects =
            "current_dynamics,flux_dynamics,d_axis_dynamics,cross_coupling_dynamics,thermal_drift";
        let compare = ["compare", "--json", "--effects", effects, "--params"];
        let v = run_json(&compare, &params, &log, &scenario);
        let drift = v["fitted_effects"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["effect"] == "thermal_drift")
            .unwrap_or_else(|| panic!("no drift fitted: {v}"));
        drift["parameters"]["rise_k"]["value"].as_f64().unwrap()
    };
    let warm = rise(true);
    assert!(
        (warm - 50.0).abs() <= 12.5,
        "rise {warm:.1} K, 50 K injected"
    );
    let cold = rise(false);
    assert!(cold.abs() < 50.0 / 3.0, "the control warmed by {cold:.1} K");
}

/// The 2.2 kW machine on a supply that sags by 1 % a second from 1 s to 7 s (to 93 %, the
/// phase voltages measured at its terminals), its viscous load stepping down and back;
/// `warming`: a stator and rotor heating by 30 K (3 s time constant) on top.
fn sagging_scenario(warming: bool) -> String {
    let steps: Vec<String> = (1..=7)
        .map(|s| format!("{{ t_s = {s}.0, v_scale = {} }}", 1.0 - 0.01 * f64::from(s)))
        .collect();
    let mut s = format!(
        "duration_s = 8.0\nsample_rate_hz = 10000.0\nseed = 3\n\n[supply]\nsteps = [{}]\n\n\
         [load]\nkind = \"viscous\"\nsteps = [{{ t_s = 3.0, bl_scale = 0.5 }}, {{ t_s = 4.5, bl_scale = 1.0 }}]\n",
        steps.join(", ")
    );
    if warming {
        s.push_str("\n[[effects]]\nname = \"thermal_drift\"\nrise_k = 30.0\n");
    }
    s
}

/// A warm stator and a sagging supply (issue 87, item 2) both lower the current the
/// stator's voltage drives; they are one reading only where the voltage the model is driven
/// by is not the terminals'. With the phase voltages measured, the sag is in the model's
/// input and the log tells the two apart: on the sagging supply alone the ladder names no
/// thermal drift, reports no base change and says nothing is alike; with 30 K of heating
/// on top it names the drift, the stator's rise within 25 % of the 30 K. Full sweeps only
/// (two ladders of 80 000 samples, about 5 s).
#[test]
fn a_sagging_supply_is_not_a_warm_stator() {
    if !full() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let params = repo().join("examples/params/2p2kw.toml");
    let climb = |warming: bool| -> serde_json::Value {
        let scenario = dir.path().join(format!("sag_{warming}.toml"));
        std::fs::write(&scenario, sagging_scenario(warming)).unwrap();
        let log = dir.path().join(format!("sag_{warming}.csv"));
        simulate_and_climb(&params, &scenario, &log, "0")
    };
    let drift_step = |v: &serde_json::Value| -> Option<serde_json::Value> {
        v["ladder"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| {
                s["added"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|e| e == "thermal_drift")
            })
            .cloned()
    };
    let sag = climb(false);
    assert!(
        drift_step(&sag).is_none(),
        "a sagging supply read as a warming: {}",
        sag["summary"]
    );
    assert_eq!(
        sag["base_changes"],
        serde_json::json!([]),
        "{}",
        sag["summary"]
    );
    let alike = &sag["final_fit"]["alike"];
    assert!(
        alike.is_null() || alike == &serde_json::json!([]),
        "{alike}"
    );
    let warm = climb(true);
    let step = drift_step(&warm).unwrap_or_else(|| panic!("no drift named: {}", warm["summary"]));
    let rise = step["fitted"]["stator_rise_k"]["value"].as_f64().unwrap();
    assert!(
        (rise - 30.0).abs() <= 7.5,
        "stator rise {rise:.1} K, 30 K injected"
    );
}
