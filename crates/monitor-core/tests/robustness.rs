//! The monitor recovers from anything a real acquisition chain delivers: any sample rate
//! from 1 to 50 kHz, gaps in the samples, stalled or backward clocks, counter jumps and
//! stretches of garbage (NaN, inf, huge values). After the garbage the lamps are dark and
//! evaluating again within [`RECOVERY_S`], and a fault that comes later is still detected.
#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]

use core::f32::consts::TAU;
use monitor_core::monitor::decimation_for;
use monitor_core::{
    reference, Abc, CommissioningState, ConfigErrorKind, Monitor, MonitorConfig, MonitorOutput,
    Sample,
};
use proptest::prelude::*;

/// Longest time from the end of the garbage until the monitor evaluates again with dark
/// lamps [s]: the sensor-fault hold (1 s), the settling time (1 s) and the quasi-steady gate
/// (0.5 s after the last fast change) with margin.
const RECOVERY_S: f32 = 3.0;

/// A steady operating point of the 3 hp motor, sampled at `fs`: balanced 179.6 V, 10 A
/// lagging by 0.5 rad, the shaft at 1750 rpm; `gain` scales the current reading (a current
/// sensor gain fault when not 1).
struct Healthy {
    fs: f32,
    gain: f32,
    /// Added to the timestamps (a clock that stalled resumes behind real time).
    tick_offset: u32,
}

impl Healthy {
    fn at(&self, k: u64, ticks: u32) -> Sample {
        let t = (k as f64 / self.fs as f64) as f32;
        let t_mod = (k as f64 / self.fs as f64 % 1.0) as f32;
        let w = TAU * 60.0 * t_mod;
        let ph = |x: f32| [x.cos(), (x - TAU / 3.0).cos(), (x + TAU / 3.0).cos()];
        let (pv, pi) = (ph(w), ph(w - 0.5));
        let (v, i) = (179.6, 10.0 * self.gain);
        let wm = 1750.0 / 60.0 * TAU;
        Sample {
            v_abc: Abc {
                a: v * pv[0],
                b: v * pv[1],
                c: v * pv[2],
            },
            i_abc: Abc {
                a: i * pi[0],
                b: i * pi[1],
                c: i * pi[2],
            },
            encoder_count: (wm as f64 * t as f64 / TAU as f64 * 4096.0) as u32,
            timestamp_ticks: ticks,
            v_saturated: false,
            i_saturated: false,
            clipped: false,
        }
    }
}

fn config(fs: f32) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(reference::MOTOR_3HP.motor.model(), 60.0, 220.0, fs);
    cfg.limits.i_max = 200.0;
    cfg
}

/// Runs `n` healthy samples from sample `k` on; returns the last output. The speed never
/// leaves the configured range (2 x synchronous speed).
fn run(m: &mut Monitor, h: &Healthy, k: &mut u64, n: u64) -> MonitorOutput {
    let mut o = *m.output();
    for _ in 0..n {
        let ticks =
            ((*k as f64 * 1e6 / h.fs as f64).round() as u64 as u32).wrapping_add(h.tick_offset);
        o = *m.update(&h.at(*k, ticks));
        assert!(
            o.speed_rad_s.abs() <= 2.0 * TAU * 60.0,
            "speed {}",
            o.speed_rad_s
        );
        *k += 1;
    }
    o
}

/// A monitor commissioned on the healthy operating point at `fs`.
fn commissioned(fs: f32) -> (Monitor, Healthy, u64) {
    let h = Healthy {
        fs,
        gain: 1.0,
        tick_offset: 0,
    };
    let mut m = Monitor::new(config(fs)).unwrap();
    let mut k = 0;
    run(&mut m, &h, &mut k, (2.0 * fs) as u64);
    assert!(m.start_commissioning(2.0).is_ok());
    run(&mut m, &h, &mut k, (3.0 * fs) as u64);
    assert_eq!(m.output().commissioning, CommissioningState::Commissioned);
    (m, h, k)
}

/// The monitor is evaluating with dark lamps within RECOVERY_S from now, and a current
/// gain fault switched on afterwards lights a lamp within 3 s.
fn recovers_then_detects(m: &mut Monitor, h: &mut Healthy, k: &mut u64) {
    let fs = h.fs;
    let o = run(m, h, k, (RECOVERY_S * fs) as u64);
    assert!(
        o.evaluating,
        "not evaluating {RECOVERY_S} s after the garbage: {o:?}"
    );
    assert!(
        !o.lamps.iter().any(|l| *l),
        "lamps lit after recovery: {o:?}"
    );
    assert!(o.residuals.iter().all(|r| r.is_finite()));
    h.gain = 1.5;
    let o = run(m, h, k, (3.0 * fs) as u64);
    assert!(
        o.lamps.iter().any(|l| *l),
        "fault not detected after recovery: {o:?}"
    );
    h.gain = 1.0;
}

