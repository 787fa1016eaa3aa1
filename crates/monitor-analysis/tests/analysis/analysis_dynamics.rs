//! The dynamics effects up to the full-order machine (issue 10): effect-free logs with a
//! direct-on-line start, a V/f step and a supply voltage step, both reference motors and
//! an 11 kW machine the code was not developed on, at 2, 5 and 10 kHz, analysed over the
//! whole log (start included). The figures are printed (`--nocapture`) and in docs/model-vs-measurement.md ("Measured").
//!
//! Full sweeps: by default each sweep over motors, rates and effects checks a
//! representative subset (each effect on one motor at one rate, every motor and every rate
//! on some effect); `MONITOR_FULL_SWEEPS=1` checks every case (`analysis_common`'s module
//! doc; `.ci/run` runs it).
use crate::analysis_common;
mod dynamics_recovery;

use analysis_common::*;
use monitor_io::params::ParamFile;
use monitor_sim::{Scenario, SupplyStep};

/// All four dynamics effects: the full-order T-equivalent machine.
const FULL: [&str; 4] = [
    "flux_dynamics",
    "current_dynamics",
    "d_axis_dynamics",
    "cross_coupling_dynamics",
];

/// A made-up 11 kW, 400 V, 50 Hz, 4-pole machine with textbook per-unit values
/// (Z_base = 14.5 ohm: Rs 0.026 pu, Rr 0.024 pu, leakages 0.076 pu each, Xm 1.95 pu,
/// sigma 0.07, Lr/Rr 0.27 s, inertia constant about 0.2 s with a coupled load). A
/// simulator's machine: its Lm is the unsaturated one (`lm_at`), as the simulator's
/// reference machines'.
fn motor_11kw() -> ParamFile {
    ParamFile::from_toml_str(
        "[motor]\nrs_ohm = 0.38\nrr_ohm = 0.35\nls_h = 0.0935\nlr_h = 0.0935\nlm_h = 0.09\npoles = 4\nj_kgm2 = 0.09\nb_nms = 0.01\nbl_nms = 0.45\nlm_at = \"unsaturated\"\n[supply]\nv_ll_rms = 400.0\nf_hz = 50.0\n",
        "11 kW test machine",
    )
    .expect("11 kW parameters")
}

fn params(which: &str) -> ParamFile {
    match which {
        "11kw" => motor_11kw(),
        w => motor(w),
    }
}

/// `|got - want| <= tol` (false for NaN).
fn within(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol
}

/// Start from standstill, a V/f step to 60 % at 1.5 s, back to rated at 2.2 s, a 10 %
/// supply voltage dip at 2.8 s: 3.4 s at `rate_hz`, default sensors (12-bit, 0.1 % noise).
fn transients(which: &str, rate_hz: f64) -> Scenario {
    let f0 = params(which).supply.f_hz;
    let mut s = Scenario::steady(3.4, rate_hz);
    s.sensors = sensors(1);
    s.supply.steps = vec![
        SupplyStep {
            t_s: 1.5,
            v_scale: Some(0.6),
            f_hz: Some(0.6 * f0),
        },
        SupplyStep {
            t_s: 2.2,
            v_scale: Some(1.0),
            f_hz: Some(f0),
        },
        SupplyStep {
            t_s: 2.8,
            v_scale: Some(0.9),
            f_hz: None,
        },
    ];
    s
}

/// The ratio error / noise floor of `compare` with the paper's model and with the
/// full-order machine over the whole log, for one motor and rate.
fn ratios(dir: &std::path::Path, which: &str, rate_hz: f64) -> (f64, f64) {
    let p = params(which);
    let log = write_log(
        dir,
        &format!("{which}_{rate_hz}"),
        &p,
        &transients(which, rate_hz),
        false,
    );
    let a = analyse(&log, &p, 0.0);
    let paper = a.compare(&opts(&[])).unwrap().report;
    let full = a.compare(&opts(&FULL)).unwrap().report;
    let r_paper = paper.normalized_rms_error / paper.noise_floor;
    // Against the same floor, so that r_paper / r_full is the error's gain.
    let r_full = full.normalized_rms_error / paper.noise_floor;
    eprintln!(
        "{which} {rate_hz} Hz: paper's model {:.4} ({r_paper:.0}x noise), full order {:.4} ({r_full:.1}x that noise floor, {:.4}), plausible {}",
        paper.normalized_rms_error, full.normalized_rms_error, paper.noise_floor, full.plausible
    );
    assert!(
        full.plausible,
        "{which} {rate_hz}: {:?}",
        full.implausible_because
    );
    (r_paper, r_full)
}

