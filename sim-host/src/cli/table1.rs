//! `sim-host table1`: reproduce the paper's Table 1 end to end
//! ([`monitor_studies::fault_signatures`]).

use super::args::AngleArg;
use super::{progress, render};
use clap::Args;
use monitor_api::files::ParamFile;
use monitor_studies::fault_signatures::{run_all, Protocol};
use std::path::PathBuf;

/// Arguments of `table1`.
#[derive(Debug, Args)]
#[command(
    about = "Reproduce the paper's Table 1 end to end: every fault at +50 % and -50 %",
    long_about = "For each of the nine faults of the paper's Table 1, at +50 % and -50 %: simulate \
the motor (direct-on-line start, viscous load Bl*omega, 12-bit noisy sensors), commission the monitor \
on the healthy part (2-4 s), switch the fault on at 4.5 s, and read the residual lamps at the end of \
the run. Prints the measured signature next to the paper's; '*' marks a difference (see docs/paper-errata.md's \
notes on where the physics disagrees with the paper).\n\nExample:\n  sim-host table1 --json"
)]
pub struct Table1Args {
    /// Motor parameter file (default: the 3 hp reference motor).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Frame angle source.
    #[arg(long, value_enum, default_value_t = AngleArg::RotorFlux)]
    pub angle: AngleArg,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `table1`.
///
/// # Errors
/// A bad parameter file, or a simulation the parameters make impossible.
pub fn run(args: &Table1Args) -> anyhow::Result<()> {
    let (params, name) = match &args.params {
        Some(p) => (ParamFile::load(p)?, p.display().to_string()),
        None => (
            ParamFile::reference_3hp(),
            "3 hp reference motor".to_string(),
        ),
    };
    let proto = Protocol {
        angle_source: args.angle.into(),
        ..Protocol::default()
    };
    let bar = progress::bar(18, "simulating 18 fault cases", true);
    let rows = run_all(&params, &proto, || bar.inc(1))?;
    bar.finish_and_clear();
    let table = render::json::Table1Report::new(name, proto.angle_source, rows);
    if args.json {
        render::json::print(&mut crate::cli::out::stdout(), &table)
    } else {
        render::text::table1(&mut crate::cli::out::text(), &table)
    }
}
