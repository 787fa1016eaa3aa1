//! The command line: clap's argument types and one `run` per command. Each command turns
//! its arguments into the library's domain types at once, calls the library and hands the
//! result to one renderer per output format ([`render`]: text, JSON, HTML and plots).
//! Progress bars ([`progress`]) and the guard against overwriting an input
//! ([`output_guard`]) are the binary's too.

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
mod output_guard;
mod params_cmd;
mod progress;
mod render;
mod simulate;
mod store_run;
mod table1;
mod trend;
pub mod words;

use clap::{Parser, Subcommand, ValueEnum};
use monitor_core::{AngleSource, EffectKind, Fault, ResidualForm};

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

/// Frame angle source on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AngleArg {
    /// Rotor-flux angle from the core's current model (encoder speed, nominal Rr, Lr): the
    /// frame in which the paper's steady-state model is exact.
    RotorFlux,
    /// SRF-PLL on the voltages (voltage orientation).
    Pll,
    /// Phase-a voltage zero crossing + frequency estimate (the paper's hardware).
    ZeroCrossing,
}

impl From<AngleArg> for AngleSource {
    fn from(a: AngleArg) -> Self {
        match a {
            AngleArg::RotorFlux => AngleSource::RotorFluxCurrentModel,
            AngleArg::Pll => AngleSource::Pll,
            AngleArg::ZeroCrossing => AngleSource::ZeroCrossing,
        }
    }
}

impl From<AngleSource> for AngleArg {
    fn from(a: AngleSource) -> Self {
        match a {
            AngleSource::RotorFluxCurrentModel => AngleArg::RotorFlux,
            AngleSource::Pll => AngleArg::Pll,
            AngleSource::ZeroCrossing => AngleArg::ZeroCrossing,
        }
    }
}

/// What is known of the load, on the command line (`diagnose --load`, `hmi --load`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LoadArg {
    /// The load is an unknown input (real service): a load change is an operating-point
    /// change, reported as a load move; the friction class b/bl is never named.
    Unknown,
    /// The paper's fixed viscous load (Table 1): a B/Bl change is a fault, named `b/bl`.
    Viscous,
}

impl From<LoadArg> for monitor_api::replay::LoadModel {
    fn from(a: LoadArg) -> Self {
        match a {
            LoadArg::Unknown => monitor_api::replay::LoadModel::Unknown,
            LoadArg::Viscous => monitor_api::replay::LoadModel::Viscous,
        }
    }
}

impl From<monitor_api::replay::LoadModel> for LoadArg {
    fn from(a: monitor_api::replay::LoadModel) -> Self {
        match a {
            monitor_api::replay::LoadModel::Unknown => LoadArg::Unknown,
            monitor_api::replay::LoadModel::Viscous => LoadArg::Viscous,
        }
    }
}

/// Residual form on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ResidualArg {
    /// Eq. (37), derivative terms dropped (the paper's).
    Steady,
    /// Eq. (36), with filtered derivatives: valid in transients.
    Full,
}

impl From<ResidualArg> for ResidualForm {
    fn from(a: ResidualArg) -> Self {
        match a {
            ResidualArg::Steady => ResidualForm::Steady,
            ResidualArg::Full => ResidualForm::Full,
        }
    }
}

impl From<ResidualForm> for ResidualArg {
    fn from(a: ResidualForm) -> Self {
        match a {
            ResidualForm::Steady => ResidualArg::Steady,
            ResidualForm::Full => ResidualArg::Full,
        }
    }
}

/// Parses a fault name ([`monitor_core::Fault::name`]).
pub fn parse_fault(s: &str) -> Result<Fault, String> {
    Fault::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Fault::ALL.iter().map(|f| f.name()).collect();
        format!("unknown fault '{s}' (one of {})", names.join(", "))
    })
}

/// Parses an effect name of the library.
pub fn parse_effect(s: &str) -> Result<EffectKind, String> {
    monitor_api::analysis::parse_effect(s.trim()).map_err(|e| e.to_string())
}

/// A time on the command line [s]: a finite number >= 0 (negative values reach this
/// parser, so that `--from -5` is refused by name rather than taken for a flag).
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        Ok(x) => Err(format!(
            "{x} is not a time: give a finite number of seconds >= 0"
        )),
        Err(_) => Err(format!("'{s}' is not a number of seconds")),
    }
}

/// A duration or step on the command line [s]: a finite number > 0.
pub fn parse_positive_seconds(s: &str) -> Result<f64, String> {
    match parse_seconds(s)? {
        x if x > 0.0 => Ok(x),
        x => Err(format!("{x} s: give a finite number of seconds > 0")),
    }
}

