//! The figures of `sim-host bench` (`docs/performance.md`), measured on this machine.
//!
//! - Simulator throughput on the reference scenario (2.2 kW, direct-on-line, 14.6 N m from
//!   2.5 s, 10 s at 10 kHz), in simulated seconds per wall second, in memory and with CSV
//!   writing, and its accuracy: the largest phase-current difference against a run with a
//!   100x smaller integrator step.
//! - `Monitor` (the core) time per sample on the host.
//!
//! - `bench --isolation`: the isolation's naming, sizing and timing on every Table 1 fault
//!   ([`isolation`]).
//!
//! Timings are repeated and reported as the median with the range (a shared machine's
//! other jobs show in the range, not in a best case).

pub mod isolation;

use crate::experiment::ExperimentError;
use monitor_core::{Fault, Monitor};
use monitor_io::log::{LogWriter, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{monitor_config_for_log, LogSampler, ReplayOptions};
use monitor_sim::{simulate, Scenario};
use serde::Serialize;
use std::time::Instant;

/// The median and the range of repeated measurements.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Median.
    pub median: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Spread {
    /// Of a non-empty set of values (NaN for an empty one).
    pub fn of(values: &[f64]) -> Self {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            return Spread {
                median: f64::NAN,
                min: f64::NAN,
                max: f64::NAN,
            };
        }
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        Spread {
            median,
            min: v[0],
            max: v[n - 1],
        }
    }

    /// `f` of each bound (for a monotonically decreasing `f` the bounds swap).
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let (a, b) = (f(self.min), f(self.max));
        Spread {
            median: f(self.median),
            min: a.min(b),
            max: a.max(b),
        }
    }
}

/// The measured figures.
#[derive(Debug, Serialize)]
pub struct BenchFigures {
    /// Repetitions of each timing.
    pub repeat: u32,
    /// Simulated seconds per wall second, rows kept in memory (not stored).
    pub sim_in_memory_s_per_s: Spread,
    /// Simulated seconds per wall second, writing the CSV to a temporary file.
    pub sim_with_csv_s_per_s: Spread,
    /// Max |i| difference against the 100x-finer run [A].
    pub max_current_error_a: f64,
    /// Integrator step used [s].
    pub step_s: f64,
    /// Core Monitor time per sample [ns].
    pub monitor_ns_per_sample: Spread,
    /// Rows in the reference run.
    pub rows: u64,
}

/// Runs `f` `n` times (at least once); the wall times [s] and the last result.
fn timed<T>(
    n: u32,
    mut f: impl FnMut() -> Result<T, ExperimentError>,
) -> Result<(Spread, T), ExperimentError> {
    // A warm-up run first (page faults, caches, the CPU's clock), not timed.
    let mut last = f()?;
    let mut times = Vec::new();
    for _ in 0..n.max(1) {
        let t = Instant::now();
        last = f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok((Spread::of(&times), last))
}

/// Runs the benchmarks, each timing `repeat` times after a warm-up run.
///
/// # Errors
/// Simulator or I/O errors (not expected for the reference scenario).
pub fn measure(repeat: u32) -> Result<BenchFigures, ExperimentError> {
    let params = ParamFile::reference_2p2kw();
    let sc = Scenario::reference_2p2kw();
    let (t_mem, (rows, step)) = timed(repeat, || {
        let mut n = 0u64;
        let mut acc = 0.0f64;
        let s = simulate(&params, &sc, |r: &Row| {
            n += 1;
            acc += r.i_abc[0];
        })?;
        std::hint::black_box(acc);
        Ok((n, s.step_s))
    })?;
    let t_csv = time_with_csv(repeat, &params, &sc)?;
    let (coarse, err) = step_error(&params, &sc, step)?;
    let t_mon = time_monitor(repeat, &params, &sc, &coarse)?;
    Ok(BenchFigures {
        repeat: repeat.max(1),
        sim_in_memory_s_per_s: t_mem.map(|t| sc.duration_s / t),
        sim_with_csv_s_per_s: t_csv.map(|t| sc.duration_s / t),
        max_current_error_a: err,
        step_s: step,
        monitor_ns_per_sample: t_mon,
        rows,
    })
}

/// The wall times [s] of the scenario `sc` simulated and written to a CSV file in a
/// temporary folder.
fn time_with_csv(
    repeat: u32,
    params: &ParamFile,
    sc: &Scenario,
) -> Result<Spread, ExperimentError> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("bench.csv");
    let (t_csv, ()) = timed(repeat, || {
        let mut w = LogWriter::create(&path, sc.sensors.channels())?;
        let mut err = None;
        simulate(params, sc, |r: &Row| {
            if err.is_none() {
                if let Err(e) = w.write_row(r) {
                    err = Some(e);
                }
            }
        })?;
        if let Some(e) = err {
            return Err(e.into());
        }
        w.finish()?;
        Ok(())
    })?;
    Ok(t_csv)
}

/// The rows of the scenario `sc` at the integrator step `step` [s], and their largest
/// phase-current difference [A] against a run with a 100x finer step.
fn step_error(
    params: &ParamFile,
    sc: &Scenario,
    step: f64,
) -> Result<(Vec<Row>, f64), ExperimentError> {
    let coarse = monitor_sim::simulate_to_vec(params, sc)?;
    let fine_sc = Scenario {
        max_step_s: Some(step / 100.0),
        ..sc.clone()
    };
    let fine = monitor_sim::simulate_to_vec(params, &fine_sc)?;
    let mut err = 0.0f64;
    for (a, b) in coarse.iter().zip(&fine) {
        for k in 0..3 {
            err = err.max((a.i_abc[k] - b.i_abc[k]).abs());
        }
    }
    Ok((coarse, err))
}

