//! `diagnose`'s profile by stage (docs/performance.md, "Where the time goes"): one run of
//! `sim-host diagnose --json` under `perf record` (a sampling profiler, 999 samples per
//! second per thread), each sample's function put into the stage it belongs to. Skipped with
//! a message where `perf` is not installed or may not sample (`DIAGNOSE_BENCH_PROFILE=0`
//! skips it too).
//!
//! The functions are those of the release binary, after inlining: a filter inlined into the
//! sequence analysis counts as the sequence analysis, which is where its work is asked for.
//! The shares are of all samples of the process (every thread).

use std::path::Path;
use std::process::{Command, Stdio};

/// The stages, each with the function-name fragments that put a sample into it; the first
/// stage whose fragment a function's name contains takes it.
const STAGES: [(&str, &[&str]); 9] = [
    (
        "data quality (clock, cells, stuck, clipping, wiring)",
        &[
            "monitor_io::log::quality",
            "monitor_io::log::clipping",
            // (The replay's sink before the pipe; the pipe's `Feeder` is the hand-over.)
            "monitor_replay::front::ReplaySink",
        ],
    ),
    (
        "read and parse (the log's rows)",
        &[
            "monitor_io::",
            "parquet::",
            "snap::",
            "lz4",
            "fast_float",
            "rayon",
            "crossbeam",
            "in_place_collect",
            // (The Parquet rows built from the columns, `hand_columns`' iterator.)
            "core::iter::adapters::map::Map",
        ],
    ),
    (
        "core monitor (Clarke/Park, residuals, lamps, commissioning)",
        &[
            "monitor_core::monitor",
            "monitor_core::encoder",
            "monitor_core::signature",
            "monitor_core::residuals",
            "monitor_core::commissioning",
            "monitor_core::threshold",
            "monitor_replay::sampler",
            "monitor_replay::commission",
        ],
    ),
    (
        "isolation (follower, single and joint fits, events)",
        &[
            "monitor_core::isolation",
            "monitor_replay::isolation",
            "monitor_replay::events",
            "monitor_replay::temperature",
            "hypot",
            "exp_ln2",
        ],
    ),
    (
        "sequences and winding (PLL, filters, phasor fits)",
        &[
            "monitor_replay::sequences",
            "monitor_replay::trig",
            "monitor_replay::winding",
            "monitor_core::sequence",
            "monitor_core::angle",
            "monitor_core::filter",
            "sincos",
            "__cos",
            "__sin",
        ],
    ),
    (
        "rotor spectrum (demodulation, FFT)",
        &["monitor_replay::rotor", "rustfft"],
    ),
    (
        "report (verdict, JSON)",
        &["monitor_replay::report", "monitor_replay::verdict", "serde"],
    ),
    (
        "replay hand-over and bookkeeping (the thread's batches, timeline)",
        &["monitor_replay::", "std::sync::mpmc"],
    ),
    (
        "kernel, allocator and copies",
        &[
            "[k]", "memmove", "memset", "memcpy", "malloc", "free", "_int_",
        ],
    ),
];

/// The stage of a `perf report` line's function (`[.] name` or `[k] name`).
fn stage_of(line: &str) -> usize {
    STAGES
        .iter()
        .position(|(_, keys)| keys.iter().any(|k| line.contains(k)))
        .unwrap_or(STAGES.len())
}

/// Profiles one `diagnose --json` of `log` with `params` by `bin` and prints each stage's
/// share of the samples and its part of `cpu_s` (the runs' median CPU time) [s].
pub fn by_stage(bin: &str, log: &Path, params: &Path, cpu_s: f64) {
    if std::env::var("DIAGNOSE_BENCH_PROFILE").is_ok_and(|v| v == "0") {
        return;
    }
    let dir = tempfile::tempdir().expect("temporary folder");
    let data = dir.path().join("perf.data");
    let recorded = Command::new("perf")
        .args(["record", "-F", "999", "-q", "-o"])
        .arg(&data)
        .arg("--")
        .arg(bin)
        .arg("diagnose")
        .arg("--params")
        .arg(params)
        .arg(log)
        .arg("--json")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    if !recorded.is_ok_and(|s| s.success()) {
        println!("profile by stage skipped: `perf record` is not available here (install linux-perf, or allow it: kernel.perf_event_paranoid <= 1)");
        return;
    }
    let report = Command::new("perf")
        .args([
            "report",
            "--no-children",
            "--sort",
            "symbol",
            "--stdio",
            "-q",
            "-i",
        ])
        .arg(&data)
        .stderr(Stdio::null())
        .output();
    let Ok(report) = report else {
        println!("profile by stage skipped: `perf report` failed");
        return;
    };
    let mut share = [0.0f64; STAGES.len() + 1];
    for line in String::from_utf8_lossy(&report.stdout).lines() {
        let Some(pct) = line
            .split_whitespace()
            .next()
            .and_then(|p| p.strip_suffix('%'))
            .and_then(|p| p.parse::<f64>().ok())
        else {
            continue;
        };
        share[stage_of(line)] += pct;
    }
    println!(
        "profile by stage of `diagnose` of {} (perf, share of all samples; CPU-s at the median {cpu_s:.2} s):",
        log.display()
    );
    let names = STAGES.iter().map(|(n, _)| *n).chain(["other"]);
    for (name, pct) in names.zip(share) {
        println!(
            "  {name:<68} {pct:5.1} %  {:5.2} CPU-s",
            pct / 100.0 * cpu_s
        );
    }
}
