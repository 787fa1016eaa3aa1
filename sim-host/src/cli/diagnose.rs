//! `sim-host diagnose`: replay a log through the core ([`monitor_api::replay::diagnose_file`])
//! and report lamps, candidates and the negative-sequence analysis.

use super::args::{AngleArg, LoadArg, ResidualArg};
use super::{progress, render};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `diagnose`.
#[derive(Debug, Args)]
#[command(
    about = "Replay a measurement log through the core: lamps r1..r4, fault candidates, unbalance",
    long_about = "Replay a measurement log (CSV, schema in docs/design.md; or TDMS / Parquet with the \
same channel names, by the file's extension) through exactly the core code the \
firmware runs, and report the residual lamps r1..r4, the fault candidates of the paper's Table 1 with \
their probabilities, when a fault was first detected, and the negative-sequence (unbalance / faulty \
phase) analysis.\n\nWithout --commission the fixed thresholds are used (3 % of each normalised \
residual). With --commission START:END the healthy mean and spread of every residual are learned \
over that part of the log (seconds) and the lamps use mean +/- k*spread with debounce and \
hysteresis.\n\nThe load is an unknown input by default (--load unknown, real service): a load \
change is reported as a load move with its time (isolation.events), never as a fault, and \
electrical faults are named from the stator-voltage equations and the torque against the load \
measured just before a change; --load viscous takes the paper's fixed viscous load, where a \
B/Bl change is the fault b/bl.\n\nThe frame (--angle rotor-flux, the default) is the core's current-model rotor-flux \
angle (encoder speed, nominal Rr and Lr); compare/explain use a voltage-model rotor-flux estimate \
instead.\n\nLogs with only t_s and the three currents still get the unbalance analysis (the \
supply is taken from the parameter file).\n\nAny sample rate from 1 kHz to 50 kHz works (at \
least 8 samples per supply period). Every row first passes the data-quality stage: dropped \
samples and short gaps are bridged with the real elapsed time, long gaps restart the \
monitor's estimators, repeated or backward times are dropped, bad cells (NaN, inf, out of \
range) are held out, time in ms or us is recognised; the report's data_quality says what \
was found and done, and the verdict is withheld when the log cannot be trusted.\n\n\
Commissioning: a window the log does not complete is an error unless --allow-incomplete. \
The learned thresholds hold only over the load and voltage range seen while learning: \
commission over healthy running that covers the whole range.\n\nThe faulty winding (shorted \
turns) is judged from the change of the negative-sequence current, measured by least-squares \
phasors over windows of ten supply periods and grouped into steady stretches (a short \
switched on and off within the log is a stretch of its own), against the healthy machine's: \
--baseline HEALTHY... replays logs of the same motor when it was healthy (same supply and \
load if possible; several files, or a folder of them): their mean is the reference and their \
spread, with a default spread counted as one run, sets the least change that names a phase \
(JSON unbalance.least_change, baseline_runs, baseline_spread). Without --baseline, the \
--commission window's; without either, the log's own healthy stretch when it has one (a \
short switched on within the log), else a healthy machine's own asymmetry \
(unbalance.judged_against). A baseline at another operating point widens the least change \
and says so (unbalance.least_change_widened). The reference angle is measured from the \
voltages where logged, else the model's at the measured speed, else at the current's \
magnitude when the parameter file can draw it, else unknown between no load and full load. \
unbalance.phase_confidence is the probability that the winding has a short in the named \
phase, with its uncertainties (unbalance.phase_probabilities, operating_point, \
correction_uncertainty_deg); a FAULT needs 0.5.\n\nA winding (or frame) \
temperature column, t_winding_c in degC (or a DAQ's channel in degC, K or degF through the \
parameter file's [columns] table), compensates Rs and Rr with the rise measured since \
commissioning (copper 0.393 %/K) instead of tracking it from the residuals; JSON \
isolation.winding_temperature_c, measured_rise_k and temperature_channel (used, or not used: \
why: NaN or out of -40..250 degC for 10 s, a jump faster than a winding heats, stuck for 30 s, \
or the resistances disagree by more than 20 K; then the rise is tracked from the \
resistances).\n\nExample:\n  sim-host \
diagnose --params motor.toml log.csv --commission 2:4\n  sim-host diagnose --params motor.toml \
today.csv --baseline healthy_1.csv healthy_2.csv\n  sim-host diagnose --params motor.toml \
today.csv --baseline healthy_runs/"
)]
pub struct DiagnoseArgs {
    /// Motor parameter file (TOML, docs/design.md).
    #[arg(long)]
    pub params: PathBuf,
    /// Measurement log: CSV, TDMS (`.tdms`) or Parquet (`.parquet`), by its extension.
    pub log: PathBuf,
    /// What the log is replayed with (the same for `hmi LOG`).
    #[command(flatten)]
    pub replay: ReplayArgs,
    /// Report even when the --commission window was not learned (the log ends first, or
    /// the motor was not quasi-steady long enough); the fixed thresholds are used and the
    /// verdict is withheld.
    #[arg(long)]
    pub allow_incomplete: bool,
    /// Timeline resolution in the output [s].
    #[arg(long, default_value_t = defaults().options.timeline_step, allow_negative_numbers = true, value_parser = super::words::parse_timeline_step)]
    pub timeline_step: monitor_api::replay::TimelineStep,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write the report a crew prints and a planner files: one self-contained HTML
    /// page (the verdict, the findings, the residuals, lamps and state over time with the
    /// events marked, the negative sequence, the rotor's sidebands, the data quality),
    /// written atomically; never over an input.
    #[arg(long, value_name = "R.html")]
    pub report: Option<PathBuf>,
}

