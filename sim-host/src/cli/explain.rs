//! `sim-host explain`: which physical effect is missing from the model.

use super::compare::{self, check_outputs, human_number, load, progress_bar, Common};
use crate::analysis::{report, Options};
use std::path::PathBuf;

/// Arguments of `explain`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    about = "Rank the physical effects that could explain the model's error",
    long_about = "Rank the physical effects missing from the paper's simplified model.\n\n\
Every library effect not yet in the model (thermal_drift, saturation, iron_loss, \
coulomb_friction, windage, load_torque, supply_unbalance, phase_asymmetry, flux_dynamics, \
current_dynamics) is added in turn and fitted together with the base parameters (Ra, Ls, \
B+Bl, J). Candidates are ranked by the error on held-back time windows the fit never saw, \
so an effect that only fits noise does not win. When no candidate explains at least 50 % of \
the held-back error, or the error is already near the noise floor, the answer is \
`unexplained: true` rather than a wrong name.\n\n\
Workflow:\n  sim-host compare --params motor.toml run.csv          # where does the model fail?\n  \
sim-host explain --params motor.toml run.csv          # which effect is missing?\n  \
sim-host explain --compare --params motor.toml run.csv  # both, reading a long log once\n  \
sim-host compare --params motor.toml run.csv --effects load_torque   # the error falls\n  \
sim-host explain --params motor.toml run.csv --effects load_torque   # anything else?\n\n\
JSON (--json): baseline_normalized_rms_error, ranking [{effect, normalized_rms_error, \
explained_fraction, validation_normalized_rms_error, n_parameters, parameters, summary}], \
unexplained, verdict, skipped, unbalance, noise_floor."
)]
pub struct ExplainArgs {
    /// Shared options.
    #[command(flatten)]
    pub common: Common,
    /// Also run `compare` on the same read of the log and print its result first: one read
    /// of a long log instead of two. With --json the output is {"compare": ..., "explain":
    /// ...}; --plot and --report get explain's charts and report.
    #[arg(long)]
    pub compare: bool,
}

/// Runs `explain`.
///
/// # Errors
/// Bad parameter file, unreadable or malformed log, unknown effect, output not writable;
/// each a one-line message.
pub fn run(args: &ExplainArgs) -> anyhow::Result<()> {
    let c = &args.common;
    check_outputs(c)?;
    let a = load(c)?;
    let opts = Options {
        effects: c.effect_list(),
        fit_base: !c.no_fit,
    };
    // compare's result is printed (or kept as JSON) before explain runs, and its prediction
    // dropped, so memory stays at explain's.
    let compared = if args.compare {
        let out = a.compare(&opts)?;
        if c.json {
            Some(serde_json::to_value(&out.report)?)
        } else {
            compare::print_text(&c.log, &out.report);
            None
        }
    } else {
        None
    };
    let pb = progress_bar(a.data.len() > 50_000, "explain: fitting candidates");
    let pbc = pb.clone();
    let out = a.explain(&opts, &move |f| pbc.set_position((f * 1000.0) as u64))?;
    pb.finish_and_clear();
    // Charts only when something is written (they thin copies of the full series).
    let charts = if c.plot.is_some() || c.report.is_some() {
        report::explain_charts(&a.data, &out.before, out.after.as_ref())
    } else {
        Vec::new()
    };
    if let Some(dir) = &c.plot {
        report::write_charts(dir, &charts).map_err(anyhow::Error::msg)?;
    }
    if let Some(dir) = &c.report {
        // The report folder gets its own copy of the plots (SVG inline, PNG beside).
        let svgs = report::write_charts(dir, &charts).map_err(anyhow::Error::msg)?;
        let html = report::explain_html(&c.log.display().to_string(), &out, &svgs);
        let path: PathBuf = dir.join("report.html");
        crate::log::write_atomic(&path, html.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        eprintln!("report: {}", path.display());
    }
    let r = &out.report;
    if c.json {
        match compared {
            Some(cmp) => println!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({
                    "compare": cmp,
                    "explain": r,
                }))?
            ),
            None => println!("{}", serde_json::to_string_pretty(r)?),
        }
        return Ok(());
    }
    println!("explain {}", c.log.display());
    println!(
        "  model as configured: {}; error {} (held-back {}), noise floor {}",
        if r.effects.is_empty() {
            "paper's model".to_string()
        } else {
            r.effects.join(",")
        },
        human_number(r.baseline_normalized_rms_error),
        human_number(r.baseline_validation_normalized_rms_error),
        human_number(r.noise_floor)
    );
    println!(
        "  {:<4} {:<18} {:>10} {:>10} {:>10}  fitted",
        "rank", "effect", "error", "held-back", "explained"
    );
    for (i, k) in r.ranking.iter().enumerate() {
        println!(
            "  {:<4} {:<18} {:>10} {:>10} {:>9.0}%  {}",
            i + 1,
            k.effect,
            human_number(k.normalized_rms_error),
            human_number(k.validation_normalized_rms_error),
            100.0 * k.explained_fraction,
            k.summary
        );
    }
    for s in &r.skipped {
        println!("  skipped: {s}");
    }
    println!("  unbalance: {}", r.unbalance.summary);
    println!("{}", r.verdict);
    Ok(())
}
