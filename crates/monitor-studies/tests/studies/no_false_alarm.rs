//! No false alarm: after commissioning, 85 simulated seconds of healthy running (of which at
//! least 60 s quasi-steady and evaluated) with load steps, +-5 % supply steps and sensor
//! noise light no lamp. The profile is `sim_host::service` (commissioned over its first
//! cycle of steps, because to the paper's model a load change is a Bl change).

use monitor_core::Fault;
use monitor_io::params::ParamFile;
use monitor_sim::FaultSpec;
use monitor_studies::service_profile::{watch, watch_mismatched};

#[test]
fn sixty_seconds_of_healthy_service_light_no_lamp() {
    for (params, seed) in [
        (ParamFile::reference_3hp(), 7),
        (ParamFile::reference_2p2kw(), 11),
    ] {
        let w = watch(&params, seed, 115.0, None).expect("run");
        assert!(
            w.evaluated_s >= 60.0,
            "only {:.1} s were evaluated",
            w.evaluated_s
        );
        assert_eq!(
            w.alarm_samples, 0,
            "false alarm on the {} Hz motor at {:?} s, calibration {:?}",
            params.supply.f_hz, w.first_alarm_s, w.calibration
        );
        // Nor does the isolation name a fault (the friction class is a load change).
        let false_names: Vec<_> = w
            .isolation_names
            .iter()
            .filter(|g| g.name.name() != "b/bl")
            .collect();
        assert!(
            false_names.is_empty(),
            "{} Hz motor: {false_names:?}",
            params.supply.f_hz
        );
    }
}

#[test]
fn the_same_service_with_a_fault_does_light_a_lamp() {
    // Guards against bands so wide that nothing could ever light: the learned thresholds
    // still catch real faults under the same load and supply steps.
    for (params, seed) in [
        (ParamFile::reference_3hp(), 7),
        (ParamFile::reference_2p2kw(), 11),
    ] {
        for (kind, change) in [(Fault::Rr, 0.5), (Fault::Ls, 0.5), (Fault::Lr, -0.5)] {
            let fault = FaultSpec::parametric(kind, 50.0, change);
            let w = watch(&params, seed, 70.0, Some(fault)).expect("run");
            let first = w.first_alarm_s.unwrap_or(f64::NAN);
            assert!(
                first > 50.0 && first < 55.0,
                "{kind:?} {change} on the {} Hz motor: first alarm {first}",
                params.supply.f_hz
            );
        }
    }
}

/// The same healthy service with the monitor told parameters 15-25 % off (as from a
/// nameplate): commissioning learns the baselines where the machine runs, and the
/// isolation names no fault while the load and the supply step (the friction class aside,
/// which a load change is to the paper's model).
#[test]
fn healthy_service_with_parameters_off_names_no_fault() {
    for (truth, seed) in [
        (ParamFile::reference_3hp(), 7),
        (ParamFile::reference_2p2kw(), 11),
    ] {
        let mut nominal = truth;
        nominal.motor.rs_ohm *= 1.2;
        nominal.motor.rr_ohm *= 0.8;
        nominal.motor.lm_h *= 0.85;
        nominal.motor.ls_h = nominal.motor.lm_h + 1.25 * (truth.motor.ls_h - truth.motor.lm_h);
        nominal.motor.lr_h = nominal.motor.lm_h + 0.8 * (truth.motor.lr_h - truth.motor.lm_h);
        let w = watch_mismatched(&truth, &nominal, seed, 115.0, None).expect("run");
        let false_names: Vec<_> = w
            .isolation_names
            .iter()
            .filter(|g| g.name.name() != "b/bl")
            .collect();
        eprintln!(
            "{} Hz motor: names {:?}, lamp samples {}, evaluated {:.1} s, commissioned {}",
            truth.supply.f_hz,
            w.isolation_names,
            w.alarm_samples,
            w.evaluated_s,
            w.calibration.is_some()
        );
        assert!(w.evaluated_s >= 60.0 && w.calibration.is_some(), "{w:?}");
        assert!(
            false_names.is_empty(),
            "{} Hz motor: {false_names:?}",
            truth.supply.f_hz
        );
        // The same run with Rr +50 % from 50 s: the lamps catch it, and the isolation
        // names no wrong fault. Measured: the lamps light at 51.2 s (3 hp); the isolation
        // names nothing. Before the misfit was widened away from the learned point
        // (`monitor_core::isolation`, "Away from the learned point"), `speed_sensor` was
        // named first, 1.3 s after the fault, for about 5 s before `rr`: Rr and a speed
        // reading move the circuit alike through ws / Rr, and with the parameters off and
        // the load moving, the torque balance that separates them is off too, which the
        // isolation now allows for (it says it cannot tell instead).
        let fault = FaultSpec::parametric(Fault::Rr, 50.0, 0.5);
        let w = watch_mismatched(&truth, &nominal, seed, 115.0, Some(fault)).expect("run");
        eprintln!(
            "  with Rr +50 %: names {:?}, first lamp {:?} s",
            w.isolation_names, w.first_alarm_s
        );
        assert!(
            w.first_alarm_s.is_some_and(|t| t > 50.0 && t < 55.0),
            "{w:?}"
        );
        assert!(
            w.isolation_names
                .iter()
                .all(|g| g.name.name() == "rr" || g.name.name() == "b/bl"),
            "{w:?}"
        );
    }
}
