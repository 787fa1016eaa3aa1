//! `sim-host`: the drive monitor's host tool. See `sim-host --help`.
//!
//! The binary owns the command line and the rendering (`cli`): clap parses the arguments,
//! each command turns them into the library's domain types at once, calls the library
//! (`sim_host`), and renders the result as text, JSON or HTML/plots (`cli::render`).
//! Errors reach `main` as one `anyhow` chain and leave as one line on stderr.
//!
//! Exit status:
//! - 0: success, and also when the reader of stdout went away (`sim-host table1 --json |
//!   head`): a closed pipe is the reader's choice, not a failure, so the tool stops
//!   quietly, as `cat` or `grep` would with SIGPIPE, but with status 0 rather than 141 so
//!   that `set -o pipefail` scripts do not fail on `| head`;
//! - 1: stdout could not be written (a full disk, an I/O error): one line on stderr;
//! - 2: bad arguments or input, or any other error: one line on stderr;
//! - 130 / 143: interrupted by SIGINT / SIGTERM (128 + the signal, the shell's
//!   convention) during a command that catches it (`simulate` and `convert` remove their
//!   partial output, `diagnose` stops its replay): one line says what was stopped.

mod alloc_tuning;
mod cli;

use clap::{CommandFactory, FromArgMatches};
use std::io::IsTerminal;
use std::process::ExitCode;

/// The width `--help` is wrapped at: the terminal's, at most this; this where the output is
/// no terminal (a pager, a file, a test): 160 characters, the widest line any output keeps
/// to.
const HELP_WIDTH: usize = 160;

/// The command line, its help wrapped at [`HELP_WIDTH`].
fn parse() -> Result<cli::Cli, clap::Error> {
    let mut cmd = cli::Cli::command().max_term_width(HELP_WIDTH);
    if !std::io::stdout().is_terminal() {
        cmd = cmd.term_width(HELP_WIDTH);
    }
    cli::Cli::from_arg_matches(&cmd.try_get_matches()?)
}

fn main() -> ExitCode {
    alloc_tuning::keep_freed_memory();
    let args = match parse() {
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
            // One line: clap's first paragraph names the problem (a missing argument's
            // name is on the lines after the first); the usage hint is dropped.
            let text = e.render().to_string();
            let first: Vec<&str> = text
                .lines()
                .skip_while(|l| l.trim().is_empty())
                .take_while(|l| !l.trim().is_empty())
                .map(str::trim)
                .collect();
            let first = if first.is_empty() {
                "bad arguments".to_string()
            } else {
                first.join(" ")
            };
            report(&format!("{first}{} (see --help)", did_you_mean(&e)));
            return ExitCode::from(2);
        }
    };
    match cli::run(args.cmd) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let status = exit_status(&e);
            if status != 0 {
                report(&format!("error: {}", one_line_error(&e)));
            }
            ExitCode::from(status)
        }
    }
}

/// clap's suggestion for a misspelt command, option or value (`sim-host diagnos`: "; did
/// you mean 'diagnose'?"), which its usage paragraphs carry and the one line keeps; empty
/// when clap has none.
fn did_you_mean(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let kinds = [
        ContextKind::SuggestedSubcommand,
        ContextKind::SuggestedArg,
        ContextKind::SuggestedValue,
    ];
    let names: Vec<String> = kinds
        .iter()
        .filter_map(|k| e.get(*k))
        .flat_map(|v| match v {
            ContextValue::String(s) => vec![s.clone()],
            ContextValue::Strings(s) => s.clone(),
            _ => Vec::new(),
        })
        .map(|s| format!("'{s}'"))
        .collect();
    if names.is_empty() {
        String::new()
    } else {
        format!("; did you mean {}?", names.join(" or "))
    }
}

/// The exit status of a failed command (see the module documentation).
fn exit_status(e: &anyhow::Error) -> u8 {
    if let Some(i) = e.downcast_ref::<cli::Interrupted>() {
        return i.exit_status();
    }
    match cli::stdout_error_kind(e) {
        Some(std::io::ErrorKind::BrokenPipe) => 0,
        Some(_) => 1,
        None => 2,
    }
}

/// Writes one line to stderr; a stderr that cannot be written is ignored (there is nowhere
/// left to report to, and `eprintln!` would panic).
fn report(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// The error and its causes on one line, in the command line's words (a library error
/// names its fields by their flags, `cli::words`); a cause whose text the message already holds
/// (many errors quote their source) is not repeated.
fn one_line_error(e: &anyhow::Error) -> String {
    let mut msg = cli::words::error_text(e.as_ref());
    for cause in e.chain().skip(1) {
        let c = cli::words::error_text(cause);
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    monitor_api::files::one_line(&msg)
}
