//! Sensor chain: noise statistics, quantisation, reproducibility, encoder, sensor faults.

use monitor_core::Fault;
use monitor_core::Phase;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use monitor_sim::{self as sim, FaultSpec, Scenario, SensorFaultMode, SensorSpec};

fn pair(sensors: SensorSpec, faults: Vec<FaultSpec>, seed: u64) -> (Vec<Row>, Vec<Row>) {
    let p = ParamFile::reference_2p2kw();
    let mut ideal = Scenario::steady(1.0, 10_000.0);
    ideal.seed = seed;
    let mut real = ideal.clone();
    real.sensors = sensors;
    real.faults = faults;
    (
        sim::simulate_to_vec(&p, &ideal).unwrap(),
        sim::simulate_to_vec(&p, &real).unwrap(),
    )
}

fn mean_std(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / (n - 1.0);
    (m, v.sqrt())
}

#[test]
fn sim_sensor_noise_offset_gain_and_quantisation_statistics() {
    let spec = SensorSpec {
        v_range_v: Some(400.0),
        i_range_a: Some(40.0),
        noise_v: Some(0.8),
        noise_i: Some(0.03),
        i_offset_a: 0.05,
        v_gain_error: 0.01,
        ..SensorSpec::default()
    };
    let (ideal, real) = pair(spec, vec![], 5);
    let lsb_i = 40.0 / 2048.0;
    let lsb_v = 400.0 / 2048.0;
    let mut di = Vec::new();
    let mut dv = Vec::new();
    for (a, b) in ideal.iter().zip(&real) {
        for k in 0..3 {
            di.push(b.i_abc[k] - a.i_abc[k]);
            let va = a.v_abc.unwrap()[k];
            dv.push(b.v_abc.unwrap()[k] - 1.01 * va);
            // Every reading is a whole number of LSBs.
            let c = b.i_abc[k] / lsb_i;
            assert!((c - c.round()).abs() < 1e-6);
            let c = b.v_abc.unwrap()[k] / lsb_v;
            assert!((c - c.round()).abs() < 1e-6);
        }
    }
    let (m, s) = mean_std(&di);
    let s_expect = (0.03f64.powi(2) + lsb_i * lsb_i / 12.0).sqrt();
    assert!((m - 0.05).abs() < 3e-3, "current offset {m}");
    assert!(
        (s / s_expect - 1.0).abs() < 0.05,
        "current noise {s} vs {s_expect}"
    );
    let (m, s) = mean_std(&dv);
    let s_expect = (0.8f64.powi(2) + lsb_v * lsb_v / 12.0).sqrt();
    assert!(m.abs() < 0.05, "voltage mean error {m}");
    assert!(
        (s / s_expect - 1.0).abs() < 0.05,
        "voltage noise {s} vs {s_expect}"
    );
}

#[test]
fn sim_sensor_noise_is_reproducible_and_seeded() {
    let spec = SensorSpec::default();
    let (_, a) = pair(spec.clone(), vec![], 11);
    let (_, b) = pair(spec.clone(), vec![], 11);
    let (_, c) = pair(spec, vec![], 12);
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn sim_adc_clamps_to_range() {
    let spec = SensorSpec {
        i_range_a: Some(5.0),
        noise_i: Some(0.0),
        ..SensorSpec::default()
    };
    let (ideal, real) = pair(spec, vec![], 1);
    let max_ideal = ideal.iter().map(|r| r.i_abc[0].abs()).fold(0.0, f64::max);
    let max_real = real.iter().map(|r| r.i_abc[0]).fold(f64::MIN, f64::max);
    let min_real = real.iter().map(|r| r.i_abc[0]).fold(f64::MAX, f64::min);
    assert!(max_ideal > 10.0);
    assert!((max_real - (5.0 - 5.0 / 2048.0)).abs() < 1e-9, "{max_real}");
    assert!((min_real + 5.0).abs() < 1e-9, "{min_real}");
}

#[test]
fn sim_encoder_counts_follow_the_shaft() {
    let (ideal, _) = pair(SensorSpec::ideal(), vec![], 1);
    // Integrate the speed (trapezoid) and compare with the count: 4096 counts per rev.
    let dt = 1e-4;
    let mut theta = 0.0;
    for w in ideal.windows(2) {
        theta += 0.5 * (w[0].wm_rad_s.unwrap() + w[1].wm_rad_s.unwrap()) * dt;
        let expect = theta * 4096.0 / (2.0 * std::f64::consts::PI);
        let got = w[1].enc_count.unwrap() as f64;
        assert!(
            (got - expect).abs() < 2.0,
            "t={} {got} vs {expect}",
            w[1].t_s
        );
    }
    assert!(ideal.last().unwrap().enc_count.unwrap() > 4096 * 5);
}

#[test]
fn sim_sensor_faults_one_phase_gain_stuck_disconnected() {
    let faults = vec![
        FaultSpec {
            phase: Some(Phase::A),
            ..FaultSpec::sensor_gain(Fault::CurrentSensor, 0.5, 0.5)
        },
        FaultSpec {
            kind: Fault::VoltageSensor,
            at_s: 0.5,
            change: None,
            mode: Some(SensorFaultMode::Stuck),
            offset: None,
            phase: Some(Phase::C),
        },
        FaultSpec {
            kind: Fault::SpeedSensor,
            at_s: 0.7,
            change: None,
            mode: Some(SensorFaultMode::Disconnected),
            offset: None,
            phase: None,
        },
    ];
    let (ideal, real) = pair(SensorSpec::ideal(), faults, 1);
    let held = real[4999].v_abc.unwrap()[2];
    for (a, b) in ideal.iter().zip(&real) {
        let (ia, ra) = (a.i_abc, b.i_abc);
        if a.t_s < 0.5 - 1e-9 {
            assert_eq!(ia, ra);
        } else {
            assert!((ra[0] - 1.5 * ia[0]).abs() < 1e-12);
            assert_eq!(ra[1], ia[1]);
            assert_eq!(ra[2], ia[2]);
            assert_eq!(b.v_abc.unwrap()[2], held);
            assert_eq!(b.v_abc.unwrap()[0], a.v_abc.unwrap()[0]);
        }
        if a.t_s >= 0.7 - 1e-9 {
            assert_eq!(b.wm_rad_s, Some(0.0));
            assert_eq!(b.enc_count, real[6999].enc_count);
        }
    }
}

#[test]
fn sim_channels_can_be_dropped() {
    let spec = SensorSpec {
        voltages: false,
        speed: false,
        ..SensorSpec::ideal()
    };
    let (_, real) = pair(spec, vec![], 1);
    assert!(real
        .iter()
        .all(|r| r.v_abc.is_none() && r.wm_rad_s.is_none()));
    assert!(real.iter().all(|r| r.enc_count.is_some()));
}
