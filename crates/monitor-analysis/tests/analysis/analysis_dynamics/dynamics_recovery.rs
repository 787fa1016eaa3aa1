//! The effect library inside the full-order machine (`tests/analysis/analysis_dynamics.rs`): each
//! effect's fitted parameters are what the simulator injected, through a start and steps.

use super::*;

/// Length of the [`transients`] log [s].
const LOG_S: f64 = 3.4;

/// What the simulator injects with an effect at its defaults
/// (`EffectSpec::with_defaults`, `sim::scenario`), as `(parameter, value, relative
/// tolerance)` of the analysis' fitted parameter; `None` for parameters whose analysis form
/// is not the simulator's (the winding asymmetry's `c` is the negative-sequence current
/// ratio it makes, judged by its phase below).
fn injected(kind: monitor_core::EffectKind, p: &ParamFile) -> Vec<(&'static str, f64, f64)> {
    use monitor_core::EffectKind as K;
    let we = 2.0 * std::f64::consts::PI * p.supply.f_hz;
    // The simulator's "rated torque estimate": the viscous load's torque at synchronous speed.
    let t_rated = p.motor.bl_nms * sync_speed_mech(p);
    let xm = we * p.motor.lm_h;
    match kind {
        // Over 3.4 s (about one time constant) the rise and the time constant trade off;
        // the rise reached at the log's end is checked apart (below).
        K::ThermalDrift => vec![("tau_s", 3.0, 0.2)],
        K::Saturation => vec![
            ("psi_sat_wb", 1.3 * p.supply.v_phase_peak() / we, 0.03),
            ("exponent", 6.0, 0.05),
        ],
        // Near the noise floor in these short logs: the loosest bound.
        K::IronLoss => vec![("g_fe_s", 1.0 / (25.0 * xm), 0.3)],
        K::CoulombFriction => vec![("torque_nm", 0.02 * t_rated, 0.1)],
        K::Windage => vec![("k_nms2", 0.05 * t_rated / sync_speed_mech(p).powi(2), 0.1)],
        K::SupplyUnbalance => vec![("y_re", 1.0, 0.03)],
        K::RotorAsymmetry => vec![("delta", 0.1, 0.05)],
        _ => vec![],
    }
}

