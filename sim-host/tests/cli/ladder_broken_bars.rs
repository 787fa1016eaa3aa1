//! `explain --ladder` on broken rotor bars of an independent textbook machine
//! (`monitor_testkit::textbook_machine`, Krause's fifth-order model with its
//! `rotor_asymmetry` hidden effect; not `monitor-sim`): issue 62's bar "rotor asymmetry
//! named on the ladder, with the bar count agreeing with the spectrum's within one bar (1
//! and 2 broken bars); healthy runs of the same motor: no rotor asymmetry".
//!
//! Krause's 3 hp machine with a 28-bar cage (the parameter file carries `rotor_bars = 28`),
//! started direct on line into its rated viscous load, logged 9 s at 4 kHz (8 s after the
//! start has settled), with 0, 1 and 2 adjacent broken bars
//! (`delta = 3 n / (N - 3 n)`). On each log:
//! * `explain --ladder --json` on the whole log (as `ladder_matrix.rs`): with 1 and 2 bars
//!   `rotor_asymmetry` is added along the ladder and its fitted `delta` gives
//!   `n = delta N / (3 (1 + delta))` within one bar of the injected count; with 0 bars it is
//!   never added;
//! * `explain --json --rotor-bars 28 --from 2` (the motor current signature analysis needs
//!   a steady slip, and `--ladder` does not take `--rotor-bars`): the sidebands' count
//!   `rotor_asymmetry.spectral_broken_bars`, which the ladder's count must be within one bar
//!   of.
//!
//! Each case is a ladder of about 20-30 CPU-s in release, so the cases run under
//! `MONITOR_FULL_SWEEPS=1` only (a plain `cargo test` prints a note and passes):
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test --release -p sim-host --test cli ladder_broken_bars:: -- --nocapture
//! ```
#![allow(missing_docs)]

use assert_cmd::Command;
use monitor_testkit::textbook_machine;
use std::path::Path;
use textbook_machine::{broken_bars_delta, broken_bars_of, Machine, Scenario};

/// The cage's bar count.
const BARS: f64 = 28.0;
/// Sample rate [Hz] and length [s] of every log.
const RATE_HZ: f64 = 4000.0;
const DURATION_S: f64 = 9.0;

fn full() -> bool {
    let run = std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1");
    if !run {
        eprintln!(
            "ladder_broken_bars: part of the full sweep only (MONITOR_FULL_SWEEPS=1 runs it)"
        );
    }
    run
}

/// What the ladder and the spectrum said on one log.
#[derive(Debug)]
struct Outcome {
    /// Each step's effect (with what it added).
    steps: Vec<String>,
    /// Every effect named along the ladder (steps' `added` and `final_effects`).
    named: Vec<String>,
    /// The ladder's fitted `rotor_asymmetry.delta`, when it was added.
    delta: Option<f64>,
    /// The spectrum's `spectral_delta` and `spectral_broken_bars`.
    spectral_delta: Option<f64>,
    spectral_bars: Option<f64>,
    end_ratio: f64,
    stop: String,
}

fn sim_host(args: &[&str], params: &Path, log: &Path) -> serde_json::Value {
    let out = Command::cargo_bin("sim-host")
        .expect("the sim-host binary")
        .args(args)
        .arg("--params")
        .arg(params)
        .arg(log)
        .output()
        .expect("run sim-host");
    assert!(
        out.status.success(),
        "sim-host {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document")
}

