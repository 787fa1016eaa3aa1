//! Per-phase sensor redundancy (issue 9): a gain error on ONE phase's current or voltage
//! sensor leaves a zero sequence in the three readings (a star without neutral has none),
//! which names the sensor's phase and its own gain error; the isolation alone sees a third
//! of it on the three-phase vector and the negative-sequence analysis would blame a winding.
//! Simulated at 5 kHz with the default 12-bit noisy sensors, both reference motors and the
//! 11 kW machine the code was not developed on; the replay is not told the phase.

use monitor_core::{Fault, Phase};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, DiagnoseReport, ReplayOptions};
use monitor_sim::{simulate_to_vec, EffectSpec, FaultSpec, Scenario, SensorSpec};
use rayon::prelude::*;

/// The parameter files: (name, file, commissioning window, fault time).
fn motors() -> Vec<(&'static str, ParamFile, (f64, f64), f64)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let eleven = ParamFile::load(&root.join("examples/params/11kw_2pole.toml")).expect("11 kW"); // ok: test
    vec![
        ("3 hp", ParamFile::reference_3hp(), (2.0, 4.0), 4.5),
        ("2.2 kW", ParamFile::reference_2p2kw(), (2.0, 4.0), 4.5),
        ("11 kW", eleven, (3.0, 5.0), 5.5),
    ]
}

fn diagnose(p: &ParamFile, sc: &Scenario, commission: Option<(f64, f64)>) -> DiagnoseReport {
    let rows = simulate_to_vec(p, sc).expect("simulate"); // ok: test
    let opts = ReplayOptions {
        commission: commission.map(|(a, b)| monitor_replay::CommissionWindow::of(a, b)),
        ..ReplayOptions::default()
    };
    diagnose_rows(p, sc.sensors.channels(), &rows, opts).expect("replay") // ok: test
}

fn scenario(at_s: f64) -> Scenario {
    let mut sc = Scenario::steady(at_s + 2.5, 5_000.0);
    sc.sensors = SensorSpec::default();
    sc
}

#[test]
fn one_phase_sensor_gain_is_named_with_its_phase_and_size() {
    let mut cases = Vec::new();
    for (name, p, window, at) in motors() {
        for (fault, phase, change) in [
            (Fault::CurrentSensor, Phase::A, 0.3),
            (Fault::CurrentSensor, Phase::B, -0.2),
            (Fault::CurrentSensor, Phase::C, 0.1),
            (Fault::VoltageSensor, Phase::A, -0.1),
            (Fault::VoltageSensor, Phase::C, 0.15),
        ] {
            cases.push((name, p, window, at, fault, phase, change));
        }
    }
    let failures: Vec<String> = cases
        .par_iter()
        .filter_map(|(name, p, window, at, fault, phase, change)| {
            let mut sc = scenario(*at);
            let mut f = FaultSpec::sensor_gain(*fault, *at, *change);
            f.phase = Some(*phase);
            sc.faults.push(f);
            let rep = diagnose(p, &sc, Some(*window));
            let top = rep.candidates.first();
            let ok = top.is_some_and(|c| {
                c.fault.name() == fault.name()
                    && c.probability >= 0.5
                    && c.phase.map(Phase::name) == Some(phase.name())
                    && c.change.is_some_and(|x| (f64::from(x) - change).abs() <= 0.2 * change.abs())
            });
            // The sensor's negative sequence is not blamed on a winding.
            let no_winding = rep.unbalance.suspect_phase.is_none();
            (!(ok && no_winding)).then(|| {
                format!(
                    "{name} {fault:?} phase {} {change:+}: candidates {:?}, winding {:?}, sensors {:?} / {:?}",
                    phase.name(),
                    rep.candidates,
                    rep.unbalance.suspect_phase,
                    rep.unbalance.current_sensor_phase,
                    rep.unbalance.voltage_sensor_phase
                )
            })
        })
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn healthy_machines_shorted_windings_and_unbalanced_supplies_blame_no_sensor() {
    let mut cases = Vec::new();
    for (name, p, _, at) in motors() {
        cases.push((name, p, at, None));
        cases.push((name, p, at, Some(Phase::B)));
    }
    let failures: Vec<String> = cases
        .par_iter()
        .filter_map(|(name, p, at, shorted)| {
            let mut sc = scenario(*at);
            sc.effects.push(EffectSpec::SupplyUnbalance {
                fraction: 0.02,
                angle_deg: 40.0,
            });
            if let Some(phase) = shorted {
                sc.effects.push(EffectSpec::PhaseAsymmetry {
                    phase: *phase,
                    fraction: 0.05,
                    fault_resistance_ohm: None,
                });
            }
            // (No commissioning: the supply's 2f ripple keeps the lamps' gate closed; the
            // sequence analysis does not need it.)
            let rep = diagnose(p, &sc, None);
            let u = &rep.unbalance;
            let sensor_blamed = u.current_sensor_phase.is_some()
                || u.voltage_sensor_phase.is_some()
                || rep.candidates.iter().any(|c| c.phase.is_some());
            let winding_right = u.suspect_phase.map(Phase::name) == shorted.map(Phase::name);
            (sensor_blamed || !winding_right).then(|| {
                format!(
                    "{name}, shorted {shorted:?}: winding {:?}, sensors {:?} / {:?}, candidates {:?}",
                    u.suspect_phase, u.current_sensor_phase, u.voltage_sensor_phase, rep.candidates
                )
            })
        })
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A current-only log at 1 kHz (the analysis' PLL then locks to the currents, which the
/// wrong sensor unbalances): the sensor's phase and size are still found, and no winding is
/// blamed for what is left of its negative sequence.
#[test]
fn current_only_1khz_names_the_sensor_not_a_winding() {
    for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let mut sc = Scenario::steady(8.0, 1_000.0);
        sc.sensors = SensorSpec::default();
        let mut f = FaultSpec::sensor_gain(Fault::CurrentSensor, 4.0, -0.15);
        f.phase = Some(Phase::C);
        sc.faults.push(f);
        let rows = simulate_to_vec(&p, &sc).expect("simulate"); // ok: test
        let currents_only = monitor_io::log::Channels {
            voltages: false,
            speed: false,
            encoder: false,
            temperature: false,
        };
        let rep =
            diagnose_rows(&p, currents_only, &rows, ReplayOptions::default()).expect("replay"); // ok: test
        let u = &rep.unbalance;
        let s = u.current_sensor_phase.as_ref().expect("the sensor found"); // ok: test
        assert_eq!(s.phase.name(), "c", "{u:?}");
        assert!((s.gain_error + 0.15).abs() <= 0.03, "{u:?}");
        assert_eq!(u.suspect_phase, None, "{u:?}");
    }
}
