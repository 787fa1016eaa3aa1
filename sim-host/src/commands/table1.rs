//! `sim-host table1`: reproduce the paper's Table 1 end to end.

use crate::params::ParamFile;
use crate::table1::{run_all, Protocol, Table1Row};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `table1`.
#[derive(Debug, Args)]
#[command(
    about = "Reproduce the paper's Table 1 end to end: every fault at +50 % and -50 %",
    long_about = "For each of the nine faults of the paper's Table 1, at +50 % and -50 %: simulate \
the motor (direct-on-line start, viscous load Bl*omega, 12-bit noisy sensors), commission the monitor \
on the healthy part (2-4 s), switch the fault on at 4.5 s, and read the residual lamps at the end of \
the run. Prints the measured signature next to the paper's; '*' marks a difference (see the README's \
notes on where the physics disagrees with the paper).\n\nExample:\n  sim-host table1 --json"
)]
pub struct Table1Args {
    /// Motor parameter file (default: the DESIGN.md 3 hp textbook motor).
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Frame angle source.
    #[arg(long, value_enum, default_value_t = super::diagnose::AngleArg::RotorFlux)]
    pub angle: super::diagnose::AngleArg,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Table1Report {
    motor: String,
    angle_source: String,
    rows: Vec<Table1Row>,
    matches_paper: usize,
}

/// Runs `table1`.
pub fn run(args: &Table1Args) -> anyhow::Result<()> {
    let (params, name) = match &args.params {
        Some(p) => (ParamFile::load(p)?, p.display().to_string()),
        None => (
            ParamFile::reference_3hp(),
            "3 hp textbook motor (DESIGN.md)".to_string(),
        ),
    };
    let proto = Protocol {
        angle_source: args.angle.into(),
        ..Protocol::default()
    };
    let bar = crate::progress::bar(18, "simulating 18 fault cases");
    let rows = run_all(&params, &proto, || bar.inc(1))?;
    bar.finish_and_clear();
    let matches = rows.iter().filter(|r| r.signature == r.paper).count();
    if args.json {
        return super::print_json(&Table1Report {
            motor: name,
            angle_source: crate::replay::angle_source_name(proto.angle_source).into(),
            rows,
            matches_paper: matches,
        });
    }
    println!(
        "Table 1 end to end — {name}, angle: {}",
        crate::replay::angle_source_name(proto.angle_source)
    );
    println!("fault           change   measured r1 r2 r3 r4   paper r1 r2 r3 r4   physics r1 r2 r3 r4   candidates");
    let bit = |b: u8| if b == 1 { "I" } else { "0" };
    for r in &rows {
        let m: Vec<&str> = r.signature.iter().map(|b| bit(*b)).collect();
        let p: Vec<&str> = r.paper.iter().map(|b| bit(*b)).collect();
        let e: Vec<&str> = r.expected.iter().map(|b| bit(*b)).collect();
        let diff = if r.signature == r.paper { " " } else { "*" };
        let cands: Vec<String> = r
            .candidates
            .iter()
            .map(|(f, p)| format!("{f} {:.0}%", 100.0 * p))
            .collect();
        println!(
            "{:<15} {:+5.0} %        {}  {}  {}  {}          {}  {}  {}  {} {diff}          {}  {}  {}  {}   {}",
            r.fault,
            100.0 * r.change,
            m[0],
            m[1],
            m[2],
            m[3],
            p[0],
            p[1],
            p[2],
            p[3],
            e[0],
            e[1],
            e[2],
            e[3],
            if cands.is_empty() { "none".to_string() } else { cands.join(", ") }
        );
    }
    let phys = rows.iter().filter(|r| r.signature == r.expected).count();
    println!(
        "\n{matches} of {n} rows equal the paper's Table 1, {phys} of {n} the physically expected signature \
         ('I' = residual moves; '*' = differs from the paper; see the README for why).",
        n = rows.len()
    );
    Ok(())
}
