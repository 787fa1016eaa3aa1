//! `sim-host bench`: the figures DESIGN.md §4 asks for, measured on this machine
//! ([`sim_host::bench`]).

use super::{progress, render};
use clap::Args;

/// Arguments of `bench`.
#[derive(Debug, Args)]
#[command(
    about = "Measure simulator throughput and accuracy, and the core's time per sample",
    long_about = "Measure on this machine: the simulator's throughput on DESIGN.md's reference \
scenario (2.2 kW machine started direct-on-line, 14.6 N m load from 2.5 s, 10 s at 10 kHz) in \
simulated seconds per wall second, in memory and with CSV writing; its accuracy against a run with a \
100x smaller step; and the core Monitor's time per sample. Each timing runs --repeat times after a \
warm-up; the median and the range are reported (on a shared machine the range shows the other \
jobs).\n\nExample:\n  cargo run --release -p sim-host -- bench --repeat 7"
)]
pub struct BenchArgs {
    /// Repetitions of each timing (the median and the range are reported).
    #[arg(long, default_value_t = 5)]
    pub repeat: u32,
    /// Also find, per fault and sign, the smallest change detected within 10 s under the
    /// healthy service profile (load and supply steps, noisy sensors) at zero false alarms
    /// (about a minute on two cores).
    #[arg(long)]
    pub detection: bool,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bench`.
///
/// # Errors
/// Simulator errors, or a healthy profile that alarms (the detection limits would mean
/// nothing).
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let figures = sim_host::bench::measure(args.repeat)?;
    let limits = if args.detection {
        let bar = progress::bar(36, "detection limits", true);
        let l = sim_host::bench::detection_limits(&|| bar.inc(1))?;
        bar.finish_and_clear();
        Some(l)
    } else {
        None
    };
    if args.json {
        render::json::print(&render::json::BenchReport {
            figures: &figures,
            detection_limits: limits.as_deref(),
        })
    } else {
        render::text::bench(&figures, limits.as_deref())
    }
}
