//! Faults and physical effects against the physics they stand for: the analytic steady state
//! of the changed machine, the thermal law, the saturation law, symmetrical components of
//! the supply, torque balances of the friction laws.

use monitor_core::{EffectKind, Fault};
use monitor_io::params::ParamFile;
use monitor_sim::{
    self as sim, EffectSpec, FaultSpec, LoadKind, Scenario, SensorSpec, SteadyLoad, Truth,
};

fn run(p: &ParamFile, sc: &Scenario) -> Vec<Truth> {
    let mut v = Vec::new();
    sim::simulate_with_truth(p, sc, |_, t| v.push(*t)).unwrap();
    v
}

/// RMS of the terminal phase currents over the last `n` truths.
fn i_rms(tr: &[Truth], n: usize) -> f64 {
    let s = &tr[tr.len() - n..];
    (s.iter()
        .map(|t| t.i_abc.iter().map(|i| i * i).sum::<f64>() / 3.0)
        .sum::<f64>()
        / n as f64)
        .sqrt()
}

fn mean(tr: &[Truth], n: usize, f: impl Fn(&Truth) -> f64) -> f64 {
    tr[tr.len() - n..].iter().map(f).sum::<f64>() / n as f64
}

/// A parametric fault ends in the analytic steady state of the changed machine.
fn fault_steady(p: &ParamFile, kind: Fault, change: f64, changed: ParamFile, rate: f64) {
    let mut sc = Scenario::steady(4.0, rate);
    sc.faults.push(FaultSpec::parametric(kind, 1.5, change));
    let tr = run(p, &sc);
    let n = (10.0 * rate / p.supply.f_hz).round() as usize;
    let st = sim::solve_slip(&changed, SteadyLoad::viscous(&changed)).unwrap();
    let i = i_rms(&tr, n);
    let wm = mean(&tr, n, |t| t.wm_rad_s);
    eprintln!(
        "{kind:?}{change:+}: I {i:.5} vs {:.5}; wm {wm:.4} vs {:.4}",
        st.i_phase_rms_a, st.wm_rad_s
    );
    assert!((i / st.i_phase_rms_a - 1.0).abs() < 2e-3);
    assert!((wm - st.wm_rad_s).abs() < 2e-3 * (st.wm_rad_s * st.slip / (1.0 - st.slip)).max(0.05));
}

#[test]
fn sim_fault_rs_rr_b_bl_reach_the_changed_steady_state() {
    let p = ParamFile::reference_2p2kw();
    let mut c = p;
    c.motor.rs_ohm *= 1.5;
    fault_steady(&p, Fault::Rs, 0.5, c, 10_000.0);
    let mut c = p;
    c.motor.rr_ohm *= 0.5;
    fault_steady(&p, Fault::Rr, -0.5, c, 10_000.0);
    let mut c = p;
    c.motor.bl_nms *= 1.5;
    fault_steady(&p, Fault::Bl, 0.5, c, 10_000.0);
    let mut c = p;
    c.motor.b_nms *= 3.0;
    fault_steady(&p, Fault::B, 2.0, c, 10_000.0);
}

#[test]
fn sim_fault_ls_lr_change_leakage_inductances() {
    // 3 hp (T model): ls/lr scale the leakage, the self inductances follow.
    let p = ParamFile::reference_3hp();
    let mut c = p;
    c.motor.ls_h = p.motor.lm_h + 1.5 * p.motor.model::<f64>().lls_h();
    fault_steady(&p, Fault::Ls, 0.5, c, 12_000.0);
    let mut c = p;
    c.motor.lr_h = p.motor.lm_h + 0.5 * p.motor.model::<f64>().llr_h();
    fault_steady(&p, Fault::Lr, -0.5, c, 12_000.0);
    // 2.2 kW (Gamma model, Lls = 0): ls scales Ls = Lm, the rotor leakage is kept.
    let p = ParamFile::reference_2p2kw();
    let mut c = p;
    c.motor.lm_h *= 0.5;
    c.motor.ls_h = c.motor.lm_h;
    c.motor.lr_h = c.motor.lm_h + p.motor.model::<f64>().llr_h();
    fault_steady(&p, Fault::Ls, -0.5, c, 10_000.0);
}

#[test]
fn sim_thermal_drift_follows_the_copper_law() {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(2.0, 1000.0);
    sc.effects.push(EffectSpec::ThermalDrift {
        rise_k: Some(60.0),
        tau_s: 0.5,
        at_s: 0.2,
        r_th_k_per_w: None,
        alpha_per_k: 0.00393,
        rotor: true,
    });
    let tr = run(&p, &sc);
    for t in &tr {
        let dt = if t.t_s >= 0.2 {
            60.0 * (1.0 - (-(t.t_s - 0.2) / 0.5).exp())
        } else {
            0.0
        };
        assert!((t.rs_ohm - 3.7 * (1.0 + 0.00393 * dt)).abs() < 1e-9);
        assert!((t.rr_ohm - 2.5 * (1.0 + 0.00393 * dt)).abs() < 1e-9);
    }
    // Loss-driven: the rise approaches r_th * P_loss.
    let mut sc = Scenario::steady(3.0, 1000.0);
    sc.effects.push(EffectSpec::ThermalDrift {
        rise_k: None,
        tau_s: 0.3,
        at_s: 0.0,
        r_th_k_per_w: Some(0.2),
        alpha_per_k: 0.00393,
        rotor: true,
    });
    let tr = run(&p, &sc);
    let last = tr.last().unwrap();
    let target = 0.2 * (last.p_cu_w + last.p_fe_w);
    assert!(last.temperature_rise_k > 10.0);
    assert!((last.temperature_rise_k / target - 1.0).abs() < 0.02);
}

