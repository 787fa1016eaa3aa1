//! Energy balance of the simulated machine: input electrical power = copper losses + iron
//! losses + air-gap mechanical power + d/dt (stored magnetic energy), through a
//! direct-on-line start (large transients), with dW/dt by fourth-order central differences (20 kHz).

use monitor_core::{EffectKind, Phase};
use monitor_io::params::ParamFile;
use monitor_sim::{self as sim, EffectSpec, Scenario, Truth};

fn balance(p: &ParamFile, effects: Vec<EffectSpec>) -> f64 {
    let rate = 20_000.0;
    let mut sc = Scenario::steady(0.6, rate);
    sc.effects = effects;
    let mut tr: Vec<Truth> = Vec::new();
    sim::simulate_with_truth(p, &sc, |_, t| tr.push(*t)).unwrap();
    let dt = 1.0 / rate;
    let mut worst = 0.0f64;
    let mut p_max = 0.0f64;
    // Fourth-order central difference of the stored energy over windows of five samples.
    for win in tr.windows(5) {
        let w = |j: usize| win[j].stored_energy_j;
        let dw = (-w(4) + 8.0 * w(3) - 8.0 * w(1) + w(0)) / (12.0 * dt);
        let t = &win[2];
        let res = t.p_in_w - t.p_cu_w - t.p_fe_w - t.p_mech_w - dw;
        worst = worst.max(res.abs());
        p_max = p_max.max(t.p_in_w.abs());
    }
    eprintln!("worst residual {worst:.3e} W of peak input {p_max:.3e} W");
    worst / p_max
}

#[test]
fn sim_energy_balance_2p2kw() {
    assert!(balance(&ParamFile::reference_2p2kw(), vec![]) < 1e-6);
}

#[test]
fn sim_energy_balance_3hp() {
    assert!(balance(&ParamFile::reference_3hp(), vec![]) < 1e-6);
}

#[test]
fn sim_energy_balance_with_iron_loss_and_asymmetry() {
    let eff = vec![
        EffectSpec::with_defaults(EffectKind::IronLoss),
        EffectSpec::PhaseAsymmetry {
            phase: Phase::B,
            fraction: 0.08,
            fault_resistance_ohm: None,
        },
    ];
    assert!(balance(&ParamFile::reference_3hp(), eff.clone()) < 1e-6);
    assert!(balance(&ParamFile::reference_2p2kw(), eff) < 1e-6);
}
