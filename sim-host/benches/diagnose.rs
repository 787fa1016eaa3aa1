//! `diagnose` benchmark: `sim-host diagnose --json` on a 1 h log at 10 kHz (36 M rows),
//! as CSV and as Parquet, side by side with polars' `read_csv` of the same CSV. The bar
//! (issue 41): the diagnosis of the CSV in less wall time and less CPU time than polars
//! needs to parse it, and of the Parquet copy in under half that time (measured figures:
//! docs/performance.md, "diagnose of a 1 h log").
//!
//! Run: `cargo bench -p sim-host --bench diagnose` (release profile). The log is the
//! analysis benchmark's (`common::ensure_log`: the simulator, 2.2 kW motor, thermal drift,
//! default sensors, about 3 GB for 1 h), generated once into `$DIAGNOSE_BENCH_LOG`
//! (default `/tmp/sim-host-bench-<seconds>s.csv`, the analysis benchmark's file) and reused;
//! its Parquet copy (`sim-host convert`) beside it, with the extension `.parquet`.
//! `DIAGNOSE_BENCH_SECONDS` shortens the log (default 3600); `DIAGNOSE_BENCH_REPEAT` sets the
//! rounds (default 3). polars runs in `$POLARS_PYTHON` (default `python3`); where it cannot
//! import polars, its runs are skipped with a message naming the interpreter.
//!
//! Each round runs, one after the other, polars' `read_csv`, `diagnose` of the CSV and
//! `diagnose` of the Parquet copy, each a child process with its output to a temporary
//! file. Per run: the wall time, the CPU time (user + system) and the peak resident memory
//! (VmHWM, sampled every 20 ms), and the load average before; polars' figures are those of
//! the `read_csv` call alone (timed inside the interpreter, without its start and the
//! import), the diagnoses' those of the whole process. After the rounds: the medians and
//! the ratios to polars'.

mod common;
mod stages;

use monitor_io::params::ParamFile;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Times `pl.read_csv(path)` inside the interpreter: prints `wall_s cpu_s rows`.
const POLARS_SCRIPT: &str = "import sys, time, resource, polars as pl
t = time.perf_counter(); r0 = resource.getrusage(resource.RUSAGE_SELF)
df = pl.read_csv(sys.argv[1])
r1 = resource.getrusage(resource.RUSAGE_SELF); w = time.perf_counter() - t
cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
print(w, cpu, df.height, pl.__version__)";

/// One run's figures.
#[derive(Debug, Clone, Copy)]
struct BenchRun {
    wall_s: f64,
    cpu_s: f64,
    rss_mb: f64,
}

/// A process's peak resident memory so far [MB] (VmHWM), `None` once it has exited.
fn peak_rss_mb(pid: u32) -> Option<f64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let l = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = l.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Runs `cmd` with stdout to `out`; its wall and CPU time (this process's children's) and
/// peak resident memory. Panics when it fails: a benchmark has nothing to report then.
fn measure(mut cmd: Command, out: &Path) -> BenchRun {
    // (Fields 13 and 14: the CPU time of the children waited for.)
    let c0 = common::stat_seconds(13);
    let t0 = Instant::now();
    let mut child = cmd
        .stdout(Stdio::from(
            std::fs::File::create(out).expect("output file"),
        ))
        .spawn()
        .expect("start the child process");
    let mut rss = 0.0f64;
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        rss = rss.max(peak_rss_mb(child.id()).unwrap_or(0.0));
        std::thread::sleep(Duration::from_millis(20));
    };
    let wall_s = t0.elapsed().as_secs_f64();
    assert!(status.success(), "{cmd:?} failed: {status}");
    BenchRun {
        wall_s,
        cpu_s: common::stat_seconds(13) - c0,
        rss_mb: rss,
    }
}

/// What a diagnosis concluded: the rows read, the verdict and its finding (the fault named
/// and its size), compared between the CSV and its Parquet copy.
#[derive(Debug, PartialEq)]
struct DiagnosisConclusion {
    rows: f64,
    verdict: serde_json::Value,
    finding: serde_json::Value,
}

/// `sim-host diagnose --json` of `log`: the run and what it concluded.
fn diagnose(log: &Path, params: &Path, out: &Path) -> (BenchRun, DiagnosisConclusion) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_sim-host"));
    cmd.arg("diagnose")
        .arg("--params")
        .arg(params)
        .arg(log)
        .arg("--json");
    let run = measure(cmd, out);
    let report: serde_json::Value =
        serde_json::from_reader(std::fs::File::open(out).expect("output")).expect("JSON");
    let concluded = DiagnosisConclusion {
        rows: report["rows"].as_f64().unwrap_or(f64::NAN),
        verdict: report["verdict"].clone(),
        finding: report["verdict_finding"].clone(),
    };
    (run, concluded)
}

/// polars' `read_csv` of `log` in `python`: the call's wall and CPU time, the process's
/// peak memory, and polars' version.
fn polars(python: &str, log: &Path, out: &Path) -> (BenchRun, String) {
    let mut cmd = Command::new(python);
    cmd.arg("-c").arg(POLARS_SCRIPT).arg(log);
    let whole = measure(cmd, out);
    let text = std::fs::read_to_string(out).unwrap_or_default();
    let f: Vec<&str> = text.split_whitespace().collect();
    let num = |k: usize| f.get(k).and_then(|s| s.parse::<f64>().ok());
    let run = BenchRun {
        wall_s: num(0).unwrap_or(whole.wall_s),
        cpu_s: num(1).unwrap_or(whole.cpu_s),
        rss_mb: whole.rss_mb,
    };
    (run, f.get(3).map_or("?", |v| v).to_string())
}

