//! No false alarm: after commissioning, 85 simulated seconds of healthy running (of which at
//! least 60 s quasi-steady and evaluated) with load steps, +-5 % supply steps and sensor
//! noise light no lamp. The profile is `sim_host::service` (commissioned over its first
//! cycle of steps, because to the paper's model a load change is a Bl change).

use monitor_core::Fault;
use sim_host::params::ParamFile;
use sim_host::service_profile::watch;
use sim_host::sim::FaultSpec;

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