/// Physics check of the whole effect library inside the full-order machine: a log of the
/// true machine through a start, a V/f step and a dip (default sensors, 2, 5 and 10 kHz)
/// with one effect injected at the simulator's defaults, analysed with the true
/// parameters and the four dynamics effects plus that effect: each fitted parameter is
/// what the simulator injected ([`injected`]), and the injected shorted turns are named in
/// phase a. Both reference motors and the 11 kW machine (its load torque would drive it
/// backwards at the simulator's default: not run there). A parameter recovered wrong with
/// the error still cut is a model that is wrong in a way a fit hides: this found the
/// double-counted negative-sequence voltage (`y` 0.67) and, on the 11 kW machine, a rotor
/// asymmetry fit that ended at delta = 0 from a phase start half a turn off (error 0.0107
/// -> 0.0107; now 0.0024 with delta 0.1003, `FitSetup::with_alt_init`). Measured (2026-11-23,
/// fitted / injected over the 9 logs): thermal rise at the end 0.995-1.027, tau
/// 0.97-1.15; psi_sat 0.994-1.009, exponent 0.970-1.019; 1/Rfe 0.78-0.96; Coulomb
/// 0.946-1.042; windage 0.972-1.038; each segment's total load 0.992-1.024; y
/// 0.9973-1.000; delta 0.9989-1.0061.
#[test]
fn effect_parameters_are_recovered_through_transients() {
    use monitor_core::EffectKind as K;
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let kinds: Vec<K> = K::ALL.into_iter().filter(|k| !k.is_dynamics()).collect();
    // By default each effect once, on the motors and rates in turn (each motor and each
    // rate three times).
    let in_default = |which: &str, rate: f64, kind: K| {
        let i = kinds.iter().position(|k| *k == kind).unwrap_or(0);
        which == ["2p2", "3hp", "11kw"][(i + 1) % 3]
            && rate == [2000.0, 5000.0, 10_000.0][(i / 3) % 3]
    };
    let cases = sweep(
        "effect parameters",
        ["2p2", "3hp", "11kw"]
            .into_iter()
            .flat_map(|w| {
                [2000.0, 5000.0, 10_000.0].into_iter().flat_map(move |r| {
                    K::ALL
                        .into_iter()
                        .filter(|k| !k.is_dynamics())
                        .map(move |k| (w, r, k))
                })
            })
            // (The 11 kW machine's load torque is not run: see the doc above.)
            .filter(|&(w, _, k)| !(w == "11kw" && k == K::LoadTorque)),
        |&(w, r, k)| in_default(w, r, k),
    );
    for (which, rate) in ["2p2", "3hp", "11kw"]
        .into_iter()
        .flat_map(|w| [2000.0, 5000.0, 10_000.0].map(|r| (w, r)))
    {
        let p = params(which);
        for kind in K::ALL.into_iter().filter(|k| !k.is_dynamics()) {
            if !cases.contains(&(which, rate, kind)) {
                continue;
            }
            let mut s = transients(which, rate);
            s.effects = vec![monitor_sim::EffectSpec::with_defaults(kind)];
            let log = write_log(
                dir.path(),
                &format!("{which}_{}", kind.name()),
                &p,
                &s,
                false,
            );
            let a = analyse(&log, &p, 0.0);
            let mut with: Vec<&str> = FULL.to_vec();
            with.push(kind.name());
            let r = a.compare(&opts(&with)).unwrap().report;
            let Some(fe) = r.fitted_effects.iter().find(|e| e.effect == kind) else {
                failures.push(format!("{which} {}: not fitted", kind.name()));
                continue;
            };
            let value = |k: &str| fe.parameters.get(k).map_or(f64::NAN, |v| v.value);
            let tag = format!("{which} {rate} Hz {}", kind.name());
            for (name, want, tol) in injected(kind, &p) {
                let got = value(name);
                eprintln!("{tag}: {name} {got:.5e} (injected {want:.5e})");
                // (NaN fails.)
                if !within(got, want, tol * want.abs()) {
                    failures.push(format!("{tag}: {name} {got:.5e}, injected {want:.5e}"));
                }
            }
            match kind {
                K::LoadTorque => {
                    // The injected constant torque replaces the viscous load (the machine's
                    // own B stays). A level per segment at nearly one speed trades with the
                    // refitted viscous term (`compare` reports B + Bl as not identified on
                    // the 3 hp log), so what is recovered is each segment's total load,
                    // level + (B + Bl fitted - B) x the segment's mean speed.
                    let want = p.motor.bl_nms * sync_speed_mech(&p);
                    let b_fit = r
                        .base_parameters
                        .get("b_plus_bl_nms")
                        .map_or(f64::NAN, |v| v.value);
                    let np = f64::from(p.motor.poles) / 2.0;
                    let d = &a.data;
                    let mut levels: Vec<(f64, f64)> = fe
                        .parameters
                        .iter()
                        .filter_map(|(name, v)| {
                            let from = name.split("_from_").nth(1)?.trim_end_matches("_s");
                            Some((from.parse::<f64>().ok()?, v.value))
                        })
                        .collect();
                    levels.sort_by(|x, y| x.0.total_cmp(&y.0));
                    for (j, &(from, level)) in levels.iter().enumerate() {
                        let to = levels.get(j + 1).map_or(f64::INFINITY, |l| l.0);
                        let (sum, count) = d
                            .t_s
                            .iter()
                            .zip(&d.omega_r)
                            .filter(|(t, _)| **t >= from && **t < to)
                            .fold((0.0, 0.0), |(s, c), (_, w)| (s + w / np, c + 1.0));
                        let total = level + (b_fit - p.motor.b_nms) * sum / count;
                        eprintln!("{tag}: load from {from:.2} s {total:.3} N m (level {level:.3}; injected {want:.3})");
                        if !within(total, want, 0.03 * want) {
                            failures.push(format!(
                                "{tag}: load from {from:.2} s {total:.3} N m, injected {want:.3}"
                            ));
                        }
                    }
                    if levels.is_empty() {
                        failures.push(format!("{tag}: no levels in {:?}", fe.parameters.keys()));
                    }
                }
                K::ThermalDrift => {
                    let end = |rise: f64, tau: f64| rise * (1.0 - (-LOG_S / tau).exp());
                    let (got, want) = (end(value("rise_k"), value("tau_s")), end(60.0, 3.0));
                    eprintln!("{tag}: rise at the end {got:.2} K (injected {want:.2} K)");
                    if !within(got, want, 0.05 * want) {
                        failures.push(format!(
                            "{tag}: rise at the end {got:.2} K, injected {want:.2} K"
                        ));
                    }
                }
                K::PhaseAsymmetry if !fe.summary.starts_with("phase a ") => {
                    failures.push(format!("{tag}: {}", fe.summary));
                }
                K::SupplyUnbalance if value("y_im").abs() > 0.03 => {
                    failures.push(format!("{tag}: y_im {:.4}", value("y_im")));
                }
                _ => {}
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