/// Writes the log with `n` broken bars and its parameter file, runs the ladder and the
/// spectrum on it.
fn run_case(dir: &Path, n: u32) -> Outcome {
    let m = Machine::hp3();
    let mut s = Scenario::new(&m, DURATION_S, RATE_HZ);
    s.sensors.seed = 40 + u64::from(n);
    if n > 0 {
        s.hidden.rotor_asymmetry = Some(broken_bars_delta(f64::from(n), BARS));
    }
    let name = format!("bars{n}");
    let log = textbook_machine::write_log(dir, &name, &m, &s);
    let params = dir.join(format!("{name}.toml"));
    let toml = m
        .params_toml(m.bl, 0.0)
        .replace("poles = 4\n", "poles = 4\nrotor_bars = 28\n");
    assert!(toml.contains("rotor_bars = 28"), "{toml}");
    std::fs::write(&params, toml).expect("write params");

    let j = sim_host(&["explain", "--ladder", "--json"], &params, &log);
    let num = |v: &serde_json::Value| v.as_f64();
    let mut o = Outcome {
        steps: Vec::new(),
        named: Vec::new(),
        delta: None,
        spectral_delta: None,
        spectral_bars: None,
        end_ratio: num(&j["start"]["ratio_to_floor"]).unwrap_or(f64::NAN),
        stop: j["stop"].as_str().unwrap_or_default().to_string(),
    };
    for step in j["ladder"].as_array().into_iter().flatten() {
        o.end_ratio = num(&step["ratio_to_floor"]).unwrap_or(f64::NAN);
        o.steps
            .push(step["effect"].as_str().unwrap_or_default().to_string());
        for a in step["added"].as_array().into_iter().flatten() {
            let a = a.as_str().unwrap_or_default().to_string();
            if a == "rotor_asymmetry" {
                let f = &step["fitted"];
                o.delta =
                    num(&f["delta"]["value"]).or_else(|| num(&f["rotor_asymmetry.delta"]["value"]));
            }
            o.named.push(a);
        }
    }
    for e in j["final_effects"].as_array().into_iter().flatten() {
        o.named.push(e.as_str().unwrap_or_default().to_string());
    }
    let e = sim_host(
        &["explain", "--json", "--rotor-bars", "28", "--from", "2"],
        &params,
        &log,
    );
    let r = &e["rotor_asymmetry"];
    o.spectral_delta = num(&r["spectral_delta"]);
    o.spectral_bars =
        num(&r["spectral_broken_bars"]).or(o.spectral_delta.map(|d| broken_bars_of(d, BARS)));
    if o.spectral_bars.is_none() {
        eprintln!("bars {n}: the spectrum gave no count: {r}");
    }
    o
}

fn row(n: u32, o: &Outcome) -> String {
    let fit_bars = o.delta.map(|d| broken_bars_of(d, BARS));
    let f = |x: Option<f64>, p: usize| x.map_or("-".to_string(), |v| format!("{v:.p$}"));
    format!(
        "{:>8} {:<70} {:>8} {:>9} {:>8} {:>9} {:>8} {:>9} {}",
        n,
        o.steps.join(","),
        f(o.delta, 3),
        f(fit_bars, 2),
        f(o.spectral_delta, 3),
        f(o.spectral_bars, 2),
        format!("{:.2}", o.end_ratio),
        o.named.contains(&"rotor_asymmetry".to_string()),
        o.stop
    )
}

fn header() -> String {
    format!(
        "{:>8} {:<70} {:>8} {:>9} {:>8} {:>9} {:>8} {:>9} {}",
        "injected",
        "ladder steps",
        "delta",
        "bars(fit)",
        "sp.delta",
        "bars(sp.)",
        "end/flr",
        "named",
        "stop"
    )
}

/// Runs the case with `n` broken bars and checks the bar.
fn check(n: u32) {
    if !full() {
        return;
    }
    let tmp = tempfile::tempdir().expect("tempdir");
    let t = std::time::Instant::now();
    let o = run_case(tmp.path(), n);
    eprintln!(
        "3hp, 28 bars, rated viscous load, {DURATION_S} s at {RATE_HZ} Hz ({:.1} s)\n{}\n{}",
        t.elapsed().as_secs_f64(),
        header(),
        row(n, &o)
    );
    let named = o.named.iter().any(|e| e == "rotor_asymmetry");
    if n == 0 {
        assert!(!named, "rotor_asymmetry named on the healthy run: {o:?}");
        return;
    }
    assert!(
        named,
        "rotor_asymmetry not named with {n} broken bars: {o:?}"
    );
    let fit = broken_bars_of(o.delta.expect("the fitted delta"), BARS);
    assert!(
        (fit - f64::from(n)).abs() <= 1.0,
        "{n} broken bars: the fit's count {fit:.2}: {o:?}"
    );
    let spectral = o.spectral_bars.expect("the spectrum's count");
    assert!(
        (fit - spectral).abs() <= 1.0,
        "{n} broken bars: the fit's count {fit:.2}, the spectrum's {spectral:.2}: {o:?}"
    );
}

