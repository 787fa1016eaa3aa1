//! `sim-host bench`: the performance figures (`docs/performance.md`), measured on this machine
//! ([`monitor_studies::bench`]); with `--isolation`, the isolation's bench
//! ([`monitor_studies::bench::isolation`]).

use super::{output_guard::OutputGuard, progress, render};
use clap::Args;
use std::path::PathBuf;

/// File the confusion heatmap is written to in `--plot DIR`.
pub const CONFUSION_SVG: &str = "isolation_confusion.svg";

/// Arguments of `bench`.
#[derive(Debug, Args)]
#[command(
    about = "Measure simulator throughput and accuracy, the core's time per sample, or (--isolation) how well faults are named",
    long_about = "Measure on this machine: the simulator's throughput on the reference \
scenario (2.2 kW machine started direct-on-line, 14.6 N m load from 2.5 s, 10 s at 10 kHz) in \
simulated seconds per wall second, in memory and with CSV writing; its accuracy against a run with a \
100x smaller step; and the core Monitor's time per sample. Each timing runs --repeat times after a \
warm-up; the median and the range are reported (on a shared machine the range shows the other \
jobs).\n\nWith --isolation, instead: every Table 1 fault at -50, -10, +10 and +50 % on the 3 hp, \
2.2 kW and 11 kW (2-pole) motors, in both angle modes (rotor-flux and pll), with 12-bit noisy \
sensors at 5 kHz and two load levels (432 simulated runs in parallel, about a minute on two \
cores). Per case: detected, named right by the isolation (B and Bl as the friction class b/bl), \
wrong names at probability >= 0.5 (must be none), the size error and the time to name it; a \
summary per motor and mode, a confusion matrix per mode (true fault x named) and every case not \
named right. --plot DIR writes the confusion matrices as an SVG heatmap.\n\nExamples:\n  \
cargo run --release -p sim-host -- bench --repeat 7\n  \
cargo run --release -p sim-host -- bench --isolation --plot /tmp/isoplot"
)]
pub struct BenchArgs {
    /// Repetitions of each timing (the median and the range are reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
    /// Also find, per fault and sign, the smallest change detected within 10 s under the
    /// healthy service profile (load and supply steps, noisy sensors) at zero false alarms
    /// (about a minute on two cores).
    #[arg(long, conflicts_with = "isolation")]
    pub detection: bool,
    /// Run the isolation bench instead of the timings: every Table 1 fault at -50/-10/+10/+50 %,
    /// three motors, both angle modes, noisy sensors, two loads.
    #[arg(long)]
    pub isolation: bool,
    /// With --isolation: write the confusion matrices as an SVG heatmap
    /// (`isolation_confusion.svg`) into this folder (created if missing).
    #[arg(long, value_name = "DIR", requires = "isolation")]
    pub plot: Option<PathBuf>,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bench`.
///
/// # Errors
/// Simulator errors, or a healthy profile that alarms (the detection limits would mean
/// nothing), or a plot folder that cannot be written.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if args.isolation {
        return run_isolation(args);
    }
    let figures = monitor_studies::bench::measure(args.repeat)?;
    let limits = if args.detection {
        let bar = progress::bar(36, "detection limits", true);
        let l = monitor_studies::bench::detection_limits(&|| bar.inc(1))?;
        bar.finish_and_clear();
        Some(l)
    } else {
        None
    };
    if args.json {
        render::json::print(
            &mut crate::cli::out::stdout(),
            &render::json::BenchReport {
                figures: &figures,
                detection_limits: limits.as_deref(),
            },
        )
    } else {
        render::bench_text::bench(&mut crate::cli::out::stdout(), &figures, limits.as_deref())
    }
}

/// `bench --isolation`.
fn run_isolation(args: &BenchArgs) -> anyhow::Result<()> {
    use monitor_studies::bench::isolation::{run, BenchPlan};
    if let Some(dir) = &args.plot {
        OutputGuard::new(&[]).check_folder(dir, &[CONFUSION_SVG.to_string()])?;
    }
    let plan = BenchPlan::full()?;
    let bar = progress::bar(plan.len() as u64, "isolation bench", true);
    let result = run(&plan, || bar.inc(1))?;
    bar.finish_and_clear();
    if let Some(dir) = &args.plot {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create the plot folder {}: {e}", dir.display()))?;
        let svg = render::plot::confusion_svg(&result.confusion).map_err(anyhow::Error::msg)?;
        let path = dir.join(CONFUSION_SVG);
        monitor_api::files::write_atomic(&path, svg.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if args.json {
        render::json::print(&mut crate::cli::out::stdout(), &result)
    } else {
        render::bench_text::isolation_bench(&mut crate::cli::out::stdout(), &result)
    }
}
