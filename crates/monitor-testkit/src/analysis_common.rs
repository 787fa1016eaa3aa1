//! Shared scenarios of the analysis tests (`crates/monitor-analysis/tests/` and the
//! command line's, `sim-host/tests/`): generate logs with the simulator (the analysis is
//! never told what was injected). Running the analysis on them (`analyse`, `opts`) is the
//! tests' own `analysis_common` module, which re-exports this one: the testkit sits below
//! `monitor-analysis`, whose tests use it.
//!
//! # Full sweeps
//! The physics sweeps of `analysis_dynamics.rs`, `analysis_effects.rs` and
//! `rotor_asymmetry.rs` (every motor at every sample rate, every hidden-effect case, every
//! noise level and load) take minutes. By default each runs a representative subset that
//! can still fail on every kind of physics the sweep checks (each effect on one motor at
//! one rate, every motor and rate on some effect); with the environment variable
//! `MONITOR_FULL_SWEEPS=1` they run whole (`.ci/run` does, after `cargo test`):
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test -p monitor-analysis --test analysis -- analysis_dynamics:: analysis_effects:: rotor_asymmetry::
//! ```
#![allow(dead_code, missing_docs)]

use monitor_core::EffectKind;
use monitor_io::log::{Channels, Log};
use monitor_io::params::ParamFile;
use monitor_sim::{
    self as sim, EffectSpec, LoadKind, LoadSpec, LoadStep, Scenario, SensorSpec, SupplyStep,
};
use std::path::{Path, PathBuf};

/// The environment variable that turns the full sweeps on (see the module doc).
pub const FULL_SWEEPS: &str = "MONITOR_FULL_SWEEPS";

/// True when `MONITOR_FULL_SWEEPS=1`: the tests run their full sweeps.
pub fn full_sweeps() -> bool {
    std::env::var(FULL_SWEEPS).is_ok_and(|v| v == "1")
}

/// The cases of a sweep this run checks: all of `all` under `MONITOR_FULL_SWEEPS=1`, else
/// those `in_default` keeps (the representative subset); says which on stderr.
pub fn sweep<T>(
    what: &str,
    all: impl IntoIterator<Item = T>,
    in_default: impl Fn(&T) -> bool,
) -> Vec<T> {
    let all: Vec<T> = all.into_iter().collect();
    let n = all.len();
    if full_sweeps() {
        eprintln!("{what}: all {n} cases ({FULL_SWEEPS}=1)");
        return all;
    }
    let kept: Vec<T> = all.into_iter().filter(|c| in_default(c)).collect();
    eprintln!(
        "{what}: {} of {n} cases (the representative subset; {FULL_SWEEPS}=1 runs all)",
        kept.len()
    );
    kept
}

/// False, with a note on stderr, for a test that belongs to the full sweeps only (it runs
/// under `MONITOR_FULL_SWEEPS=1`).
pub fn in_this_run(test: &str) -> bool {
    let run = full_sweeps();
    if !run {
        eprintln!("{test}: part of the full sweep only ({FULL_SWEEPS}=1 runs it)");
    }
    run
}

/// Nominal parameters deliberately off: every electrical and mechanical value scaled by
/// 1 +/- `off` (alternating signs), as a user's datasheet values would be.
pub fn perturbed(p: &ParamFile, off: f64) -> ParamFile {
    let mut q = *p;
    let m = &mut q.motor;
    m.rs_ohm *= 1.0 + off;
    m.rr_ohm *= 1.0 - off;
    let lls = m.ls_h - m.lm_h;
    let llr = m.lr_h - m.lm_h;
    m.lm_h *= 1.0 + off;
    m.ls_h = m.lm_h + lls * (1.0 - off);
    m.lr_h = m.lm_h + llr * (1.0 + off);
    m.j_kgm2 *= 1.0 - off;
    m.b_nms *= 1.0 + off;
    m.bl_nms *= 1.0 - off;
    q
}

/// Sensor chain: `noise` 0 = ideal sensors, 1 = default 12-bit ADC with 0.1 % noise,
/// 2 = 3x that noise.
pub fn sensors(noise: u32) -> SensorSpec {
    match noise {
        0 => SensorSpec::ideal(),
        1 => SensorSpec::default(),
        _ => SensorSpec::default(), // noise set below per motor
    }
}

pub fn motor(which: &str) -> ParamFile {
    match which {
        "3hp" => ParamFile::reference_3hp(),
        _ => ParamFile::reference_2p2kw(),
    }
}

