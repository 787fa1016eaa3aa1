//! The leftover placed on logs whose error is known: a steady 2.2 kW machine at 4 % slip
//! (shaft frequency 24 Hz on a 50 Hz supply) at 2 kHz, its "measurement" the model's
//! output plus what the model lacks plus white sensor noise.

use super::*;
use crate::prep::C64;
use monitor_io::params::ParamFile;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::TAU;

const DT: f64 = 5e-4;
const F_S: f64 = 50.0;
const SLIP: f64 = 0.04;

/// What the model lacks, as a function of time [s] and the shaft angle [rad]: added to the
/// measured I_qs [A] and to the measured omega_r [rad/s].
type Missing<'a> = dyn Fn(f64, f64) -> (f64, f64) + 'a;

/// A log of `secs` seconds whose measurement is the model's plus `missing` plus noise, and
/// the model's prediction; the speed `speed(t)` [share of synchronous].
fn log(secs: f64, speed: &dyn Fn(f64) -> f64, missing: &Missing<'_>) -> (Prepared, Prediction) {
    let n = (secs / DT) as usize;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let noise_i = Normal::new(0.0, 0.02).expect("normal");
    let noise_w = Normal::new(0.0, 0.05).expect("normal");
    let ws = TAU * F_S;
    let mut d = Prepared {
        dt_s: DT,
        channels: monitor_io::log::Channels {
            voltages: true,
            speed: true,
            ..Default::default()
        },
        block_rows: 5,
        log_rate_hz: 10_000.0,
        rows: n as u64 * 5,
        ..Default::default()
    };
    let mut p = Prediction::default();
    let mut theta_m = 0.0;
    for k in 0..n {
        let t = k as f64 * DT;
        let wr = ws * speed(t);
        if k > 0 {
            theta_m += wr / 2.0 * DT;
        }
        let (di, dw) = missing(t, theta_m);
        let iq = 5.0 + di + noise_i.sample(&mut rng);
        let id = 3.0 + noise_i.sample(&mut rng);
        let th = ws * t;
        let rot = C64::from_polar(1.0, th);
        d.t_s.push(t);
        d.theta.push(th);
        d.omega_s.push(ws);
        d.vd.push(0.0);
        d.vq.push(320.0);
        d.id.push(id);
        d.i_f.push(3.0);
        d.iq.push(iq);
        d.iq_pos.push(iq);
        d.i_ab.push(C64::new(id, iq) * rot);
        d.i0.push(0.0);
        d.v_neg.push(C64::new(0.0, 0.0));
        d.i_neg.push(C64::new(0.0, 0.0));
        d.omega_r.push(wr + dw + noise_w.sample(&mut rng));
        p.iq.push(5.0);
        p.omega_r.push(wr);
        p.i_ab.push(C64::new(id, 5.0) * rot);
    }
    (d, p)
}

fn machine() -> MachineConstants {
    MachineConstants::from_params(&ParamFile::reference_2p2kw())
}

/// The caller's figures: `error` and its `floor`, at the ladder's band.
fn measured(error: f64, noise_floor: f64) -> Measured {
    Measured {
        error,
        noise_floor,
        band: 1.12,
    }
}

fn steady(_: f64) -> f64 {
    1.0 - SLIP
}

/// The shaft frequency of the steady log [Hz].
fn f_r() -> f64 {
    (1.0 - SLIP) * F_S / 2.0
}

/// A load torque pulsing once per revolution: the q current and the speed ripple at the
/// shaft frequency. The strongest line is within 5 % of it (here within a tenth of a bin),
/// read as the shaft frequency; the error is locked to the shaft angle once per revolution,
/// and the law to try is a load torque of the angle.
#[test]
fn a_torque_pulsing_once_per_revolution_is_at_the_shaft_frequency() {
    let (d, p) = log(8.0, &steady, &|_, th| (0.3 * th.sin(), 0.4 * th.cos()));
    let l = locate(&d, &machine(), &p, measured(0.05, 0.01)).expect("a leftover");
    assert!(!l.at_floor);
    let ErrorSpectrum::Taken {
        stretches,
        resolution_hz,
        shaft_hz,
        ..
    } = l.spectrum
    else {
        panic!("no spectrum: {:?}", l.spectrum);
    };
    assert_eq!(stretches, Stretches::Steady);
    assert!((shaft_hz - f_r()).abs() < 0.01, "{shaft_hz}");
    assert!(resolution_hz <= 0.25 + 1e-9, "{resolution_hz}");
    let top = l.lines.first().expect("a line");
    assert!(
        (top.frequency_hz - f_r()).abs() < 0.05 * f_r(),
        "{top:?} against {}",
        f_r()
    );
    assert!(
        (top.frequency_hz - f_r()).abs() < 0.1 * resolution_hz,
        "{top:?}"
    );
    assert_eq!(top.reading.reading, LineReading::ShaftFrequency, "{top:?}");
    assert_eq!(top.reading.multiple, 1);
    // 0.3 A of ripple on 20 mA of noise: the line is nearly all of the error.
    assert!(top.share > 0.8, "{top:?}");
    assert_eq!(top.equation, Equation::StatorQ);
    assert!((top.amplitude - 0.3).abs() < 0.03, "{top:?}");
    let once = &l.shaft_angle[0];
    assert_eq!(once.per_revolution, 1);
    assert!(once.share > 0.8, "{:?}", l.shaft_angle);
    assert!(l.shaft_angle[1].share < 0.01, "{:?}", l.shaft_angle);
    assert_eq!(
        l.hint,
        Some(LawHint::LoadOfShaftAngle { per_revolution: 1 })
    );
}

