//! `sim-host diagnose`: replay a log through the core and report lamps, candidates and
//! the negative-sequence analysis.

use crate::log::LogReader;
use crate::params::ParamFile;
use crate::replay::{Replay, ReplayOptions};
use anyhow::Context;
use clap::{Args, ValueEnum};
use monitor_core::{AngleSource, ResidualForm};
use std::path::PathBuf;

/// Frame angle source on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AngleArg {
    /// Rotor-flux angle from the current model (encoder speed, nominal Rr, Lr): the frame in
    /// which the paper's steady-state model is exact.
    RotorFlux,
    /// SRF-PLL on the voltages (voltage orientation).
    Pll,
    /// Phase-a voltage zero crossing + frequency estimate (the paper's hardware).
    ZeroCrossing,
}

impl From<AngleArg> for AngleSource {
    fn from(a: AngleArg) -> Self {
        match a {
            AngleArg::RotorFlux => AngleSource::RotorFlux,
            AngleArg::Pll => AngleSource::Pll,
            AngleArg::ZeroCrossing => AngleSource::ZeroCrossing,
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

/// Arguments of `diagnose`.
#[derive(Debug, Args)]
#[command(
    about = "Replay a measurement log through the core: lamps r1..r4, fault candidates, unbalance",
    long_about = "Replay a measurement log (DESIGN.md CSV schema) through exactly the core code the \
firmware runs, and report the residual lamps r1..r4, the fault candidates of the paper's Table 1 with \
their probabilities, when a fault was first detected, and the negative-sequence (unbalance / faulty \
phase) analysis.\n\nWithout --commission the fixed thresholds are used (3 % of each normalised \
residual). With --commission START:END the healthy mean and spread of every residual are learned \
over that part of the log (seconds) and the lamps use mean +/- k*spread with debounce and \
hysteresis.\n\nLogs with only t_s and the three currents still get the unbalance analysis (the \
supply is taken from the parameter file).\n\nExample:\n  sim-host diagnose --params motor.toml \
log.csv --commission 2:4"
)]
pub struct DiagnoseArgs {
    /// Motor parameter file (TOML, DESIGN.md §3).
    #[arg(long)]
    pub params: PathBuf,
    /// Measurement log (CSV).
    pub log: PathBuf,
    /// Learn healthy thresholds over START:END seconds of the log.
    #[arg(long, value_name = "START:END", value_parser = parse_window)]
    pub commission: Option<(f64, f64)>,
    /// Frame angle source.
    #[arg(long, value_enum, default_value_t = AngleArg::RotorFlux)]
    pub angle: AngleArg,
    /// Residual form the lamps act on.
    #[arg(long, value_enum, default_value_t = ResidualArg::Steady)]
    pub residuals: ResidualArg,
    /// Timeline resolution in the output [s].
    #[arg(long, default_value_t = 0.5)]
    pub timeline_step: f64,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Parses `START:END` (seconds).
pub fn parse_window(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("'{s}' is not START:END (seconds), e.g. 2:4"))?;
    let a: f64 = a
        .trim()
        .parse()
        .map_err(|_| format!("'{a}' is not a number of seconds"))?;
    let b: f64 = b
        .trim()
        .parse()
        .map_err(|_| format!("'{b}' is not a number of seconds"))?;
    if !(a >= 0.0 && b > a) {
        return Err(format!("'{s}': need 0 <= START < END"));
    }
    Ok((a, b))
}

/// Runs `diagnose`.
pub fn run(args: &DiagnoseArgs) -> anyhow::Result<()> {
    let params = ParamFile::load(&args.params)?;
    let mut reader = LogReader::open(&args.log)?;
    // Estimate the sample rate from the first rows, then stream the rest.
    let mut head = Vec::new();
    while head.len() < 64 {
        match reader.next_row()? {
            Some(r) => head.push(r),
            None => break,
        }
    }
    if head.len() < 2 {
        anyhow::bail!(
            "{}: the log needs at least two data rows",
            args.log.display()
        );
    }
    let (first, last) = (head[0].t_s, head[head.len() - 1].t_s);
    let fs = (head.len() - 1) as f64 / (last - first);
    let opts = ReplayOptions {
        angle_source: args.angle.into(),
        residual_form: match args.residuals {
            ResidualArg::Steady => ResidualForm::Steady,
            ResidualArg::Full => ResidualForm::Full,
        },
        commission: args.commission,
        timeline_step_s: args.timeline_step.max(1e-4),
    };
    let mut replay = Replay::new(&params, reader.channels(), fs, opts)
        .with_context(|| format!("{}", args.log.display()))?;
    for r in &head {
        replay.push(r);
    }
    while let Some(r) = reader.next_row()? {
        replay.push(&r);
    }
    let rep = replay.finish();
    if args.json {
        return super::print_json(&rep);
    }
    println!(
        "diagnose {} ({} rows, {:.0} Hz, angle: {})",
        args.log.display(),
        rep.rows,
        fs,
        rep.angle_source
    );
    match rep.commission {
        Some((a, b)) => println!("thresholds: learned over {a}..{b} s (mean +/- k*spread)"),
        None => println!("thresholds: fixed (no --commission window given)"),
    }
    for s in &rep.skipped {
        println!("skipped: {s}");
    }
    if rep.skipped.is_empty() {
        println!("\n  time    speed   r1      r2      r3      r4      lamps     top candidate");
        for p in &rep.timeline {
            let lamps: String = p
                .lamps
                .iter()
                .map(|l| super::lamp(*l))
                .collect::<Vec<_>>()
                .join("");
            let state = if p.commissioning {
                "learning".to_string()
            } else if !p.quasi_steady {
                "transient (lamps hold)".to_string()
            } else if !p.evaluating {
                "settling".to_string()
            } else {
                p.top
                    .as_ref()
                    .map(|t| format!("{t} {:.0} %", 100.0 * p.top_probability))
                    .unwrap_or_else(|| "healthy".into())
            };
            println!(
                "{:6.2} s {:6.1} {:+.4} {:+.4} {:+.4} {:+.4}  {lamps}  {state}",
                p.t_s,
                p.speed_rad_s,
                p.residuals[0],
                p.residuals[1],
                p.residuals[2],
                p.residuals[3]
            );
        }
        let lit: Vec<&str> = rep
            .lamps
            .iter()
            .filter(|(_, v)| **v)
            .map(|(k, _)| k.as_str())
            .collect();
        println!(
            "\nfinal lamps: {}",
            if lit.is_empty() {
                "none".to_string()
            } else {
                lit.join(" ")
            }
        );
        match rep.first_detection_s {
            Some(t) => println!("first detection: {t:.2} s"),
            None => println!("first detection: none"),
        }
        if rep.candidates.is_empty() {
            println!("candidates: none");
        } else {
            let c: Vec<String> = rep
                .candidates
                .iter()
                .map(|c| format!("{} {:.0} %", c.fault, 100.0 * c.probability))
                .collect();
            println!("candidates: {}", c.join(", "));
        }
    }
    let u = &rep.unbalance;
    println!(
        "unbalance: |I2|/|I1| = {:.2} %, suspect phase: {}",
        100.0 * u.negative_sequence_ratio,
        u.suspect_phase.as_deref().unwrap_or("none")
    );
    Ok(())
}