/// Rated torque of the reference motors [N m] (3 hp: 2238 W at about 1750 rpm; 2.2 kW:
/// the reference scenario's load, `examples/scenarios/reference_2p2kw.toml`).
pub fn rated_nm(which: &str) -> f64 {
    if which == "3hp" {
        12.2
    } else {
        14.6
    }
}

/// A direct-on-line start at no load, `load` times the rated torque ([`rated_nm`])
/// switched on at the settle time ([`settle_s`]), logged at `rate_hz` for `duration_s`.
pub fn loaded_start(which: &str, load: f64, duration_s: f64, rate_hz: f64) -> Scenario {
    let mut s = Scenario::steady(duration_s, rate_hz);
    s.load = LoadSpec {
        kind: LoadKind::Torque,
        torque_nm: Some(0.0),
        bl_nms: None,
        steps: vec![LoadStep {
            t_s: settle_s(which),
            torque_nm: Some(load * rated_nm(which)),
            bl_scale: None,
        }],
    };
    s
}

/// Time for the direct-on-line start to settle [s] (analyses start here).
pub fn settle_s(which: &str) -> f64 {
    match which {
        "3hp" => 2.0,
        _ => 1.2,
    }
}

/// The scenario a test engineer would run to excite `effect` (None = effect-free).
pub fn scenario(which: &str, effect: Option<&str>, noise: u32) -> Scenario {
    let p = motor(which);
    let mut s = Scenario::steady(6.0, 4000.0);
    s.sensors = sensors(noise);
    if noise >= 2 {
        let vr = (1.25 * p.supply.v_phase_peak() / 50.0).ceil() * 50.0;
        s.sensors.noise_v = Some(3.0 * 0.001 * vr);
        // current range as the simulator's default is analytic; take 3x 0.1 % of 40 A.
        s.sensors.noise_i = Some(if which == "3hp" { 0.15 } else { 0.06 });
    }
    let t0 = settle_s(which);
    let f0 = p.supply.f_hz;
    // Default operating scenario: the paper's viscous load, constant (a load change is a
    // `bl` fault or a torque load for the paper's model, so effect scenarios add their own).
    let Some(name) = effect else { return s };
    let mut e = EffectSpec::with_defaults(EffectKind::from_name(name).expect("library name"));
    match name {
        "saturation" => {
            // A slow supply-voltage sweep (variac-like staircase, 0.2 % steps): the flux
            // level changes, the transients stay small.
            s.duration_s = 7.0;
            s.supply.steps = ramp(
                &[
                    (t0 + 0.3, 1.0, 1.0),
                    (t0 + 1.8, 0.8, 1.0),
                    (t0 + 3.3, 1.15, 1.0),
                    (t0 + 4.3, 1.0, 1.0),
                ],
                f0,
            );
        }
        "thermal_drift" => {
            // A heat run: 100 K rise (class F insulation allows 105 K) with the simulator's
            // accelerated 3 s time constant.
            s.duration_s = 8.0;
            if let EffectSpec::ThermalDrift { rise_k, .. } = &mut e {
                *rise_k = Some(100.0);
            }
        }
        "coulomb_friction" | "windage" | "iron_loss" => {
            // A slow V/f speed sweep (variable-frequency supply, staircase of small steps).
            s.duration_s = 7.0;
            s.supply.steps = ramp(
                &[
                    (t0 + 0.3, 1.0, 1.0),
                    (t0 + 1.8, 0.3, 0.3),
                    (t0 + 3.3, 0.7, 0.7),
                    (t0 + 4.3, 1.0, 1.0),
                ],
                f0,
            );
            if name == "iron_loss" {
                // A lossy core (Rfe = 8 Xm): visible at rated load over a speed sweep.
                if let EffectSpec::IronLoss { rfe_over_xm, .. } = &mut e {
                    *rfe_over_xm = 8.0;
                }
            }
            if name == "windage" {
                if let EffectSpec::Windage { k_nms2 } = &mut e {
                    *k_nms2 = Some(if which == "3hp" { 5.0e-5 } else { 1.2e-4 });
                }
            }
            if name == "coulomb_friction" {
                if let EffectSpec::CoulombFriction { torque_nm, .. } = &mut e {
                    *torque_nm = Some(if which == "3hp" { 1.5 } else { 1.0 });
                }
            }
        }
        "supply_unbalance" => {
            // Vary the supply (variac sweep): the negative-sequence current follows the
            // negative-sequence voltage, not the load current as a winding fault's would.
            s.duration_s = 7.0;
            s.supply.steps = ramp(
                &[
                    (t0 + 0.3, 1.0, 1.0),
                    (t0 + 2.8, 0.9, 1.0),
                    (t0 + 5.5, 1.0, 1.0),
                ],
                f0,
            );
        }
        "load_torque" => {
            // The load as a torque input that changes: a torque load with steps (the
            // simulator's `load_torque` effect alone is a constant torque, which at positive
            // speed is the same equation as dry friction).
            let t = if which == "3hp" { 8.0 } else { 10.0 };
            s.load = LoadSpec {
                kind: LoadKind::Torque,
                torque_nm: Some(0.5 * t),
                bl_nms: None,
                steps: vec![
                    LoadStep {
                        t_s: t0 + 1.5,
                        torque_nm: Some(t),
                        bl_scale: None,
                    },
                    LoadStep {
                        t_s: t0 + 3.0,
                        torque_nm: Some(0.3 * t),
                        bl_scale: None,
                    },
                ],
            };
            s.effects.clear();
            return s;
        }
        "flux_dynamics" => {
            s.supply.steps = vec![
                SupplyStep {
                    t_s: t0 + 1.5,
                    v_scale: Some(0.8),
                    f_hz: None,
                },
                SupplyStep {
                    t_s: t0 + 3.0,
                    v_scale: Some(1.0),
                    f_hz: None,
                },
            ];
        }
        "current_dynamics" => {
            // Fast voltage modulation (a chopper-like +/-3 % square wave at 50 Hz) excites
            // the La dI/dt term; the rotor flux is too slow to follow it.
            let mut steps = Vec::new();
            let mut t = t0 + 0.5;
            let mut hi = true;
            while t < s.duration_s {
                steps.push(SupplyStep {
                    t_s: t,
                    v_scale: Some(if hi { 1.03 } else { 0.97 }),
                    f_hz: None,
                });
                hi = !hi;
                t += 0.01;
            }
            s.supply.steps = steps;
        }
        "rotor_asymmetry" => {
            // Two broken bars of 28 (delta 0.27, Kliman's relation) are what a user looks
            // for; the simulator's default (0.1, about one bar) leaves the 2sf ripple near
            // the noise on a 6 s log. 0.2 here, and 8 s so that the sidebands at (1 +/- 2s)f
            // are resolved well beyond the 0.125 Hz bins.
            s.duration_s = 8.0;
            if let EffectSpec::RotorAsymmetry { delta, .. } = &mut e {
                *delta = Some(0.2);
            }
        }
        _ => {}
    }
    s.effects = vec![e];
    // The ramps are laid out from the motor's settling time and may run past the end on the
    // slower motor: the steps after the end never acted, and simulate refuses them.
    let end = s.duration_s;
    s.supply.steps.retain(|st| st.t_s <= end);
    s
}

