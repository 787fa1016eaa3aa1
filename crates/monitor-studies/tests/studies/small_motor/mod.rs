//! The three motors of `monitor_testkit::small_motor` (re-exported), and the replay of a
//! scenario whose windings warm (the studies' `simulate_and_replay`, above the testkit).

pub use monitor_testkit::small_motor::*;

use monitor_io::params::ParamFile;

/// Replays `sc` on `p` commissioned cold over 1.5-3.5 s, its windings warming from 4 s by
/// `rise_k` with the thermal time constant `tau_s` (the simulator's `thermal_drift`; no
/// warming for a rise of 0), with `fault` (kind, time [s], relative change) on top.
#[allow(dead_code)] // (not every test of the three motors warms them)
pub fn replay_warming(
    p: &ParamFile,
    sc: monitor_sim::Scenario,
    (rise_k, tau_s): (f64, f64),
    fault: Option<(monitor_core::Fault, f64, f64)>,
) -> monitor_replay::DiagnoseReport {
    replay_warming_from(p, sc, (rise_k, tau_s, 4.0), fault, (1.5, 3.5))
}

/// [`replay_warming`] with the warming from `at_s` and commissioned over `commission`.
#[allow(dead_code)] // (not every test of the three motors warms them)
pub fn replay_warming_from(
    p: &ParamFile,
    mut sc: monitor_sim::Scenario,
    (rise_k, tau_s, at_s): (f64, f64, f64),
    fault: Option<(monitor_core::Fault, f64, f64)>,
    commission: (f64, f64),
) -> monitor_replay::DiagnoseReport {
    use monitor_sim::{EffectSpec, FaultSpec};
    if rise_k > 0.0 {
        let toml = format!(
            "name = \"thermal_drift\"\nrise_k = {rise_k}\ntau_s = {tau_s}\nat_s = {at_s}\n"
        );
        sc.effects
            .push(toml::from_str::<EffectSpec>(&toml).expect("effect"));
    }
    if let Some((f, at_s, change)) = fault {
        sc.faults.push(FaultSpec::parametric(f, at_s, change));
    }
    let opts = monitor_replay::ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(
            commission.0,
            commission.1,
        )),
        ..Default::default()
    };
    monitor_studies::experiment::simulate_and_replay(p, p, &sc, opts, |_, _| {})
        .expect("runs")
        .finish()
}
