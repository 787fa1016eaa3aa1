//! The `sim-host` subcommands. Each module holds its clap arguments (`*Args`) and a
//! `run(&Args) -> anyhow::Result<()>`; `main.rs` only dispatches.

pub mod bench;
pub mod compare;
pub mod demo;
pub mod diagnose;
pub mod explain;
pub mod simulate;
pub mod table1;

use std::path::Path;

/// Refuses to write `out` when it is one of the `inputs` (never overwrite an input).
pub fn refuse_overwrite(out: &Path, inputs: &[&Path]) -> anyhow::Result<()> {
    let canon = |p: &Path| std::fs::canonicalize(p).ok();
    let o = canon(out);
    for i in inputs {
        if o.is_some() && o == canon(i) {
            anyhow::bail!("refusing to overwrite the input {}", i.display());
        }
    }
    Ok(())
}

/// Prints `v` as one JSON document on stdout.
pub fn print_json<T: serde::Serialize>(v: &T) -> anyhow::Result<()> {
    println!("{}", serde_json::to_string_pretty(v)?);
    Ok(())
}

/// A lamp as a character: lit or dark.
pub fn lamp(on: bool) -> &'static str {
    if on {
        "●"
    } else {
        "○"
    }
}
