//! The ladder's benchmark (`docs/performance.md`): `explain --ladder` on a 10 s, 10 kHz
//! log with two hidden effects, goal at most 10 CPU-s on this 2-core machine.
//!
//! Run: `cargo bench -p sim-host --bench ladder` (release profile). The log is simulated
//! once into `$LADDER_BENCH_LOG` (default `/tmp/sim-host-ladder-bench.csv`): the 2.2 kW
//! reference machine started direct-on-line, the paper's viscous load stepping down and
//! back, a 10 % voltage dip and back, default 12-bit sensors, and two effects the
//! parameter file does not hold: a 3 % supply unbalance and a stator heating by 60 K with a
//! 4 s time constant (accelerated). Prints the wall time, the CPU time (user + system, from
//! `/proc`), the effects named, the end against the noise floor and the machine's load
//! average (a wall time on a shared machine means little without it).
//! `LADDER_BENCH_REPEAT` runs the ladder that many times (default 1) and prints each.

#[allow(dead_code)] // each benchmark uses part of what the benchmarks share
mod common;

use monitor_analysis::{prep::ReadOptions, Analysis, Options};
use monitor_io::log::{Channels, LogWriter};
use monitor_io::params::ParamFile;
use std::path::PathBuf;
use std::time::Instant;

/// The benchmark's scenario (the simulator's TOML form).
const SCENARIO: &str = r#"
duration_s = 10.0
sample_rate_hz = 10000.0
seed = 7

[supply]
steps = [{ t_s = 7.0, v_scale = 0.9 }, { t_s = 8.5, v_scale = 1.0 }]

[load]
kind = "viscous"
steps = [{ t_s = 3.5, bl_scale = 0.6 }, { t_s = 5.5, bl_scale = 1.0 }]

[[effects]]
name = "supply_unbalance"
fraction = 0.03

[[effects]]
name = "thermal_drift"
rise_k = 60.0
tau_s = 4.0
rotor = false
"#;

fn main() {
    let path = PathBuf::from(
        std::env::var("LADDER_BENCH_LOG")
            .unwrap_or_else(|_| "/tmp/sim-host-ladder-bench.csv".into()),
    );
    let p = ParamFile::reference_2p2kw();
    if !path.exists() {
        let s: monitor_sim::Scenario = toml::from_str(SCENARIO).expect("the bench's scenario");
        let channels = Channels {
            voltages: true,
            speed: true,
            encoder: false,
            temperature: false,
        };
        let mut w = LogWriter::create(&path, channels).expect("create log");
        monitor_sim::simulate(&p, &s, |r| {
            let mut r = *r;
            r.enc_count = None;
            w.write_row(&r).expect("write row");
        })
        .expect("simulate");
        w.finish().expect("finish log");
    }
    let repeat: usize = std::env::var("LADDER_BENCH_REPEAT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    for _ in 0..repeat {
        let c0 = common::stat_seconds(11);
        let t0 = Instant::now();
        let a = Analysis::load(&path, p, ReadOptions::default(), &mut |_| {}).expect("load");
        let opts = Options {
            effects: vec![],
            fit_base: true,
            laws: Default::default(),
        };
        let r = a.ladder(&opts, &|_| {}).expect("ladder");
        let wall = t0.elapsed().as_secs_f64();
        let cpu = common::stat_seconds(11) - c0;
        let named: Vec<&str> = r
            .final_effects
            .iter()
            .filter(|k| !k.is_dynamics())
            .map(|k| k.name())
            .collect();
        let end = r.final_fit.as_ref().map_or(f64::NAN, |f| f.ratio_to_floor);
        println!(
            "ladder bench: {} rows, {} threads: {wall:.2} s wall, {cpu:.2} CPU-s (goal 10); named {:?}, base {:?}, end {end:.2}x the floor; load average after: {}",
            a.data.rows,
            rayon::current_num_threads(),
            named,
            r.base_changes
                .iter()
                .map(|c| format!("{} {:+.3}", c.base, c.change))
                .collect::<Vec<_>>(),
            common::load_average()
        );
    }
}
