//! `sim-host compare`: the paper's simplified model against a measurement log.

use crate::analysis::{prep::ReadOptions, report, Analysis, Options};
use anyhow::Context as _;
use std::path::{Path, PathBuf};

/// Options shared by `compare` and `explain`.
#[derive(clap::Args, Debug, Clone)]
pub struct Common {
    /// Parameter file (TOML, DESIGN.md §3) with the user's nominal motor and supply values.
    #[arg(long)]
    pub params: PathBuf,
    /// Measurement log (CSV: t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s; t_s and the
    /// currents are the minimum).
    pub log: PathBuf,
    /// Effects already in the model, comma separated (e.g. `thermal_drift,load_torque`).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the plots (SVG with labels, PNG without text) into this folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write a one-page HTML report (report.html plus the plots) into this folder.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Analyse from this time on [s] (e.g. to leave a start-up out).
    #[arg(long, value_name = "SECONDS")]
    pub from: Option<f64>,
    /// Analyse up to this time [s].
    #[arg(long, value_name = "SECONDS")]
    pub to: Option<f64>,
    /// Keep the nominal base parameters (do not refit Ra, Ls, B+Bl, J).
    #[arg(long)]
    pub no_fit: bool,
}

impl Common {
    /// The effect names, trimmed, empty entries dropped.
    pub fn effect_list(&self) -> Vec<String> {
        self.effects
            .iter()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect()
    }
}

/// Arguments of `compare`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    about = "Compare the paper's simplified model with a measurement log: where does it fail?",
    long_about = "Compare the paper's simplified induction-motor model (eqs. 28-29) with a measurement.\n\n\
The model is driven by the measured voltage (V_qs in the rotor-flux frame) and predicts \
I_qs, the rotor speed omega_r and the phase currents. The parameters the data identify \
(Ra, Ls, B+Bl, J) are refitted, because nominal values are never exact. The output gives \
the RMS error per channel, normalized_rms_error (each channel's RMS error over its RMS, \
averaged), the noise floor, and the worst time windows with their operating condition \
(speed, load current, voltage, time since start) and the dominant frequency of the error.\n\n\
Workflow:\n  sim-host compare --params motor.toml run.csv --report out/   # where does it fail?\n  \
sim-host explain --params motor.toml run.csv                  # which effect is missing?\n  \
sim-host compare --params motor.toml run.csv --effects thermal_drift   # the error falls\n\n\
Current-only logs (t_s, ia_A, ib_A, ic_A) get the unbalance / faulty-phase analysis; the \
model prediction needs the voltages and is skipped with a note.\n\n\
JSON (--json): effects, normalized_rms_error, noise_floor, channels [{channel, rms_error, \
rms_measured, normalized}], worst_windows [{t_start_s, t_end_s, normalized_rms_error, \
condition{speed_rpm, load_current_a, voltage_v, voltage_percent, supply_hz, \
time_since_start_s}, dominant_error_hz, error_kind}], base_parameters, fitted_effects, \
skipped, unbalance, data."
)]
pub struct CompareArgs {
    /// Shared options.
    #[command(flatten)]
    pub common: Common,
}

/// A stderr progress bar (hidden when stderr is not a terminal or `show` is false).
pub fn progress_bar(show: bool, msg: &'static str) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::with_draw_target(
        Some(1000),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(st) =
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed}")
    {
        pb.set_style(st.progress_chars("=> "));
    }
    pb.set_message(msg);
    pb
}

/// Formats a number for the tables (NaN as "-").
pub fn human_number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        "-".into()
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Refuses outputs that would overwrite an input.
///
/// # Errors
/// When report.html or a plot file would be the log or the parameter file.
pub fn check_outputs(c: &Common) -> anyhow::Result<()> {
    for dir in [&c.plot, &c.report].into_iter().flatten() {
        if same_file(dir, &c.log) || same_file(dir, &c.params) {
            anyhow::bail!("output folder {} is an input file", dir.display());
        }
        for f in ["report.html", "overlay_iqs.svg", "overlay_iqs.png"] {
            let p = dir.join(f);
            if same_file(&p, &c.log) || same_file(&p, &c.params) {
                anyhow::bail!("refusing to overwrite input {}", p.display());
            }
        }
    }
    if let (Some(a), Some(b)) = (c.from, c.to) {
        if b <= a {
            anyhow::bail!("--to ({b}) must be after --from ({a})");
        }
    }
    Ok(())
}

