//! `diagnose` benchmark: `sim-host diagnose --json` on a 1 h log at 10 kHz (36 M rows).
//! Goal: at most 5 s wall on 2 cores and 0.15 CPU-s per million rows, with bounded memory
//! (measured figures and where the time goes: docs/performance.md).
//!
//! Run: `cargo bench -p sim-host --bench diagnose` (release profile). The log is the
//! analysis benchmark's (`common::ensure_log`: the simulator, 2.2 kW motor, thermal drift,
//! default sensors, about 3 GB for 1 h), generated once into `$DIAGNOSE_BENCH_LOG`
//! (default `/tmp/sim-host-bench-<seconds>s.csv`, the analysis benchmark's file) and reused.
//! `DIAGNOSE_BENCH_SECONDS` shortens it (default 3600); `DIAGNOSE_BENCH_REPEAT` runs the
//! command that many times (default 3).
//!
//! The command is the binary itself (its allocator settings, the JSON and all), a child
//! process with stdout to a temporary file. Per run: the wall time, the child's CPU time
//! (user + system: this process's `cutime` and `cstime`), the CPU time per million rows,
//! the child's peak resident memory (VmHWM, sampled every 20 ms) and the load average
//! before and after.

mod common;

use sim_host::params::ParamFile;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A process's peak resident memory so far [MB] (VmHWM), `None` once it has exited.
fn peak_rss_mb(pid: u32) -> Option<f64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let l = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() {
    let env = |k: &str| std::env::var(k).ok().and_then(|s| s.parse::<f64>().ok());
    let secs = env("DIAGNOSE_BENCH_SECONDS").unwrap_or(3600.0);
    let repeat = env("DIAGNOSE_BENCH_REPEAT").unwrap_or(3.0) as u32;
    let path = common::log_path("DIAGNOSE_BENCH_LOG", secs);
    common::ensure_log(&path, &ParamFile::reference_2p2kw(), secs);
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/2p2kw.toml");
    let size_gb = std::fs::metadata(&path).map_or(0.0, |m| m.len() as f64 / 1e9);
    let out = tempfile::NamedTempFile::new().expect("temporary output");
    for k in 1..=repeat {
        let load_before = common::load_average();
        // (Fields 13 and 14: the CPU time of the children waited for.)
        let c0 = common::stat_seconds(13);
        let t0 = Instant::now();
        let mut child = Command::new(env!("CARGO_BIN_EXE_sim-host"))
            .arg("diagnose")
            .arg("--params")
            .arg(&params)
            .arg(&path)
            .arg("--json")
            .stdout(Stdio::from(out.reopen().expect("reopen output")))
            .spawn()
            .expect("run sim-host diagnose");
        let mut rss = 0.0f64;
        let status = loop {
            if let Some(s) = child.try_wait().expect("wait") {
                break s;
            }
            rss = rss.max(peak_rss_mb(child.id()).unwrap_or(0.0));
            std::thread::sleep(Duration::from_millis(20));
        };
        let wall = t0.elapsed().as_secs_f64();
        let cpu = common::stat_seconds(13) - c0;
        assert!(status.success(), "sim-host diagnose failed: {status}");
        let report: serde_json::Value =
            serde_json::from_reader(std::fs::File::open(out.path()).expect("output"))
                .expect("diagnose's JSON");
        let rows = report["rows"].as_f64().unwrap_or(f64::NAN);
        println!(
            "diagnose bench run {k}/{repeat}: {rows:.0} rows ({size_gb:.2} GB), {} threads: wall {wall:.2} s, CPU (user + system) {cpu:.2} s, {:.3} CPU-s per million rows, peak RSS {rss:.0} MB; verdict {}; load average before {load_before}, after {}",
            std::thread::available_parallelism().map_or(0, |n| n.get()),
            cpu / (rows / 1e6),
            report["verdict"],
            common::load_average()
        );
    }
}
