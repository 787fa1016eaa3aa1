//! `diagnose` and `explain` agree on one log (issue 40): where `explain` finds nothing beyond
//! the noise floor, `diagnose` does not give a FAULT verdict, and where `diagnose` gives one,
//! `explain` finds the model's error above the noise floor.
//!
//! Twenty logs on two motors (the 3 hp and 2.2 kW reference motors of `examples/params/`):
//! healthy, six parametric faults (+-50 %, at 5 s), two sensor gain faults, and three
//! effects no fault is (a warming, main-flux saturation, iron loss), 8 s at 4 kHz with the
//! default 12-bit noisy sensors and the paper's viscous load. Each is written to a CSV file
//! and judged through the library calls the command line runs (`monitor_api`):
//! `diagnose --commission 2:4` and `explain --from 1.5` (after the start). About 20 s in the test
//! profile on 2 cores.

use monitor_api::{self as api, AnalysisRequest, DiagnoseRequest, ParamsSource};
use monitor_replay::Verdict;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// One log's scenario: its name and the TOML lines after the header.
const CASES: [(&str, &str); 10] = [
    ("healthy", ""),
    (
        "rs +50 %",
        "[[faults]]\nkind = \"rs\"\nat_s = 5.0\nchange = 0.5\n",
    ),
    (
        "rr +50 %",
        "[[faults]]\nkind = \"rr\"\nat_s = 5.0\nchange = 0.5\n",
    ),
    (
        "rr -30 %",
        "[[faults]]\nkind = \"rr\"\nat_s = 5.0\nchange = -0.3\n",
    ),
    (
        "lr +50 %",
        "[[faults]]\nkind = \"lr\"\nat_s = 5.0\nchange = 0.5\n",
    ),
    (
        "b +50 %",
        "[[faults]]\nkind = \"b\"\nat_s = 5.0\nchange = 0.5\n",
    ),
    (
        "speed sensor +10 %",
        "[[faults]]\nkind = \"speed_sensor\"\nat_s = 5.0\nmode = \"gain\"\nchange = 0.1\n",
    ),
    (
        "warming 40 K",
        "[[effects]]\nname = \"thermal_drift\"\nrise_k = 40.0\ntau_s = 3.0\n",
    ),
    ("saturation", "[[effects]]\nname = \"saturation\"\n"),
    ("iron loss", "[[effects]]\nname = \"iron_loss\"\n"),
];

const MOTORS: [&str; 2] = ["3hp.toml", "2p2kw.toml"];

fn params(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/params")
        .join(file)
}

/// Simulates `case` on `motor` into `dir`; returns the log's path.
fn simulate(dir: &Path, motor: &str, (name, extra): (&str, &str)) -> PathBuf {
    let toml = format!(
        "duration_s = 8.0\nsample_rate_hz = 4000.0\nseed = 3\n[load]\nkind = \"viscous\"\n{extra}"
    );
    let slug: String = format!("{motor}_{name}")
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let out = dir.join(format!("{slug}.csv"));
    api::simulate_to_file(ParamsSource::Path(&params(motor)), &toml, &out)
        .unwrap_or_else(|e| panic!("{motor} {name}: {e}"));
    out
}