/// The options a log is replayed with, the same for `diagnose` and the HMI's log replay
/// (`hmi LOG`): parsed by the library's parsers ([`super::words`]) and built into one
/// `monitor_api::DiagnoseRequest` ([`ReplayArgs::request`]), so that both accept and refuse
/// the same values with the same words.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The TDMS group holding the channels (when the file has several).
    #[arg(long, value_name = "NAME")]
    pub group: Option<String>,
    /// Learn healthy thresholds over START:END seconds of the log (healthy running that
    /// covers the load and voltage range to be monitored).
    #[arg(long, value_name = "START:END", value_parser = super::words::parse_window)]
    pub commission: Option<monitor_api::replay::CommissionWindow>,
    /// Logs of the same motor when healthy (several files, or a folder of them; read
    /// only; the same formats as LOG): the winding is judged against their mean negative
    /// sequence, and their spread sets the least change that names a phase. Give LOG
    /// before --baseline, or repeat --baseline for each file.
    #[arg(long, value_name = "HEALTHY", num_args = 1.., action = clap::ArgAction::Append)]
    pub baseline: Vec<PathBuf>,
    /// Frame angle source.
    #[arg(long, value_enum, default_value_t = defaults().options.angle_source.into())]
    pub angle: AngleArg,
    /// Residual form the lamps act on.
    #[arg(long, value_enum, default_value_t = defaults().options.residual_form.into())]
    pub residuals: ResidualArg,
    /// What is known of the load: `unknown` (service: a load change is an operating-point
    /// change, never a named fault) or `viscous` (the paper's fixed viscous load: a B/Bl
    /// change is the fault `b/bl`).
    #[arg(long, value_enum, default_value_t = defaults().options.load.into())]
    pub load: LoadArg,
    /// Parallel paths of each phase of the winding (1 for a series star or delta, 2 for a
    /// double star, as the motor's connection diagram says): the shorted turns lie in one
    /// path, and the shorted-turn level (unbalance.shorted_turns) is sized with that
    /// path's resistance.
    #[arg(long, default_value_t = defaults().options.turn_level.parallel_paths, value_parser = super::words::parse_parallel_paths)]
    pub parallel_paths: monitor_api::replay::ParallelPaths,
    /// A calibration of the shorted-turn level learned from labelled runs of the same
    /// motor (JSON, `monitor_api::replay::TurnCalibration`): the level is read from it instead
    /// of the model (unbalance.shorted_turns.basis says which; the model's stays in
    /// unbalance.shorted_turns_physics).
    #[arg(long, value_name = "FILE")]
    pub turn_calibration: Option<PathBuf>,
}

impl ReplayArgs {
    /// The library's request for these options (the rest, `allow_incomplete` and
    /// `timeline_step`, at their defaults), its report in the command line's words (each
    /// value checked once, by its parser, `super::words`).
    ///
    /// # Errors
    /// A `--turn-calibration` file that cannot be read; a request the library refuses.
    pub fn request(&self) -> anyhow::Result<monitor_api::DiagnoseRequest> {
        let req = monitor_api::DiagnoseRequest {
            options: monitor_api::replay::ReplayOptions {
                angle_source: self.angle.into(),
                residual_form: self.residuals.into(),
                commission: self.commission,
                load: self.load.into(),
                turn_level: monitor_api::replay::TurnLevelOptions {
                    parallel_paths: self.parallel_paths,
                    calibration: self
                        .turn_calibration
                        .as_ref()
                        .map(|f| read_calibration(f))
                        .transpose()?,
                },
                ..defaults().options
            },
            baseline: self
                .baseline
                .iter()
                .map(monitor_api::LogSource::from)
                .collect(),
            group: self.group.clone(),
        };
        Ok(req)
    }
}