pub fn write_log(
    dir: &Path,
    name: &str,
    p: &ParamFile,
    s: &Scenario,
    current_only: bool,
) -> PathBuf {
    let rows = sim::simulate_to_vec(p, s).expect("simulate");
    let mut log = Log {
        channels: Channels {
            voltages: true,
            speed: true,
            encoder: false,
            temperature: false,
        },
        rows,
    };
    if current_only {
        log.channels = Channels {
            voltages: false,
            speed: false,
            encoder: false,
            temperature: false,
        };
        for r in &mut log.rows {
            r.v_abc = None;
            r.wm_rad_s = None;
            r.enc_count = None;
        }
    } else {
        for r in &mut log.rows {
            r.enc_count = None;
        }
    }
    let path = dir.join(format!("{name}.csv"));
    log.write(&path).expect("write log");
    path
}

pub fn write_params(dir: &Path, name: &str, p: &ParamFile) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, p.to_toml_string()).expect("write params");
    path
}

/// Where the analysis starts for an effect's scenario: after the start-up, except for the
/// dynamics effects whose scenarios are about transients.
pub fn from_for(which: &str, name: &str) -> f64 {
    match name {
        "flux_dynamics" | "current_dynamics" => settle_s(which),
        _ => settle_s(which),
    }
}

/// A staircase approximating straight lines through (t, v_scale, f_scale) points, one step
/// every 10 ms (a variac or a V/f ramp, with negligible step transients).
pub fn ramp(points: &[(f64, f64, f64)], f0: f64) -> Vec<SupplyStep> {
    let mut v = Vec::new();
    for w in points.windows(2) {
        let (t1, v1, f1) = w[0];
        let (t2, v2, f2) = w[1];
        let n = ((t2 - t1) / 0.01).round() as usize;
        for k in 0..n {
            let a = (k + 1) as f64 / n as f64;
            v.push(SupplyStep {
                t_s: t1 + a * (t2 - t1),
                v_scale: Some(v1 + a * (v2 - v1)),
                f_hz: Some(f0 * (f1 + a * (f2 - f1))),
            });
        }
    }
    v
}
