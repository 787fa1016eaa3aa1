//! Discrepancy-analysis benchmark (`docs/performance.md`): `compare` + `explain` on a 1 h
//! log at 10 kHz (36 M samples), goal <= 10 s on 2 cores with bounded memory.
//!
//! Run: `cargo bench -p sim-host --bench analysis` (release profile). The log is generated
//! once with the simulator (2.2 kW motor, thermal drift with a 20 min time constant,
//! default sensors) into `$ANALYSIS_BENCH_LOG` (default `/tmp/sim-host-bench-<seconds>s.csv`,
//! about 3.3 GB for 1 h) and reused. `ANALYSIS_BENCH_SECONDS` shortens the log (default 3600).
//! Prints wall times of the read (parse + decimate + frame), `compare`, `explain`, the
//! peak resident memory (VmHWM, also after the read and after `compare`), the CPU time of
//! each stage and the machine's load average before and after.
//!
//! The same log is also converted once to Parquet beside it (`.parquet`, through the one
//! log writer, about 1.3 GB for 1 h) and analysed from there: one line per format.
//! `ANALYSIS_BENCH_FORMATS` picks them (default `csv,parquet`; `tdms` too if asked). The peak
//! memory is the process's (VmHWM): the second format's figure includes the first's.

#[path = "../src/alloc_tuning.rs"]
mod alloc_tuning;

use sim_host::analysis::{prep::ReadOptions, Analysis, Options};
use sim_host::log::{Channels, LogFile, LogWriter, Row};
use sim_host::params::ParamFile;
use sim_host::sim::{self, EffectSpec, Scenario, SensorSpec};
use std::path::PathBuf;
use std::time::Instant;

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|v| v.parse::<f64>().ok())
            })
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

/// CPU time (user + system) of this process so far [s], from /proc/self/stat (clock ticks
/// of 10 ms); NaN where unavailable. With the wall times it tells a shared machine's
/// interference apart from the work itself.
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // Fields after the command name (which is in parentheses): utime is the 14th
            // field of the line, stime the 15th.
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split_whitespace().collect();
            let ut: f64 = f.get(11)?.parse().ok()?;
            let st: f64 = f.get(12)?.parse().ok()?;
            Some((ut + st) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

fn main() {
    alloc_tuning::keep_freed_memory();
    let secs: f64 = std::env::var("ANALYSIS_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0);
    let path = PathBuf::from(
        std::env::var("ANALYSIS_BENCH_LOG")
            .unwrap_or_else(|_| format!("/tmp/sim-host-bench-{}s.csv", secs as u64)),
    );
    let p = ParamFile::reference_2p2kw();
    if !path.exists() {
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
        let mut w = LogWriter::create(
            &path,
            Channels {
                voltages: true,
                speed: true,
                encoder: false,
            },
        )
        .expect("create log");
        sim::simulate(&p, &s, |r| {
            let mut r = *r;
            r.enc_count = None;
            w.write_row(&r).expect("write row");
        })
        .expect("simulate");
        w.finish().expect("finish log");
        eprintln!(
            "generated {} in {:.1} s",
            path.display(),
            t.elapsed().as_secs_f64()
        );
    }
    let formats = std::env::var("ANALYSIS_BENCH_FORMATS").unwrap_or_else(|_| "csv,parquet".into());
    for ext in formats.split(',').map(str::trim) {
        let log = if ext == "csv" {
            path.clone()
        } else {
            let out = path.with_extension(ext);
            if !out.exists() {
                convert(&path, &out);
            }
            out
        };
        run(&log, p, ext);
    }
}

/// Converts `from` to `to` (the format of its extension) once, through the one reader and
/// writer.
fn convert(from: &std::path::Path, to: &std::path::Path) {
    let t = Instant::now();
    let file = LogFile::open(from).expect("open log");
    let mut w = LogWriter::create(to, file.channels()).expect("create");
    struct Sink<'a>(&'a mut LogWriter);
    impl sim_host::log::RowSink for Sink<'_> {
        fn row(&mut self, r: &Row) -> bool {
            self.0.write_row(r).is_ok()
        }
        fn restart(&mut self) {
            panic!("the generated log is read by the fast path, which does not restart");
        }
    }
    file.for_each_row(&mut |_| {}, &mut Sink(&mut w))
        .expect("read");
    w.finish().expect("finish");
    eprintln!(
        "converted to {} in {:.1} s",
        to.display(),
        t.elapsed().as_secs_f64()
    );
}

/// The 1, 5 and 15 min load averages (from /proc/loadavg): on a shared machine the wall
/// times mean little without them.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// Times read, compare and explain on one log.
fn run(path: &std::path::Path, p: ParamFile, format: &str) {
    eprintln!("[{format}] load average before the run: {}", load_average());
    let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let c0 = cpu_s();
    let t0 = Instant::now();
    let a = Analysis::load(
        path,
        p,
        ReadOptions {
            from_s: 1.0,
            to_s: f64::INFINITY,
        },
        &mut |_| {},
    )
    .expect("load");
    let t_read = t0.elapsed().as_secs_f64();
    let c_read = cpu_s() - c0;
    let rss_read = peak_rss_mb();
    let opts = Options {
        effects: vec![],
        fit_base: true,
    };
    let t1 = Instant::now();
    let c = a.compare(&opts).expect("compare");
    let t_cmp = t1.elapsed().as_secs_f64();
    let c_cmp = cpu_s() - c0 - c_read;
    let rss_cmp = peak_rss_mb();
    // As `explain --compare` does: compare's result is reported, then dropped.
    let cmp_error = c.report.normalized_rms_error;
    drop(c);
    let t2 = Instant::now();
    let e = a.explain(&opts, &|_| {}).expect("explain");
    let t_exp = t2.elapsed().as_secs_f64();
    let c_exp = cpu_s() - c0 - c_read - c_cmp;
    println!(
        "analysis bench [{format}]: {} rows ({:.2} GB), {} threads: read+frame {:.2} s, compare {:.2} s, explain {:.2} s, total {:.2} s; peak RSS {:.0} MB (after read {:.0} MB, after compare {:.0} MB); working samples {}; error {:.4}, top {:?}",
        a.data.rows,
        size as f64 / 1e9,
        rayon::current_num_threads(),
        t_read,
        t_cmp,
        t_exp,
        t_read + t_cmp + t_exp,
        peak_rss_mb(),
        rss_read,
        rss_cmp,
        a.data.len(),
        cmp_error,
        e.report.ranking.first().map(|r| (&r.effect, r.explained_fraction))
    );
    println!(
        "CPU time (user + system): read+frame {c_read:.2} s, compare {c_cmp:.2} s, explain {c_exp:.2} s, total {:.2} s; load average after: {}",
        c_read + c_cmp + c_exp,
        load_average()
    );
}
