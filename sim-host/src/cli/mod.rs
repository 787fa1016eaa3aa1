//! The command line: clap's argument types and one `run` per command. Each command turns
//! its arguments into the library's domain types at once, calls the library and hands the
//! result to one renderer per output format ([`render`]: text, JSON, HTML and plots).
//! Progress bars ([`progress`]) and the guard against overwriting an input
//! ([`output_guard`]) are the binary's too.

mod args;
mod bench;
mod board_record;
mod calibrate_turns;
mod compare;
pub mod convert;
mod demo;
mod diagnose;
mod fleet;
mod hmi;
mod identify;
mod out;
mod output_guard;
mod params_cmd;
mod progress;
mod render;
mod simulate;
mod store_run;
mod table1;
mod trend;
pub mod words;

pub use out::{stdout_error_kind, Interrupted};

use clap::{Parser, Subcommand};

/// The command line.
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
D.csv\n  sim-host hmi\n  sim-host convert D.csv D.parquet\n\nYour own motor (docs/own-motor.md):\n  \
sim-host params from-nameplate --power-kw 2.2 --voltage-v 400 ... --out P.toml\n  \
sim-host identify --params P.toml LOG --out P2.toml --keep-columns\n  sim-host diagnose --params P2.toml LOG --commission A:B\n\nLogs are CSV, TDMS (.tdms) or Parquet (.parquet), by \
their extension.\n\nEvery command but the interactive hmi takes --json (one JSON document on stdout; progress \
and logs on stderr)."
)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub cmd: Cmd,
}

/// The commands. (The variants carry plain comments, not doc comments: clap would take a
/// variant's doc comment as the command's help and hide the teaching `about`/`long_about`
/// of its arguments' struct.)
#[derive(Subcommand)]
pub enum Cmd {
    // The main job.
    Demo(demo::DemoArgs),
    // Generate a log.
    Simulate(simulate::SimulateArgs),
    // Replay a log through the core.
    Diagnose(diagnose::DiagnoseArgs),
    // The paper's Table 1 end to end.
    Table1(table1::Table1Args),
    // Model vs measurement.
    Compare(compare::CompareArgs),
    // Which effect is missing.
    Explain(compare::ExplainArgs),
    // Benchmarks.
    Bench(bench::BenchArgs),
    // The live terminal HMI.
    Hmi(hmi::HmiArgs),
    // Convert a log between CSV, TDMS and Parquet.
    Convert(convert::ConvertArgs),
    // Write the board's motor record.
    BoardRecord(board_record::BoardRecordArgs),
    // Make a parameter file (from a nameplate).
    Params(params_cmd::ParamsArgs),
    // Identify the circuit from a log.
    Identify(identify::IdentifyArgs),
    // Many motors' logs, one row each.
    Fleet(fleet::FleetArgs),
    // A motor's history: the trend of its stored logs.
    Trend(trend::TrendArgs),
    // The shorted-turn level's calibration from labelled runs.
    CalibrateTurns(calibrate_turns::CalibrateTurnsArgs),
}

/// Runs a command.
///
/// # Errors
/// Bad input (one line naming the file, line, column or key) or an I/O error.
pub fn run(cmd: Cmd) -> anyhow::Result<()> {
    match &cmd {
        Cmd::Demo(a) => demo::run(a),
        Cmd::Simulate(a) => simulate::run(a),
        Cmd::Diagnose(a) => diagnose::run(a),
        Cmd::Table1(a) => table1::run(a),
        Cmd::Compare(a) => compare::run_compare(a),
        Cmd::Explain(a) => compare::run_explain(a),
        Cmd::Bench(a) => bench::run(a),
        Cmd::Hmi(a) => hmi::run(a),
        Cmd::Convert(a) => convert::run(a),
        Cmd::BoardRecord(a) => board_record::run(a),
        Cmd::Params(a) => params_cmd::run(a),
        Cmd::Identify(a) => identify::run(a),
        Cmd::Fleet(a) => fleet::run(a),
        Cmd::Trend(a) => trend::run(a),
        Cmd::CalibrateTurns(a) => calibrate_turns::run(a),
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Every option the library describes by name (`DIAGNOSE_OPTIONS`, Python's keywords)
    /// is a flag of `diagnose` (`diagnose.rs`), spelled as the command line spells its field.
    #[test]
    fn every_described_option_is_a_flag() {
        let cli = super::Cli::command();
        let diagnose = cli.find_subcommand("diagnose").expect("diagnose"); // ok: test
        let flags: Vec<&str> = diagnose
            .get_arguments()
            .filter_map(|a| a.get_long())
            .collect();
        for spec in monitor_api::replay::DIAGNOSE_OPTIONS {
            let flag = spec.field.name().replace('_', "-");
            assert!(
                flags.contains(&flag.as_str()),
                "--{flag} is not a flag of diagnose"
            );
        }
    }
}
