//! `sim-host simulate --params P.toml --scenario S.toml --out D.csv [--json]`: generate a
//! measurement log (the CSV schema of `docs/design.md`) from a motor parameter file and a scenario
//! (format: `monitor_sim`).
//!
//! The CSV is written atomically (`monitor_api::files::LogWriter`): a failed run, or one stopped by
//! SIGINT (Ctrl-C) or SIGTERM, removes its temporary file and leaves no output (exit status
//! 130 / 143), and the output may not be one of the inputs. Before anything is written the
//! run's size is estimated and a run beyond [`MAX_OUTPUT_BYTES`] or [`MAX_STEPS`] is refused
//! unless `--force`. A progress bar goes to stderr when it is a terminal and the run is
//! expected to take more than [`PROGRESS_AFTER_S`].

use super::out::Interruption;
use super::output_guard::OutputGuard;
use super::{progress, render};
use clap::Args;
use monitor_api::files::LogWriter;
use monitor_api::files::ParamFile;
use monitor_api::sim::{simulate_while, Scenario, Workload};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Largest output a run writes without `--force` [bytes]: 20 GB, about 6 h of the
/// log schema at 10 kHz (a 1 h log at 10 kHz is about 3 GB) and more than any analysis
/// here reads in reasonable time; a typo in `duration_s` or `sample_rate_hz` (8e5 s, 1e9 Hz)
/// asks for hundreds of GB.
pub const MAX_OUTPUT_BYTES: f64 = 20.0e9;

/// Most integrator steps a run takes without `--force`: 2e9, about 3 minutes of RK4 on one
/// core of this machine (measured: about 1.1e7 steps per second in memory) and 55 h of
/// simulated time at the default 100 us step.
pub const MAX_STEPS: f64 = 2.0e9;

/// Runs expected to take longer than this [s] show a progress bar (on a terminal).
pub const PROGRESS_AFTER_S: f64 = 2.0;

/// RK4 steps per second of the release build (measured, `docs/performance.md`: about
/// 1100 simulated seconds per wall second at 100 us steps).
const STEPS_PER_S: f64 = 1.1e7;

/// CSV bytes written per second of the release build (measured: about 228 simulated
/// seconds per wall second at 10 kHz and about 90 bytes a row).
const CSV_BYTES_PER_S: f64 = 2.0e8;

/// Arguments of `simulate`.
#[derive(Debug, Args)]
#[command(
    about = "Simulate an induction motor (faults, effects, sensors) and write a log (CSV, TDMS, Parquet)",
    long_about = "Simulate a 3-phase induction motor (full-order T-equivalent model, started \
direct-on-line) with the supply, load, faults, physical effects and sensor chain of a scenario \
file, and write the sensor readings as a log (t_s, va_V..vc_V, ia_A..ic_A, wm_rad_s, \
enc_count): CSV, or TDMS / Parquet when --out ends in .tdms / .parquet. See examples/scenarios/*.toml for the scenario format. Values are written at f32 \
precision (7 significant digits; time at f64).\n\nA run estimated to write more than 20 GB or \
to take more than 2e9 integrator steps is refused unless --force. Ctrl-C removes the partial \
output.\n\nExample:\n  sim-host \
simulate --params examples/params/2p2kw.toml --scenario examples/scenarios/reference_2p2kw.toml \
--out ref.csv"
)]
pub struct SimulateArgs {
    /// Motor parameter file (TOML, docs/design.md).
    #[arg(long)]
    pub params: PathBuf,
    /// Scenario file (TOML; see examples/scenarios).
    #[arg(long)]
    pub scenario: PathBuf,
    /// Output log (written atomically; never one of the inputs), in the format of its
    /// extension: `.csv` (or any other), `.tdms`, `.parquet`.
    #[arg(long)]
    pub out: PathBuf,
    /// Override the scenario's noise seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// A file of your own laws (the format `compare --laws` reads): the run injects each law
    /// at its parameters' start values (a load torque of t, w and theta, a resistance of t,
    /// Lm of psi_m or a no-load test's curve), evaluated as the analysis fits them.
    #[arg(long, value_name = "FILE")]
    pub laws: Option<PathBuf>,
    /// Run even when the output is estimated above 20 GB or the run above 2e9 integrator
    /// steps.
    #[arg(long)]
    pub force: bool,
    /// Print one JSON summary document on stdout instead of the text summary.
    #[arg(long)]
    pub json: bool,
}