/// `diagnose`'s defaults: the API request's, whose one home is the replay's options
/// (`monitor_api::replay::ReplayOptions::default`).
fn defaults() -> monitor_api::DiagnoseRequest {
    monitor_api::DiagnoseRequest::default()
}

/// Runs `diagnose`.
///
/// # Errors
/// Bad parameter file or log (one line naming the file, line and column), or a log the
/// core cannot be configured for.
pub fn run(args: &DiagnoseArgs) -> anyhow::Result<()> {
    let mut req = args.replay.request()?;
    req.options.allow_incomplete = args.allow_incomplete;
    req.options.timeline_step = args.timeline_step;
    if let Some(out) = &args.report {
        let mut inputs = vec![args.params.as_path(), args.log.as_path()];
        inputs.extend(args.replay.baseline.iter().map(PathBuf::as_path));
        inputs.extend(args.replay.turn_calibration.as_deref());
        super::output_guard::OutputGuard::new(&inputs).check_files(&[out])?;
    }
    let big = std::fs::metadata(&args.log)
        .map(|m| m.len() > 20_000_000)
        .unwrap_or(false);
    let bar = progress::bar(progress::FRACTION_STEPS, "reading log", big);
    let d = replay_until_signal(args, req, &bar)?;
    bar.finish_and_clear();
    render::text::quality_warnings(&d.report.data_quality);
    if let Some(out) = &args.report {
        render::diagnose_html::write(out, &args.log, &d)?;
    }
    if args.json {
        render::json::print(
            &mut crate::cli::out::stdout(),
            &monitor_api::words::diagnose::document(&d.report, &super::words::CliWords),
        )
    } else {
        render::text::diagnose(&mut crate::cli::out::text(), &args.log, &d)
    }
}

/// The replay of `diagnose`, on a thread of its own, while this one watches for SIGINT and
/// SIGTERM: a signal stops the command at once with [`super::out::Interrupted`] ("diagnose of
/// LOG stopped; nothing was written", status 130 or 143) instead of ending the process
/// without a word. Nothing is printed before the replay ends, so nothing is half written;
/// the replay's thread ends with the process.
///
/// # Errors
/// The replay's error, or [`super::out::Interrupted`].
fn replay_until_signal(
    args: &DiagnoseArgs,
    req: monitor_api::DiagnoseRequest,
    bar: &indicatif::ProgressBar,
) -> anyhow::Result<monitor_api::replay::Diagnosed> {
    use std::sync::mpsc::{channel, RecvTimeoutError};
    let interruption = super::out::Interruption::catch()?;
    let (params, log, worker_bar) = (args.params.clone(), args.log.clone(), bar.clone());
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        let d = monitor_api::diagnose(
            monitor_api::ParamsSource::Path(&params),
            &log,
            &req,
            &mut |f| progress::set_fraction(&worker_bar, f),
        );
        // (The receiver is gone only when a signal already ended the command.)
        let _ = tx.send(d);
    });
    loop {
        match rx.recv_timeout(std::time::Duration::from_millis(50)) {
            Ok(d) => return Ok(d?),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                anyhow::bail!("diagnose of {}: the replay stopped", args.log.display())
            }
        }
        let what = format!(
            "diagnose of {} stopped; nothing was written",
            args.log.display()
        );
        if let Some(sig) = interruption.signal(&what) {
            bar.finish_and_clear();
            return Err(sig.into());
        }
    }
}

/// Reads a `--turn-calibration` file.
///
/// # Errors
/// A file that cannot be read or is not a calibration, naming the file.
fn read_calibration(f: &std::path::Path) -> anyhow::Result<monitor_api::replay::TurnCalibration> {
    let text = std::fs::read_to_string(f)
        .map_err(|e| anyhow::anyhow!("--turn-calibration {}: {e}", f.display()))?;
    serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("--turn-calibration {}: not a calibration: {e}", f.display()))
}
