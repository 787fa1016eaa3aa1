//! `sim-host simulate --params P.toml --scenario S.toml --out D.csv [--json]`: generate a
//! measurement log (DESIGN.md §3 CSV schema) from a motor parameter file and a scenario
//! (format: `sim_host::sim`).
//!
//! The CSV is written atomically (`sim_host::log::LogWriter`): an interrupted or failed run
//! leaves no partial output, and the output may not be one of the inputs. A progress bar
//! goes to stderr when it is a terminal.

use super::output_guard::OutputGuard;
use super::{progress, render};
use clap::Args;
use sim_host::log::LogWriter;
use sim_host::params::ParamFile;
use sim_host::sim::{simulate, Scenario};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `simulate`.
#[derive(Debug, Args)]
#[command(
    about = "Simulate an induction motor (faults, effects, sensors) and write a CSV log",
    long_about = "Simulate a 3-phase induction motor (full-order T-equivalent model, started \
direct-on-line) with the supply, load, faults, physical effects and sensor chain of a scenario \
file, and write the sensor readings as a CSV log (t_s, va_V..vc_V, ia_A..ic_A, wm_rad_s, \
enc_count). See examples/scenarios/*.toml for the scenario format. Values are written at f32 \
precision (7 significant digits; time at f64).\n\nExample:\n  sim-host \
simulate --params examples/params/2p2kw.toml --scenario examples/scenarios/reference_2p2kw.toml \
--out ref.csv"
)]
pub struct SimulateArgs {
    /// Motor parameter file (TOML, DESIGN.md §3).
    #[arg(long)]
    pub params: PathBuf,
    /// Scenario file (TOML; see examples/scenarios).
    #[arg(long)]
    pub scenario: PathBuf,
    /// Output CSV (written atomically; never one of the inputs).
    #[arg(long)]
    pub out: PathBuf,
    /// Override the scenario's noise seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Print one JSON summary document on stdout instead of the text summary.
    #[arg(long)]
    pub json: bool,
}

/// Runs `simulate`.
///
/// # Errors
/// Unreadable or invalid inputs (one line naming the file and key), an output that is an
/// input, or an I/O error writing the output.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    OutputGuard::new(&[&args.params, &args.scenario]).check_files(&[&args.out])?;
    let params = ParamFile::load(&args.params)?;
    let mut sc = Scenario::load(&args.scenario)?;
    if let Some(s) = args.seed {
        sc.seed = s;
    }
    let start = Instant::now();
    let n = (sc.duration_s * sc.sample_rate_hz).round() as u64;
    let bar = progress::bar(n, "simulate", true);
    let mut w = LogWriter::create(&args.out, sc.sensors.channels())?;
    let mut err = None;
    let mut k = 0u64;
    let summary = simulate(&params, &sc, |r| {
        if err.is_none() {
            if let Err(e) = w.write_row(r) {
                err = Some(e);
            }
        }
        k += 1;
        if k.is_multiple_of(8192) {
            bar.set_position(k);
        }
    })?;
    if let Some(e) = err {
        return Err(e.into());
    }
    w.finish()?;
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    if args.json {
        render::json::print(&render::json::simulate(&args.out, wall_s, &summary))
    } else {
        render::text::simulate(&args.out, wall_s, &summary)
    }
}
