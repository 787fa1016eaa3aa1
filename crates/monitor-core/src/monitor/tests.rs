//! Tests of the per-sample monitor.

use super::*;
use crate::Fault;
use proptest::prelude::*;

use crate::testing::motor_3hp as motor;

fn monitor(src: AngleSource) -> Monitor {
    let mut cfg = MonitorConfig::new(motor(), 60.0, 220.0, 10_000.0);
    cfg.angle_source = src;
    cfg.limits.i_max = 200.0;
    match Monitor::new(cfg) {
        Ok(m) => m,
        Err(e) => panic!("{e}"), // ok: test
    }
}

/// A balanced supply and a balanced current lagging by 0.5 rad, shaft at 1750 rpm.
fn healthy(k: u32) -> Sample {
    crate::testing::steady_sample(k, 179.6)
}

#[test]
fn bad_configuration_is_rejected_when_built() {
    let good = MonitorConfig::new(motor(), 60.0, 220.0, 10_000.0);
    assert!(Monitor::new(good).is_ok());
    let mut c = good;
    c.motor.lm_h = c.motor.ls_h * 1.1;
    assert_eq!(
        Monitor::new(c).err().map(|e| e.kind()),
        Some(crate::ConfigErrorKind::MotorParameter)
    );
    let mut c = good;
    c.sample_rate_hz = 300.0;
    assert_eq!(
        Monitor::new(c).err().map(|e| e.kind()),
        Some(crate::ConfigErrorKind::SampleRate)
    );
    let mut c = good;
    c.encoder.counter_bits = 40;
    assert_eq!(
        Monitor::new(c).err().map(|e| e.kind()),
        Some(crate::ConfigErrorKind::Encoder)
    );
    let mut c = good;
    c.thresholds.hysteresis = 0.0;
    assert_eq!(
        Monitor::new(c).err().map(|e| e.kind()),
        Some(crate::ConfigErrorKind::Threshold)
    );
    let mut c = good;
    c.filter_hz = f32::NAN;
    assert_eq!(
        Monitor::new(c).err().map(|e| e.kind()),
        Some(crate::ConfigErrorKind::Filter)
    );
}

#[test]
fn nan_current_names_the_current_sensor() {
    let mut m = monitor(AngleSource::Pll);
    for k in 0..20_000 {
        m.update(&healthy(k));
    }
    // Flagged at the end of the block that held the bad reading (25 samples = 2.5 ms).
    let mut s = healthy(20_000);
    s.i_abc.b = f32::NAN;
    m.update(&s);
    let mut o = *m.output();
    for k in 20_001..20_026 {
        o = *m.update(&healthy(k));
    }
    assert!(o.sensor_fault.current && o.fault_detected);
    assert_eq!(o.top(), Some((Fault::CurrentSensor, 1.0)));
    // A disconnected phase (reads 0) breaks ia + ib + ic = 0 and is caught too.
    let mut m = monitor(AngleSource::Pll);
    let mut last = MonitorOutput::default();
    for k in 0..5_000 {
        let mut s = healthy(k);
        s.i_abc.c = 0.0;
        last = *m.update(&s);
    }
    assert!(last.sensor_fault.current);
    // And a saturated voltage ADC names the voltage sensor.
    let mut s = healthy(5_000);
    s.v_saturated = true;
    let mut m = monitor(AngleSource::Pll);
    m.update(&s);
    for k in 5_001..5_026 {
        m.update(&healthy(k));
    }
    assert_eq!(m.output().top(), Some((Fault::VoltageSensor, 1.0)));
}

/// A clipped reading (`Sample::clipped`: beyond the front end's linear range) holds its
/// block out of the filters and the residuals, as a saturated one does, but flags no sensor
/// (the synthetic machine's lamps are lit from the start: its fault candidates stay the
/// lamps' own); the same reading flagged saturated names the current sensor.
#[test]
fn a_clipped_sample_is_held_out_and_names_no_sensor() {
    let run = |mark: fn(&mut Sample)| {
        let mut m = monitor(AngleSource::RotorFluxCurrentModel);
        for k in 0..20_000 {
            m.update(&healthy(k));
        }
        let before = *m.output();
        assert!(before.evaluating && !before.sensor_fault.any());
        // One sample of the next block marked, the rest of the block healthy.
        let mut s = healthy(20_000);
        s.i_abc.a *= 1.3;
        mark(&mut s);
        m.update(&s);
        for k in 20_001..20_025 {
            m.update(&healthy(k));
        }
        let after = *m.output();
        // The next block, healthy: evaluated unless the settling time started again.
        for k in 20_025..20_050 {
            m.update(&healthy(k));
        }
        (before, after, m.output().evaluating)
    };
    let (before, after, evaluating) = run(|s| s.clipped = true);
    assert!(!after.sensor_fault.any());
    assert_eq!(after.top(), before.top());
    assert!(!matches!(after.top(), Some((Fault::CurrentSensor, _))));
    // Held out: the filters did not take the block, and the lamps wait for the settling time.
    assert_eq!(after.operating, before.operating);
    assert!(!evaluating);
    // A healthy block moves the filters (the control).
    let (before, after, evaluating) = run(|_| {});
    assert_ne!(after.operating, before.operating);
    assert!(evaluating);
    // Saturated, the same reading names the current sensor.
    let (_, after, _) = run(|s| s.i_saturated = true);
    assert!(after.sensor_fault.current);
    assert_eq!(after.top(), Some((Fault::CurrentSensor, 1.0)));
}

