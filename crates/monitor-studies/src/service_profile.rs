//! A healthy service profile for false-alarm and detection-limit studies: the motor runs
//! with the paper's viscous load stepping between 0.7 and 1.15 x Bl and the supply
//! stepping +-5 %, with 12-bit noisy sensors; the monitor is commissioned over the first
//! cycle of steps (2-30 s), then watched.
//!
//! The paper's model lumps the load into `Bl omega`, so a load change is, to the model, a
//! change of Bl (`docs/design.md`): a monitor on a machine whose load varies learns the healthy
//! spread of its residuals over the load and supply range it sees in service.

use crate::experiment::{simulate_and_replay, ExperimentError};
use monitor_core::{AngleSource, ResidualForm};
use monitor_io::params::ParamFile;
use monitor_replay::{CommissionWindow, NameGiven, ReplayOptions};
use monitor_sim::{FaultSpec, LoadSpec, LoadStep, Scenario, SensorSpec, SupplyStep};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Commissioning window of the profile [s].
pub const COMMISSION: CommissionWindow = CommissionWindow::of(2.0, 30.0);

/// The healthy service scenario, `duration_s` long (steps past the end are ignored).
pub fn healthy_service(params: &ParamFile, seed: u64, duration_s: f64) -> Scenario {
    let mut sc = Scenario::steady(duration_s, 10_000.0);
    sc.seed = seed;
    sc.sensors = SensorSpec::default();
    // A commissioning cycle of load and supply steps, then a different order of the same
    // kinds of steps.
    let load = [
        (6.0, 0.7),
        (12.0, 1.15),
        (18.0, 1.0),
        (36.0, 0.8),
        (44.0, 1.1),
        (55.0, 0.75),
        (63.0, 1.0),
        (72.0, 1.15),
        (84.0, 0.9),
        (97.0, 0.7),
        (106.0, 1.0),
    ];
    let supply = [
        (9.0, 1.05),
        (15.0, 0.95),
        (24.0, 1.0),
        (40.0, 0.95),
        (50.0, 1.05),
        (60.0, 1.0),
        (68.0, 1.05),
        (78.0, 0.95),
        (90.0, 1.0),
        (101.0, 0.95),
        (110.0, 1.05),
    ];
    sc.load = LoadSpec {
        bl_nms: Some(params.motor.bl_nms),
        steps: load
            .iter()
            .filter(|(t, _)| *t < duration_s)
            .map(|(t, k)| LoadStep {
                t_s: *t,
                torque_nm: None,
                bl_scale: Some(*k),
            })
            .collect(),
        ..LoadSpec::default()
    };
    sc.supply.steps = supply
        .iter()
        .filter(|(t, _)| *t < duration_s)
        .map(|(t, v)| SupplyStep {
            t_s: *t,
            v_scale: Some(*v),
            f_hz: None,
        })
        .collect();
    sc
}

/// What a watched run saw after commissioning.
#[derive(Debug, Clone, Default)]
pub struct ServiceWatch {
    /// Samples after commissioning with a fault indication (lamp or sensor fault).
    pub alarm_samples: usize,
    /// Seconds after commissioning during which lamps were evaluated.
    pub evaluated_s: f64,
    /// First alarm time [s], if any.
    pub first_alarm_s: Option<f64>,
    /// The learned calibration.
    pub calibration: Option<monitor_core::Calibration>,
    /// Every name the fault isolation gave, with the first time [s] (`b/bl`, the friction
    /// class, is what a load change is to the paper's model; any other is a false name).
    pub isolation_names: Vec<NameGiven>,
}

/// Runs the service profile (optionally with a fault) and watches the monitor after the
/// commissioning window.
///
/// # Errors
/// Simulator errors.
pub fn watch(
    params: &ParamFile,
    seed: u64,
    duration_s: f64,
    fault: Option<FaultSpec>,
) -> Result<ServiceWatch, ExperimentError> {
    watch_mismatched(params, params, seed, duration_s, fault)
}