/// Reads the parameter file and the log (with a progress bar for large logs).
///
/// # Errors
/// One-line messages naming the file and the problem.
pub fn load(c: &Common) -> anyhow::Result<Analysis> {
    let params = crate::params::ParamFile::load(&c.params)?;
    for e in c.effect_list() {
        if crate::analysis::effects::by_name(&e).is_none() {
            anyhow::bail!(crate::analysis::AnalysisError::UnknownEffect(e));
        }
    }
    let big = std::fs::metadata(&c.log)
        .map(|m| m.len() > 20_000_000)
        .unwrap_or(false);
    let pb = progress_bar(big, "reading log");
    let opts = ReadOptions {
        from_s: c.from.unwrap_or(f64::NEG_INFINITY),
        to_s: c.to.unwrap_or(f64::INFINITY),
    };
    let a = Analysis::load(&c.log, params, opts, &mut |f| {
        pb.set_position((f * 1000.0) as u64)
    })
    .with_context(|| "cannot analyse the log".to_string())
    .map_err(|e| anyhow::anyhow!(crate::params::one_line(&format!("{:#}", e))))?;
    pb.finish_and_clear();
    Ok(a)
}

/// Runs `compare`.
///
/// # Errors
/// Bad parameter file, unreadable or malformed log, unknown effect, output not writable;
/// each a one-line message.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let c = &args.common;
    check_outputs(c)?;
    let a = load(c)?;
    let opts = Options {
        effects: c.effect_list(),
        fit_base: !c.no_fit,
    };
    let out = a.compare(&opts)?;
    // Charts only when something is written (they thin copies of the full series).
    let charts = if c.plot.is_some() || c.report.is_some() {
        report::compare_charts(&a.data, &out)
    } else {
        Vec::new()
    };
    if let Some(dir) = &c.plot {
        report::write_charts(dir, &charts).map_err(anyhow::Error::msg)?;
    }
    if let Some(dir) = &c.report {
        // The report folder gets its own copy of the plots (SVG inline, PNG beside).
        let svgs = report::write_charts(dir, &charts).map_err(anyhow::Error::msg)?;
        let html = report::compare_html(&c.log.display().to_string(), &out, &svgs);
        let path = dir.join("report.html");
        crate::log::write_atomic(&path, html.as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        eprintln!("report: {}", path.display());
    }
    let r = &out.report;
    if c.json {
        println!("{}", serde_json::to_string_pretty(r)?);
        return Ok(());
    }
    print_text(&c.log, r);
    Ok(())
}

/// Prints a `compare` result as text (what `compare` without `--json` shows).
pub fn print_text(log: &Path, r: &crate::analysis::CompareReport) {
    println!("compare {}", log.display());
    println!(
        "  model: {}",
        if r.effects.is_empty() {
            "paper's simplified model (eqs. 28-29)".to_string()
        } else {
            format!("paper's model + {}", r.effects.join(" + "))
        }
    );
    println!(
        "  normalized_rms_error {}   (noise floor {})",
        human_number(r.normalized_rms_error),
        human_number(r.noise_floor)
    );
    for ch in &r.channels {
        println!(
            "  {:<14} rms error {:>10.4}  of rms {:>10.4}  ({:.2} %)",
            ch.channel,
            ch.rms_error,
            ch.rms_measured,
            100.0 * ch.normalized
        );
    }
    if !r.worst_windows.is_empty() {
        println!("  worst windows:");
        for w in &r.worst_windows {
            println!(
                "    {:>7.2}-{:<7.2} s  error {:.4}  speed {} rpm, I_qs {:.2} A, voltage {:.0} %, {:.1} Hz, {:.2} s after start; error mostly {}",
                w.t_start_s,
                w.t_end_s,
                w.normalized_rms_error,
                w.condition.speed_rpm.map(|s| format!("{s:.0}")).unwrap_or("-".into()),
                w.condition.load_current_a,
                w.condition.voltage_percent,
                w.condition.supply_hz,
                w.condition.time_since_start_s,
                w.error_kind
            );
        }
    }
    for e in &r.fitted_effects {
        println!("  {}: {}", e.effect, e.summary);
    }
    for (k, v) in &r.base_parameters {
        println!(
            "  fitted {:<14} {:>12.5} {} (nominal {:.5})",
            k,
            v.value,
            v.unit,
            v.nominal.unwrap_or(f64::NAN)
        );
    }
    for s in &r.skipped {
        println!("  skipped: {s}");
    }
    println!("  unbalance: {}", r.unbalance.summary);
}
