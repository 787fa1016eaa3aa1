//! The motor current signature analysis on short records (issue 23): 2 s steady records at
//! 1 and 2 kHz and 8 s records at 10 kHz of the simulated 3 hp and 2.2 kW reference motors
//! with 0, 1 and 2 broken bars of a 28-bar cage. The analysis must judge them (the
//! Blackman-Harris resolution rule, `rotor_asymmetry`'s module doc), its broken-bar
//! estimate from the sidebands must be within +/- 0.5 bar of the injected count, and a
//! healthy cage must not be named (no broken bars, the spectrum contradicting any fitted
//! asymmetry). The injected count is given to the simulator as `broken_bars` and `bars`
//! (the simulator turns it into its resistance asymmetry); the analysis is told only the
//! bar count, as a user's `--rotor-bars` would.
//!
//! The records are of ideal sensors, and some of the simulator's default sensor chain
//! (12-bit ADCs, 0.1 % noise). By default the ideal 2 s records at 1 and 2 kHz of both
//! motors with 1 and 2 bars, a healthy one of each motor, one 8 s record at 10 kHz and two
//! noisy ones; with `MONITOR_FULL_SWEEPS=1` every motor, bar count and rate
//! (`analysis_common`'s module doc).

use crate::analysis_common;

use analysis_common::{analyse, loaded_start, motor, settle_s, sweep, write_log};
use monitor_analysis::rotor_asymmetry::{fit_and_spectrum_agree, mcsa, McsaReport, MIN_BINS};
use monitor_sim::{EffectSpec, Scenario, SensorSpec};

/// Bars of the cage (the simulator's broken bars are of this many, and the analysis is
/// told it).
const BARS: f64 = 28.0;

/// Every motor with 0, 1 and 2 broken bars.
const EVERY_CAGE: [(&str, f64); 6] = [
    ("3hp", 0.0),
    ("3hp", 1.0),
    ("3hp", 2.0),
    ("2p2kw", 0.0),
    ("2p2kw", 1.0),
    ("2p2kw", 2.0),
];

/// Time after the load step before the record starts [s]: the slip has settled.
const AFTER_STEP_S: f64 = 1.5;

/// A direct-on-line start, rated load switched on at the settle time, `broken` adjacent
/// broken bars of [`BARS`]; the log at `rate_hz` ends `record_s` after the slip settled.
fn scenario(which: &str, broken: f64, record_s: f64, rate_hz: f64, noisy: bool) -> Scenario {
    let duration_s = settle_s(which) + AFTER_STEP_S + record_s;
    let mut s = loaded_start(which, 1.0, duration_s, rate_hz);
    if noisy {
        s.sensors = SensorSpec::default();
    }
    if broken > 0.0 {
        s.effects = vec![EffectSpec::RotorAsymmetry {
            delta: None,
            broken_bars: Some(broken),
            bars: Some(BARS),
        }];
    }
    s
}

/// The MCSA of the last `record_s` of the log (the record a user would take of a motor in
/// steady running), told the bar count and no fitted delta.
fn record(which: &str, broken: f64, record_s: f64, rate_hz: f64, noisy: bool) -> McsaReport {
    let dir = tempfile::tempdir().unwrap();
    let p = motor(which);
    let s = scenario(which, broken, record_s, rate_hz, noisy);
    let log = write_log(dir.path(), "log", &p, &s, false);
    let a = analyse(&log, &p, s.duration_s - record_s);
    let m = mcsa(&a.data, a.constants.np, Some(BARS), None);
    eprintln!(
        "| {which} | {broken} | {record_s} s | {} kHz{} | {:.1} | {:.1} | {:.3} | {:.2} | {:.2} s | {} |",
        rate_hz / 1000.0,
        if noisy { ", noisy" } else { "" },
        m.lower_sideband_db.unwrap_or(f64::NAN),
        m.upper_sideband_db.unwrap_or(f64::NAN),
        m.torque_current_share.unwrap_or(f64::NAN),
        m.spectral_broken_bars.unwrap_or(f64::NAN),
        m.window_s.last().unwrap_or(&0.0) - m.window_s.first().unwrap_or(&0.0),
        m.cannot_judge_because.as_deref().unwrap_or("judged"),
    );
    m
}

