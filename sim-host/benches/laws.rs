//! A user's law against the library's (issue 85, `docs/performance.md`): the same physics, a
//! fan's drag `k w |w|`, fitted on a 10 s, 10 kHz log once as the library's `windage` and
//! once as a user's law of the same form (`--laws`, an expression compiled once and
//! evaluated per sample). Goal: the user's law costs at most twice the library's.
//!
//! Run: `cargo bench -p sim-host --bench laws` (release profile). The log is simulated once
//! into `$LAWS_BENCH_LOG` (default `/tmp/sim-host-laws-bench.csv`): the 2.2 kW reference
//! machine started direct-on-line driving a fan (the library's windage, 80 % of the rated
//! torque at synchronous speed), a 10 % voltage dip and back, default 12-bit sensors.
//! Prints each fit's CPU time (user + system, from `/proc`), their ratio, the fitted
//! coefficients and the machine's load average. `LAWS_BENCH_REPEAT` repeats the pair.

#[allow(dead_code)] // each benchmark uses part of what the benchmarks share
mod common;

use monitor_analysis::effects::Registry;
use monitor_analysis::{prep::ReadOptions, Analysis, EffectId, Options};
use monitor_io::params::ParamFile;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The benchmark's scenario (the simulator's TOML form).
const SCENARIO: &str = r#"
duration_s = 10.0
sample_rate_hz = 10000.0
seed = 9

[supply]
steps = [{ t_s = 6.0, v_scale = 0.9 }, { t_s = 8.0, v_scale = 1.0 }]

[load]
kind = "viscous"
bl_nms = 0.0

[[effects]]
name = "windage"
k_nms2 = 4.7e-4
"#;

/// The user's law: the library's windage written as an expression.
const FAN: &str = "[[law]]\nname = \"fan\"\nacts_on = \"load_torque\"\nexpr = \"k * w * abs(w)\"\n[law.parameters]\nk = { start = 1e-4, low = -1e-3, high = 1e-2, unit = \"N m s^2/rad^2\" }\n";

fn ensure(path: &Path, p: &ParamFile) {
    if path.exists() {
        return;
    }
    let s: monitor_sim::Scenario = toml::from_str(SCENARIO).expect("the bench's scenario");
    common::write_log(path, p, &s);
}

/// `compare` with `effect` (and the laws of `registry`): CPU-s, the fitted coefficient.
fn fit(a: &Analysis, registry: &Registry, effect: &str) -> (f64, f64) {
    let opts = Options {
        effects: vec![EffectId::named(effect)],
        fit_base: true,
        laws: registry.clone(),
    };
    let c0 = common::stat_seconds(11);
    let out = a.compare(&opts).expect("compare");
    let cpu = common::stat_seconds(11) - c0;
    let k = out
        .report
        .fitted_effects
        .iter()
        .flat_map(|e| e.parameters.values())
        .next()
        .map_or(f64::NAN, |v| v.value);
    (cpu, k)
}

fn main() {
    let path = PathBuf::from(
        std::env::var("LAWS_BENCH_LOG").unwrap_or_else(|_| "/tmp/sim-host-laws-bench.csv".into()),
    );
    let p = ParamFile::reference_2p2kw();
    ensure(&path, &p);
    let laws = monitor_laws_of(FAN);
    let library = Registry::library();
    let users = Registry::with_laws(&laws);
    let repeat: usize = std::env::var("LAWS_BENCH_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let t0 = Instant::now();
    let a = Analysis::load(&path, p, ReadOptions::default(), &mut |_| {}).expect("load");
    eprintln!(
        "read {} rows in {:.2} s",
        a.data.rows,
        t0.elapsed().as_secs_f64()
    );
    for _ in 0..repeat {
        let (lib_cpu, lib_k) = fit(&a, &library, "windage");
        let (law_cpu, law_k) = fit(&a, &users, "fan");
        println!(
            "laws bench: windage {lib_cpu:.2} CPU-s (k {lib_k:.3e}), the user's fan {law_cpu:.2} CPU-s (k {law_k:.3e}): {:.2}x (goal at most 2x); load average after: {}",
            law_cpu / lib_cpu,
            common::load_average()
        );
    }
}

/// The laws of the law file `text`.
fn monitor_laws_of(text: &str) -> Vec<std::sync::Arc<monitor_api::laws::Law>> {
    monitor_api::laws::LawFile::parse(text, Path::new("fan.toml"))
        .expect("the bench's law")
        .laws
}