/// Whether `python` imports polars.
fn has_polars(python: &str) -> bool {
    Command::new(python)
        .args(["-c", "import polars"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The Parquet copy of `csv` (written by `sim-host convert` unless it exists).
fn parquet_copy(csv: &Path) -> PathBuf {
    let pq = csv.with_extension("parquet");
    if !pq.exists() {
        let t = Instant::now();
        let ok = Command::new(env!("CARGO_BIN_EXE_sim-host"))
            .arg("convert")
            .arg(csv)
            .arg(&pq)
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "sim-host convert {} failed", csv.display());
        eprintln!(
            "wrote {} in {:.1} s",
            pq.display(),
            t.elapsed().as_secs_f64()
        );
    }
    pq
}

/// The median of `x` (the mean of the middle two for an even count).
fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

fn print_run(what: &str, k: u32, repeat: u32, r: &BenchRun, load: &str) {
    println!(
        "round {k}/{repeat} {what:<16} wall {:6.2} s  CPU {:6.2} s  peak RSS {:6.0} MB  (load average before: {load})",
        r.wall_s, r.cpu_s, r.rss_mb
    );
}

/// The medians of `runs` and, with polars', the ratios.
fn summary(what: &str, runs: &[BenchRun], polars: Option<(f64, f64)>) {
    let wall = median(runs.iter().map(|r| r.wall_s).collect());
    let cpu = median(runs.iter().map(|r| r.cpu_s).collect());
    let rss = median(runs.iter().map(|r| r.rss_mb).collect());
    let ratio = polars.map_or(String::new(), |(w, c)| {
        format!("; {:.2} x polars' wall, {:.2} x its CPU", wall / w, cpu / c)
    });
    println!("median {what:<16} wall {wall:6.2} s  CPU {cpu:6.2} s  peak RSS {rss:6.0} MB{ratio}");
}

fn main() {
    let env = |k: &str| std::env::var(k).ok().and_then(|s| s.parse::<f64>().ok());
    let secs = env("DIAGNOSE_BENCH_SECONDS").unwrap_or(3600.0);
    let repeat = env("DIAGNOSE_BENCH_REPEAT").unwrap_or(3.0).max(1.0) as u32;
    let csv = common::log_path("DIAGNOSE_BENCH_LOG", secs);
    common::ensure_log(&csv, &ParamFile::reference_2p2kw(), secs);
    let pq = parquet_copy(&csv);
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/2p2kw.toml");
    let python = std::env::var("POLARS_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let with_polars = has_polars(&python);
    let size = |p: &Path| std::fs::metadata(p).map_or(0.0, |m| m.len() as f64 / 1e9);
    println!(
        "diagnose bench: {} ({:.2} GB) and {} ({:.2} GB), {} rounds, {} threads",
        csv.display(),
        size(&csv),
        pq.display(),
        size(&pq),
        repeat,
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    if !with_polars {
        println!(
            "polars skipped: {python} cannot import polars (set POLARS_PYTHON to an interpreter that can, e.g. a venv with `pip install polars`)"
        );
    }
    let out = tempfile::NamedTempFile::new().expect("temporary output");
    let (mut runs_pl, mut runs_csv, mut runs_pq) = (Vec::new(), Vec::new(), Vec::new());
    for k in 1..=repeat {
        if with_polars {
            let load = common::load_average();
            let (r, version) = polars(&python, &csv, out.path());
            print_run(&format!("polars {version}"), k, repeat, &r, &load);
            runs_pl.push(r);
        }
        let load = common::load_average();
        let (r, rows) = diagnose(&csv, &params, out.path());
        print_run("diagnose CSV", k, repeat, &r, &load);
        runs_csv.push(r);
        let load = common::load_average();
        let (r, rows_pq) = diagnose(&pq, &params, out.path());
        print_run("diagnose Parquet", k, repeat, &r, &load);
        runs_pq.push(r);
        assert_eq!(
            rows, rows_pq,
            "the CSV and the Parquet copy: the same rows, verdict, fault and size"
        );
        if k == repeat {
            println!(
                "verdict (CSV and Parquet): {} {}",
                rows.verdict, rows.finding
            );
        }
    }
    let reference = (!runs_pl.is_empty()).then(|| {
        (
            median(runs_pl.iter().map(|r| r.wall_s).collect()),
            median(runs_pl.iter().map(|r| r.cpu_s).collect()),
        )
    });
    if with_polars {
        summary("polars read_csv", &runs_pl, None);
    }
    summary("diagnose CSV", &runs_csv, reference);
    summary("diagnose Parquet", &runs_pq, reference);
    println!("load average after: {}", common::load_average());
    let cpu_pq = median(runs_pq.iter().map(|r| r.cpu_s).collect());
    stages::by_stage(env!("CARGO_BIN_EXE_sim-host"), &pq, &params, cpu_pq);
}
