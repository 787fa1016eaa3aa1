//! Issue 86, item 3: no number out of physics printed as a finding. A fitted effect value
//! pinned at a bound of its fit is "at the bound of its fit", not a value the log shows;
//! a saturation law that takes Lm below what a running motor keeps is not plausible. On
//! motulator's 2.2 kW log of a machine without saturation (`kw2p2_control`), `compare
//! --effects saturation` named saturation with its exponent at its fit's bound (14.0) as a
//! finding. About 2 s.
//!
//! Over every shipped log and scenario (`MONITOR_FULL_SWEEPS=1`: the 17 motulator logs, the
//! README's, and the project's own `examples/scenarios/effect_*.toml` simulated): no value
//! `explain` ranks as plausible,
//! and none the ladder's end reports as plausible, sits at a bound of its fit or outside its
//! physical range, judged against the effect's own set-up on the log (not the fit's flag).

use crate::analysis_common;
use analysis_common::*;
use monitor_analysis::effects::{self, EffectModel, Saturation};
use monitor_analysis::{Analysis, ParamValue};
use monitor_core::EffectKind;
use monitor_io::params::ParamFile;
use monitor_laws::EffectId;
use std::collections::BTreeMap;
use std::path::Path;

#[test]
fn an_effect_value_at_its_fit_bound_or_an_lm_no_motor_keeps_is_no_finding() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../sim-host/tests/data/motulator");
    let p = ParamFile::load(&dir.join("kw2p2.toml")).expect("params"); // ok: test
    let a = analyse(&dir.join("kw2p2_control.csv"), &p, 1.0);
    let s = Saturation.setup(&a.data, &a.constants).expect("set up"); // ok: test
    let psi = &s.params[0];
    let inside = [psi.init, 7.0];
    assert!(s.pinned(&inside).is_empty(), "{:?}", s.pinned(&inside));
    for pinned in [[psi.init, 14.0], [psi.hi, 7.0], [psi.init, 2.0]] {
        let why = s.pinned(&pinned);
        assert_eq!(why.len(), 1, "{pinned:?}: {why:?}");
        assert!(why[0].contains("at the bound of its fit"), "{why:?}");
    }
    // A knee at half the log's flux, as sharp as the fit allows: Lm a few per cent of its
    // unsaturated value, no running motor's.
    let deep = Saturation
        .contradicted_by(&a.data, &a.constants, &[psi.lo, 14.0])
        .expect("values"); // ok: test
    assert!(deep.is_some(), "{deep:?}");
    let mild = Saturation
        .contradicted_by(&a.data, &a.constants, &[2.0 * psi.init, 7.0])
        .expect("values"); // ok: test
    assert!(mild.is_none(), "{mild:?}");
    // What compare reports of it on this log: the exponent ends at its bound, no finding.
    let c = a.compare(&opts(&["saturation"])).expect("compare").report; // ok: test
    let sat = c
        .fitted_effects
        .iter()
        .find(|e| e.effect == EffectKind::Saturation)
        .expect("saturation fitted"); // ok: test
    assert!(!sat.plausible, "{sat:?}");
    assert!(
        sat.implausible_because
            .iter()
            .any(|w| w.contains("at the bound of its fit") || w.contains("unsaturated")),
        "{:?}",
        sat.implausible_because
    );
}

/// The shipped logs with their parameter files: motulator's logs the tests ship
/// (`sim-host/tests/data/motulator/manifest.toml`, every `[[log]]` and `[[user_law_log]]`)
/// and the README's motulator log.
fn shipped_logs() -> Vec<(std::path::PathBuf, std::path::PathBuf)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = root.join("sim-host/tests/data/motulator");
    let text = std::fs::read_to_string(dir.join("manifest.toml")).expect("manifest"); // ok: test
    let m: toml::Table = toml::from_str(&text).expect("manifest's form"); // ok: test
    let mut logs = vec![(
        root.join("examples/logs/motulator_2p2kw_dol.csv"),
        root.join("examples/logs/motulator_2p2kw_dol.toml"),
    )];
    for key in ["log", "user_law_log"] {
        for l in m
            .get(key)
            .and_then(toml::Value::as_array)
            .into_iter()
            .flatten()
        {
            let (Some(csv), Some(params)) = (
                l.get("csv").and_then(toml::Value::as_str),
                l.get("params").and_then(toml::Value::as_str),
            ) else {
                continue;
            };
            logs.push((dir.join(csv), dir.join(params)));
        }
    }
    logs
}

