//! `sim-host compare` and `sim-host explain`: the paper's simplified model against a
//! measurement log ([`monitor_analysis`]).

use super::output_guard::OutputGuard;
use super::{progress, render};
use monitor_api::analysis::{Analysis, Options};
use std::path::PathBuf;

/// A parameter file as read once: its values and its `[columns]` mapping.
type Params = (
    monitor_api::files::ParamFile,
    monitor_api::files::ColumnMapping,
);

/// Options shared by `compare` and `explain`.
#[derive(clap::Args, Debug, Clone)]
pub struct Common {
    /// Parameter file (TOML, docs/design.md) with the user's nominal motor and supply values.
    #[arg(long)]
    pub params: PathBuf,
    /// Measurement log (t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s; t_s and the
    /// currents are the minimum) as CSV, TDMS (`.tdms`) or Parquet (`.parquet`).
    pub log: PathBuf,
    /// The TDMS group holding the channels (when the file has several).
    #[arg(long, value_name = "NAME")]
    pub group: Option<String>,
    /// Effects already in the model, comma separated (e.g. `thermal_drift,load_torque`): the
    /// library's, or the name of a law of `--laws`.
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// A file of your own laws (TOML, `[[law]]` with name, acts_on, expr or table, and
    /// `[law.parameters]`; docs/your-own-law.md): each law is a
    /// candidate beside the library's effects, fitted and judged the same way, reported by
    /// its name, and `--effects NAME` puts it in the model.
    #[arg(long, value_name = "FILE")]
    pub laws: Option<PathBuf>,
    /// Print one JSON document on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the plots (each as SVG and PNG, with title, axis labels and legend) into this
    /// folder.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Write a one-page HTML report (report.html plus the plots) into this folder.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Analyse from this time on [s] (e.g. to leave a start-up out).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = super::args::parse_seconds)]
    pub from: Option<f64>,
    /// Analyse up to this time [s].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = super::args::parse_positive_seconds)]
    pub to: Option<f64>,
    /// Keep the nominal base parameters (do not refit Ra, Ls, B+Bl, J).
    #[arg(long)]
    pub no_fit: bool,
}

impl Common {
    /// The analysis options for the loaded log `a` (the law file checked against its
    /// parameter file, the effect names resolved).
    fn options(&self, a: &Analysis) -> anyhow::Result<Options> {
        Ok(self.request(None).options(a)?)
    }

    /// Refuses outputs that would overwrite an input, and a window that ends before it
    /// starts, before anything is read or written.
    fn check(&self, charts: &[&str]) -> anyhow::Result<()> {
        // The law file and the effect names first: a mistake there is said before a long
        // log is read.
        let laws = monitor_api::laws::read_laws(self.laws.as_deref())?;
        monitor_api::laws::effect_ids(
            &self.effects,
            &monitor_api::analysis::Registry::with_laws(&laws),
        )?;
        let mut inputs: Vec<&std::path::Path> = vec![&self.log, &self.params];
        if let Some(l) = &self.laws {
            inputs.push(l);
        }
        let guard = OutputGuard::new(&inputs);
        let mut files = render::charts::file_names(charts);
        if let Some(dir) = &self.plot {
            guard.check_folder(dir, &files)?;
        }
        if let Some(dir) = &self.report {
            files.push(render::html::REPORT_FILE.to_string());
            guard.check_folder(dir, &files)?;
        }
        if let (Some(a), Some(b)) = (self.from, self.to) {
            if b <= a {
                anyhow::bail!("--to ({b}) must be after --from ({a})");
            }
        }
        Ok(())
    }

    /// Reads the parameter file (once) and the log (with a progress bar for large logs);
    /// the file's values are returned for the calls that follow.
    fn load(&self) -> anyhow::Result<(Analysis, Params)> {
        let (params, columns) = self.read_params()?;
        let a = self.load_with(&params, &columns)?;
        Ok((a, (params, columns)))
    }

    /// Reads the parameter file and its `[columns]` mapping for this log.
    fn read_params(&self) -> anyhow::Result<Params> {
        Ok(monitor_api::load_params_for(
            monitor_api::ParamsSource::Path(&self.params),
            &monitor_api::LogSource::from(self.log.as_path()),
        )?)
    }