/// Twice per revolution: the line at 2 f_r, read as the shaft frequency's second multiple.
#[test]
fn twice_per_revolution_is_the_second_multiple() {
    let (d, p) = log(8.0, &steady, &|_, th| (0.3 * (2.0 * th).sin(), 0.0));
    let l = locate(&d, &machine(), &p, measured(0.05, 0.01)).expect("a leftover");
    let top = l.lines.first().expect("a line");
    assert!(
        (top.frequency_hz - 2.0 * f_r()).abs() < 0.05 * f_r(),
        "{top:?}"
    );
    assert_eq!(top.reading.reading, LineReading::ShaftFrequency);
    assert_eq!(top.reading.multiple, 2);
    assert_eq!(
        l.hint,
        Some(LawHint::LoadOfShaftAngle { per_revolution: 2 })
    );
}

/// A control log (the model's output plus noise only): no line is claimed, nothing is
/// locked to the shaft angle, no law is hinted; the equations' shares are those of noise.
#[test]
fn a_control_log_claims_no_line() {
    let (d, p) = log(8.0, &steady, &|_, _| (0.0, 0.0));
    let l = locate(&d, &machine(), &p, measured(0.03, 0.01)).expect("a leftover");
    assert!(matches!(l.spectrum, ErrorSpectrum::Taken { .. }));
    assert!(l.lines.is_empty(), "{:?}", l.lines);
    assert!(
        l.shaft_angle.iter().all(|a| a.share < 0.01),
        "{:?}",
        l.shaft_angle
    );
    assert_eq!(l.hint, None);
}

/// Three lines at once, each read as its physics: the shaft frequency (the strongest),
/// 2 s f (a rotor asymmetry's sidebands) and twice the supply frequency (a negative
/// sequence).
#[test]
fn each_line_gets_its_reading() {
    let two_sf = 2.0 * SLIP * F_S;
    let (d, p) = log(8.0, &steady, &|t, th| {
        (
            0.3 * th.sin() + 0.15 * (TAU * two_sf * t).sin() + 0.1 * (TAU * 2.0 * F_S * t).cos(),
            0.0,
        )
    });
    let l = locate(&d, &machine(), &p, measured(0.05, 0.01)).expect("a leftover");
    let reading_at = |f: f64| {
        l.lines
            .iter()
            .find(|x| (x.frequency_hz - f).abs() < 0.02 * f)
            .map(|x| (x.reading.reading, x.reading.multiple))
    };
    assert_eq!(l.lines[0].reading.reading, LineReading::ShaftFrequency);
    assert_eq!(
        reading_at(two_sf),
        Some((LineReading::TwiceSlipFrequency, 1)),
        "{:?}",
        l.lines
    );
    assert_eq!(
        reading_at(2.0 * F_S),
        Some((LineReading::SupplyFrequency, 2)),
        "{:?}",
        l.lines
    );
}

/// An error whose size grows with the speed (a load torque of the speed the model lacks),
/// on a log whose speed steps: the envelope follows the speed, and the hint is a load
/// torque of the speed.
#[test]
fn an_error_that_grows_with_the_speed_follows_it() {
    let speed = |t: f64| 0.6 + 0.35 * (t / 2.0).floor().min(1.0);
    let (d, p) = log(4.0, &speed, &|t, _| {
        let s = 0.6 + 0.35 * (t / 2.0).floor().min(1.0);
        (2.0 * s * s, 0.0)
    });
    let l = locate(&d, &machine(), &p, measured(0.05, 0.01)).expect("a leftover");
    let sp = l
        .follows
        .iter()
        .find(|c| c.variable == OperatingVariable::Speed)
        .expect("speed");
    assert!(sp.varies && sp.follows, "{sp:?}");
    assert!(sp.r.is_some_and(|r| r > 0.9), "{sp:?}");
    let v = l
        .follows
        .iter()
        .find(|c| c.variable == OperatingVariable::Voltage)
        .expect("voltage");
    assert!(!v.varies && v.r.is_none(), "{v:?}");
    assert_eq!(l.hint, Some(LawHint::LoadOfSpeed), "{l:?}");
}

/// A load step at 2 s the model follows 0.2 s late: the error lives in the load move, in
/// the q-axis current, in a window far shorter than its share of the error.
#[test]
fn the_error_lives_where_it_was_put() {
    let (mut d, mut p) = log(4.0, &steady, &|_, _| (0.0, 0.0));
    for k in 0..d.len() {
        let t = d.t_s[k];
        if t >= 2.0 {
            d.iq[k] += 2.0;
        }
        if t >= 2.2 {
            p.iq[k] += 2.0;
        }
    }
    let l = locate(&d, &machine(), &p, measured(0.05, 0.01)).expect("a leftover");
    assert_eq!(
        l.equations[0].equation,
        Equation::StatorQ,
        "{:?}",
        l.equations
    );
    assert!(l.equations[0].share > 0.95, "{:?}", l.equations);
    let w = l.windows.first().expect("a window");
    assert_eq!(w.kind, StratumKind::LoadMove, "{:?}", l.windows);
    assert!(w.t_start_s <= 2.0 && w.t_end_s >= 2.2, "{w:?}");
    assert!(w.share > 0.9 && w.time_share < 0.2, "{w:?}");
    assert_eq!(l.in_time[0].kind, StratumKind::LoadMove, "{:?}", l.in_time);
}
