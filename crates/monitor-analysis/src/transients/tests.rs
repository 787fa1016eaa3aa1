//! The transients' rules on series written here.
use super::{settling_s, sliding_span, speed_transient, SPEED_CHANGE_MIN};
use crate::prep::Prepared;
use crate::simplified_model::MachineConstants;
use monitor_io::params::ParamFile;

/// A 2 kHz log of `secs` on a 50 Hz supply whose electrical speed runs along `w(t)`.
fn log_with_speed(secs: f64, w: impl Fn(f64) -> f64) -> Prepared {
    let dt = 5e-4;
    let len = (secs / dt) as usize;
    let t_s: Vec<f64> = (0..len).map(|k| k as f64 * dt).collect();
    let mut d = Prepared {
        omega_r: t_s.iter().map(|&t| w(t)).collect(),
        omega_s: vec![std::f64::consts::TAU * 50.0; len],
        t_s,
        dt_s: dt,
        ..Default::default()
    };
    d.channels.speed = true;
    d
}

/// A load step that slows the shaft by 4.4 % of synchronous speed (motulator's 2.2 kW
/// machine, no load to rated) within 10 ms is a transient for the flux; the same fall
/// spread over three settling times, or a fall of half the threshold at once, is not;
/// nor is a log without a speed column.
#[test]
fn a_fast_speed_change_is_a_transient_and_a_slow_one_is_not() {
    let n = MachineConstants::from_params(&ParamFile::reference_2p2kw());
    let ws = std::f64::consts::TAU * 50.0;
    let fall = 0.044 * ws;
    let step = |t: f64| ws - fall * ((t - 1.0) / 0.01).clamp(0.0, 1.0);
    assert!(speed_transient(&log_with_speed(3.0, step), &n));
    let ramp_s = 3.0 * settling_s(&n);
    let ramp = |t: f64| ws - fall * ((t - 0.5) / ramp_s).clamp(0.0, 1.0);
    assert!(!speed_transient(&log_with_speed(1.0 + ramp_s, ramp), &n));
    let small = |t: f64| ws - 0.5 * SPEED_CHANGE_MIN * ws * ((t - 1.0) / 0.01).clamp(0.0, 1.0);
    assert!(!speed_transient(&log_with_speed(3.0, small), &n));
    let mut blind = log_with_speed(3.0, step);
    blind.channels.speed = false;
    assert!(!speed_transient(&blind, &n));
}

#[test]
fn sliding_span_matches_a_direct_computation() {
    let x: Vec<f64> = (0..200)
        .map(|k| ((k * 37 % 101) as f64).sin() + 0.01 * k as f64)
        .collect();
    for w in [1, 3, 17, 250] {
        let s = sliding_span(&x, w);
        for k in 0..x.len() {
            let win = &x[(k + 1).saturating_sub(w)..=k];
            let lo = win.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = win.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mean = win.iter().sum::<f64>() / win.len() as f64;
            assert_eq!((s[k].0, s[k].1), (lo, hi), "w {w} k {k}");
            assert!((s[k].2 - mean).abs() < 1e-9, "w {w} k {k}");
        }
    }
}