    /// Reads the log for the model's analysis with the parameter file already read.
    fn load_with(
        &self,
        params: &monitor_api::files::ParamFile,
        columns: &monitor_api::files::ColumnMapping,
    ) -> anyhow::Result<Analysis> {
        let big = std::fs::metadata(&self.log)
            .map(|m| m.len() > 20_000_000)
            .unwrap_or(false);
        let pb = progress::bar(progress::FRACTION_STEPS, "reading log", big);
        let req = self.request(None);
        let a = monitor_api::load_analysis(
            monitor_api::ParamsSource::Read { params, columns },
            &self.log,
            &req,
            &mut |f| progress::set_fraction(&pb, f),
        )
        .map_err(|e| match e.kind() {
            monitor_api::ErrorKind::Params | monitor_api::ErrorKind::Option => {
                anyhow::Error::new(e)
            }
            _ => anyhow::Error::new(e).context("cannot analyse the log"),
        })?;
        pb.finish_and_clear();
        render::text::quality_warnings(&a.quality);
        Ok(a)
    }

    /// The library's request for these options.
    fn request(&self, rotor_bars: Option<u32>) -> monitor_api::AnalysisRequest {
        monitor_api::AnalysisRequest {
            effects: self.effects.clone(),
            laws: self.laws.clone(),
            from_s: self.from,
            to_s: self.to,
            no_fit: self.no_fit,
            group: self.group.clone(),
            rotor_bars,
        }
    }
}

/// Arguments of `compare`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    about = "Compare the paper's simplified model with a measurement log: where does it fail?",
    long_about = "Compare the paper's simplified induction-motor model (eqs. 28-29) with a measurement.\n\n\
The model is driven by the measured voltage (V_qs in a rotor-flux frame estimated from the \
voltages: the voltage model, which needs no speed and no rotor parameters) and predicts \
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
skipped, unbalance, data, data_quality (what the data-quality stage found in the log: gaps, \
dropped samples, bad cells, segments, and what was done; the longest regular segment is \
analysed), leftover (where the error lives: equations, in_time, windows, spectrum, lines \
[{frequency_hz, reading, multiple, expected_hz, share, amplitude, says}], follows, \
shaft_angle, hint, summary)."
)]
pub struct CompareArgs {
    /// Shared options.
    #[command(flatten)]
    pub common: Common,
}

/// Arguments of `explain`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    about = "Rank the physical effects that could explain the model's error",
    long_about = "Rank the physical effects missing from the paper's simplified model.\n\n\
Every library effect not yet in the model (thermal_drift, saturation, iron_loss, \
coulomb_friction, windage, load_torque, supply_unbalance, phase_asymmetry, flux_dynamics, \
current_dynamics, d_axis_dynamics, cross_coupling_dynamics, rotor_asymmetry), and each law of \
your own with --laws FILE (docs/your-own-law.md), is added in turn and fitted together with \
the base parameters (Ra, Ls, B+Bl, J). The dynamics effects (those \
with a time constant) are proposed only when the analysed span holds a start or a supply \
step; with all four the model is the full-order machine. Candidates are ranked by the error \
on held-back time windows the fit never saw (each kind of event the log holds, its start, \
transients, load moves and steady stretches, falls in both parts), so an effect that only fits noise does not \
win; a fit outside its physical range is marked plausible: false, is listed apart with its reason \
and never named, and a plausible fit that explains under 5 % of the held-back error is no \
candidate (listed apart as no effect). The base \
parameters refitted to the log are printed with the parameter file's values, and those the \
log does not identify are named; when the file's values do not fit the log at all (the \
refit outside their physical range), the model is first recentred on the identified refitted \
values and the effects are judged against that. When no candidate explains at least 50 % of \
the held-back error, or the error is already within 1.12x its noise floor on the whole log \
and on the held-back windows, the answer is \
`unexplained: true` rather than a wrong name.\n\n\
Workflow:\n  sim-host compare --params motor.toml run.csv          # where does the model fail?\n  \
sim-host explain --params motor.toml run.csv          # which effect is missing?\n  \
sim-host explain --compare --params motor.toml run.csv  # both, reading a long log once\n  \
sim-host compare --params motor.toml run.csv --effects load_torque   # the error falls\n  \
sim-host explain --params motor.toml run.csv --effects load_torque   # anything else?\n\n\
The text opens with the verdict diagnose gives the same log, then explain's answer on the \
model's error and, where the verdict names a fault, how the ranking relates to it.\n\n\
JSON (--json): headline, motor_verdict, verdict_finding, beside_verdict, \
baseline_normalized_rms_error, ranking [{effect, rank, standing (candidate | no_effect | \
not_plausible), normalized_rms_error, \
explained_fraction (held-back), whole_log_explained_fraction, \
validation_normalized_rms_error, n_parameters, parameters, summary, \
plausible, implausible_because, fit {iterations, cost, termination: converged | slow_progress | \
iteration_limit | stalled | nothing_to_fit}}], \
no_effect, unexplained, verdict, skipped, unbalance, noise_floor, data_quality, rotor_asymmetry (the \
motor current signature analysis: lower_sideband_db, upper_sideband_db, slip, sideband_hz, \
speed_ripple_hz, speed_ripple_rad_s, delta, equivalent_broken_bars (with --rotor-bars N), \
spectral_delta, spectral_broken_bars, fit_and_spectrum_agree, window_s, resolution_hz, \
resolution_needed_hz, or cannot_judge_because), base_refit {parameters [{parameter, unit, \
configured, refitted, identified}], recentred, because}. When the data-quality \
stage does not trust the log the verdict says \"could not judge\" and why."
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
    /// Rotor bar count N: the `rotor_asymmetry` report gives the fitted and the sidebands'
    /// asymmetry as a number of adjacent broken bars, n = delta N / (3 (1 + delta)).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(6..))]
    pub rotor_bars: Option<u32>,
    /// Walk the ladder instead of ranking once: add the effect that lowers the held-back
    /// error most, keep it when the step passes its test (it removes at least the share of
    /// the held-back error beyond the noise floor that the output's `test` states, and
    /// lowers the whole-log error), and go on
    /// from the new model until the error is within the noise-floor band or nothing
    /// plausible helps. One row per step; --report draws the error falling onto the floor.
    /// JSON: start, ladder [{effect, added, fitted {name: {value, unit, low, high}}, error,
    /// heldback_error, noise_floor, heldback_noise_floor, ratio_to_floor,
    /// heldback_ratio_to_floor, significance, explained, heldback_explained}], stop
    /// (noise_floor | nothing_helps | library_exhausted | no_model | untrusted),
    /// stopped_because, final_effects, last_round, skipped, split, test, data,
    /// data_quality, leftover (where the error lives when it stops above the floor).
    #[arg(long, conflicts_with_all = ["compare", "rotor_bars"], long_help = ladder_help())]
    pub ladder: bool,
}