/// The core `Monitor`'s time per sample [ns] over the rows `rows` of the scenario `sc`.
fn time_monitor(
    repeat: u32,
    params: &ParamFile,
    sc: &Scenario,
    rows: &[Row],
) -> Result<Spread, ExperimentError> {
    let cfg = monitor_config_for_log(params, sc.sample_rate_hz, &ReplayOptions::default());
    let mut sampler = LogSampler::default();
    let samples: Vec<_> = rows.iter().map(|r| sampler.sample(r)).collect();
    let (t_mon, ()) = timed(repeat, || {
        let mut m = Monitor::new(cfg).map_err(|source| monitor_replay::ReplayError::Config {
            source,
            sample_rate_hz: sc.sample_rate_hz,
        })?;
        let mut acc = 0.0f32;
        for s in &samples {
            acc += m.update(s).residuals[0];
        }
        std::hint::black_box(acc);
        Ok(())
    })?;
    let per_sample_ns = 1e9 / samples.len().max(1) as f64;
    Ok(t_mon.map(|t| t * per_sample_ns))
}

/// Smallest detected change of one fault (the fault detection bar of `docs/performance.md`).
#[derive(Debug, Serialize)]
pub struct DetectionLimitCase {
    /// Motor.
    pub motor: String,
    /// The fault (JSON: its name).
    pub fault: Fault,
    /// Smallest relative increase detected (None: not even +90 %).
    pub smallest_increase: Option<f64>,
    /// Smallest relative decrease detected, as a positive fraction (None: not even -90 %).
    pub smallest_decrease: Option<f64>,
}

/// Bisects, per fault and sign, the smallest change that lights a lamp within 10 s of its
/// onset at 50 s in the service profile ([`crate::service_profile`]), after checking that the
/// healthy profile itself raises no alarm.
///
/// # Errors
/// [`DetectionError`]: the healthy profile alarmed, or a simulator error.
pub fn detection_limits(
    on_case: &(dyn Fn() + Sync),
) -> Result<Vec<DetectionLimitCase>, DetectionError> {
    use rayon::prelude::*;
    let motors = [
        ("3 hp", ParamFile::reference_3hp(), 7u64),
        ("2.2 kW", ParamFile::reference_2p2kw(), 11u64),
    ];
    for (name, p, seed) in &motors {
        let w = crate::service_profile::watch(p, *seed, 60.0, None)?;
        if w.alarm_samples > 0 {
            return Err(DetectionError::FalseAlarm {
                motor: name.to_string(),
                at_s: w.first_alarm_s,
            });
        }
    }
    let cases: Vec<(&str, ParamFile, u64, Fault, f64)> = motors
        .iter()
        .flat_map(|(n, p, s)| {
            Fault::ALL
                .iter()
                .flat_map(move |f| [(*n, *p, *s, *f, 1.0), (*n, *p, *s, *f, -1.0)])
        })
        .collect();
    let found: Vec<(String, Fault, f64, Option<f64>)> = cases
        .par_iter()
        .map(|(n, p, seed, f, sign)| {
            let r = smallest_detected(p, *seed, *f, *sign);
            on_case();
            (n.to_string(), *f, *sign, r)
        })
        .collect();
    let mut out = Vec::new();
    for (n, _, _) in &motors {
        for f in Fault::ALL {
            let get = |sg: f64| {
                found
                    .iter()
                    .find(|(m, ff, s, _)| m == n && *ff == f && *s == sg)
                    .and_then(|x| x.3)
            };
            out.push(DetectionLimitCase {
                motor: n.to_string(),
                fault: f,
                smallest_increase: get(1.0),
                smallest_decrease: get(-1.0),
            });
        }
    }
    Ok(out)
}

/// The smallest change of fault `f` in the direction `sign` (+1, -1) on a log grid from
/// 0.25 % to 90 % that lights a lamp within 10 s of its onset at 50 s in the service
/// profile of the machine `p` (noise seed `seed`); `None`: not even 90 %. A grid, not a
/// bisection: detection need not be monotonic (e.g. a voltage reading falling below the
/// "motor running" level is no longer evaluated).
fn smallest_detected(p: &ParamFile, seed: u64, f: Fault, sign: f64) -> Option<f64> {
    const GRID: [f64; 14] = [
        0.0025, 0.004, 0.006, 0.01, 0.015, 0.025, 0.04, 0.06, 0.1, 0.15, 0.25, 0.4, 0.6, 0.9,
    ];
    let detected = |x: f64| -> bool {
        let spec = monitor_sim::FaultSpec::at_change(f, 50.0, sign * x);
        crate::service_profile::watch(p, seed, 60.0, Some(spec))
            .map(|w| w.first_alarm_s.is_some_and(|t| t >= 50.0))
            .unwrap_or(false)
    };
    GRID.iter().copied().find(|x| detected(*x))
}

/// Why the detection-limit study could not run.
#[derive(Debug, thiserror::Error)]
pub enum DetectionError {
    /// The healthy profile itself alarmed: no limit means anything.
    #[error("the healthy {motor} service profile raised an alarm at {at_s:?} s")]
    FalseAlarm {
        /// The motor.
        motor: String,
        /// When.
        at_s: Option<f64>,
    },
    /// A simulation or replay failed.
    #[error(transparent)]
    Experiment(#[from] ExperimentError),
}