#[test]
fn every_rate_from_1_to_50_khz_is_configured_and_quiet() {
    for fs in [1000.0, 1428.6, 2000.0, 5000.0, 10_000.0, 20_000.0, 50_000.0] {
        for f in [50.0f32, 60.0] {
            let d = decimation_for(fs, f);
            assert!(fs / f32::from(d) >= 6.0 * f, "{fs} Hz, {f} Hz: {d}");
            let cfg = MonitorConfig::new(reference::MOTOR_3HP.motor.model(), f, 220.0, fs);
            assert_eq!(cfg.validate(), Ok(()), "{fs} Hz at {f} Hz");
        }
        // Healthy and commissioned: dark; a current gain fault: lit.
        let (mut m, mut h, mut k) = commissioned(fs);
        let o = run(&mut m, &h, &mut k, (2.0 * fs) as u64);
        assert!(
            o.evaluating && !o.lamps.iter().any(|l| *l),
            "{fs} Hz: {o:?}"
        );
        h.gain = 1.5;
        let o = run(&mut m, &h, &mut k, (3.0 * fs) as u64);
        assert!(o.lamps.iter().any(|l| *l), "{fs} Hz: fault not detected");
    }
    assert_eq!(decimation_for(10_000.0, 50.0), 25, "the firmware's default");
    // Below 8 samples per supply period: refused, naming the sample rate.
    let e = MonitorConfig::new(reference::MOTOR_3HP.motor.model(), 60.0, 220.0, 450.0)
        .validate()
        .unwrap_err();
    assert_eq!(
        (e.kind(), e.field()),
        (ConfigErrorKind::SampleRate, "sample_rate_hz")
    );
}

#[test]
fn a_stalled_clock_neither_freezes_the_monitor_nor_invents_a_speed() {
    // The timer stops for 10 s while the encoder counts on, then resumes from where it
    // stopped (10 s behind).
    let (mut m, mut h, mut k) = commissioned(10_000.0);
    let stall_ticks = (k as f64 * 100.0) as u32;
    for _ in 0..100_000 {
        let o = *m.update(&h.at(k, stall_ticks));
        k += 1;
        assert!(
            o.speed_rad_s.abs() <= 2.0 * TAU * 60.0,
            "speed {}",
            o.speed_rad_s
        );
    }
    assert!(m.output().timing.timing_faults > 0);
    h.tick_offset = 0u32.wrapping_sub(100_000 * 100);
    recovers_then_detects(&mut m, &mut h, &mut k);
    assert!((m.output().speed_rad_s - 1750.0 / 60.0 * TAU).abs() < 2.0);
}

#[test]
fn short_gaps_are_bridged_and_long_ones_restart() {
    let (mut m, h, mut k) = commissioned(10_000.0);
    // Every 1000th sample missing (0.1 % dropped), for 10 s: bridged, lamps dark.
    for j in 0..100_000u64 {
        let ticks = (k as f64 * 100.0) as u32;
        if j % 1000 != 999 {
            let o = *m.update(&h.at(k, ticks));
            assert!(
                !o.lamps.iter().any(|l| *l),
                "lamp after a dropped sample: {o:?}"
            );
        }
        k += 1;
    }
    let t = m.output().timing;
    assert!(t.gaps_bridged >= 90 && t.timing_faults == 0, "{t:?}");
    assert!(m.output().evaluating);
    // 10 ms missing every second (half a supply period, inside a block): bridged before
    // the first sample after the gap, so the frame is right for the rest of the block and
    // the residuals do not move. (Bridged at the block's end, the rotor-flux model took
    // the block's remaining currents in a frame behind by the gap's angle: |r| reached
    // 0.08 and the quasi-steady gate closed for 0.9 s of every second.)
    // (The synthetic operating point is no model steady state: the residuals sit at an
    // offset, and it is their movement that counts.)
    let r0 = m.output().residuals;
    let (mut evaluating, mut worst) = (0u32, 0.0f32);
    for j in 0..50_000u64 {
        if j % 10_000 >= 100 {
            let ticks = (k as f64 * 100.0) as u32;
            let o = *m.update(&h.at(k, ticks));
            evaluating += u32::from(o.evaluating);
            worst = o
                .residuals
                .iter()
                .zip(r0)
                .fold(worst, |w, (r, r0)| w.max((r - r0).abs()));
        }
        k += 1;
    }
    let o = *m.output();
    assert!(
        !o.lamps.iter().any(|l| *l) && !o.sensor_fault.any(),
        "{o:?}"
    );
    assert!(
        evaluating as f32 > 0.95 * 49_500.0 && worst < 0.01,
        "evaluating {evaluating} of 49500 samples, largest change of |r| {worst}"
    );
    // A 2 s gap: the estimators restart, the lamps hold, then the monitor evaluates.
    k += 20_000;
    let mut h = h;
    recovers_then_detects(&mut m, &mut h, &mut k);
    assert!(m.output().timing.timing_faults >= 1);
}