/// `explain --ladder`'s long help: the doc comment above with the step's test in the
/// library's own figure ([`monitor_api::analysis::STEP_MIN`]), so the help and the output
/// cannot disagree.
fn ladder_help() -> String {
    format!(
        "Walk the ladder instead of ranking once: add the effect that lowers the held-back error most, keep it when the step passes its test (it removes at least {:.0} % of the held-back error beyond the noise floor and lowers the whole-log error), and go on from the new model until the error is within the noise-floor band or nothing plausible helps. One row per step; --report draws the error falling onto the floor. JSON: start, ladder [{{effect, added, fitted {{name: {{value, unit, low, high}}}}, error, heldback_error, noise_floor, heldback_noise_floor, ratio_to_floor, heldback_ratio_to_floor, significance, explained, heldback_explained}}], stop (noise_floor | nothing_helps | library_exhausted | no_model | untrusted), stopped_because, final_effects, last_round, skipped, split, test, data, data_quality, leftover (where the error lives when it stops above the floor: equations, in_time, spectrum, lines [{{frequency_hz, reading, ...}}], follows, hint).",
        100.0 * monitor_api::analysis::STEP_MIN
    )
}

/// Runs `compare`.
///
/// # Errors
/// Bad parameter file, unreadable or malformed log, an effect the log cannot carry, an
/// output that is an input or is not writable; each a one-line message.
pub fn run_compare(args: &CompareArgs) -> anyhow::Result<()> {
    let c = &args.common;
    c.check(&render::charts::COMPARE)?;
    let (a, _) = c.load()?;
    let out = a.compare(&c.options(&a)?)?;
    render::html::write_compare(c.plot.as_deref(), c.report.as_deref(), &c.log, &a, &out)?;
    if c.json {
        let doc = monitor_api::words::compare::document(&out.report, &super::words::CliWords);
        render::json::print(&mut crate::cli::out::stdout(), &doc)
    } else {
        render::text::compare(&mut crate::cli::out::text(), &c.log, &out.report)
    }
}

/// What `explain` works out on the calling thread: the log read for the model's analysis,
/// `compare`'s report with `--compare` (printed first in text mode, its prediction dropped
/// so that memory stays at explain's), and the ranking.
type Explained = (
    Analysis,
    Option<monitor_api::analysis::CompareReport>,
    monitor_api::analysis::ExplainOutput,
);

