//! `sim-host`: the drive monitor's host tool. See `sim-host --help`.

use clap::{Parser, Subcommand};
use sim_host::commands::{bench, compare, demo, diagnose, explain, simulate, table1};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "sim-host",
    version,
    about = "Induction-motor drive monitor, host side: simulator, log replay through the core, model-vs-measurement",
    long_about = "The host side of the drive monitor. It simulates 3-phase induction motors with \
faults and physical effects, replays measurement logs through exactly the core code the firmware runs \
(Clarke/Park, synchronous angle, M/T encoder speed, parity-equation residuals of the paper's simplified \
D-Q model, fault signature matching), and compares the model with measurements to show where it fails \
and which physical effect is missing.\n\nStart with:\n  sim-host demo\n  sim-host table1\n  \
sim-host simulate --params P.toml --scenario S.toml --out D.csv\n  sim-host diagnose --params P.toml \
D.csv --commission 2:4\n  sim-host compare --params P.toml D.csv\n  sim-host explain --params P.toml \
D.csv\n\nEvery command takes --json (one JSON document on stdout; progress and logs on stderr)."
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    Demo(demo::DemoArgs),
    Simulate(simulate::SimulateArgs),
    Diagnose(diagnose::DiagnoseArgs),
    Table1(table1::Table1Args),
    Compare(compare::CompareArgs),
    Explain(explain::ExplainArgs),
    Bench(bench::BenchArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                e.exit();
            }
            // One line: clap's first line names the problem; the usage hint is dropped.
            let text = e.render().to_string();
            let first = text
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("bad arguments");
            eprintln!("{} (see --help)", first.trim());
            return ExitCode::from(2);
        }
    };
    let r = match &cli.cmd {
        Cmd::Demo(a) => demo::run(a),
        Cmd::Simulate(a) => simulate::run(a),
        Cmd::Diagnose(a) => diagnose::run(a),
        Cmd::Table1(a) => table1::run(a),
        Cmd::Compare(a) => compare::run(a),
        Cmd::Explain(a) => explain::run(a),
        Cmd::Bench(a) => bench::run(a),
    };
    match r {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let msg = format!("{e:#}");
            eprintln!(
                "error: {}",
                msg.split_whitespace().collect::<Vec<_>>().join(" ")
            );
            ExitCode::from(2)
        }
    }
}