/// Runs `simulate`.
///
/// # Errors
/// Unreadable or invalid inputs (one line naming the file and key), an output that is an
/// input, a run too large without `--force`, an I/O error writing the output, or
/// [`super::out::Interrupted`] after SIGINT/SIGTERM (the partial output removed).
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let mut inputs: Vec<&Path> = vec![&args.params, &args.scenario];
    if let Some(l) = &args.laws {
        inputs.push(l);
    }
    OutputGuard::new(&inputs).check_files(&[&args.out])?;
    let (params, sc) = inputs_of(args)?;
    let work = sc.workload();
    let bytes = work.rows as f64
        * LogWriter::estimated_row_bytes_for(&args.out, sc.sensors.channels()) as f64;
    if !args.force {
        check_size(&args.scenario, &work, bytes)?;
    }
    let interruption = Interruption::catch()?;
    let start = Instant::now();
    let bar = progress::bar(
        work.rows,
        "simulate",
        expected_wall_s(&work, bytes) > PROGRESS_AFTER_S,
    );
    let mut w = LogWriter::create(&args.out, sc.sensors.channels())?;
    let mut err = None;
    let mut k = 0u64;
    let summary = simulate_while(&params, &sc, |r| {
        if let Err(e) = w.write_row(r) {
            err = Some(e);
            return ControlFlow::Break(());
        }
        k += 1;
        if k.is_multiple_of(8192) {
            bar.set_position(k);
        }
        if interruption.caught() {
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    })?;
    bar.finish_and_clear();
    if let Some(e) = err {
        return Err(e.into());
    }
    let Some(summary) = summary else {
        // Stopped by a signal: the unfinished writer deletes its temporary file.
        drop(w);
        let what = format!("temporary file removed, {} not written", args.out.display());
        return Err(interruption.signal(&what).map_or_else(
            || anyhow::anyhow!("the simulation stopped early"),
            anyhow::Error::new,
        ));
    };
    w.finish()?;
    let wall_s = start.elapsed().as_secs_f64();
    let out = &mut crate::cli::out::stdout();
    if args.json {
        render::json::print(out, &render::json::simulate(&args.out, wall_s, &summary))
    } else {
        render::text::simulate(out, &args.out, wall_s, &summary)
    }
}

/// The parameter file and the scenario `args` name, the seed and the user's laws (`--laws`,
/// checked against the file) in it.
///
/// # Errors
/// An unreadable or invalid file, a law that does not check (one line each).
fn inputs_of(args: &SimulateArgs) -> anyhow::Result<(ParamFile, Scenario)> {
    let params = ParamFile::load(&args.params)?;
    let mut sc = Scenario::load(&args.scenario)?;
    if let Some(s) = args.seed {
        sc.seed = s;
    }
    let laws = monitor_api::laws::read_laws(args.laws.as_deref())?;
    monitor_api::laws::check_laws(&laws, &params)?;
    sc.laws = monitor_api::sim::UserLaws(
        laws.into_iter()
            .map(monitor_api::laws::BoundLaw::at_start)
            .collect(),
    );
    Ok((params, sc))
}

/// Refuses a run whose output or integration is beyond the limits.
///
/// # Errors
/// One line naming the scenario, the estimate, the limit and the keys to change.
fn check_size(scenario: &Path, work: &Workload, bytes: f64) -> anyhow::Result<()> {
    if bytes > MAX_OUTPUT_BYTES {
        anyhow::bail!(
            "scenario {}: duration_s x sample_rate_hz = {} rows would write about {:.0} GB, \
             above the {:.0} GB limit: shorten duration_s or lower sample_rate_hz, or pass --force",
            scenario.display(),
            work.rows,
            bytes / 1e9,
            MAX_OUTPUT_BYTES / 1e9
        );
    }
    if work.steps > MAX_STEPS {
        anyhow::bail!(
            "scenario {}: {} rows x {} integrator steps per row = {:.2e} steps, above the {:.0e} \
             limit: raise max_step_s (at most the sample period), shorten duration_s, or pass --force",
            scenario.display(),
            work.rows,
            work.steps_per_row,
            work.steps,
            MAX_STEPS
        );
    }
    Ok(())
}

/// The expected wall time of a release build [s]: integration plus CSV writing.
fn expected_wall_s(work: &Workload, bytes: f64) -> f64 {
    work.steps / STEPS_PER_S + bytes / CSV_BYTES_PER_S
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario(text: &str) -> Scenario {
        Scenario::from_toml_str(text, "s.toml").expect("valid scenario")
    }

    #[test]
    fn runs_beyond_the_limits_are_refused_before_writing() {
        let p = Path::new("s.toml");
        let bytes = |sc: &Scenario| {
            sc.workload().rows as f64 * LogWriter::estimated_row_bytes(sc.sensors.channels()) as f64
        };
        // 8e5 s at 10 kHz: 8e9 rows of about 90 bytes, 720 GB.
        let long = scenario("duration_s = 8e5\nsample_rate_hz = 10000.0\n");
        let e = check_size(p, &long.workload(), bytes(&long))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("GB") && e.contains("duration_s") && e.contains("--force"),
            "{e}"
        );
        // 1 h at 1 kHz with a 0.1 us step: 3.6e6 rows (0.35 GB) but 3.6e10 steps.
        let fine = scenario("duration_s = 3600.0\nsample_rate_hz = 1000.0\nmax_step_s = 1e-7\n");
        let e = check_size(p, &fine.workload(), bytes(&fine))
            .unwrap_err()
            .to_string();
        assert!(e.contains("max_step_s") && e.contains("steps"), "{e}");
        // The reference run (10 s at 10 kHz, 1e5 rows and steps) passes, and is quick.
        let reference = Scenario::reference_2p2kw();
        check_size(p, &reference.workload(), bytes(&reference)).unwrap();
        assert!(expected_wall_s(&reference.workload(), bytes(&reference)) < PROGRESS_AFTER_S);
        // An hour at 10 kHz (3.6e7 rows, about 3 GB) shows the bar.
        let hour = scenario("duration_s = 3600.0\nsample_rate_hz = 10000.0\n");
        check_size(p, &hour.workload(), bytes(&hour)).unwrap();
        assert!(expected_wall_s(&hour.workload(), bytes(&hour)) > PROGRESS_AFTER_S);
    }
}