/// Judged, and the spectral broken-bar estimate within +/- 0.5 bar of `broken`; a healthy
/// cage (`broken` 0) is not named: no fitted asymmetry agrees with its spectrum.
fn check(which: &str, broken: f64, record_s: f64, rate_hz: f64, noisy: bool) {
    let m = record(which, broken, record_s, rate_hz, noisy);
    let case = format!("{which}, {broken} bars, {record_s} s at {rate_hz} Hz, noise {noisy}");
    assert!(m.judged, "{case}: {:?}", m.cannot_judge_because);
    // The record is the whole steady stretch, and the rule's resolution holds on it.
    let (t_a, t_e) = (m.window_s[0], m.window_s[1]);
    assert!(t_e - t_a > record_s - 0.25, "{case}: {t_a}..{t_e}");
    assert!(m.resolution_hz.unwrap() <= m.resolution_needed_hz.unwrap());
    let n = m.spectral_broken_bars.unwrap();
    assert!(
        (n - broken).abs() <= 0.5,
        "{case}: {n} broken bars from the spectrum"
    );
    if broken == 0.0 {
        // Far below one bar's sidebands, and no fitted asymmetry of half a bar or more
        // agrees with it.
        assert!(m.lower_sideband_db.unwrap() < -60.0, "{case}: {m:?}");
        let half_bar = 3.0 * 0.5 / (BARS - 1.5);
        let d = m.spectral_delta.unwrap();
        assert!(!fit_and_spectrum_agree(half_bar, d), "{case}: {d}");
    } else {
        let lo = m.lower_sideband_db.unwrap();
        assert!(lo > -50.0 && lo < -15.0, "{case}: {lo}");
    }
}

#[test]
fn two_second_records_at_1_and_2_khz_are_judged_and_counted() {
    let cases = [("3hp", 1.0), ("3hp", 2.0), ("2p2kw", 1.0), ("2p2kw", 2.0)];
    for (which, broken) in sweep("2 s records", cases, |_| true) {
        for rate in [1000.0, 2000.0] {
            check(which, broken, 2.0, rate, false);
        }
    }
}

#[test]
fn two_second_records_of_healthy_motors_are_not_named() {
    for which in ["3hp", "2p2kw"] {
        for rate in sweep("healthy 2 s records", [1000.0, 2000.0], |r| {
            *r == if which == "3hp" { 1000.0 } else { 2000.0 }
        }) {
            check(which, 0.0, 2.0, rate, false);
        }
    }
}

#[test]
fn eight_second_records_at_10_khz() {
    for (which, broken) in sweep("8 s records at 10 kHz", EVERY_CAGE, |c| {
        *c == ("2p2kw", 2.0)
    }) {
        check(which, broken, 8.0, 10_000.0, false);
    }
}

#[test]
fn two_second_records_with_sensor_noise() {
    // The simulator's default sensor chain: 12-bit ADCs and 0.1 % noise.
    let default = |c: &(&str, f64)| *c == ("3hp", 1.0) || *c == ("2p2kw", 0.0);
    for (which, broken) in sweep("noisy 2 s records at 2 kHz", EVERY_CAGE, default) {
        check(which, broken, 2.0, 2000.0, true);
    }
}

#[test]
fn a_record_too_short_says_how_long_is_needed() {
    // 3 hp at rated load: 2sf about 5.4 Hz, so 5 bins need about 0.93 s; 0.6 s of record
    // is refused with the length it needs.
    let m = record("3hp", 1.0, 0.6, 2000.0, false);
    assert!(!m.judged);
    let why = m.cannot_judge_because.unwrap();
    assert!(why.contains("are needed"), "{why}");
    let fs = m.sideband_hz[1] - m.fundamental_hz.unwrap();
    assert!(
        why.contains(&format!("{:.2} s are needed", MIN_BINS / fs)),
        "{why}"
    );
}