/// [`watch`] with the machine simulated from `truth` and the monitor told `nominal` (a
/// nameplate's parameters, some tens of per cent off).
///
/// # Errors
/// Simulator errors.
pub fn watch_mismatched(
    truth: &ParamFile,
    nominal: &ParamFile,
    seed: u64,
    duration_s: f64,
    fault: Option<FaultSpec>,
) -> Result<ServiceWatch, ExperimentError> {
    let params = nominal;
    let mut sc = healthy_service(truth, seed, duration_s);
    sc.faults.extend(fault);
    let opts = ReplayOptions {
        angle_source: AngleSource::RotorFluxCurrentModel,
        residual_form: ResidualForm::Steady,
        commission: Some(COMMISSION),
        allow_incomplete: false,
        timeline_step: const { monitor_replay::TimelineStep::of(1.0) },
        unbalance_baseline: None,
        load: monitor_replay::LoadModel::Unknown,
        ..ReplayOptions::default()
    };
    let mut w = ServiceWatch::default();
    let dt = 1.0 / sc.sample_rate_hz;
    let replay = simulate_and_replay(truth, params, &sc, opts, |row, o| {
        if row.t_s > COMMISSION.end_s() {
            if o.evaluating {
                w.evaluated_s += dt;
            }
            if o.fault_detected {
                w.alarm_samples += 1;
                w.first_alarm_s.get_or_insert(row.t_s);
            }
        }
    })?;
    w.calibration = replay.calibration();
    w.isolation_names = replay.isolation_names().to_vec();
    Ok(w)
}

/// A service log whose load moves (issue 24's service logs): the paper's viscous load
/// `Bl omega` with Bl stepped every [`MOVING_PERIOD_S`] between 0.7 and 1.3 times the
/// parameter file's (+-30 %). Over [`MOVING_COMMISSION`] the load visits 0.7, 0.85, 1.0,
/// 1.15 and 1.3 in an order drawn from `seed` (the commissioning sees the whole range);
/// afterwards every level is drawn from `seed` uniformly in 0.7..1.3, at least 0.1 from
/// the one before. The supply is the file's, the sensors the simulator's default 12-bit,
/// 0.1 %-noise ones; `rate_hz` [Hz] the log's sample rate.
pub fn moving_load(params: &ParamFile, seed: u64, duration_s: f64, rate_hz: f64) -> Scenario {
    let mut sc = Scenario::steady(duration_s, rate_hz);
    sc.seed = seed;
    sc.sensors = SensorSpec::default();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EED_10AD);
    let mut first = [0.7, 0.85, 1.0, 1.15, 1.3];
    first.shuffle(&mut rng);
    let mut steps = Vec::new();
    let mut t = MOVING_PERIOD_S;
    let mut last: f64 = 1.0;
    let mut k = 0;
    while t < duration_s {
        let level = match first.get(k) {
            Some(&l) => l,
            None => loop {
                let l = rng.gen_range(0.7..1.3);
                if (l - last).abs() >= 0.1 {
                    break l;
                }
            },
        };
        steps.push(LoadStep {
            t_s: t,
            torque_nm: None,
            bl_scale: Some(level),
        });
        last = level;
        k += 1;
        t += MOVING_PERIOD_S;
    }
    sc.load = LoadSpec {
        bl_nms: Some(params.motor.bl_nms),
        steps,
        ..LoadSpec::default()
    };
    sc
}

/// How often the load of [`moving_load`] steps [s].
pub const MOVING_PERIOD_S: f64 = 4.0;

/// The commissioning window of [`moving_load`] [s]: from the end of the start (a 37 kW
/// machine's run-up takes about a second and a half) over the five first load levels.
pub const MOVING_COMMISSION: CommissionWindow = CommissionWindow::of(2.0, 24.0);