#[test]
fn healthy_run_names_no_rotor_asymmetry() {
    check(0);
}

#[test]
fn one_broken_bar_is_named_with_its_count() {
    check(1);
}

#[test]
fn two_broken_bars_are_named_with_their_count() {
    check(2);
}

/// Broken bars on records like real ones (issue 87, item 4: one story across commands):
/// the project's simulator (`monitor-sim`, not the textbook machine above) with what a
/// plant's supply and a DAQ add: the 5th, 7th and 11th voltage harmonics (3 %, 2 %,
/// 0.8 %), a 1 % supply unbalance, 12-bit sensors with noise; the 2.2 kW machine with 28
/// bars on its viscous load, 2 s at 1.4 kHz read after the start has settled. On each
/// record `diagnose`'s verdict and `explain --ladder` tell one story: with 1 and 2 broken
/// bars the verdict names broken bars and the ladder names `rotor_asymmetry`, their
/// counts within one bar of each other and of the truth; on the healthy cage neither; no
/// saturation named on any (the record holds one flux level). And
/// the noise floor is the sensors' noise: `compare`'s within 15 % of the same record's
/// without the harmonics, the ladder's within 1.5x of that (the fourth difference read the
/// harmonics, 300 Hz in the machine's frame, as 5x the noise, and the ladder stopped "at
/// the floor" after the dynamics, before the unbalance and the bars).
mod short_records {
    use super::*;

    /// The scenario: 4 s from a direct-on-line start, `bars` broken of 28, the supply's
    /// harmonics when `harmonics`.
    fn scenario(bars: u32, harmonics: bool) -> String {
        let mut s = String::from("duration_s = 4.0\nsample_rate_hz = 1400.0\nseed = 3\n\n");
        if harmonics {
            s.push_str(
                "[supply]\nharmonics = [{ order = 5, fraction = 0.03, phase_deg = 20.0 }, \
                 { order = 7, fraction = 0.02, phase_deg = -40.0 }, { order = 11, fraction = 0.008 }]\n\n",
            );
        }
        s.push_str(
            "[load]\nkind = \"viscous\"\n\n[sensors]\nadc_bits = 12\nnoise_v = 0.5\nnoise_i = 0.02\n\n\
             [[effects]]\nname = \"supply_unbalance\"\nfraction = 0.01\n",
        );
        if bars > 0 {
            s.push_str(&format!(
                "\n[[effects]]\nname = \"rotor_asymmetry\"\nbroken_bars = {bars}\nbars = 28\n"
            ));
        }
        s
    }

    /// Simulates the scenario into `dir` and keeps its last 2 s (the record a DAQ takes of
    /// a motor in service): the record's path.
    fn record(dir: &Path, params: &Path, bars: u32, harmonics: bool) -> std::path::PathBuf {
        let name = format!("bars{bars}_{harmonics}");
        let sc = dir.join(format!("{name}.toml"));
        let full = dir.join(format!("{name}_full.csv"));
        std::fs::write(&sc, scenario(bars, harmonics)).expect("write scenario");
        Command::cargo_bin("sim-host")
            .expect("the sim-host binary")
            .args(["simulate", "--params"])
            .arg(params)
            .arg("--scenario")
            .arg(&sc)
            .arg("--out")
            .arg(&full)
            .assert()
            .success();
        let text = std::fs::read_to_string(&full).expect("read log");
        let mut lines = text.lines();
        let mut kept = format!("{}\n", lines.next().expect("a header"));
        for l in lines {
            let t: f64 = l
                .split(',')
                .next()
                .and_then(|t| t.parse().ok())
                .expect("t_s");
            if t >= 2.0 {
                kept.push_str(l);
                kept.push('\n');
            }
        }
        let out = dir.join(format!("{name}.csv"));
        std::fs::write(&out, kept).expect("write record");
        out
    }

