//! `sim-host`: the drive monitor's host tool. See `sim-host --help`.
//!
//! The binary owns the command line and the rendering (`cli`): clap parses the arguments,
//! each command turns them into the library's domain types at once, calls the library
//! (`sim_host`), and renders the result as text, JSON or HTML/plots (`cli::render`).
//! Errors reach `main` as one `anyhow` chain and leave as one line on stderr, exit code 2.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match cli::Cli::try_parse() {
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
    match cli::run(args.cmd) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line_error(&e));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes on one line; a cause whose text the message already holds
/// (many errors quote their source) is not repeated.
fn one_line_error(e: &anyhow::Error) -> String {
    let mut msg = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    sim_host::one_line(&msg)
}
