//! What the long-log benchmarks share (`analysis`, `diagnose`): the 1 h, 10 kHz log they
//! read, and the figures of the machine they run on (load average, CPU time from `/proc`).

use monitor_io::log::{Channels, LogWriter};
use monitor_io::params::ParamFile;
use monitor_sim::{self as sim, EffectSpec, Scenario, SensorSpec};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The benchmark log's path: `$var` if set, else `/tmp/sim-host-bench-<seconds>s.csv`
/// (one file for every benchmark that reads a log of that length).
pub fn log_path(var: &str, secs: f64) -> PathBuf {
    PathBuf::from(
        std::env::var(var).unwrap_or_else(|_| format!("/tmp/sim-host-bench-{}s.csv", secs as u64)),
    )
}

/// Writes the benchmark log of `secs` seconds to `path` unless it exists: the simulator
/// with `p` at 10 kHz, thermal drift (60 K rise, time constant 20 min or a third of the
/// log), default sensors; voltages, currents and speed (no encoder column).
pub fn ensure_log(path: &Path, p: &ParamFile, secs: f64) {
    if path.exists() {
        return;
    }
    let mut s = Scenario::steady(secs, 10_000.0);
    s.sensors = SensorSpec::default();
    s.effects = vec![EffectSpec::ThermalDrift {
        rise_k: Some(60.0),
        tau_s: 1200.0_f64.min(secs / 3.0),
        at_s: 0.0,
        r_th_k_per_w: None,
        alpha_per_k: 0.00393,
        rotor: true,
    }];
    let t = Instant::now();
    write_log(path, p, &s);
    eprintln!(
        "generated {} in {:.1} s",
        path.display(),
        t.elapsed().as_secs_f64()
    );
}

/// Simulates `s` with the motor of `p` into the log at `path`: voltages, currents and
/// speed (no encoder column).
pub fn write_log(path: &Path, p: &ParamFile, s: &Scenario) {
    let channels = Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let mut w = LogWriter::create(path, channels).expect("create log");
    sim::simulate(p, s, |r| {
        let mut r = *r;
        r.enc_count = None;
        w.write_row(&r).expect("write row");
    })
    .expect("simulate");
    w.finish().expect("finish log");
}

/// The 1, 5 and 15 min load averages (from /proc/loadavg): on a shared machine the wall
/// times mean little without them.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// Two fields of /proc/self/stat after the command name (0: the state, the line's third
/// field), summed and read as clock ticks of 10 ms [s]; NaN where unavailable. Fields 11
/// and 12 are this process's user and system time, 13 and 14 those of the children waited
/// for.
pub fn stat_seconds(first: usize) -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split_whitespace().collect();
            let a: f64 = f.get(first)?.parse().ok()?;
            let b: f64 = f.get(first + 1)?.parse().ok()?;
            Some((a + b) / 100.0)
        })
        .unwrap_or(f64::NAN)
}