    fn check(bars: u32) {
        if !full() {
            return;
        }
        let tmp = tempfile::tempdir().expect("tempdir");
        let dir = tmp.path();
        let params = dir.join("machine.toml");
        let file = include_str!("../../../examples/params/2p2kw.toml").replacen(
            "[motor]\n",
            "[motor]\nrotor_bars = 28\n",
            1,
        );
        assert!(file.contains("rotor_bars = 28"));
        std::fs::write(&params, file).expect("write params");
        let log = record(dir, &params, bars, true);
        let d = sim_host(&["diagnose", "--json"], &params, &log);
        let l = sim_host(&["explain", "--ladder", "--json"], &params, &log);
        let clean = record(dir, &params, bars, false);
        let c = sim_host(&["compare", "--json", "--no-fit"], &params, &clean);
        let h = sim_host(&["compare", "--json", "--no-fit"], &params, &log);
        let verdict_bars = d["verdict_finding"]["fault"] == "broken_bars";
        let spectral = d["rotor"]["broken_bars"].as_f64();
        let delta = l["ladder"].as_array().into_iter().flatten().find_map(|s| {
            let added = s["added"].as_array()?;
            added.iter().any(|a| a == "rotor_asymmetry").then(|| {
                let f = &s["fitted"];
                f["delta"]["value"]
                    .as_f64()
                    .or_else(|| f["rotor_asymmetry.delta"]["value"].as_f64())
            })?
        });
        let ladder_bars = delta.map(|d| broken_bars_of(d, BARS));
        let floor = l["start"]["noise_floor"]
            .as_f64()
            .expect("the ladder's floor");
        let sensors = c["noise_floor"].as_f64().expect("the clean record's floor");
        eprintln!(
            "{bars} broken bars: verdict {} ({spectral:?} bars), the ladder {ladder_bars:?} bars \
             (steps {:?}), floor {floor:.4} against {sensors:.4} without the harmonics",
            d["verdict_line"],
            l["ladder"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|s| s["effect"].as_str().unwrap_or_default())
                .collect::<Vec<_>>()
        );
        let with_lines = h["noise_floor"].as_f64().expect("compare's floor");
        assert!(
            (with_lines / sensors - 1.0).abs() < 0.15,
            "compare's noise floor {with_lines:.4} with the harmonics, {sensors:.4} without"
        );
        assert!(
            floor <= 1.5 * sensors,
            "the ladder's noise floor {floor:.4} is not the sensors' ({sensors:.4} without the harmonics)"
        );
        // The record holds one flux level (a settled motor on one supply voltage): no
        // saturation is there, and the log cannot show one (issue 87, item 4: the ladder
        // named saturation beside 1 and 2 broken bars, its knee exponent at 13.9 of 14).
        let saturation = l["ladder"].as_array().into_iter().flatten().any(|s| {
            s["added"]
                .as_array()
                .is_some_and(|a| a.iter().any(|e| e == "saturation"))
        });
        assert!(
            !saturation,
            "the ladder names saturation on a record at one flux level"
        );
        if bars == 0 {
            assert!(
                !verdict_bars,
                "the verdict names broken bars on a healthy cage"
            );
            assert_eq!(
                ladder_bars, None,
                "the ladder names a rotor asymmetry on a healthy cage"
            );
            return;
        }
        assert!(
            verdict_bars,
            "the verdict misses {bars} broken bars: {}",
            d["verdict_line"]
        );
        let spectral = spectral.expect("the spectrum's count");
        let ladder = ladder_bars.unwrap_or_else(|| panic!("the ladder misses {bars} broken bars"));
        let n = f64::from(bars);
        assert!(
            (spectral - n).abs() <= 1.0,
            "the spectrum's count {spectral:.2} of {bars}"
        );
        assert!(
            (ladder - n).abs() <= 1.0,
            "the ladder's count {ladder:.2} of {bars}"
        );
        assert!(
            (ladder - spectral).abs() <= 1.0,
            "two stories: the ladder's {ladder:.2} bars, the verdict's {spectral:.2}"
        );
    }

    #[test]
    fn a_healthy_cage_is_named_by_neither() {
        check(0);
    }

    #[test]
    fn one_broken_bar_is_one_story() {
        check(1);
    }

    #[test]
    fn two_broken_bars_are_one_story() {
        check(2);
    }
}
