//! The simulator against the analytic steady state of the T-equivalent circuit
//! (stator current RMS, torque, slip) for both reference motors at no load and full load.

use monitor_io::params::ParamFile;
use monitor_sim::{self as sim, LoadKind, LoadStep, Scenario, SteadyLoad};

/// Runs `duration_s` with a torque load stepped to `torque_nm` at 0.3 s and returns
/// (phase current RMS, mean torque, mean slip) over the last `cycles` supply cycles.
fn run(p: &ParamFile, torque_nm: f64, duration_s: f64, rate: f64) -> (f64, f64, f64) {
    let mut sc = Scenario::steady(duration_s, rate);
    sc.load.kind = LoadKind::Torque;
    sc.load.torque_nm = Some(0.0);
    sc.load.steps.push(LoadStep {
        t_s: 0.3,
        torque_nm: Some(torque_nm),
        bl_scale: None,
    });
    let per_cycle = (rate / p.supply.f_hz).round() as usize;
    assert!((per_cycle as f64 - rate / p.supply.f_hz).abs() < 1e-9);
    let n_keep = 10 * per_cycle;
    let n_total = (duration_s * rate).round() as usize;
    let (mut sq, mut te, mut slip, mut cnt) = (0.0, 0.0, 0.0, 0usize);
    let mut k = 0usize;
    let np = p.motor.model::<f64>().np();
    sim::simulate_with_truth(p, &sc, |row, tr| {
        if k >= n_total - n_keep {
            sq += row.i_abc.iter().map(|i| i * i).sum::<f64>() / 3.0;
            te += tr.te_nm;
            slip += 1.0 - np * tr.wm_rad_s / tr.we_rad_s;
            cnt += 1;
        }
        k += 1;
    })
    .unwrap();
    let c = cnt as f64;
    ((sq / c).sqrt(), te / c, slip / c)
}

fn check(p: &ParamFile, torque_nm: f64, duration_s: f64, rate: f64) {
    let (i_rms, te, slip) = run(p, torque_nm, duration_s, rate);
    let st = sim::solve_slip(p, SteadyLoad::torque(p, torque_nm)).unwrap();
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    eprintln!(
        "T_L={torque_nm}: I sim {i_rms:.6} ana {:.6}; Te sim {te:.6} ana {:.6}; s sim {slip:.6e} ana {:.6e}",
        st.i_phase_rms_a, st.torque_nm, st.slip
    );
    // Tolerances: 0.01 % on current and torque; slip to 0.1 % (or 2e-7 absolute at no
    // load, where it is tiny and set by friction only).
    assert!(rel(i_rms, st.i_phase_rms_a) < 1e-4, "current");
    assert!(
        (te - st.torque_nm).abs() < 1e-4 * st.torque_nm.max(1.0),
        "torque"
    );
    assert!((slip - st.slip).abs() < (1e-3 * st.slip).max(2e-7), "slip");
}

#[test]
fn sim_steady_2p2kw_no_load() {
    check(&ParamFile::reference_2p2kw(), 0.0, 3.0, 10_000.0);
}

#[test]
fn sim_steady_2p2kw_full_load() {
    check(&ParamFile::reference_2p2kw(), 14.6, 3.0, 10_000.0);
}

#[test]
fn sim_steady_3hp_no_load() {
    check(&ParamFile::reference_3hp(), 0.0, 5.0, 12_000.0);
}

#[test]
fn sim_steady_3hp_full_load() {
    // 3 hp = 2237 W at about 1750 rpm: 12 N m.
    check(&ParamFile::reference_3hp(), 12.0, 5.0, 12_000.0);
}

#[test]
fn sim_steady_viscous_load_matches_paper_load() {
    // The paper's load Bl*omega: the operating point solves T_e = (B + Bl) omega_m.
    let p = ParamFile::reference_2p2kw();
    let sc = Scenario::steady(3.0, 10_000.0);
    let mut last = None;
    sim::simulate_with_truth(&p, &sc, |_, tr| last = Some(*tr)).unwrap();
    let tr = last.unwrap();
    let st = sim::solve_slip(&p, SteadyLoad::viscous(&p)).unwrap();
    assert!(
        (tr.wm_rad_s - st.wm_rad_s).abs() < 1e-3,
        "{} vs {}",
        tr.wm_rad_s,
        st.wm_rad_s
    );
    assert!((tr.te_nm - st.torque_nm).abs() < 1e-2 * st.torque_nm);
}

/// Integration accuracy on the reference scenario: the default step (100 us)
/// against a 100x finer run. The bar is motulator's 1.2e-5 A.
#[test]
fn sim_reference_accuracy_against_fine_step() {
    let p = ParamFile::reference_2p2kw();
    let sc = Scenario::reference_2p2kw();
    let coarse = sim::simulate_to_vec(&p, &sc).unwrap();
    let fine_sc = Scenario {
        max_step_s: Some(1e-6),
        ..sc.clone()
    };
    let fine = sim::simulate_to_vec(&p, &fine_sc).unwrap();
    let err = coarse
        .iter()
        .zip(&fine)
        .flat_map(|(a, b)| (0..3).map(move |k| (a.i_abc[k] - b.i_abc[k]).abs()))
        .fold(0.0, f64::max);
    eprintln!("max current error {err:.3e} A");
    assert!(err < 1.2e-5, "{err}");
}
