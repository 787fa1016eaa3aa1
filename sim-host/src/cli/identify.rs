//! `sim-host identify`: the T-equivalent circuit and the mechanics from a log of the
//! healthy machine (`monitor_api::analysis::identify`), starting from a parameter file; the result
//! written atomically, never over an input, nor over an existing file without `--force`.

use super::output_guard::OutputGuard;
use super::progress;
use clap::Args;
use monitor_api::analysis::{identify, Identification};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `identify`.
#[derive(Debug, Args)]
#[command(
    about = "Identify the motor's circuit (Rs, Rr, leakage, Lm) and J, B+Bl from a log of its healthy running",
    long_about = "Identify the T-equivalent circuit and the mechanics of your motor from a log of its \
healthy running, starting from a parameter file (e.g. the one `params from-nameplate` wrote: its \
values are 10-30 % off; identify brings them within about 1 % on simulated logs, the leakage split aside).\n\n\
What the log must hold: the three phase voltages and currents (the model is driven by the \
voltages), at least 0.2 s, and something that moves the machine: a direct-on-line start, supply \
or load steps, or steady running at two or more operating points. A speed channel (wm_rad_s, or \
mapped by [columns]) is imposed on the model, which separates the electrical parameters from the \
mechanics; without it the log must start from standstill and the shaft is simulated.\n\n\
How: the simulator's full-order T-equivalent machine is driven by the measured voltages (and \
speed) and Levenberg-Marquardt fits Rs, Rr, Lls + Llr and Lm to the measured currents; then J and \
B + Bl come from the torque balance T_e = J dw/dt + (B + Bl) w with the identified model's torque. \
Each value gets a 95 % interval (from the fit's Jacobian and its residual variance: a lower bound \
when the model misses an effect of the real motor, such as saturation or temperature).\n\n\
What it cannot tell: Lls and Llr apart (no terminal measurement can: only their sum is \
identified, split as in the start file, and Rr and Lm are those of that split; the split-free \
inverse-Gamma form R_R, L_sigma, L_M is printed too, and is what to compare with a machine \
published in that form); a parameter the log does not excite (steady running at \
one point gives one complex impedance for the four electrical parameters; constant speed leaves \
J free) is reported \"not identified\" with the reason, and the written file keeps the start value for it. \
A constant load torque is not in the model: B + Bl then absorbs it.\n\n\
Output: a table (parameter, start, identified, 95 % interval), or --json (one document: \
estimates [{name, key, unit, start, value, lo, hi, not_identified_because}], inverse_gamma \
{rs_ohm, r_r_ohm, l_sigma_h, l_m_h}, relative errors, solver, toml). --out writes the parameter file (atomically; never over the log or the start \
file, nor over another file without --force), each line saying where its value came from. The \
start file's [columns] table (a DAQ's channel names and units) is left out, so that the new file \
reads logs with the standard column names; --keep-columns keeps it, for more logs of the same \
DAQ.\n\n\
Example (docs/own-motor.md):\n  \
sim-host params from-nameplate --power-kw 2.2 --voltage-v 400 --current-a 4.8 --frequency-hz 50 \\\n    \
--speed-rpm 1438 --power-factor 0.77 --efficiency 0.863 --out nameplate.toml\n  \
sim-host identify --params nameplate.toml examples/logs/motulator_2p2kw_dol.csv --out motor.toml\n  \
sim-host diagnose --params motor.toml run.csv --commission 1.5:2.4"
)]
pub struct IdentifyArgs {
    /// The start parameter file (its [columns] table maps the log's channels).
    #[arg(long, value_name = "START.toml")]
    pub params: PathBuf,
    /// The log of the healthy motor (CSV, TDMS or Parquet).
    pub log: PathBuf,
    /// Write the identified parameter file here (atomically).
    #[arg(long, value_name = "P.toml")]
    pub out: Option<PathBuf>,
    /// Keep the start file's [columns] table in the written file (and in --json's toml),
    /// for more logs of the same DAQ; without it the file reads logs with the standard
    /// column names.
    #[arg(long)]
    pub keep_columns: bool,
    /// Overwrite --out when it exists (never an input).
    #[arg(long)]
    pub force: bool,
    /// Print one JSON document on stdout.
    #[arg(long)]
    pub json: bool,
    /// Use the log from this time on [s].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = super::args::parse_seconds)]
    pub from: Option<f64>,
    /// Use the log up to this time [s].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = super::args::parse_seconds)]
    pub to: Option<f64>,
    /// The TDMS group holding the channels (when the log has several).
    #[arg(long, value_name = "NAME")]
    pub group: Option<String>,
}

