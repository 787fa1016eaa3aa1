//! Load steps located to the sample (`load_torque`'s change-point detection,
//! `monitor_analysis::change_point`): one step in the log is one step in the fit, where
//! it is and of its size, on a log another simulator made and on the project's simulator;
//! a log without a step gets none.
use crate::analysis_common;
use analysis_common::*;
use monitor_analysis::effects::{load_segments, model_of, LoadSegment};
use monitor_analysis::{Analysis, FittedEffect};
use monitor_core::EffectKind;
use monitor_sim::{LoadKind, LoadSpec, LoadStep, Scenario};

/// The four dynamics effects: the full-order machine.
const DYNAMICS: [&str; 4] = [
    "current_dynamics",
    "flux_dynamics",
    "d_axis_dynamics",
    "cross_coupling_dynamics",
];

/// The model's effects: the four dynamics effects and `load_torque`.
fn with_load() -> Vec<&'static str> {
    let mut e = DYNAMICS.to_vec();
    e.push("load_torque");
    e
}

/// The fitted load levels in segment order [N m] (the parameters are named
/// `level_<k>_from_<t>_s`, k from 1).
fn levels(f: &[FittedEffect]) -> Vec<f64> {
    let lt = f
        .iter()
        .find(|e| e.effect == EffectKind::LoadTorque)
        .expect("load_torque fitted");
    let mut v: Vec<(usize, f64)> = lt
        .parameters
        .iter()
        .map(|(name, p)| {
            let k = name
                .strip_prefix("level_")
                .and_then(|s| s.split('_').next())
                .and_then(|s| s.parse().ok())
                .expect("level_<k>_...");
            (k, p.value)
        })
        .collect();
    v.sort_by_key(|x| x.0);
    v.into_iter().map(|x| x.1).collect()
}

fn segments(a: &Analysis) -> Vec<LoadSegment> {
    load_segments(&a.data, &a.constants)
}

/// The motulator log (examples/logs: an independent simulator, no noise, a direct-on-line
/// start, the load 0 -> 14.6 N m at 2.50 s): the whole log, start included, with the
/// full-order model and `load_torque` is reproduced to 0.003 (0.0615 with the former
/// low-passed observer and its grid of segments); one step, at 2.50 +/- 0.01 s, of
/// 14.6 N m +/- 2 %. Up to 2.4 s (the start, no step) no step is placed.
#[test]
fn motulator_load_step_is_found_where_it_is() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/logs");
    let log = root.join("motulator_2p2kw_dol.csv");
    let p = monitor_io::params::ParamFile::load(&root.join("motulator_2p2kw_dol.toml")).unwrap();
    let a = analyse(&log, &p, f64::NEG_INFINITY);
    let seg = segments(&a);
    assert_eq!(seg.len(), 2, "one step: {seg:?}");
    assert!((seg[1].from_s - 2.50).abs() <= 0.01, "{seg:?}");
    let c = a.compare(&opts(&with_load())).unwrap().report;
    let err = c.normalized_rms_error;
    let lv = levels(&c.fitted_effects);
    eprintln!("motulator whole log: error {err:.5}, steps {seg:?}, fitted levels {lv:?}");
    assert!(err <= 0.003, "whole-log error {err}");
    assert_eq!(lv.len(), 2, "{lv:?}");
    let size = lv[1] - lv[0];
    assert!((size / 14.6 - 1.0).abs() <= 0.02, "step {size} N m");
    // The start alone: no step.
    let start = Analysis::load(
        &log,
        p,
        monitor_analysis::prep::ReadOptions {
            from_s: f64::NEG_INFINITY,
            to_s: 2.4,
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(segments(&start).len(), 1, "{:?}", segments(&start));
}

/// A 4 s log of the project's simulator, 2.2 kW machine at 5 kHz, 0.1 % sensor noise, a
/// direct-on-line start, a torque load of 2 N m with `steps` (time [s], new torque [N m]).
fn project_log(steps: &[(f64, f64)]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let truth = motor("2p2");
    let mut s = Scenario::steady(4.0, 5000.0);
    s.sensors = sensors(1);
    s.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(2.0),
        bl_nms: None,
        steps: steps
            .iter()
            .map(|&(t_s, nm)| LoadStep {
                t_s,
                torque_nm: Some(nm),
                bl_scale: None,
            })
            .collect(),
    };
    let log = write_log(dir.path(), "steps", &truth, &s, false);
    (dir, log)
}

/// The steps' true times: the first 5 kHz output sample at or after each.
const STEPS: [(f64, f64); 2] = [(1.2345, 9.0), (2.7311, 4.0)];

fn true_time(t: f64) -> f64 {
    (t * 5000.0).ceil() / 5000.0
}

/// Two load steps at times on no grid of the log (1.2345 s and 2.7311 s; the simulator
/// applies a step at its first output sample at or after the time), the whole log with its
/// start: each step found within 2 ms. A torque load without steps: no step, one level.
#[test]
fn steps_off_any_grid_are_found_to_the_sample() {
    let truth = motor("2p2");
    let (_dir, log) = project_log(&STEPS);
    let a = analyse(&log, &truth, f64::NEG_INFINITY);
    let seg = segments(&a);
    eprintln!("project's simulator: {seg:?}");
    assert_eq!(seg.len(), 3, "two steps: {seg:?}");
    for (s, (t, _)) in seg[1..].iter().zip(STEPS) {
        assert!((s.from_s - true_time(t)).abs() <= 0.002, "{s:?} vs {t}");
    }
    // No step in the log: none placed; `load_torque` fits one constant level.
    let (_dir0, log0) = project_log(&[]);
    let a0 = analyse(&log0, &truth, f64::NEG_INFINITY);
    assert_eq!(segments(&a0).len(), 1, "{:?}", segments(&a0));
    let setup = model_of(EffectKind::LoadTorque)
        .expect("a library effect")
        .setup(&a0.data, &a0.constants)
        .unwrap();
    assert_eq!(setup.len(), 1, "{:?}", setup.params);
}

/// The sizes of the two steps above from the fit (full-order model and `load_torque`,
/// the true parameters): each within 2 % (the steps 2 -> 9 -> 4 N m).
#[test]
fn steps_off_any_grid_are_sized_by_the_fit() {
    let truth = motor("2p2");
    let (_dir, log) = project_log(&STEPS);
    let a = analyse(&log, &truth, f64::NEG_INFINITY);
    let c = a.compare(&opts(&with_load())).unwrap().report;
    let lv = levels(&c.fitted_effects);
    eprintln!(
        "project's simulator: error {:.5} (floor {:.5}), levels {lv:?}",
        c.normalized_rms_error, c.noise_floor
    );
    assert_eq!(lv.len(), 3, "{lv:?}");
    let mut before = 2.0;
    for (k, (_, nm)) in STEPS.iter().enumerate() {
        let (size, want) = (lv[k + 1] - lv[k], nm - before);
        assert!(
            (size / want - 1.0).abs() <= 0.02,
            "step {k}: {size} vs {want}"
        );
        before = *nm;
    }
}
