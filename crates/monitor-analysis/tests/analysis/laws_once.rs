//! Physics once (issue 85): the simulator injects and the analysis fits the same law. For
//! the library's closed-form laws (windage, dry friction) and a user's law of time, speed
//! and the shaft's angle, the load torque the simulator's machine puts on its shaft
//! (`monitor_sim::machine::Machine::load_torque`) and the one the analysis' model writes
//! into its torque balance (the effect's contribution, `ModelTerms::shaft`) are the same
//! number at the same time, speed and angle.
#![allow(missing_docs)]

use monitor_analysis::effects::{CoulombFriction, EffectModel, LawEffect, Windage};
use monitor_analysis::prep::Prepared;
use monitor_analysis::simplified_model::{MachineConstants, ModelTerms};
use monitor_io::params::ParamFile;
use monitor_laws::{BoundLaw, LawFile};
use monitor_sim::machine::{LoadLaw, Machine};
use std::sync::Arc;

/// The simulator's machine of the 2.2 kW file with the load law `load` and the users' load
/// laws `laws`.
fn machine(load: LoadLaw, laws: Vec<BoundLaw>) -> Machine {
    let p = ParamFile::reference_2p2kw();
    let m = p.motor.model::<f64>();
    let mut machine = Machine::new(
        m.rs_ohm,
        None,
        m.lls_h(),
        m.llr_h(),
        m.rr_ohm,
        m.lm_h,
        None,
        None,
        m.np(),
        m.j_kgm2,
        0.0,
        load,
    )
    .expect("the reference machine");
    machine.load_laws = Arc::from(laws);
    machine
}

fn no_load() -> LoadLaw {
    LoadLaw {
        bl_nms: 0.0,
        torque_nm: 0.0,
        coulomb_nm: 0.0,
        inv_w0: 1.0,
        windage: 0.0,
    }
}

/// A log's working series of `n` samples at 1 kHz turning at `w` [rad/s, mechanical].
fn series(n: usize, w: f64, np: f64) -> Prepared {
    let mut d = Prepared {
        t_s: (0..n).map(|k| k as f64 * 1e-3).collect(),
        dt_s: 1e-3,
        omega_r: vec![np * w; n],
        ..Default::default()
    };
    d.channels.voltages = true;
    d.channels.speed = true;
    d
}

/// The analysis' extra shaft torque of `effect` at `values` on `d`, at sample `k` and speed
/// `w`.
fn analysis_torque(
    effect: &dyn EffectModel,
    values: &[f64],
    d: &Prepared,
    k: usize,
    w: f64,
) -> f64 {
    let n = MachineConstants::from_params(&ParamFile::reference_2p2kw());
    let s = effect.setup(d, &n).expect("set up");
    let mut t = ModelTerms::default();
    s.contribute(values, d, &n, &mut t).expect("contribute");
    t.shaft.extra_nm(k, w)
}

#[test]
fn the_simulator_and_the_analysis_evaluate_one_definition_of_each_law() {
    let np = 2.0;
    let d = series(2000, 150.0, np);
    for w in [-80.0, 0.3, 151.0] {
        let sim = machine(
            LoadLaw {
                windage: 7.3e-4,
                ..no_load()
            },
            vec![],
        );
        let a = analysis_torque(&Windage, &[7.3e-4], &d, 10, w);
        assert_eq!(sim.load_torque(0.0, w, 0.0), a, "windage at {w} rad/s");
        // Dry friction: the analysis' over 1 rad/s is the simulator's default.
        let sim = machine(
            LoadLaw {
                coulomb_nm: 2.2,
                inv_w0: 1.0,
                ..no_load()
            },
            vec![],
        );
        let a = analysis_torque(&CoulombFriction, &[2.2], &d, 10, w);
        assert_eq!(sim.load_torque(0.0, w, 0.0), a, "dry friction at {w} rad/s");
    }
    // A user's compressor: t0 + a sin(theta + phi), theta integrated from the speed.
    let f = LawFile::parse(
        "[[law]]\nname = \"compressor\"\nacts_on = \"load_torque\"\nexpr = \"t0 + a * sin(theta + phi) + c * t\"\n[law.parameters]\nt0 = { start = 5.0, low = 0.0, high = 40.0 }\na = { start = 2.0, low = 0.0, high = 20.0 }\nphi = { start = 0.5, low = -4.0, high = 4.0 }\nc = { start = 0.1, low = -1.0, high = 1.0 }\n",
        std::path::Path::new("laws.toml"),
    )
    .expect("the law");
    let law = Arc::clone(&f.laws[0]);
    let values = [9.5, 3.6, 0.9, 0.2];
    let sim = machine(
        no_load(),
        vec![BoundLaw {
            law: Arc::clone(&law),
            values: values.to_vec(),
        }],
    );
    let e = LawEffect::new(law);
    for k in [0usize, 1, 777, 1999] {
        let t = k as f64 * 1e-3;
        let theta = 150.0 * t;
        let a = analysis_torque(&e, &values, &d, k, 151.0);
        let s = sim.load_torque(t, 151.0, theta);
        assert!(
            (a - s).abs() <= 1e-9 * s.abs(),
            "sample {k}: analysis {a}, simulator {s}"
        );
    }
}
