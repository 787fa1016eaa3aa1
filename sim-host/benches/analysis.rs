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
mod common;

use monitor_analysis::{prep::ReadOptions, Analysis, Options};
use monitor_io::log::{LogFile, LogWriter, Row};
use monitor_io::params::ParamFile;
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

fn main() {
    alloc_tuning::keep_freed_memory();
    let secs: f64 = std::env::var("ANALYSIS_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0);
    let path = common::log_path("ANALYSIS_BENCH_LOG", secs);
    let p = ParamFile::reference_2p2kw();
    common::ensure_log(&path, &p, secs);
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
    struct RowsToWriter<'a>(&'a mut LogWriter);
    impl monitor_io::log::RowSink for RowsToWriter<'_> {
        fn row(&mut self, r: &Row) -> bool {
            self.0.write_row(r).is_ok()
        }
        fn restart(&mut self) {
            panic!("the generated log is read by the fast path, which does not restart");
        }
    }
    file.for_each_row(&mut |_| {}, &mut RowsToWriter(&mut w))
        .expect("read");
    w.finish().expect("finish");
    eprintln!(
        "converted to {} in {:.1} s",
        to.display(),
        t.elapsed().as_secs_f64()
    );
}

/// Times read, compare and explain on one log.
fn run(path: &std::path::Path, p: ParamFile, format: &str) {
    eprintln!(
        "[{format}] load average before the run: {}",
        common::load_average()
    );
    let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let c0 = common::stat_seconds(11);
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
    let c_read = common::stat_seconds(11) - c0;
    let rss_read = peak_rss_mb();
    let opts = Options {
        effects: vec![],
        fit_base: true,
        laws: Default::default(),
    };
    let t1 = Instant::now();
    let c = a.compare(&opts).expect("compare");
    let t_cmp = t1.elapsed().as_secs_f64();
    let c_cmp = common::stat_seconds(11) - c0 - c_read;
    let rss_cmp = peak_rss_mb();
    // As `explain --compare` does: compare's result is reported, then dropped.
    let cmp_error = c.report.normalized_rms_error;
    drop(c);
    let t2 = Instant::now();
    let e = a.explain(&opts, &|_| {}).expect("explain");
    let t_exp = t2.elapsed().as_secs_f64();
    let c_exp = common::stat_seconds(11) - c0 - c_read - c_cmp;
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
        common::load_average()
    );
}
