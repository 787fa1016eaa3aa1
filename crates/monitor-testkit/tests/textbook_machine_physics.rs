//! The textbook machine of `sim-host/tests/ladder_matrix.rs` (this crate's
//! `textbook_machine`) checked against physics, so that the ladder's bars rest on a model that can be trusted:
//! * its steady state at rated slip equals the T-equivalent circuit's (analytic) torque
//!   and current, on each of the three machines;
//! * energy balance over a direct-on-line start with every hidden effect on (and with
//!   none): electrical input = copper losses + mechanical losses and output + the change
//!   of stored magnetic and kinetic energy.
#![allow(missing_docs)]

use monitor_testkit::textbook_machine;
use textbook_machine::{equivalent_circuit, Hidden, Load, Machine, Model, Scenario};

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
        };
        let torque = Load::Torque {
            t0: 0.3 * m.rated_nm,
            steps: vec![(0.8, 0.8 * m.rated_nm)],
        };
        for (what, hidden, load) in [
            ("no effect", Hidden::default(), Load::Viscous(m.bl)),
            ("every effect", every, torque),
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
