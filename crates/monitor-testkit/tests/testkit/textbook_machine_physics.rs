//! The textbook machine of `sim-host/tests/cli/ladder_matrix.rs` (this crate's
//! `textbook_machine`) checked against physics, so that the ladder's bars rest on a model that can be trusted:
//! * its steady state at rated slip equals the T-equivalent circuit's (analytic) torque
//!   and current, on each of the three machines;
//! * energy balance over a direct-on-line start with every hidden effect on (and with
//!   none): electrical input = copper losses + mechanical losses and output + the change
//!   of stored magnetic and kinetic energy; also with the rotor cage asymmetry alone;
//! * a loaded run with the rotor cage asymmetry (two broken bars of 28) shows the classic
//!   stator current sideband at `(1 - 2 s) f`, far above the healthy run's level there.
#![allow(missing_docs)]

use monitor_testkit::textbook_machine;
use std::f64::consts::PI;
use textbook_machine::{
    broken_bars_delta, equivalent_circuit, simulate, Hidden, Load, Machine, Model, Scenario,
};

fn machines() -> [Machine; 3] {
    [Machine::kw2p2(), Machine::hp3(), Machine::hp50()]
}

/// The slip at which the equivalent circuit gives the rated torque (bisection below the
/// breakdown slip, where the torque rises with slip).
fn rated_slip(m: &Machine) -> f64 {
    let (mut lo, mut hi) = (1e-5, 0.1);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if equivalent_circuit(m, mid).1 < m.rated_nm {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Runs the model on its own (no sensors) to `t_end`, returning the final state.
fn run(model: &Model<'_>, t_end: f64) -> textbook_machine::State {
    let h = model.s.step_s;
    let n = (t_end / h).round() as usize;
    let mut x = model.initial();
    for k in 0..n {
        x = model.rk4(k as f64 * h, &x, h);
    }
    x
}

#[test]
fn steady_state_at_rated_slip_matches_the_equivalent_circuit() {
    for m in machines() {
        let slip = rated_slip(&m);
        let (i_ec, te_ec) = equivalent_circuit(&m, slip);
        let mut s = Scenario::new(&m, 3.0, 1000.0);
        s.hold_speed = Some((1.0 - slip) * m.w_sync());
        s.load = Load::Viscous(0.0);
        let model = Model { m: &m, s: &s };
        let x = run(&model, 3.0);
        let p = model.point(3.0, &x);
        let i = p.is[0].hypot(p.is[1]);
        eprintln!(
            "{}: rated slip {:.4}; torque {:.4} N m (circuit {:.4}), current {:.4} A peak \
             (circuit {:.4})",
            m.name, slip, p.te, te_ec, i, i_ec
        );
        assert!(
            (p.te / te_ec - 1.0).abs() < 1e-3,
            "{}: torque {} vs {}",
            m.name,
            p.te,
            te_ec
        );
        assert!(
            (i / i_ec - 1.0).abs() < 1e-3,
            "{}: current {} vs {}",
            m.name,
            i,
            i_ec
        );
        // Rated torque at a plausible rated slip (1-6 %).
        assert!((0.005..0.06).contains(&slip), "{}: slip {slip}", m.name);
    }
}

fn energy_residual(m: &Machine, hidden: Hidden, load: Load) -> (f64, f64) {
    let mut s = Scenario::new(m, 1.5, 1000.0);
    s.hidden = hidden;
    s.load = load;
    let model = Model { m, s: &s };
    let t_end = 1.5;
    let x0 = model.initial();
    let x = run(&model, t_end);
    let (p0, p1) = (model.point(0.0, &x0), model.point(t_end, &x));
    let kinetic = |w: f64| 0.5 * m.j * w * w;
    let (e_in, e_cu, e_out) = (x[6], x[7], x[8]);
    let stored = (p1.w_mag - p0.w_mag) + kinetic(x[4]) - kinetic(x0[4]);
    (e_in - e_cu - e_out - stored, e_in)
}

#[test]
fn energy_balance_over_a_direct_on_line_start() {
    for m in machines() {
        let every = Hidden {
            thermal_drift: Some((90.0, 0.5)),
            coulomb_friction: Some(0.1 * m.rated_nm),
            windage: Some(0.1 * m.rated_nm / m.w_sync().powi(2)),
            supply_unbalance: Some(0.04),
            saturation: Some(1.2 * m.psi_rated()),
            phase_asymmetry: Some(0.4 * m.rs),
            rotor_asymmetry: Some(broken_bars_delta(2.0, 28.0)),
        };
        let rotor = Hidden {
            rotor_asymmetry: Some(broken_bars_delta(2.0, 28.0)),
            ..Hidden::default()
        };
        let torque = Load::Torque {
            t0: 0.3 * m.rated_nm,
            steps: vec![(0.8, 0.8 * m.rated_nm)],
        };
        for (what, hidden, load) in [
            ("no effect", Hidden::default(), Load::Viscous(m.bl)),
            ("every effect", every, torque),
            ("rotor asymmetry", rotor, Load::Viscous(m.bl)),
        ] {
            let (residual, e_in) = energy_residual(&m, hidden, load);
            eprintln!(
                "{} {what}: input {e_in:.1} J, residual {residual:.3e} J ({:.2e} of input)",
                m.name,
                residual / e_in
            );
            assert!(
                residual.abs() < 1e-5 * e_in,
                "{} {what}: energy residual {residual} J of {e_in} J",
                m.name
            );
        }
    }
}

/// Amplitude of `x` (sampled at `rate` Hz) at `f` Hz: a single-bin DFT with a Hann window
/// (amplitude-corrected: a sine of amplitude A at a bin centre reads A).
fn amplitude_at(x: &[f64], rate: f64, f: f64) -> f64 {
    let n = x.len() as f64;
    let (mut re, mut im, mut wsum) = (0.0, 0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * PI * k as f64 / n).cos();
        let ph = 2.0 * PI * f * k as f64 / rate;
        re += w * v * ph.cos();
        im -= w * v * ph.sin();
        wsum += w;
    }
    2.0 * re.hypot(im) / wsum
}

/// Phase a's current and the slip over 2-8 s of a rated viscous-load run of the 3 hp
/// machine, with `hidden`.
fn loaded_current(m: &Machine, hidden: Hidden) -> (Vec<f64>, f64, f64) {
    let rate = 2000.0;
    let mut s = Scenario::new(m, 8.0, rate);
    s.hidden = hidden;
    let samples = simulate(m, &s);
    let steady: Vec<_> = samples.iter().filter(|r| r.t >= 2.0).collect();
    let w_mean = steady.iter().map(|r| r.w).sum::<f64>() / steady.len() as f64;
    let slip = 1.0 - w_mean / m.w_sync();
    (steady.iter().map(|r| r.i[0]).collect(), slip, rate)
}

#[test]
fn a_broken_bar_shows_the_lower_sideband_at_one_minus_two_s_f() {
    let m = Machine::hp3();
    let delta = broken_bars_delta(2.0, 28.0);
    let (healthy, s_h, rate) = loaded_current(&m, Hidden::default());
    let faulty = Hidden {
        rotor_asymmetry: Some(delta),
        ..Hidden::default()
    };
    let (broken, s_b, _) = loaded_current(&m, faulty);
    let f = m.f_hz;
    let (f_h, f_b) = ((1.0 - 2.0 * s_h) * f, (1.0 - 2.0 * s_b) * f);
    let fund = amplitude_at(&broken, rate, f);
    let at_b = amplitude_at(&broken, rate, f_b);
    let healthy_there = amplitude_at(&healthy, rate, f_h);
    // A bin away: 1.5 Hz below the sideband (the window's resolution is 1/6 Hz).
    let away = amplitude_at(&broken, rate, f_b - 1.5);
    let db = |a: f64| 20.0 * (a / fund).log10();
    eprintln!(
        "3hp, delta {delta:.3} (2 of 28 bars): slip {s_b:.4} (healthy {s_h:.4}); fundamental \
         {fund:.2} A; (1-2s)f = {f_b:.2} Hz: {:.1} dB (healthy {:.1} dB at {f_h:.2} Hz; \
         1.5 Hz below: {:.1} dB)",
        db(at_b),
        db(healthy_there),
        db(away)
    );
    assert!(
        at_b > 30.0 * healthy_there,
        "sideband {at_b} A vs healthy {healthy_there} A"
    );
    assert!(
        at_b > 10.0 * away,
        "sideband {at_b} A vs 1.5 Hz below {away} A"
    );
    // The classic size: a few per cent of the fundamental for two broken bars
    // (-20 .. -45 dB), not a second fundamental.
    assert!(
        (-45.0..-20.0).contains(&db(at_b)),
        "sideband {:.1} dB",
        db(at_b)
    );
}