#[test]
fn diagnose_and_explain_agree_on_twenty_logs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: Vec<(&str, (&str, &str))> = MOTORS
        .iter()
        .flat_map(|m| CASES.iter().map(move |c| (*m, *c)))
        .collect();
    let rows: Vec<(String, bool, bool)> = cases
        .par_iter()
        .map(|&(motor, case)| {
            let log = simulate(dir.path(), motor, case);
            let p = params(motor);
            let req = DiagnoseRequest {
                options: monitor_replay::ReplayOptions {
                    commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
                    ..Default::default()
                },
                ..Default::default()
            };
            let d = api::diagnose(ParamsSource::Path(&p), &log, &req, &mut |_| {})
                .unwrap_or_else(|e| panic!("{motor} {}: diagnose: {e}", case.0));
            // (From 1.5 s: the start's dynamics are not what this compares.)
            let areq = AnalysisRequest {
                from_s: Some(1.5),
                ..Default::default()
            };
            let e = api::explain(ParamsSource::Path(&p), &log, &areq, &api::words::FieldNames)
                .unwrap_or_else(|e| panic!("{motor} {}: explain: {e}", case.0));
            let verdict = e["verdict"].as_str().unwrap_or_default().to_string();
            let fault = d.report.verdict == Verdict::Fault;
            let nothing = verdict.starts_with("nothing to explain");
            let line = format!(
                "{motor} {}: diagnose {:?} (named {:?}); explain: {}",
                case.0,
                d.report.verdict,
                d.report.isolation.named,
                verdict.chars().take(110).collect::<String>()
            );
            eprintln!("{line}");
            (line, fault, nothing)
        })
        .collect();
    assert_eq!(rows.len(), 20);
    let disagree: Vec<&String> = rows
        .iter()
        .filter(|(_, fault, nothing)| *fault && *nothing)
        .map(|(l, _, _)| l)
        .collect();
    assert!(disagree.is_empty(), "{disagree:#?}");
    // The test can tell: the faults of +-50 % are FAULT verdicts with something to explain
    // on at least one motor each.
    for name in ["rs +50 %", "rr +50 %"] {
        assert!(
            rows.iter()
                .any(|(l, fault, nothing)| l.contains(name) && *fault && !*nothing),
            "{name}: no FAULT with an error to explain: {rows:#?}"
        );
    }
}

/// An effect-free control (issue 40): a healthy 0.37 kW machine (per-unit values typical of
/// its size, `tests/small_motor`) on V/f steps (50 -> 40 -> 30 -> 50 Hz with the voltage),
/// 10 s at 5 kHz, explained with the four dynamics effects `compare`'s advice leads to, on
/// the whole log and after the start: no effect is claimed. (A run of an earlier version
/// named `supply_unbalance` here.)
#[test]
fn a_healthy_motor_on_vf_steps_claims_no_effect() {
    let w = std::f64::consts::TAU * 50.0;
    let (lm, ll) = (260.0 / w, 16.0 / w);
    let w_rated = std::f64::consts::TAU * 1375.0 / 60.0;
    let bl = 370.0 / (w_rated * w_rated);
    let params = format!(
        "[motor]\nrs_ohm = 30.0\nrr_ohm = 24.0\nls_h = {ls}\nlr_h = {ls}\nlm_h = {lm}\npoles = 4\nj_kgm2 = 0.0009\nb_nms = {b}\nbl_nms = {bl}\n[supply]\nv_ll_rms = 400.0\nf_hz = 50.0\n",
        ls = lm + ll,
        b = 0.005 * bl
    );
    let source = || ParamsSource::Toml {
        text: &params,
        origin: "the 0.37 kW machine",
    };
    let scenario = "duration_s = 10.0\nsample_rate_hz = 5000.0\nseed = 4\n[supply]\nsteps = [{ t_s = 3.0, v_scale = 0.8, f_hz = 40.0 }, { t_s = 5.0, v_scale = 0.6, f_hz = 30.0 }, { t_s = 7.0, v_scale = 1.0, f_hz = 50.0 }]\n";
    let dir = tempfile::tempdir().expect("temp dir");
    let log = dir.path().join("vf.csv");
    api::simulate_to_file(source(), scenario, &log).expect("simulates");
    let dynamics: Vec<String> = [
        "flux_dynamics",
        "current_dynamics",
        "d_axis_dynamics",
        "cross_coupling_dynamics",
    ]
    .iter()
    .map(|n| n.to_string())
    .collect();
    for from_s in [None, Some(0.3)] {
        let req = AnalysisRequest {
            effects: dynamics.clone(),
            from_s,
            ..Default::default()
        };
        let e = api::explain(source(), &log, &req, &api::words::FieldNames).expect("explains");
        let verdict = e["verdict"].as_str().unwrap_or_default();
        eprintln!(
            "from {from_s:?}: {}",
            verdict.chars().take(160).collect::<String>()
        );
        assert!(
            !verdict.starts_with("missing effect"),
            "from {from_s:?}: {verdict}"
        );
    }
}