/// The values of `effect` in `values` that sit at a bound of its fit other than 0 (within a
/// millionth of the bounds' span) or outside its physical range (by more than 1 % of it), against the
/// effect's set-up on the log of `a`.
fn out_of_physics(
    a: &Analysis,
    effect: EffectId,
    values: &BTreeMap<String, ParamValue>,
) -> Vec<String> {
    let Some(setup) = effects::model_of(effect).and_then(|m| m.setup(&a.data, &a.constants).ok())
    else {
        return Vec::new();
    };
    let mut bad = Vec::new();
    for fp in &setup.params {
        let Some(v) = values.get(&fp.name).map(|p| p.value) else {
            continue;
        };
        let span = fp.hi - fp.lo;
        // A bound at 0 is no effect at all (a healthy cage's delta), not a pinned value.
        let at = |b: f64| b != 0.0 && (v - b).abs() <= 1e-6 * span;
        if at(fp.lo) || at(fp.hi) {
            bad.push(format!(
                "{effect}.{} = {v} at its fit's bound {}..{}",
                fp.name, fp.lo, fp.hi
            ));
        }
        let (lo, hi) = (fp.plausible.lo, fp.plausible.hi);
        let slack = 0.01 * (hi - lo).abs();
        if v < lo - slack || v > hi + slack {
            bad.push(format!(
                "{effect}.{} = {v} outside its physical range {lo}..{hi}",
                fp.name
            ));
        }
    }
    bad
}

/// The project's own hidden-effect scenarios (`examples/scenarios/effect_*.toml`) simulated
/// into `dir`, each with the parameter file its header names (`examples/params/X.toml`).
fn scenario_logs(dir: &Path) -> Vec<(std::path::PathBuf, std::path::PathBuf)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files: Vec<_> = std::fs::read_dir(root.join("examples/scenarios"))
        .expect("examples/scenarios") // ok: test
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("effect_") && n.ends_with(".toml"))
        })
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f).expect("scenario"); // ok: test
            let at = text
                .find("examples/params/")
                .expect("a parameter file named"); // ok: test
            let name: String = text[at..]
                .chars()
                .take_while(|c| !c.is_whitespace() && *c != ')')
                .collect();
            let params = root.join(name);
            let p = ParamFile::load(&params).expect("params"); // ok: test
            let sc = monitor_sim::Scenario::load(f).expect("scenario"); // ok: test
            let stem = f.file_stem().and_then(|n| n.to_str()).unwrap_or("log");
            (write_log(dir, stem, &p, &sc, false), params)
        })
        .collect()
}

#[test]
fn no_plausible_value_sits_at_a_fit_bound_on_any_shipped_log() {
    if !full_sweeps() {
        eprintln!("every shipped log: MONITOR_FULL_SWEEPS=1 runs it");
        return;
    }
    let mut bad = Vec::new();
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let mut logs = shipped_logs();
    assert!(logs.len() >= 15, "{} logs", logs.len());
    let ours = scenario_logs(dir.path());
    assert!(ours.len() >= 9, "{} scenarios", ours.len());
    logs.extend(ours);
    for (log, params) in &logs {
        let p = ParamFile::load(params).expect("params"); // ok: test
        let a = analyse(log, &p, 0.0);
        let name = log
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let out = a.explain(&opts(&[]), &|_| {}).expect("explain"); // ok: test
        for c in out.report.ranking.iter().filter(|c| c.plausible) {
            bad.extend(
                out_of_physics(&a, c.effect, &c.parameters)
                    .into_iter()
                    .map(|b| format!("{name} explain: {b}")),
            );
        }
        let l = a.ladder(&opts(&[]), &|_| {}).expect("ladder"); // ok: test
        for e in l
            .final_fit
            .iter()
            .flat_map(|f| &f.fitted)
            .filter(|e| e.plausible && !e.effect.is_dynamics())
        {
            bad.extend(
                out_of_physics(&a, e.effect, &e.parameters)
                    .into_iter()
                    .map(|b| format!("{name} ladder: {b}")),
            );
        }
        eprintln!("{name}: checked");
    }
    assert!(bad.is_empty(), "{bad:#?}");
}