/// Refuses an output that is an input or exists (without --force), and a window that
/// ends before it starts.
fn check(args: &IdentifyArgs) -> anyhow::Result<()> {
    if let (Some(a), Some(b)) = (args.from, args.to) {
        if b <= a {
            anyhow::bail!("--to ({b}) must be after --from ({a})");
        }
    }
    if let Some(out) = &args.out {
        OutputGuard::new(&[&args.log, &args.params]).check_new_file(out, args.force)?;
    }
    Ok(())
}

/// Runs `identify`.
///
/// # Errors
/// Bad input (one line naming the file, the column or the problem), or a write error.
pub fn run(args: &IdentifyArgs) -> anyhow::Result<()> {
    check(args)?;
    let pb = progress::bar(progress::FRACTION_STEPS, "identify", true);
    let done = monitor_api::identify(
        monitor_api::ParamsSource::Path(&args.params),
        &args.log,
        args.from,
        args.to,
        args.group.clone(),
        &mut |f| progress::set_fraction(&pb, f),
    );
    pb.finish_and_clear();
    let done = done?;
    let toml = if args.keep_columns {
        done.toml.as_str()
    } else {
        done.toml_without_columns()
    };
    let id = &done.identification;
    super::out::write_out(args.out.as_deref(), toml.as_bytes())?;
    let mut stdout = super::out::stdout();
    if args.json {
        let doc = serde_json::json!({
            "identification": id,
            "out": args.out.as_ref().map(|p| p.display().to_string()),
            "toml": toml,
        });
        writeln!(stdout, "{}", serde_json::to_string_pretty(&doc)?)?;
    } else {
        let mut stdout = super::out::text();
        write!(stdout, "{}", table(id))?;
        match &args.out {
            Some(out) => writeln!(stdout, "wrote {}", out.display())?,
            None => writeln!(stdout, "(give --out P.toml to write the parameter file)")?,
        }
    }
    Ok(())
}

/// The factor and the unit a value of `unit` about `size` is printed in, as a technician
/// reads it: ohm as `Ω` (`mΩ` below 1), henry as `mH` below 1; other units as they are.
fn engineering_unit(unit: &str, size: f64) -> (f64, String) {
    match unit {
        "ohm" if size < 1.0 => (1e3, "mΩ".into()),
        "ohm" => (1.0, "Ω".into()),
        "H" if size < 1.0 => (1e3, "mH".into()),
        u => (1.0, u.to_string()),
    }
}

/// `x` with `digits` significant digits, in plain decimal notation (`3.666`, `21.53`,
/// `0.01440`).
fn significant(x: f64, digits: i32) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor() as i32;
    let decimals = (digits - 1 - mag).max(0) as usize;
    format!("{x:.decimals$}")
}

/// The text report.
fn table(id: &Identification) -> String {
    let mut s = format!(
        "identify: {} samples, {:.3}..{:.3} s, {}; current error {:.2} % of its RMS (start file: {:.2} %); \
         solver {} after {} iterations\n",
        id.samples,
        id.window_s.0,
        id.window_s.1,
        if id.speed_imposed { "measured speed imposed" } else { "no speed channel: shaft simulated" },
        100.0 * id.relative_rms_error,
        100.0 * id.relative_rms_error_start,
        id.solver.termination,
        id.solver.iterations,
    );
    s.push_str(&format!(
        "{:<10} {:>16} {:>16}  {}\n",
        "parameter", "start", "identified", "95 % interval"
    ));
    for e in &id.estimates {
        let (k, unit) = engineering_unit(&e.unit, e.start.abs());
        let g = |x: f64| significant(x * k, 4);
        let with = |x: f64| format!("{} {unit}", g(x));
        match (e.value, e.lo, e.hi) {
            (Some(v), Some(lo), Some(hi)) => s.push_str(&format!(
                "{:<10} {:>16} {:>16}  {}..{} {unit} ({:+.1} % vs start)\n",
                e.name,
                with(e.start),
                with(v),
                g(lo),
                g(hi),
                100.0 * (v / e.start - 1.0)
            )),
            _ => s.push_str(&format!(
                "{:<10} {:>16} {:>16}  {}\n",
                e.name,
                with(e.start),
                "not identified",
                e.not_identified_because.as_deref().unwrap_or("")
            )),
        }
    }
    if let Some(g) = &id.inverse_gamma {
        s.push_str(&format!("{}\n", identify::inverse_gamma_line("", g)));
    }
    if let Some(l) = &id.supply_from_log {
        s.push_str(&format!(
            "{}\n",
            monitor_api::words::identify::supply_from_log(l)
        ));
    }
    s.push_str(&format!(
        "(the full-order model over {:.3}..{:.3} s, a start or steps included; compare and explain judge the paper's steady-state model: leave a start out there with --from, as compare's advice says)\n",
        id.window_s.0, id.window_s.1
    ));
    s
}