/// Reads the log, runs `compare` with `--compare`, and fits the candidates (with a progress
/// bar on large logs).
fn explain_here(
    args: &ExplainArgs,
    params: &monitor_api::files::ParamFile,
    columns: &monitor_api::files::ColumnMapping,
) -> anyhow::Result<Explained> {
    let c = &args.common;
    let a = c.load_with(params, columns)?;
    let opts = c.options(&a)?;
    let compared = if args.compare {
        let out = a.compare(&opts)?;
        if !c.json {
            render::text::compare(&mut crate::cli::out::text(), &c.log, &out.report)?;
        }
        Some(out.report)
    } else {
        None
    };
    let pb = progress::bar(
        progress::FRACTION_STEPS,
        "explain: fitting candidates",
        a.data.len() > 50_000,
    );
    let pbc = pb.clone();
    let out = a.explain(&opts, &move |f| progress::set_fraction(&pbc, f))?;
    pb.finish_and_clear();
    Ok((a, compared, out))
}

/// Runs `explain` (and `compare` first with `--compare`).
///
/// # Errors
/// As [`run_compare`].
pub fn run_explain(args: &ExplainArgs) -> anyhow::Result<()> {
    if args.ladder {
        return run_ladder(&args.common);
    }
    let c = &args.common;
    let mut charts = render::charts::EXPLAIN.to_vec();
    charts.push(render::mcsa::CHART);
    c.check(&charts)?;
    let (params, columns) = c.read_params()?;
    // The one verdict on the same log, which explain opens with: `diagnose` reads the log
    // on a thread of its own while the model's analysis reads it and fits the candidates
    // here (the two share nothing but the files; the documents are those of running them
    // one after the other).
    let (judged, explained) = std::thread::scope(|s| {
        let verdict = s.spawn(|| {
            monitor_api::verdict_for_explain(
                monitor_api::ParamsSource::Read {
                    params: &params,
                    columns: &columns,
                },
                &c.log,
                c.group.clone(),
            )
        });
        let explained = explain_here(args, &params, &columns);
        let judged = verdict
            .join()
            .map_err(|_| anyhow::anyhow!("the verdict's thread stopped unexpectedly"));
        (judged, explained)
    });
    let (a, compared, out) = explained?;
    let judged = judged?;
    // The motor current signature analysis, with the fitted rotor_asymmetry's delta.
    let mcsa = monitor_api::mcsa_beside(&a, &out.report, args.rotor_bars);
    let doc = monitor_api::ExplainDocument::new(
        judged.as_ref(),
        out.report,
        mcsa,
        &super::words::CliWords,
    );
    render::html::write_explain(
        c.plot.as_deref(),
        c.report.as_deref(),
        &c.log,
        &a,
        (&out.before, out.after.as_ref()),
        &doc,
    )?;
    print_explain(c, &doc, compared.as_ref())
}

/// `explain`'s document on standard output: its JSON (after `compare`'s with `--compare`),
/// or its text.
fn print_explain(
    c: &Common,
    doc: &monitor_api::ExplainDocument,
    compared: Option<&monitor_api::analysis::CompareReport>,
) -> anyhow::Result<()> {
    let json = c.json.then(|| doc.json(&super::words::CliWords));
    match (json, compared) {
        (Some(explain), Some(cmp)) => render::json::print(
            &mut crate::cli::out::stdout(),
            &render::json::ExplainWithCompare {
                compare: &monitor_api::words::compare::document(cmp, &super::words::CliWords),
                explain: &explain,
            },
        ),
        (Some(explain), None) => render::json::print(&mut crate::cli::out::stdout(), &explain),
        (None, _) => render::text::explain(&mut crate::cli::out::text(), &c.log, doc),
    }
}

/// Runs `explain --ladder`: the log read once, the ladder walked with a progress bar per
/// step, then the table (or JSON) and, with `--plot`/`--report`, the error falling step by
/// step onto the noise-floor band.
///
/// # Errors
/// As [`run_compare`].
fn run_ladder(c: &Common) -> anyhow::Result<()> {
    c.check(&render::ladder_charts::LADDER_CHARTS)?;
    let (a, _) = c.load()?;
    // A bar whenever the walk runs longer than 2 s: each round's candidates, then the
    // chosen model's refit on the whole log; it only goes forward
    // ([`progress::ladder_position`]).
    let pb = progress::LateBar::new(
        "ladder round 1 (no step kept yet): fitting candidates",
        std::time::Duration::from_secs(2),
    );
    let opts = c.options(&a)?;
    let report = a.ladder(&opts, &|p| {
        let (msg, at) = progress::ladder_position(p);
        pb.set(Some(msg), at);
    })?;
    pb.finish();
    render::html::write_ladder(c.plot.as_deref(), c.report.as_deref(), &c.log, &report)?;
    if c.json {
        let doc = monitor_api::words::ladder::document(&report, &super::words::CliWords);
        render::json::print(&mut crate::cli::out::stdout(), &doc)
    } else {
        render::text::ladder(&mut crate::cli::out::text(), &c.log, &report)
    }
}