#[test]
fn encoder_jump_names_the_speed_sensor() {
    let mut m = monitor(AngleSource::RotorFluxCurrentModel);
    for k in 0..1000 {
        m.update(&healthy(k));
    }
    let mut s = healthy(1000);
    s.encoder_count = s.encoder_count.wrapping_add(1 << 30);
    assert!(m.update(&s).sensor_fault.speed);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn monitor_never_panics_and_stays_finite(
        vals in proptest::collection::vec(
            prop_oneof![
                Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), Just(f32::MAX),
                Just(-f32::MAX), Just(0.0f32), -1e6f32..1e6, -300f32..300.0,
            ], 6..60),
        counts in proptest::collection::vec(any::<u32>(), 1..20),
        src in prop_oneof![Just(AngleSource::RotorFluxCurrentModel), Just(AngleSource::Pll), Just(AngleSource::ZeroCrossing)],
    ) {
        let mut m = monitor(src);
        prop_assert!(m.start_commissioning(0.01).is_ok());
        let mut bad_in_block = false;
        for k in 0..3000u32 {
            let s = if k % 3 == 0 {
                let j = k as usize;
                let g = |o: usize| vals[(j + o) % vals.len()];
                Sample {
                    v_abc: Abc { a: g(0), b: g(1), c: g(2) },
                    i_abc: Abc { a: g(3), b: g(4), c: g(5) },
                    encoder_count: counts[j % counts.len()],
                    timestamp_ticks: k.wrapping_mul(100),
                    v_saturated: k % 7 == 0,
                    i_saturated: false,
                    clipped: k % 11 == 0,
                }
            } else {
                healthy(k)
            };
            let o = *m.update(&s);
            prop_assert!(o.residuals.iter().all(|r| r.is_finite() && r.abs() <= 1.0));
            prop_assert!(o.diagnosis.probabilities.iter().all(|p| p.is_finite()));
            prop_assert!(o.speed_rad_s.is_finite());
            bad_in_block |= !(s.v_abc.a.is_finite() && s.v_abc.b.is_finite() && s.v_abc.c.is_finite()
                && s.i_abc.a.is_finite() && s.i_abc.b.is_finite() && s.i_abc.c.is_finite());
            // Checked at the end of each 25-sample block.
            if k % 25 == 24 {
                if bad_in_block {
                    prop_assert!(o.sensor_fault.any() && o.top().is_some_and(|(f, _)| f.is_sensor()));
                }
                bad_in_block = false;
            }
        }
    }
}

#[test]
fn a_balanced_machine_has_no_winding_part() {
    // Balanced voltages and currents: the voltages' negative sequence is nil, and so is the
    // winding's part of the currents'.
    for src in [AngleSource::Pll, AngleSource::RotorFluxCurrentModel] {
        let mut m = monitor(src);
        let mut o = MonitorOutput::default();
        for k in 0..40_000 {
            o = *m.update(&healthy(k));
        }
        let u = o.unbalance;
        assert!(
            u.negative_sequence_ratio < 0.01 && u.winding_ratio < 0.01,
            "{src:?}: {u:?}"
        );
        assert_eq!(u.suspect_phase, None);
    }
}

/// Between two revisions only the speed moves: the rest of the output and the bands stay
/// to the bit; the revision moves once per block on a steady stream, and at a speed
/// sensor's jump and a commissioning call inside a block.
#[test]
fn only_the_speed_moves_between_revisions() {
    let mut m = monitor(AngleSource::RotorFluxCurrentModel);
    let decimation = u32::from(m.config().decimation);
    let mut seen = (m.revision(), *m.output(), m.threshold_bands());
    let mut revisions = 0u32;
    for k in 0..20 * decimation {
        let mut s = healthy(k);
        if k == 7 * decimation + 3 {
            // An encoder jump: the speed sensor is flagged on this sample.
            s.encoder_count = s.encoder_count.wrapping_add(1 << 14);
        }
        if k == 11 * decimation + 5 {
            let before = m.revision();
            assert!(m.start_commissioning(1.0).is_ok());
            assert_ne!(m.revision(), before);
        }
        let out = *m.update(&s);
        let now = (m.revision(), out, m.threshold_bands());
        if now.0 == seen.0 {
            let mut rest = now.1;
            rest.speed_rad_s = seen.1.speed_rad_s;
            assert_eq!(rest, seen.1, "sample {k}");
            assert_eq!(now.2, seen.2, "sample {k}");
        } else {
            revisions += 1;
        }
        seen = now;
    }
    // 20 block ends, the jump's two flags (out and back, inside one block), and the run's
    // start.
    assert_eq!(revisions, 23);
}