/// Measured (docs/model-vs-measurement.md, "Through a start and steps"): the full-order model's error is 0.0015-0.0041,
/// 0.9-1.1x the noise floor, on both reference motors and the 11 kW machine at 2, 5 and
/// 10 kHz, where the paper's model is at 0.33-0.58 (84-425x): the target (2x the
/// noise floor) is met. (Before: 0.0065-0.022, 3-15x. The remainder came from the model
/// starting a start at the 10 ms mean speed, the spurious negative-sequence voltage the
/// sequence separation made through the start and after each step, the instant of a step
/// inside a sampling interval, and the block mean's gain, which the torque sees squared;
/// see `simplified_model::simulate_stationary`.) Bounds: within 1.3x the noise floor and
/// at least a 75-fold gain (measured 88-380x).
#[test]
fn full_order_machine_follows_starts_and_steps() {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let cases = sweep(
        "motors x rates",
        ["2p2", "3hp", "11kw"]
            .into_iter()
            .flat_map(|w| [2000.0, 5000.0, 10_000.0].map(|r| (w, r))),
        // Each motor at another rate.
        |c| matches!(c, ("2p2", 2000.0) | ("3hp", 5000.0) | ("11kw", 10_000.0)),
    );
    for (which, rate) in cases {
        {
            let (paper, full) = ratios(dir.path(), which, rate);
            // paper / full compares ratios to the same log's noise floors: the error gain.
            let gain = paper / full;
            if !(full <= 1.3 && gain >= 75.0) {
                failures.push(format!(
                    "{which} {rate}: paper {paper:.1}x, full {full:.1}x the noise floor"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Physics check of `supply_unbalance` inside the full-order machine: on a log of the
/// true machine fed from an unbalanced supply (2 and 4 %, through the start, the V/f step
/// and the dip), the fitted negative-sequence admittance relative to the nominal machine's
/// is `y = 1 + 0j`: the machine's own equations give its negative-sequence current, so
/// nothing is left for `y` to absorb. (Until 2026-11-23 the model added the previous
/// sample's negative-sequence voltage to the next step's start as well, and `y` came out
/// 0.67 on the second walkthrough's log (docs/model-vs-measurement.md) with the error still cut 19x: the fit hid
/// the double count.) Measured: y 0.9997 + 0.00002j on that log.
#[test]
fn supply_unbalance_fits_the_true_admittance() {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for which in ["2p2", "11kw"] {
        for (fraction, angle_deg) in [(0.02, 0.0), (0.04, 70.0)] {
            let p = params(which);
            let mut s = transients(which, 5000.0);
            s.effects = vec![monitor_sim::EffectSpec::SupplyUnbalance {
                fraction,
                angle_deg,
            }];
            let log = write_log(
                dir.path(),
                &format!("{which}_unb_{fraction}"),
                &p,
                &s,
                false,
            );
            let a = analyse(&log, &p, 0.0);
            let mut with: Vec<&str> = FULL.to_vec();
            with.push("supply_unbalance");
            let r = a.compare(&opts(&with)).unwrap().report;
            let y = |k: &str| {
                r.fitted_effects
                    .iter()
                    .find_map(|e| e.parameters.get(k))
                    .map_or(f64::NAN, |v| v.value)
            };
            let (re, im) = (y("y_re"), y("y_im"));
            eprintln!(
                "{which} {:.0} % at {angle_deg} deg: y = {re:.4} {im:+.4}j, error {:.4} (noise floor {:.4})",
                100.0 * fraction,
                r.normalized_rms_error,
                r.noise_floor
            );
            if !(within(re, 1.0, 0.05) && within(im, 0.0, 0.05)) {
                failures.push(format!("{which} {fraction}: y = {re:.4} {im:+.4}j"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Synchronous mechanical speed of `p` [rad/s].
fn sync_speed_mech(p: &ParamFile) -> f64 {
    2.0 * std::f64::consts::PI * p.supply.f_hz / (0.5 * f64::from(p.motor.poles))
}

/// The T-equivalent circuit's torque at standstill on the rated supply [N m]:
/// `3 |I_r|^2 Rr / omega_sync,mech`.
fn locked_rotor_torque(p: &ParamFile) -> f64 {
    use monitor_analysis::prep::C64;
    let m = &p.motor;
    let w = 2.0 * std::f64::consts::PI * p.supply.f_hz;
    let (zm, zr) = (
        C64::new(0.0, w * m.lm_h),
        C64::new(m.rr_ohm, w * (m.lr_h - m.lm_h)),
    );
    let z = C64::new(m.rs_ohm, w * (m.ls_h - m.lm_h)) + zm * zr / (zm + zr);
    let i_r = p.supply.v_ll_rms / 3f64.sqrt() / z * zm / (zm + zr);
    3.0 * i_r.norm_sqr() * m.rr_ohm / sync_speed_mech(p)
}

/// One case of issue 10's "hidden effects under transients": the start + V/f step + dip
/// log of [`transients`] at 5 kHz with `kind` injected (the simulator's defaults),
/// analysed over the whole log with the four dynamics effects in the model. Returns what
/// `explain` ranks first, its explained fraction, `unexplained`, and `compare`'s error
/// without and with the effect and the noise floor.
fn hidden_case(
    dir: &std::path::Path,
    which: &str,
    kind: monitor_core::EffectKind,
    rate_hz: f64,
) -> (String, f64, bool, f64, f64, f64) {
    let truth = params(which);
    let nominal = perturbed(&truth, 0.05);
    let mut s = transients(which, rate_hz);
    s.effects = vec![match kind {
        // The simulator's default constant load (the viscous load's torque at synchronous
        // speed, about rated) is more than the 11 kW machine's locked-rotor torque (a
        // single-cage model has no deep-bar rise of Rr at standstill), and that active load
        // drives it backwards from the start; there half of it.
        monitor_core::EffectKind::LoadTorque => {
            let default = truth.motor.bl_nms * sync_speed_mech(&truth);
            monitor_sim::EffectSpec::LoadTorque {
                torque_nm: (default > locked_rotor_torque(&truth)).then_some(0.5 * default),
            }
        }
        k => monitor_sim::EffectSpec::with_defaults(k),
    }];
    let log = write_log(
        dir,
        &format!("{which}_{}_{rate_hz}", kind.name()),
        &truth,
        &s,
        false,
    );
    let a = analyse(&log, &nominal, 0.0);
    let ex = a.explain(&opts(&FULL), &|_| {}).unwrap().report;
    let mut with: Vec<&str> = FULL.to_vec();
    with.push(kind.name());
    let before = a.compare(&opts(&FULL)).unwrap().report;
    let after = a.compare(&opts(&with)).unwrap().report;
    let top = ex.ranking.first();
    if let Some(c) = top {
        eprintln!("  {}: {}", c.effect.name(), c.summary);
    }
    let r = (
        top.map(|c| c.effect.name()).unwrap_or("-").to_string(),
        top.map(|c| c.explained_fraction).unwrap_or(0.0),
        ex.unexplained,
        before.normalized_rms_error,
        after.normalized_rms_error,
        after.noise_floor,
    );
    eprintln!(
        "{which} {rate_hz} Hz {:<17} top {:<17} ({:.0} %, unexplained {}) error {:.4} -> {:.4} ({:.1}x, noise floor {:.4})",
        kind.name(),
        r.0,
        100.0 * r.1,
        r.2,
        r.3,
        r.4,
        r.3 / r.4,
        r.5
    );
    r
}

/// The hidden effects that are found through a start and steps (docs/model-vs-measurement.md, "Hidden effects
/// under transients"), on both reference motors and the 11 kW machine, at `rate_hz`:
/// ranked first, claimed, and the error cut at least 5x or to within 2x the noise floor.
/// They are found since they act inside the full-order model as the simulator injects
/// them (the heated cage's rotor time constant, Lm on the model's own magnetising flux,
/// the unequal stator winding, the unequal cage, the negative-sequence voltage driving the
/// machine; `simplified_model`). Iron loss, friction and windage are ranked first too
/// (probe below, table in docs/model-vs-measurement.md), but at the simulator's defaults they sit at the
/// noise in this log (the error without them is already within 2x the floor), so
/// `explain` may rightly claim nothing.
fn hidden_effects_found_at(rate_hz: f64) {
    use monitor_core::EffectKind;
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let found = [
        EffectKind::LoadTorque,
        EffectKind::SupplyUnbalance,
        EffectKind::ThermalDrift,
        EffectKind::Saturation,
        EffectKind::PhaseAsymmetry,
        EffectKind::RotorAsymmetry,
    ];
    let cases = sweep(
        &format!("hidden effects at {rate_hz} Hz"),
        ["2p2", "3hp", "11kw"]
            .into_iter()
            .flat_map(|w| found.map(|k| (w, k))),
        |&(which, kind)| in_default_hidden(which, kind, rate_hz),
    );
    for (which, kind) in cases {
        let (top, _, unexplained, before, after, floor) =
            hidden_case(dir.path(), which, kind, rate_hz);
        // At the noise already without it (within 2x the floor), it may rightly be left
        // unclaimed, as in `analysis_effects.rs`.
        let claim_due = before > 2.0 * floor;
        if top != kind.name()
            || (unexplained && claim_due)
            || !(before >= 5.0 * after || after <= 2.0 * floor)
        {
            failures.push(format!(
                "{which} {kind} {rate_hz} Hz: top {top}, unexplained {unexplained}, {before:.4} -> {after:.4} (floor {floor:.4})"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The hidden-effect cases of the default run: each effect once, each motor and each rate
/// twice.
fn in_default_hidden(which: &str, kind: monitor_core::EffectKind, rate_hz: f64) -> bool {
    use monitor_core::EffectKind as K;
    let (w, r) = match kind {
        K::LoadTorque => ("2p2", 2000.0),
        K::Saturation => ("3hp", 2000.0),
        K::ThermalDrift => ("3hp", 5000.0),
        K::RotorAsymmetry => ("11kw", 5000.0),
        K::SupplyUnbalance => ("2p2", 10_000.0),
        K::PhaseAsymmetry => ("11kw", 10_000.0),
        _ => return false,
    };
    which == w && rate_hz == r
}

#[test]
fn hidden_effects_under_transients_found_at_2_khz() {
    hidden_effects_found_at(2000.0);
}

#[test]
fn hidden_effects_under_transients_found_at_5_khz() {
    hidden_effects_found_at(5000.0);
}

#[test]
fn hidden_effects_under_transients_found_at_10_khz() {
    hidden_effects_found_at(10_000.0);
}

/// Every non-dynamics effect of the library through a start and steps (a probe, ignored:
/// `--ignored --nocapture`; `MOTOR` picks the motor, default 2p2, `EFFECT` a comma-separated
/// list of effects, default all; figures in docs/model-vs-measurement.md).
#[test]
#[ignore]
fn hidden_effects_under_transients_probe() {
    let which = std::env::var("MOTOR").unwrap_or("2p2".into());
    let only = std::env::var("EFFECT").ok();
    let rate: f64 = std::env::var("RATE").map_or(5000.0, |r| r.parse().expect("RATE in Hz"));
    let dir = tempfile::tempdir().unwrap();
    for kind in monitor_core::EffectKind::ALL.into_iter().filter(|k| {
        !k.is_dynamics()
            && only
                .as_deref()
                .is_none_or(|o| o.split(',').any(|x| x == k.name()))
    }) {
        hidden_case(dir.path(), &which, kind, rate);
    }
}

/// All four states of the full-order machine dynamic, with the true La and Lr/Rr of `m`.
fn full_order_dynamics(
    m: &monitor_core::MotorModel<f64>,
) -> monitor_analysis::simplified_model::Dynamics {
    monitor_analysis::simplified_model::Dynamics {
        stator_current_la_h: Some(m.la_h()),
        rotor_flux_tau_s: Some(m.lr_h / m.rr_ohm),
        stator_d_axis: true,
        rotor_flux_q_axis: true,
    }
}

/// The full-order model with the true parameters (no fit) against effect-free logs of
/// [`transients`] with ideal sensors: what is left is the analysis's own reconstruction
/// of the working series (frame, sequence separation, block means, where a step fell),
/// not noise and not a fit. Measured 0.0003-0.0007 (2.2 kW and 11 kW, 2 and 10 kHz);
/// before the model ran in the stationary frame with the causes in docs/model-vs-measurement.md fixed,
/// 0.007-0.023.
#[test]
fn full_order_model_reproduces_the_simulator() {
    use monitor_analysis::{metrics, simplified_model as sm};
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (which, rate) in [
        ("2p2", 2000.0),
        ("2p2", 10_000.0),
        ("11kw", 2000.0),
        ("11kw", 10_000.0),
    ] {
        let p = params(which);
        let m = p.motor.model::<f64>();
        let mut s = transients(which, rate);
        s.sensors = monitor_sim::SensorSpec::ideal();
        let log = write_log(dir.path(), &format!("ideal_{which}_{rate}"), &p, &s, false);
        let a = analyse(&log, &p, 0.0);
        let terms = sm::ModelTerms {
            dynamics: full_order_dynamics(&m),
            ..Default::default()
        };
        let n = &a.constants;
        let pred = sm::simulate(&a.data, n, &sm::BaseParams::nominal(n), &terms);
        let e = metrics::errors(&a.data, &pred, None).normalized_rms_error;
        eprintln!("{which} {rate} Hz, true parameters, ideal sensors: {e:.5}");
        if e.is_nan() || e > 0.001 {
            failures.push(format!("{which} {rate}: {e:.5}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The full-order model's own saturation (`ModelTerms::magnetising.law`, the simulator's law on
/// the model's magnetising flux) with the true parameters and the simulator's default law
/// (psi_sat = 1.3 x the rated flux, n = 6), no fit, against ideal-sensor logs of
/// [`transients`] with `saturation` injected: at the reconstruction floor of the
/// effect-free case (below 0.001; measured 0.0003 and 0.0004 on the 2.2 kW and 3 hp
/// motors), 10x or more below the unsaturated model (measured 0.050 and 0.023).
#[test]
fn saturated_full_order_model_reproduces_the_simulator() {
    use monitor_analysis::{metrics, simplified_model as sm};
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for which in ["2p2", "3hp"] {
        let p = params(which);
        let m = p.motor.model::<f64>();
        let mut s = transients(which, 5000.0);
        s.sensors = monitor_sim::SensorSpec::ideal();
        s.effects = vec![monitor_sim::EffectSpec::with_defaults(
            monitor_core::EffectKind::Saturation,
        )];
        let log = write_log(dir.path(), &format!("sat_{which}"), &p, &s, false);
        let a = analyse(&log, &p, 0.0);
        let psi_sat = 1.3 * p.supply.v_phase_peak() / p.supply.omega_rad_s();
        let mut e = [0.0; 2];
        for (sat, e) in [None, Some((psi_sat, 6.0))].into_iter().zip(&mut e) {
            let terms = sm::ModelTerms {
                dynamics: full_order_dynamics(&m),
                magnetising: sm::Magnetising {
                    law: sat.map(|(psi_sat_wb, exponent)| {
                        sm::MagnetisingLaw::Power(sm::SaturationLaw {
                            psi_sat_wb,
                            exponent,
                            lm0_over_file: a.constants.lm0_over_file(psi_sat_wb, exponent),
                        })
                    }),
                    ..Default::default()
                },
                ..Default::default()
            };
            let n = &a.constants;
            let pred = sm::simulate(&a.data, n, &sm::BaseParams::nominal(n), &terms);
            *e = metrics::errors(&a.data, &pred, None).normalized_rms_error;
        }
        eprintln!(
            "{which} saturated log, true parameters, ideal sensors: unsaturated model {:.5}, saturated {:.5}",
            e[0], e[1]
        );
        if !(e[1] <= 0.001 && e[0] >= 10.0 * e[1]) {
            failures.push(format!("{which}: {:.5} -> {:.5}", e[0], e[1]));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A window just after a V/f step that falls inside the start's settling tail (five rotor
/// time constants after the run-up) is the step, not the start; a window in that tail
/// before any step is still the start. Found on a 1 kHz log of the 2-pole 11 kW machine
/// with its parameters 20 % off (rotor time constant 0.45 s): the window after the step
/// back to 50 Hz at 2.4 s was called "the direct-on-line start".
#[test]
fn a_step_inside_the_start_settling_tail_is_named_as_the_step() {
    use monitor_analysis::metrics::{Condition, WorstWindow};
    use monitor_analysis::simplified_model::MachineConstants;
    use monitor_analysis::transients::{classify, settling_s, start_end_s};
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for which in ["2p2", "3hp", "11kw"] {
        let p = params(which);
        let log = write_log(dir.path(), which, &p, &transients(which, 5000.0), false);
        let a = analyse(&log, &p, 0.0);
        let n = MachineConstants::from_params(&p);
        let te = start_end_s(&a.data).expect("the log starts from standstill");
        // A tail that reaches past the V/f step at 1.5 s, or the case is not tested.
        let look = settling_s(&n).max(1.6 - te);
        let window = |t0: f64| WorstWindow {
            t_start_s: t0,
            t_end_s: t0 + 0.1,
            normalized_rms_error: 0.0,
            condition: Condition {
                speed_rpm: None,
                load_current_a: 0.0,
                voltage_v: 0.0,
                voltage_percent: 0.0,
                supply_hz: 0.0,
                time_since_start_s: t0,
            },
            dominant_error_hz: 0.0,
            error_kind: String::new(),
            transient: None,
        };
        let kind =
            |t0: f64| classify(&a.data, &n, &window(t0), Some(te), look).map(|t| t.kind.name());
        for (t0, want) in [
            (te - 0.1, Some("start")),
            (te + 0.05, Some("start")),
            (1.52, Some("supply_step")),
        ] {
            let got = kind(t0);
            eprintln!(
                "{which}: window from {t0:.2} s (start ends {te:.2} s, tail {look:.2} s): {got:?}"
            );
            if got != want {
                failures.push(format!("{which} {t0:.2} s: {got:?}, want {want:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