#[test]
fn sim_saturation_obeys_its_law_and_raises_the_no_load_current() {
    for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
        let rate = 12_000.0 * p.supply.f_hz / 60.0;
        let base = Scenario::steady(2.0, rate);
        let mut sat = base.clone();
        sat.effects
            .push(EffectSpec::with_defaults(EffectKind::Saturation));
        let tr0 = run(&p, &base);
        let tr1 = run(&p, &sat);
        let psi_sat = 1.3 * p.supply.v_phase_peak() / p.supply.omega_rad_s();
        for t in tr1.iter().step_by(97) {
            let im = [t.i_s[0] + t.i_r[0], t.i_s[1] + t.i_r[1]];
            let psi_m = t.lm_h * im[0].hypot(im[1]);
            let law = p.motor.lm_h / (1.0 + (psi_m / psi_sat).powi(6));
            assert!((t.lm_h / law - 1.0).abs() < 1e-9, "{} vs {law}", t.lm_h);
        }
        let n = 2000;
        let (i0, i1) = (i_rms(&tr0, n), i_rms(&tr1, n));
        let lm_end = tr1.last().unwrap().lm_h / p.motor.lm_h;
        eprintln!("no-load current {i0:.4} -> {i1:.4} A, Lm/Lm0 = {lm_end:.3}");
        assert!(lm_end < 0.9 && lm_end > 0.7);
        assert!(i1 > 1.05 * i0);
    }
}

#[test]
fn sim_supply_unbalance_gives_the_stated_negative_sequence() {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(0.2, 10_000.0);
    sc.effects.push(EffectSpec::SupplyUnbalance {
        fraction: 0.04,
        angle_deg: 30.0,
    });
    let rows = sim::simulate_to_vec(&p, &sc).unwrap();
    // Symmetrical components by a DFT over whole cycles of the phase voltages.
    let w = 2.0 * std::f64::consts::PI * 50.0;
    let (mut pos, mut neg) = ([0.0f64; 2], [0.0f64; 2]);
    let n = 2000;
    for r in &rows[..n] {
        let v = r.v_abc.unwrap();
        let a = (2.0 * v[0] - v[1] - v[2]) / 3.0;
        let b = (v[1] - v[2]) / 3f64.sqrt();
        let (s, c) = (w * r.t_s).sin_cos();
        // alpha + j beta = P e^{jwt} + N e^{-jwt}
        pos[0] += a * c + b * s;
        pos[1] += b * c - a * s;
        neg[0] += a * c - b * s;
        neg[1] += b * c + a * s;
    }
    let ratio = neg[0].hypot(neg[1]) / pos[0].hypot(pos[1]);
    let ang = neg[1].atan2(neg[0]).to_degrees();
    assert!((ratio - 0.04).abs() < 1e-4, "{ratio}");
    assert!((ang - 30.0).abs() < 0.1, "{ang}");
}

/// The supply's voltage harmonics: each at its order's multiple of the fundamental, turning
/// with it (7: positive sequence) or against it (5: negative), at its stated fraction and
/// phase (phase a: `k cos(n w t + phi)`); an order divisible by 3 (zero sequence) is refused
/// with its key.
#[test]
fn sim_supply_harmonics_are_in_the_sequence_of_their_order() {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(0.2, 10_000.0);
    sc.supply.harmonics = vec![
        sim::SupplyHarmonic {
            order: 5,
            fraction: 0.03,
            phase_deg: 20.0,
        },
        sim::SupplyHarmonic {
            order: 7,
            fraction: 0.02,
            phase_deg: -40.0,
        },
    ];
    let rows = sim::simulate_to_vec(&p, &sc).unwrap();
    // alpha + j beta = sum over m of C_m e^{j m w t}: C_m by a DFT over whole cycles.
    let w = 2.0 * std::f64::consts::PI * 50.0;
    let coef = |m: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        let n = 2000;
        for r in &rows[..n] {
            let v = r.v_abc.unwrap();
            let a = (2.0 * v[0] - v[1] - v[2]) / 3.0;
            let b = (v[1] - v[2]) / 3f64.sqrt();
            let (s, c) = (m * w * r.t_s).sin_cos();
            re += a * c + b * s;
            im += b * c - a * s;
        }
        (re.hypot(im) / n as f64, im.atan2(re).to_degrees())
    };
    let (v1, _) = coef(1.0);
    let (n5, a5) = coef(-5.0);
    let (p7, a7) = coef(7.0);
    let (p5, _) = coef(5.0);
    let (n7, _) = coef(-7.0);
    eprintln!("V1 {v1:.2}; 5th {n5:.3} at {a5:.2} deg (against), {p5:.4} (with); 7th {p7:.3} at {a7:.2} deg, {n7:.4}");
    assert!((n5 / v1 - 0.03).abs() < 1e-4, "5th {}", n5 / v1);
    assert!((p7 / v1 - 0.02).abs() < 1e-4, "7th {}", p7 / v1);
    assert!(
        p5 / v1 < 1e-5 && n7 / v1 < 1e-5,
        "a harmonic in the other sequence"
    );
    // Phase a's k cos(n w t + phi): the 7th's vector k e^{j(7wt + phi)}, the 5th's
    // k e^{-j(5wt + phi)}.
    assert!((a7 + 40.0).abs() < 0.2, "7th at {a7} deg");
    assert!((a5 + 20.0).abs() < 0.2, "5th at {a5} deg");

    sc.supply.harmonics[0].order = 3;
    let e = sim::simulate_to_vec(&p, &sc).unwrap_err().to_string();
    assert!(
        e.contains("supply.harmonics.order") && e.contains("zero-sequence"),
        "{e}"
    );
}

