//! Heating is not a fault: a winding that warms raises Rs and Rr together (copper
//! 0.393 %/K), and the isolation tracks it instead of naming a fault
//! (`monitor_core::isolation`, "Heating is not a fault").
//!
//! Three motors (the 3 hp and 2.2 kW reference motors and a 0.37 kW machine of per-unit
//! values typical of its size), each commissioned cold over 1.5-3.5 s, its windings then
//! warming by 40 or 100 K with a thermal time constant of 10 s or 60 s (the simulator's
//! `thermal_drift`, which scales Rs and Rr by 1 + 0.00393 dT): no fault named, the verdict
//! not FAULT, and the reported rise within 15 K of the rise at the end of the log. Also: an
//! Rs +30 % fault on the warm motor is still named (alone on the 2.2 kW and 0.37 kW machines;
//! on the 3 hp motor, whose Rs is 1.6 % of its impedance, among the candidates of a FAULT
//! verdict), with its size against the warm Rs, and an Rr +30 % fault on a cold one is not
//! taken for heating.
//!
//! Commissioned while warming (issue 40): the windings warming from the start of the log,
//! commissioned over 2-4 s or 2-8 s (4-20 K of the rise inside the window), on four motors
//! (the three and the 11 kW 2-pole machine of `examples/params/`): no FAULT, no fault named
//! at p >= 0.5, and the rise since the window began reported within 15 K.
//!
//! Ten 40-60 s replays at 2 kHz, six 14-55 s ones and twelve 30 s ones: about 5 s in the
//! test profile on 2 cores. A real motor's thermal time constant (30 min) runs with `MONITOR_FULL_SWEEPS=1`
//! as 1 h logs at 1 kHz on two motors (`.ci/run` runs it).

use crate::small_motor;

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_replay::{DiagnoseReport, IsolationName, Verdict};
use monitor_sim::{Scenario, SensorSpec};
use rayon::prelude::*;
use std::path::Path;

fn motors() -> Vec<(&'static str, ParamFile)> {
    small_motor::three_motors()
}

/// Heating from 4 s: `rise_k` with time constant `tau_s`; `fault` on top; 2 kHz.
fn run(
    p: &ParamFile,
    duration_s: f64,
    rise_k: f64,
    tau_s: f64,
    fault: Option<(Fault, f64, f64)>,
) -> DiagnoseReport {
    run_at(p, 2000.0, duration_s, rise_k, tau_s, fault)
}

/// [`run`] at `rate_hz`.
fn run_at(
    p: &ParamFile,
    rate_hz: f64,
    duration_s: f64,
    rise_k: f64,
    tau_s: f64,
    fault: Option<(Fault, f64, f64)>,
) -> DiagnoseReport {
    let mut sc = Scenario::steady(duration_s, rate_hz);
    sc.sensors = SensorSpec::default();
    sc.seed = 5;
    small_motor::replay_warming(p, sc, (rise_k, tau_s), fault)
}

/// The rise reached at the end of a log of `duration_s` (heating from 4 s).
fn rise_at_end(rise_k: f64, tau_s: f64, duration_s: f64) -> f64 {
    rise_k * (1.0 - (-(duration_s - 4.0) / tau_s).exp())
}

/// Warming by `rise_k` with `tau_s` over `duration_s` at `rate_hz` on `p`: `None` when the
/// verdict is not FAULT, no fault is named and the reported rise is within 15 K of the rise
/// reached, else the case in words.
fn warming_fails(
    name: &str,
    p: &ParamFile,
    rate_hz: f64,
    duration_s: f64,
    rise_k: f64,
    tau_s: f64,
) -> Option<String> {
    let r = run_at(p, rate_hz, duration_s, rise_k, tau_s, None);
    let truth = rise_at_end(rise_k, tau_s, duration_s);
    let seen = r.isolation.winding_rise_k;
    let line = format!(
        "{name} +{rise_k} K tau {tau_s} s ({truth:.0} K at {duration_s} s): {:?}, named {:?}, rise {seen:?}",
        r.verdict, r.isolation.named
    );
    eprintln!("{line}");
    let ok = r.verdict != Verdict::Fault
        && r.isolation.named.is_none()
        && seen.is_some_and(|s| (f64::from(s) - truth).abs() <= 15.0);
    (!ok).then_some(line)
}

