//! `sim-host calibrate-turns`: learn a calibration of the shorted-turn level from labelled
//! runs of one motor ([`monitor_api::learn_turn_calibration`]), for `diagnose
//! --turn-calibration`.

use anyhow::Context;
use clap::Args;
use monitor_core::Phase;
use std::path::PathBuf;

/// Arguments of `calibrate-turns`.
#[derive(Debug, Args)]
#[command(
    about = "Learn the shorted-turn level's calibration from labelled runs of one motor",
    long_about = "Learn a calibration of the shorted-turn level (unbalance.shorted_turns) from \
labelled runs of one motor on a test bench: each LOG=PHASE:PERCENT (PERCENT of PHASE's turns \
shorted, e.g. run_7.csv=c:30) is diagnosed as diagnose would (same --parallel-paths and \
--baseline), and the loop ratio of the short it names is kept where it names the label's \
phase. The calibration maps, per phase, the loop ratio to the fraction through the labelled \
levels' means (docs/isolation.md, \"How many turns\"). Give it to diagnose with \
--turn-calibration FILE: the report then says the level comes from the calibration, and keeps \
the model's beside it. It holds for that motor on that bench, judged against the same kind \
of reference.\n\nExample:\n  sim-host calibrate-turns --params motor.toml --parallel-paths 2 \
--out cal.json a10.csv=a:10 a20.csv=a:20 c30.csv=c:30"
)]
pub struct CalibrateTurnsArgs {
    /// Motor parameter file (TOML, docs/design.md).
    #[arg(long)]
    pub params: PathBuf,
    /// Labelled runs, each LOG=PHASE:PERCENT (`run.csv=c:30`: 30 % of phase c's turns).
    #[arg(required = true, value_name = "LOG=PHASE:PERCENT", value_parser = parse_labelled)]
    pub labelled: Vec<(PathBuf, Phase, f32)>,
    /// Parallel paths of each phase of the winding (as for diagnose).
    #[arg(long, default_value_t = monitor_api::replay::ParallelPaths::ONE, value_parser = super::words::parse_parallel_paths)]
    pub parallel_paths: monitor_api::replay::ParallelPaths,
    /// Healthy logs of the same motor (as for diagnose); without, each run is judged
    /// within itself.
    #[arg(long, value_name = "HEALTHY", num_args = 1.., action = clap::ArgAction::Append)]
    pub baseline: Vec<PathBuf>,
    /// Where to write the calibration (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Print one JSON document (the runs used and left out) on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `LOG=PHASE:PERCENT`.
fn parse_labelled(s: &str) -> Result<(PathBuf, Phase, f32), String> {
    let (log, label) = s
        .rsplit_once('=')
        .ok_or_else(|| format!("'{s}': give LOG=PHASE:PERCENT (run.csv=c:30)"))?;
    let (phase, pct) = label
        .split_once(':')
        .ok_or_else(|| format!("'{label}': give PHASE:PERCENT (c:30)"))?;
    let phase = Phase::from_name(&phase.to_ascii_lowercase())
        .ok_or_else(|| format!("'{phase}': the phase is a, b or c"))?;
    let pct: f32 = pct
        .trim_end_matches('%')
        .parse()
        .map_err(|_| format!("'{pct}': the percentage of the turns is a number"))?;
    Ok((PathBuf::from(log), phase, pct / 100.0))
}

/// Runs `calibrate-turns`.
///
/// # Errors
/// A bad parameter file, log or label; no labelled run naming its phase; the output file
/// not writable.
pub fn run(args: &CalibrateTurnsArgs) -> anyhow::Result<()> {
    let mut req = monitor_api::DiagnoseRequest::default();
    req.options.turn_level.parallel_paths = args.parallel_paths;
    req.baseline = args
        .baseline
        .iter()
        .map(monitor_api::LogSource::from)
        .collect();
    let labelled: Vec<monitor_api::Labelled> = args
        .labelled
        .iter()
        .map(|(log, phase, fraction)| monitor_api::Labelled {
            log: monitor_api::LogSource::from(log),
            phase: *phase,
            fraction: *fraction,
        })
        .collect();
    let learned = monitor_api::learn_turn_calibration(&args.params, &labelled, &req)?;
    let text = serde_json::to_string_pretty(&learned.calibration)?;
    std::fs::write(&args.out, text).with_context(|| format!("--out {}", args.out.display()))?;
    if args.json {
        let doc = serde_json::json!({
            "out": args.out.display().to_string(),
            "used": learned.used.iter().map(|(f, r)| serde_json::json!({"log": f, "loop_ratio": r})).collect::<Vec<_>>(),
            "left_out": learned.left_out,
            "calibration": learned.calibration,
        });
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(());
    }
    println!(
        "learned from {} labelled runs, written to {}",
        learned.used.len(),
        args.out.display()
    );
    for (f, r) in &learned.used {
        println!("  {f}: loop ratio {r:.3}");
    }
    for why in &learned.left_out {
        println!("  left out: {why}");
    }
    Ok(())
}