#[test]
fn sim_phase_asymmetry_unbalances_the_currents_towards_the_faulty_phase() {
    let p = ParamFile::reference_3hp();
    let mut sc = Scenario::steady(3.0, 12_000.0);
    sc.effects.push(EffectSpec::PhaseAsymmetry {
        phase: monitor_core::Phase::B,
        fraction: 0.1,
        fault_resistance_ohm: None,
    });
    let tr = run(&p, &sc);
    let n = 2000;
    let rms = |k: usize| {
        (tr[tr.len() - n..]
            .iter()
            .map(|t| t.i_abc[k].powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt()
    };
    let (a, b, c) = (rms(0), rms(1), rms(2));
    eprintln!("phase currents {a:.4} {b:.4} {c:.4}");
    assert!(
        b > a && b > c,
        "faulty phase b should carry the largest current"
    );
    assert!((b / a.max(c)) > 1.01);
}

#[test]
fn sim_friction_laws_balance_the_torque() {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(3.0, 10_000.0);
    sc.load.kind = LoadKind::Torque;
    sc.load.torque_nm = Some(5.0);
    sc.effects.push(EffectSpec::CoulombFriction {
        torque_nm: Some(1.0),
        omega0_rad_s: 1.0,
    });
    sc.effects.push(EffectSpec::Windage { k_nms2: Some(1e-4) });
    let tr = run(&p, &sc);
    let n = 2000;
    let te = mean(&tr, n, |t| t.te_nm);
    let wm = mean(&tr, n, |t| t.wm_rad_s);
    let expect = 5.0 + 1.0 * (wm / 1.0).tanh() + 1e-4 * wm * wm + p.motor.b_nms * wm;
    assert!((te - expect).abs() < 1e-3, "{te} vs {expect}");
    // And the same steady state as the circuit with that total load.
    let st = sim::solve_slip(&p, SteadyLoad::torque(&p, expect - p.motor.b_nms * wm)).unwrap();
    assert!((wm - st.wm_rad_s).abs() < 5e-3, "{wm} vs {}", st.wm_rad_s);
}

#[test]
fn sim_load_torque_effect_replaces_the_viscous_load() {
    let p = ParamFile::reference_2p2kw();
    let mut sc = Scenario::steady(3.0, 10_000.0);
    sc.effects.push(EffectSpec::LoadTorque {
        torque_nm: Some(10.0),
    });
    let tr = run(&p, &sc);
    let last = tr.last().unwrap();
    assert!((last.t_load_nm - 10.0).abs() < 1e-12);
    let st = sim::solve_slip(&p, SteadyLoad::torque(&p, 10.0)).unwrap();
    assert!((last.wm_rad_s - st.wm_rad_s).abs() < 5e-3);
}

#[test]
fn sim_every_effect_name_exists_and_changes_the_output_or_is_documented_noop() {
    let p = ParamFile::reference_2p2kw();
    let mut base = Scenario::steady(1.0, 5_000.0);
    base.sensors = SensorSpec::ideal();
    let r0 = sim::simulate_to_vec(&p, &base).unwrap();
    for kind in EffectKind::ALL {
        let name = kind.name();
        let mut sc = base.clone();
        sc.effects.push(EffectSpec::with_defaults(kind));
        let r = sim::simulate_to_vec(&p, &sc).unwrap();
        let diff = r0
            .iter()
            .zip(&r)
            .map(|(a, b)| (a.i_abc[0] - b.i_abc[0]).abs())
            .fold(0.0, f64::max);
        if kind.is_dynamics() {
            // The simulator is always full order: the dynamics effects are documented no-ops.
            assert_eq!(diff, 0.0, "{name}");
        } else {
            assert!(diff > 0.01, "{name} makes no visible difference ({diff} A)");
        }
    }
    assert_eq!(EffectKind::from_name("thermal_drfit"), None);
}
