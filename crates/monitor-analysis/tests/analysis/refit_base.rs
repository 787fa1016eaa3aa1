//! `explain` with a parameter file that is off: it refits the base parameters the log
//! identifies before it judges effects, says which it refitted with their values, and
//! still names the hidden effect (`docs/model-vs-measurement.md`, "When the parameter file
//! is off").
//!
//! The logs are the hidden-effect protocol's (`analysis_common`): the simulator runs the
//! true machine with one effect switched on; the analysis is given a parameter file with
//! two parameters 20 % off (or Rs and Rr both half their true values), never the truth.
//! By default one case per file error is checked; `MONITOR_FULL_SWEEPS=1` checks every
//! effect on both motors with every file error.
use crate::analysis_common;
use analysis_common::*;
use monitor_analysis::refit::BaseRefit;
use monitor_analysis::simplified_model::BaseParameter;
use monitor_core::EffectKind;
use monitor_io::params::ParamFile;

/// The model the protocol starts from (a full-order simulator always has these).
const DYNAMICS: [&str; 2] = ["flux_dynamics", "current_dynamics"];

/// The parameter file's errors: two parameters 20 % off each.
const FILE_ERRORS: [&str; 3] = ["rs+20 rr-20", "lm-20 rr+20", "rs-20 j+20"];

/// `p` with the file error `which` (a leakage inductance is kept when Lm moves).
fn off(p: &ParamFile, which: &str) -> ParamFile {
    let mut q = *p;
    let m = &mut q.motor;
    let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
    let mut lm = |s: f64| {
        m.lm_h *= s;
        m.ls_h = m.lm_h + lls;
        m.lr_h = m.lm_h + llr;
    };
    match which {
        "rs+20 rr-20" => {
            q.motor.rs_ohm *= 1.2;
            q.motor.rr_ohm *= 0.8;
        }
        "lm-20 rr+20" => {
            lm(0.8);
            q.motor.rr_ohm *= 1.2;
        }
        "rs-20 j+20" => {
            q.motor.rs_ohm *= 0.8;
            q.motor.j_kgm2 *= 1.2;
        }
        "j/4" => q.motor.j_kgm2 *= 0.25,
        _ => panic!("unknown file error {which}"),
    }
    q
}

/// The true value of a base parameter of `truth` (as `BaseRefit` keys them).
fn true_value(truth: &ParamFile, key: BaseParameter) -> f64 {
    let n = monitor_analysis::simplified_model::MachineConstants::from_params(truth);
    match key {
        BaseParameter::Ra => n.ra_ohm,
        BaseParameter::Ls => n.ls_h,
        BaseParameter::BPlusBl => n.btot_nms,
        BaseParameter::J => n.j_kgm2,
    }
}

/// One case: the effect is ranked first and named, and the refit is reported.
fn judge(which: &str, name: &str, error: &str) -> (Vec<String>, BaseRefit) {
    let dir = tempfile::tempdir().unwrap();
    let truth = motor(which);
    let log = write_log(
        dir.path(),
        name,
        &truth,
        &scenario(which, Some(name), 1),
        false,
    );
    let a = analyse(&log, &off(&truth, error), from_for(which, name));
    let ex = a.explain(&opts(&DYNAMICS), &|_| {}).unwrap().report;
    let refit = ex.base_refit.clone().expect("the model ran");
    let top = ex
        .ranking
        .first()
        .map(|c| c.effect.name())
        .unwrap_or_default();
    let mut failures = Vec::new();
    let words = format!("said {:?}", said(&refit));
    eprintln!(
        "{which} {name:<17} file {error:<12} top {top:<17} unexplained {} | {words}",
        ex.unexplained
    );
    for c in ex.ranking.iter().take(4) {
        eprintln!(
            "    ranked {} {:.3} plausible {} {:?} {}",
            c.effect,
            c.explained_fraction,
            c.plausible,
            c.parameters
                .iter()
                .map(|(k, v)| (k.clone(), v.value))
                .collect::<Vec<_>>(),
            c.implausible_because.join("; ")
        );
    }
    for r in &refit.parameters {
        eprintln!(
            "    {:<14} file {:.5} refitted {:.5} true {:.5} identified {}",
            r.parameter,
            r.configured,
            r.refitted,
            true_value(&truth, r.parameter),
            r.identified
        );
    }
    if top != name || ex.unexplained {
        failures.push(format!(
            "{which} {name} ({error}): top {top}, unexplained {}",
            ex.unexplained
        ));
    }
    (failures, refit)
}