#[test]
fn a_burst_of_huge_currents_is_forgotten_quickly() {
    // 50 ms of 1e30 A: held out, and the rotor-flux model restarted rather than left to
    // decay from an absurd flux for seconds.
    let (mut m, mut h, mut k) = commissioned(10_000.0);
    for _ in 0..500 {
        let ticks = (k as f64 * 100.0) as u32;
        let mut s = h.at(k, ticks);
        s.i_abc.a = 1e30;
        s.i_abc.b = -1e30;
        m.update(&s);
        k += 1;
    }
    assert!(m.output().sensor_fault.current);
    recovers_then_detects(&mut m, &mut h, &mut k);
}

/// One kind of garbage for a stretch of samples.
#[derive(Debug, Clone, Copy)]
enum Garbage {
    Value(f32),
    StalledClock,
    BackwardClock,
    ClockJump(u32),
    CounterJump(u32),
}

fn garbage() -> impl Strategy<Value = Garbage> {
    prop_oneof![
        prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(-f32::INFINITY),
            Just(1e30f32),
            Just(-f32::MAX)
        ]
        .prop_map(Garbage::Value),
        Just(Garbage::StalledClock),
        Just(Garbage::BackwardClock),
        (1u32..100_000_000).prop_map(Garbage::ClockJump),
        any::<u32>().prop_map(Garbage::CounterJump),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn any_garbage_then_healthy_recovers_and_detects(
        stretches in proptest::collection::vec((garbage(), 1u64..3000), 1..4),
    ) {
        let (mut m, mut h, mut k) = commissioned(10_000.0);
        let mut clock_offset: u32 = 0;
        for (g, n) in stretches {
            let frozen = ((k as f64 * 100.0) as u32).wrapping_add(clock_offset);
            for j in 0..n {
                let mut ticks = ((k as f64 * 100.0) as u32).wrapping_add(clock_offset);
                let mut s = h.at(k, ticks);
                match g {
                    Garbage::Value(x) => {
                        s.i_abc.b = x;
                        s.v_abc.c = x;
                    }
                    Garbage::StalledClock => {
                        ticks = frozen;
                        if j + 1 == n {
                            // The clock resumes from where it stopped.
                            clock_offset = clock_offset.wrapping_sub(100 * n as u32);
                        }
                    }
                    Garbage::BackwardClock => ticks = frozen.wrapping_sub(100 * j as u32),
                    Garbage::ClockJump(d) => {
                        if j == 0 {
                            clock_offset = clock_offset.wrapping_add(d);
                        }
                        ticks = ((k as f64 * 100.0) as u32).wrapping_add(clock_offset);
                    }
                    Garbage::CounterJump(c) => s.encoder_count = s.encoder_count.wrapping_add(c),
                }
                s.timestamp_ticks = ticks;
                let o = *m.update(&s);
                prop_assert!(o.residuals.iter().all(|r| r.is_finite()));
                prop_assert!(o.speed_rad_s.is_finite());
                k += 1;
            }
        }
        // Healthy samples again; the clock keeps any offset a jump gave it.
        let fs = h.fs;
        let mut o = *m.output();
        for _ in 0..(RECOVERY_S * fs) as u64 {
            let ticks = ((k as f64 * 100.0) as u32).wrapping_add(clock_offset);
            o = *m.update(&h.at(k, ticks));
            k += 1;
        }
        prop_assert!(o.evaluating, "not evaluating after recovery: {:?}", o);
        prop_assert!(!o.lamps.iter().any(|l| *l), "lamps after recovery: {:?}", o);
        h.gain = 1.5;
        for _ in 0..(3.0 * fs) as u64 {
            let ticks = ((k as f64 * 100.0) as u32).wrapping_add(clock_offset);
            o = *m.update(&h.at(k, ticks));
            k += 1;
        }
        prop_assert!(o.lamps.iter().any(|l| *l), "fault not detected after recovery");
    }
}