/// Writes `bytes` to `out` atomically when an output was asked for (`--out`); nothing
/// otherwise.
///
/// # Errors
/// "writing PATH" with the I/O error.
pub fn write_out(out: Option<&std::path::Path>, bytes: &[u8]) -> anyhow::Result<()> {
    if let Some(out) = out {
        anyhow::Context::with_context(monitor_api::files::write_atomic(out, bytes), || {
            format!("writing {}", out.display())
        })?;
    }
    Ok(())
}

/// Standard output for the renderers: locked, and every write error marked as a
/// [`StdoutError`] (kept as the `io::Error`'s inner error, its kind unchanged), so that
/// `main` can tell a closed pipe (quiet exit) or a full disk on stdout from other errors.
pub fn stdout() -> Stdout {
    Stdout(std::io::stdout().lock())
}

/// Locked standard output whose write errors are [`StdoutError`]s ([`stdout`]).
pub struct Stdout(std::io::StdoutLock<'static>);

/// A write to standard output failed (the reader closed the pipe, the disk is full, ...).
#[derive(Debug, thiserror::Error)]
#[error("cannot write to standard output: {0}")]
pub struct StdoutError(std::io::Error);

impl Stdout {
    fn mark(e: std::io::Error) -> std::io::Error {
        std::io::Error::new(e.kind(), StdoutError(e))
    }
}

impl std::io::Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf).map_err(Self::mark)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush().map_err(Self::mark)
    }
}

/// The kind of the stdout write error in `e`'s chain ([`StdoutError`]), if any.
pub fn stdout_error_kind(e: &anyhow::Error) -> Option<std::io::ErrorKind> {
    e.chain().find_map(|c| {
        let io = c.downcast_ref::<std::io::Error>()?;
        io.get_ref()?.downcast_ref::<StdoutError>()?;
        Some(io.kind())
    })
}

/// A command stopped by SIGINT or SIGTERM after removing its partial output.
#[derive(Debug, thiserror::Error)]
#[error("interrupted by {signal_name}: {what}")]
pub struct Interrupted {
    /// The signal's number.
    pub signal: i32,
    /// "SIGINT" or "SIGTERM".
    pub signal_name: &'static str,
    /// What was done about the output, e.g. "no output written, temporary file removed".
    pub what: String,
}

impl Interrupted {
    /// The shell's convention: 128 + the signal number (130 for SIGINT, 143 for SIGTERM).
    pub fn exit_status(&self) -> u8 {
        u8::try_from(128 + self.signal).unwrap_or(1)
    }
}

/// SIGINT and SIGTERM as a flag a long loop checks ([`Interruption::signal`]), from
/// [`Interruption::catch`] to the end of the process.
///
/// Only the commands that clean up or report on a signal catch it (`simulate` and
/// `convert` around their write loops, `diagnose` around its replay); every other
/// command keeps the default action (the process ends at once; its outputs are written
/// atomically at the end, so it leaves at most a small temporary file).
/// A second signal while the first is being handled ends the process at once with
/// 128 + the signal, as the default action would.
pub struct Interruption {
    /// The signal that arrived, 0 for none.
    signal: std::sync::Arc<std::sync::atomic::AtomicUsize>,
}

impl Interruption {
    /// Starts catching SIGINT and SIGTERM. (There is no way back to the default action:
    /// catch only where the rest of the command checks [`Interruption::signal`].)
    ///
    /// # Errors
    /// The handlers could not be installed.
    pub fn catch() -> anyhow::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        use std::sync::atomic::{AtomicBool, AtomicUsize};
        use std::sync::Arc;
        let armed = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM] {
            // The order matters: the shutdown sees the flag as the previous signal left it.
            flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(&armed))?;
            flag::register(sig, Arc::clone(&armed))?;
            flag::register_usize(sig, Arc::clone(&signal), sig.unsigned_abs() as usize)?;
        }
        Ok(Interruption { signal })
    }

    /// Whether SIGINT or SIGTERM has arrived (one atomic load: cheap enough for every row).
    pub fn caught(&self) -> bool {
        self.signal.load(std::sync::atomic::Ordering::Relaxed) != 0
    }

    /// The signal caught so far, if any, as an [`Interrupted`] error saying `what` was done.
    pub fn signal(&self, what: &str) -> Option<Interrupted> {
        use signal_hook::consts::SIGINT;
        let sig = self.signal.load(std::sync::atomic::Ordering::SeqCst);
        let signal = i32::try_from(sig).ok().filter(|s| *s != 0)?;
        Some(Interrupted {
            signal,
            signal_name: if signal == SIGINT {
                "SIGINT"
            } else {
                "SIGTERM"
            },
            what: what.to_string(),
        })
    }
}