/// The refitted value of `key` is within `tol` of the truth, and the words name it.
fn refitted_to_truth(which: &str, refit: &BaseRefit, key: BaseParameter, tol: f64) -> Vec<String> {
    let truth = true_value(&motor(which), key);
    let r = refit
        .parameters
        .iter()
        .find(|r| r.parameter == key)
        .unwrap();
    let mut f = Vec::new();
    if !r.identified || (r.refitted / truth - 1.0).abs() > tol {
        f.push(format!(
            "{which} {key}: refitted {:.5} (identified {}), true {truth:.5}",
            r.refitted, r.identified
        ));
    }
    if !said(refit).contains(&key) {
        f.push(format!("{which}: {key} not said: {:?}", said(refit)));
    }
    f
}

/// The base parameters said beside the verdict: those refitted (identified, changed by 2 %
/// or more) and those the log does not identify.
fn said(refit: &BaseRefit) -> Vec<BaseParameter> {
    refit
        .changed()
        .chain(refit.unidentified())
        .map(|r| r.parameter)
        .collect()
}

#[test]
fn two_parameters_20_percent_off_still_name_the_hidden_effect() {
    let effects: Vec<&str> = EffectKind::ALL
        .iter()
        .filter(|k| {
            !matches!(
                k,
                EffectKind::DAxisDynamics
                    | EffectKind::CrossCouplingDynamics
                    | EffectKind::FluxDynamics
                    | EffectKind::CurrentDynamics
            )
        })
        .map(|k| k.name())
        .collect();
    let mut all = Vec::new();
    for which in ["2p2", "3hp"] {
        for &name in &effects {
            for error in FILE_ERRORS {
                all.push((which, name, error));
            }
        }
    }
    let cases = sweep("file errors", all, |c| {
        matches!(
            c,
            ("2p2", "thermal_drift", "lm-20 rr+20") | ("3hp", "iron_loss", "rs+20 rr-20")
        )
    });
    let mut failures = Vec::new();
    for (which, name, error) in cases {
        let (f, refit) = judge(which, name, error);
        failures.extend(f);
        // Lm 20 % low on the 2.2 kW machine (no stator leakage) is Ls 20 % low: where the
        // log identifies Ls the refit finds it (saturation moves Lm itself, so not there);
        // where it does not, that is said.
        if (which, error) == ("2p2", "lm-20 rr+20") && name != "saturation" {
            let ls = refit
                .parameters
                .iter()
                .find(|r| r.parameter == BaseParameter::Ls)
                .unwrap();
            if ls.identified {
                failures.extend(refitted_to_truth(which, &refit, BaseParameter::Ls, 0.05));
            } else if !refit
                .unidentified()
                .any(|r| r.parameter == BaseParameter::Ls)
            {
                failures.push(format!("{which} {name}: ls_h not identified, not said"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_file_that_does_not_fit_is_recentred_before_effects_are_judged() {
    // The coupled load's inertia, which no nameplate gives, a quarter of the true J. Where
    // the log identifies J (a start or steps inside the analysed span), its refit is four
    // times the file's, outside the factor 3 a plausible fit allows, and every effect
    // fitted on the file's model would be flagged: the model is recentred on the refitted
    // J first, and the effect is named. Where the log does not identify J, that is said
    // beside the verdict and no wrong effect is named.
    let cases = sweep(
        "recentred",
        [
            ("3hp", "iron_loss"),
            ("3hp", "windage"),
            ("3hp", "thermal_drift"),
            ("3hp", "saturation"),
            ("2p2", "iron_loss"),
            ("2p2", "windage"),
            ("2p2", "load_torque"),
        ],
        |c| c.0 == "3hp" && c.1 == "iron_loss",
    );
    let mut failures = Vec::new();
    let mut recentred = 0;
    for (which, name) in cases {
        let (f, refit) = judge(which, name, "j/4");
        let j = refit
            .parameters
            .iter()
            .find(|r| r.parameter == BaseParameter::J)
            .unwrap();
        let words = format!("{refit:?}");
        if j.identified {
            recentred += 1;
            failures.extend(f);
            if !refit.recentred || refit.because.is_empty() {
                failures.push(format!("{which} {name}: not recentred: {words}"));
            }
            failures.extend(refitted_to_truth(which, &refit, BaseParameter::J, 0.10));
        } else {
            // Not identified: said, and no wrong name (ranked first and claimed).
            if !refit
                .unidentified()
                .any(|r| r.parameter == BaseParameter::J)
            {
                failures.push(format!(
                    "{which} {name}: J not identified but not said: {words}"
                ));
            }
            failures.extend(f.into_iter().filter(|m| m.contains("unexplained false")));
        }
    }
    assert!(
        recentred >= 1,
        "no case identified J: the test checks nothing"
    );
    assert!(failures.is_empty(), "{failures:#?}");
}