#[test]
fn warming_is_reported_as_a_rise_not_a_fault() {
    let cases: Vec<(&str, ParamFile, f64, f64, f64)> = motors()
        .into_iter()
        .flat_map(|(n, p)| {
            [
                (40.0, 10.0, 40.0),
                (100.0, 10.0, 40.0),
                (40.0, 60.0, 60.0),
                (100.0, 60.0, 60.0),
            ]
            .into_iter()
            .filter(move |c| n != "2.2 kW" || c.1 < 60.0)
            .map(move |(rise, tau, dur)| (n, p, rise, tau, dur))
        })
        .collect();
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|(name, p, rise, tau, dur)| warming_fails(name, p, 2000.0, *dur, *rise, *tau))
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

/// A motor, its rise [K] and time constant [s], and the commissioning window [s].
type WarmingCase<'a> = (&'a str, &'a ParamFile, f64, f64, (f64, f64));

/// The rise at `t_s` of a warming by `rise_k` with `tau_s` from 0 s.
fn rise_at(rise_k: f64, tau_s: f64, t_s: f64) -> f64 {
    rise_k * (1.0 - (-t_s / tau_s).exp())
}

#[test]
fn a_motor_commissioned_while_it_warms_reads_heating_not_a_fault() {
    let third = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params/11kw_2pole.toml");
    let mut four = motors();
    four.push((
        "11 kW",
        ParamFile::load(&third).expect("the 11 kW parameter file"),
    ));
    // (rise, tau, commissioning window): the 3 hp case of the issue (60 K, 12 s) and a
    // faster, larger one; 30 s logs.
    let cases: Vec<WarmingCase> = four
        .iter()
        .flat_map(|(n, p)| {
            [
                (60.0, 12.0, (2.0, 8.0)),
                (60.0, 12.0, (2.0, 4.0)),
                (100.0, 10.0, (2.0, 8.0)),
            ]
            .map(|(rise, tau, w)| (*n, p, rise, tau, w))
        })
        .collect();
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|&(name, p, rise, tau, window)| {
            let mut sc = Scenario::steady(30.0, 2000.0);
            sc.sensors = SensorSpec::default();
            sc.seed = 5;
            let r = small_motor::replay_warming_from(p, sc, (rise, tau, 0.0), None, window);
            // The rise since the window began (the baseline is the machine at its start).
            let truth = rise_at(rise, tau, 30.0) - rise_at(rise, tau, window.0);
            let seen = r.isolation.winding_rise_k;
            let strong = r
                .candidates
                .iter()
                .find(|c| c.probability >= 0.5)
                .map(|c| c.fault);
            let line = format!(
                "{name} +{rise} K tau {tau} s, commissioned {window:?} ({truth:.0} K since): {:?}, named {:?}, p>=0.5 {strong:?}, rise {seen:?}",
                r.verdict, r.isolation.named
            );
            eprintln!("{line}");
            let ok = r.verdict != Verdict::Fault
                && r.isolation.named.is_none()
                && strong.is_none()
                && seen.is_some_and(|s| (f64::from(s) - truth).abs() <= 15.0);
            (!ok).then_some(line)
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn a_resistance_fault_is_still_named_on_a_warm_motor_and_not_taken_for_heating() {
    let bad: Vec<String> = motors()
        .par_iter()
        .flat_map(|(name, p)| {
            // Warm by 60 K (tau 10 s, 98 % reached at 44 s), then Rs +30 % at 45 s.
            let r = run(p, 55.0, 60.0, 10.0, Some((Fault::Rs, 45.0, 0.3)));
            let c = f64::from(r.isolation.named_change.unwrap_or(f32::NAN));
            let warm = format!(
                "{name} warm, rs +30 %: {:?}, named {:?} {c:+.3}, rise {:?}",
                r.verdict, r.isolation.named, r.isolation.winding_rise_k
            );
            eprintln!("{warm}");
            // Named alone on the 0.37 kW machine. On the 3 hp motor (Rs is 1.6 % of its
            // impedance) and the 2.2 kW one, the tracked temperature's lag (the winding may
            // have warmed a few kelvin more since it was last judged) leaves rs shared with
            // voltage_sensor (rs p 0.26-0.50): no name reaches the confidence a FAULT needs,
            // so the verdict is WATCHING (never healthy) with rs +30 % among the candidates,
            // and no other fault is named.
            let rs = r
                .candidates
                .iter()
                .find(|c| c.fault == Fault::Rs)
                .map(|c| (c.probability, f64::from(c.change.unwrap_or(f32::NAN))));
            let named_rs = r.isolation.named == Some(IsolationName::Fault(Fault::Rs))
                && (c - 0.3).abs() <= 0.075;
            let warm_ok = if *name == "0.37 kW" {
                named_rs
            } else {
                (named_rs || r.isolation.named.is_none())
                    && matches!(r.verdict, Verdict::Fault | Verdict::Watching)
                    && rs.is_some_and(|(p, c)| p >= 0.2 && (c - 0.3).abs() <= 0.075)
            };
            // Cold, Rr +30 % at 8 s: a fault, not a rise.
            let r = run(p, 14.0, 0.0, 1.0, Some((Fault::Rr, 8.0, 0.3)));
            let cold = format!(
                "{name} cold, rr +30 %: {:?}, named {:?}, rise {:?}",
                r.verdict, r.isolation.named, r.isolation.winding_rise_k
            );
            eprintln!("{cold}");
            // (Named alone on the 3 hp and 2.2 kW motors; on the 0.37 kW one a tripled
            // leakage fits too, rr p 0.6-0.86: then rr is the leading candidate.)
            let rr_top = r.candidates.first().is_some_and(|c| {
                c.fault == Fault::Rr && c.change.is_some_and(|k| (k - 0.3).abs() <= 0.075)
            });
            let cold_ok = r.verdict == Verdict::Fault
                && (r.isolation.named == Some(IsolationName::Fault(Fault::Rr))
                    || (r.isolation.named.is_none() && rr_top));
            [(!warm_ok).then_some(warm), (!cold_ok).then_some(cold)]
        })
        .flatten()
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Krause's 50 hp motor warming 100 K with a 30 s time constant, commissioned cold (issue
/// 48): its Rs is under 1 % of its impedance, so heating moves the residuals where an Rr
/// change and a speed reading a fraction of a per cent off do (0.8 degrees apart). Before,
/// names were given on the way (`rr +2.8 %` p 0.56, `voltage_sensor +0.7 %` p 0.66,
/// `speed_sensor -0.2 %` p 0.65) and the issue's log ended in a FAULT (speed_sensor p 0.37,
/// rr p 0.26). Now: no name at any time, no FAULT, the rise within 15 K; 60 s at 2 kHz and
/// 5 kHz, commissioned over 1.5-3.5 s and 3-4.5 s.
#[test]
fn a_50hp_motor_warming_fast_is_heating_and_names_nothing() {
    let p = small_motor::krause_50hp();
    let cases = [
        ((1.5, 3.5), 2000.0),
        ((3.0, 4.5), 2000.0),
        ((3.0, 4.5), 5000.0),
    ];
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|&(window, rate)| {
            let mut sc = Scenario::steady(60.0, rate);
            sc.sensors = SensorSpec::default();
            sc.seed = 5;
            let from = window.1 + 0.5;
            let r = small_motor::replay_warming_from(&p, sc, (100.0, 30.0, from), None, window);
            let truth = rise_at(100.0, 30.0, 60.0 - from);
            let names: Vec<String> = r
                .isolation
                .events
                .iter()
                .filter(|e| matches!(e, monitor_replay::IsolationEvent::Named { .. }))
                .map(monitor_words::diagnose::event_line)
                .collect();
            let strong = r.candidates.iter().find(|c| c.probability >= 0.5);
            let seen = r.isolation.winding_rise_k;
            let line = format!(
                "50 hp +100 K tau 30 s ({truth:.0} K), commissioned {window:?} at {rate} Hz: {:?}, named {:?}, names given {names:?}, p>=0.5 {strong:?}, rise {seen:?}",
                r.verdict, r.isolation.named
            );
            eprintln!("{line}");
            let ok = r.verdict != Verdict::Fault
                && r.isolation.named.is_none()
                && names.is_empty()
                && strong.is_none()
                && seen.is_some_and(|s| (f64::from(s) - truth).abs() <= 15.0);
            (!ok).then_some(line)
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

/// A real motor's thermal time constant: +100 K with tau 30 min over a 1 h log at 1 kHz
/// (86 K reached), on the 3 hp and 2.2 kW motors: healthy, the rise within 15 K. Only with
/// `MONITOR_FULL_SWEEPS=1` (about 20 s in the test profile).
#[test]
fn an_hour_of_warming_with_a_real_time_constant() {
    if !std::env::var("MONITOR_FULL_SWEEPS").is_ok_and(|v| v == "1") {
        eprintln!("skipped: set MONITOR_FULL_SWEEPS=1");
        return;
    }
    let bad: Vec<String> = motors()
        .into_iter()
        .filter(|(n, _)| *n != "0.37 kW")
        .collect::<Vec<_>>()
        .par_iter()
        .filter_map(|(name, p)| warming_fails(name, p, 1000.0, 3600.0, 100.0, 1800.0))
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Not commissioned (issue 40): the lamps' thresholds and the isolation stand against the
/// parameter file's nominal machine, so a winding 60 K warmer than the file (Rs and Rr
/// +24 %) lights them. That is no FAULT: the verdict is "could not judge", saying the
/// change is within what a nameplate's file and heating explain, and asking for
/// commissioning; the isolation's report says heating explains the change (issue 48). A
/// change that stands clear of the file's uncertainty (Rr +60 % on the cold motor) is among
/// the candidates with its size, and no other fault is named. (Before issue 48 it was named
/// `rr` and a FAULT. Against the file's nominal values, with the load an unknown input, the
/// single point is judged on the stator-voltage equations alone, where a speed reading 1-2 %
/// off moves them as Rr +60 % does; with the file's own directions uncertain, the two share
/// the probability and neither is named.)
#[test]
fn an_uncommissioned_motor_that_warms_is_not_judged_a_fault() {
    let replay = |p: &ParamFile, rise_k: f64, fault: Option<(Fault, f64, f64)>| {
        let mut sc = Scenario::steady(40.0, 2000.0);
        sc.sensors = SensorSpec::default();
        sc.seed = 7;
        if rise_k > 0.0 {
            let toml = format!("name = \"thermal_drift\"\nrise_k = {rise_k}\ntau_s = 12.0\n");
            sc.effects.push(toml::from_str(&toml).expect("effect")); // ok: test
        }
        if let Some((f, at_s, change)) = fault {
            sc.faults
                .push(monitor_sim::FaultSpec::parametric(f, at_s, change));
        }
        let opts = monitor_replay::ReplayOptions::default();
        monitor_studies::experiment::simulate_and_replay(p, p, &sc, opts, |_, _| {})
            .expect("runs") // ok: test
            .finish()
    };
    let bad: Vec<String> = motors()
        .par_iter()
        .flat_map(|(name, p)| {
            let mut bad = Vec::new();
            let warm = replay(p, 60.0, None);
            let why = monitor_words::diagnose::withheld_because(&warm, &monitor_words::FieldNames)
                .join("; ");
            eprintln!(
                "{name} warming 60 K, not commissioned: {:?}: {why}",
                warm.verdict
            );
            // Against a file never commissioned, heating that explains the change is said
            // as heating, and the verdict is never a FAULT.
            if warm.verdict == Verdict::Fault
                || !(why.contains("not commissioned") || why.contains("does not fit"))
                || !warm.isolation.heating_explains
            {
                bad.push(format!(
                    "{name} warming: {:?} ({why}), heating explains {}",
                    warm.verdict, warm.isolation.heating_explains
                ));
            }
            let faulty = replay(p, 0.0, Some((Fault::Rr, 20.0, 0.6)));
            let rr = faulty
                .candidates
                .iter()
                .find(|c| c.fault == Fault::Rr)
                .and_then(|c| c.change)
                .map(f64::from);
            eprintln!(
                "{name} Rr +60 % at 20 s, not commissioned: {:?}, named {:?} {:?}, rr among the candidates {rr:?}",
                faulty.verdict, faulty.isolation.named, faulty.isolation.named_change
            );
            let rr_named = faulty.isolation.named == Some(IsolationName::Fault(Fault::Rr));
            let rr_size = rr.is_some_and(|c| (c - 0.6).abs() <= 0.12);
            if !(rr_named || faulty.isolation.named.is_none()) || !rr_size {
                bad.push(format!(
                    "{name} Rr +60 %: {:?}, named {:?}, rr {rr:?}",
                    faulty.verdict, faulty.isolation.named
                ));
            }
            bad
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}

/// Warming while the load and the supply move (found by a probe on logs the tests did not
/// make): 80 K with a 15 s time constant from 3 s, the viscous load stepping between 0.6
/// and 1.25 of its value every 4 s from 10 s, the supply -4 % at 20 s and +3 % at 32 s,
/// 40 s at 2 kHz, commissioned 2-8 s at the first load. Every lamp lit and a name given
/// while the tracked temperature lagged used to end in `verdict: FAULT` with nothing named
/// on all three motors: the report read the friction class as the load's move, and the
/// verdict's "heating explains the lamps" did not. Now no FAULT and the rise within 15 K,
/// with the parameter file true and with it off the machine as a nameplate's would be (Rs
/// +20 %, Rr -20 %, leakages +15 %, Lm -5 %).
#[test]
fn warming_under_a_moving_load_and_supply_is_no_fault() {
    let scenario = r#"
duration_s = 40.0
sample_rate_hz = 2000.0
seed = 11
[load]
kind = "viscous"
steps = [{ t_s = 10.0, bl_scale = 0.7 }, { t_s = 14.0, bl_scale = 1.2 }, { t_s = 18.0, bl_scale = 0.9 }, { t_s = 22.0, bl_scale = 1.1 }, { t_s = 26.0, bl_scale = 0.6 }, { t_s = 30.0, bl_scale = 1.0 }, { t_s = 34.0, bl_scale = 1.25 }]
[supply]
steps = [{ t_s = 20.0, v_scale = 0.96 }, { t_s = 32.0, v_scale = 1.03 }]
[[effects]]
name = "thermal_drift"
rise_k = 80.0
tau_s = 15.0
at_s = 3.0
"#;
    let sc = Scenario::from_toml_str(scenario, "the test").expect("scenario"); // ok: test
    let off = |p: &ParamFile| {
        let mut q = *p;
        let m = &mut q.motor;
        let (lls, llr) = (m.ls_h - m.lm_h, m.lr_h - m.lm_h);
        m.rs_ohm *= 1.2;
        m.rr_ohm *= 0.8;
        m.lm_h *= 0.95;
        m.ls_h = m.lm_h + 1.15 * lls;
        m.lr_h = m.lm_h + 1.15 * llr;
        q
    };
    // The rise at the end of the log since the window's start (no rise before 3 s).
    let true_rise = 80.0 * (1.0 - (-(40.0 - 3.0) / 15.0f64).exp());
    let cases: Vec<(String, ParamFile, ParamFile)> = motors()
        .into_iter()
        .flat_map(|(name, p)| {
            [
                (format!("{name}, file true"), p, p),
                (format!("{name}, file off"), p, off(&p)),
            ]
        })
        .collect();
    let bad: Vec<String> = cases
        .par_iter()
        .filter_map(|(name, truth, file)| {
            let opts = monitor_replay::ReplayOptions {
                commission: Some(monitor_replay::CommissionWindow::of(2.0, 8.0)),
                ..Default::default()
            };
            let r =
                monitor_studies::experiment::simulate_and_replay(truth, file, &sc, opts, |_, _| {})
                    .expect("runs") // ok: test
                    .finish();
            let rise = r.isolation.winding_rise_k.map(f64::from);
            eprintln!(
                "{name}: {:?}, named {:?}, rise {rise:?} K (true {true_rise:.1} K)",
                r.verdict, r.isolation.named
            );
            let rise_ok = rise.is_some_and(|k| (k - true_rise).abs() <= 15.0);
            (r.verdict == Verdict::Fault || r.isolation.named.is_some() || !rise_ok).then(|| {
                format!(
                    "{name}: {:?}, named {:?}, rise {rise:?} (true {true_rise:.1})",
                    r.verdict, r.isolation.named
                )
            })
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
}
