//! The library's one-call interface: what each command computes, from a log file and a
//! parameter file (a path, or the file's TOML text), as the value the command's `--json`
//! prints. The command line and the Python package (`python/`) both call these, so a
//! document is the same whoever asked for it.
//!
//! Errors are [`ApiError`]s, one line each, naming the option or field they are about in
//! the library's words (`commission`, `params`); a front end says them in its own
//! ([`ApiError::spelled`]). Their kind ([`ApiError::kind`]) says which: a bad parameter
//! file, a bad log, a bad option, or an analysis that cannot run on this log.

use monitor_analysis::prep::ReadOptions;
use monitor_analysis::{Analysis, Options};
use monitor_io::log::mapping::ColumnMapping;
use monitor_io::log::OpenOptions;
use monitor_io::params::{ParamError, ParamFile};
use monitor_replay::{
    diagnose_log, diagnose_log_fitted, HealthyReference, OptionError, OptionField, ReplayError,
    ReplayOptions, UnbalanceBaseline,
};
use monitor_words::Spelling;
use std::path::{Path, PathBuf};

/// Model against measurement for a front end (from `monitor-analysis`).
pub mod analysis;
mod error;
mod explain_doc;
/// The files a front end reads and writes (from `monitor-io`).
pub mod files;
pub mod fleet;
pub mod laws;
mod log_source;
mod machine_fit;
mod outputs;
/// The replay of a log for a front end (from `monitor-replay`).
pub mod replay;
/// The simulator for a front end (from `monitor-sim`).
pub mod sim;
mod turn_calibration;
pub use error::{ApiError, ErrorKind, IdentifyWhy};
pub use explain_doc::{
    beside_verdict, explain, ladder, mcsa_beside, verdict_for_explain, ExplainDocument,
};
pub use log_source::LogSource;
pub use machine_fit::FIT_WINDOW_S;
/// The one door: every sentence a crew reads, spelled from the engines' typed values (from
/// `monitor-words`).
pub use monitor_words as words;
pub use outputs::{simulate_to_file, simulate_to_file_with_laws, ScenarioSource};
pub use turn_calibration::{learn_turn_calibration, Labelled, Learned};

/// A parameter file: its path, its TOML text, or its values already read (so that a
/// command that makes several calls reads the file once).
#[derive(Debug, Clone, Copy)]
pub enum ParamsSource<'a> {
    /// A file.
    Path(&'a Path),
    /// The file's text (`origin` names it in messages).
    Toml {
        /// The TOML text.
        text: &'a str,
        /// How messages name it.
        origin: &'a str,
    },
    /// The file as [`load_params`] read it.
    Read {
        /// Its `[motor]` and `[supply]`.
        params: &'a ParamFile,
        /// Its `[columns]` mapping.
        columns: &'a ColumnMapping,
    },
}

/// Reads a parameter file and its `[columns]` mapping (the machine's pole pairs for
/// `Hz_el`), as every command that reads a log does.
///
/// # Errors
/// [`ApiError::Params`] naming the file and the key.
pub fn load_params(source: ParamsSource<'_>) -> Result<(ParamFile, ColumnMapping), ApiError> {
    match source {
        ParamsSource::Path(p) => Ok(monitor_io::log::mapping::load_params(p)?),
        ParamsSource::Read { params, columns } => Ok((*params, columns.clone())),
        ParamsSource::Toml { text, origin } => {
            let (p, table) = ParamFile::from_toml_str_with_columns(text, origin)?;
            let columns = ColumnMapping::from_table(&table, p.motor.poles / 2).map_err(|e| {
                ParamError::Columns {
                    path: origin.to_string(),
                    message: e.to_string(),
                }
            })?;
            Ok((p, columns))
        }
    }
}

/// Reads the parameter file for a command on `log` (once per command): as [`load_params`],
/// and when the file cannot be read as one and the two paths look swapped (a log's
/// extension given as `--params`, or a `.toml` given as the log), [`ApiError::Swapped`].
///
/// # Errors
/// As [`load_params`]; [`ApiError::Swapped`].
pub fn load_params_for(
    source: ParamsSource<'_>,
    log: &LogSource,
) -> Result<(ParamFile, ColumnMapping), ApiError> {
    load_params(source).map_err(|e| swapped(source, log).unwrap_or(e))
}

/// The parameter file's TOML text and how messages name it.
///
/// # Errors
/// [`ParamError::Io`] for a file that cannot be read; [`ApiError::Swapped`] where the
/// arguments look swapped.
fn params_text(source: ParamsSource<'_>, log: &LogSource) -> Result<(String, String), ApiError> {
    match source {
        ParamsSource::Path(p) => Ok((
            std::fs::read_to_string(p).map_err(|e| {
                swapped(source, log).unwrap_or(ApiError::Params(ParamError::Io {
                    path: p.display().to_string(),
                    source: e,
                }))
            })?,
            p.display().to_string(),
        )),
        ParamsSource::Toml { text, origin } => Ok((text.to_string(), origin.to_string())),
        ParamsSource::Read { .. } => Err(ApiError::ParamsTextNeeded),
    }
}

/// [`ApiError::Swapped`] when `source` and `log` look swapped (as [`load_params_for`]
/// says).
fn swapped(source: ParamsSource<'_>, log: &LogSource) -> Option<ApiError> {
    let ext = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default()
    };
    let ParamsSource::Path(params) = source else {
        return None;
    };
    let log_is_toml = log.path().is_some_and(|l| ext(l) == "toml");
    (["csv", "tdms", "parquet"].contains(&ext(params).as_str()) || log_is_toml).then(|| {
        ApiError::Swapped {
            params: params.display().to_string(),
            also: if log_is_toml {
                format!(", and {} a parameter file", log.shown())
            } else {
                String::new()
            },
        }
    })
}

/// What `diagnose` is asked: the replay's options and the few fields of a request alone.
/// Every default is [`ReplayOptions`]'s (no baseline, no TDMS group); its options are valid
/// by construction (each front end makes their typed values with the library's one
/// constructor: `CommissionWindow`, `TimelineStep`, `ParallelPaths`).
#[derive(Debug, Clone, Default)]
pub struct DiagnoseRequest {
    /// The replay's options (the healthy reference, `unbalance_baseline`, is filled from
    /// `baseline` by [`diagnose`]).
    pub options: ReplayOptions,
    /// Healthy logs of the same motor (files, folders of them, or data; the field
    /// `baseline`).
    pub baseline: Vec<LogSource>,
    /// The TDMS group holding the channels (the field `group`).
    pub group: Option<String>,
}

/// The logs of a request's `baseline`: each file and each data as given, each folder's log files
/// (CSV, TDMS, Parquet, by extension) in name order.
///
/// # Errors
/// [`ApiError::Option`] naming `baseline` for a folder without logs, or one that cannot be
/// read.
pub fn baseline_files(given: &[LogSource]) -> Result<Vec<LogSource>, ApiError> {
    let mut files = Vec::new();
    for g in given {
        let Some(p) = g.path().filter(|p| p.is_dir()) else {
            files.push(g.clone());
            continue;
        };
        let mut in_dir: Vec<PathBuf> = std::fs::read_dir(p)
            .map_err(|e| baseline_error(&p.display().to_string(), e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|f| {
                f.is_file()
                    && f.extension().and_then(|x| x.to_str()).is_some_and(|x| {
                        ["csv", "tdms", "parquet"].contains(&x.to_ascii_lowercase().as_str())
                    })
            })
            .collect();
        if in_dir.is_empty() {
            return Err(baseline_error(
                &p.display().to_string(),
                "the folder holds no log (.csv, .tdms or .parquet)",
            ));
        }
        in_dir.sort();
        files.extend(in_dir.into_iter().map(LogSource::File));
    }
    Ok(files)
}

/// A refused `baseline` (`shown`, or empty for the field alone).
fn baseline_error(shown: &str, why: impl ToString) -> ApiError {
    OptionError::new(OptionField::Baseline, shown, why.to_string()).into()
}

/// True when `a` and `b` name the same file (or are the same data).
fn same_file(a: &LogSource, b: &LogSource) -> bool {
    match (a, b) {
        (LogSource::File(a), LogSource::File(b)) => match (a.canonicalize(), b.canonicalize()) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        },
        (LogSource::Data { log: a, .. }, LogSource::Data { log: b, .. }) => {
            std::sync::Arc::ptr_eq(a, b)
        }
        _ => false,
    }
}

/// The negative sequence of the healthy log `path` (replayed without commissioning).
fn baseline_of(
    params: &ParamFile,
    path: &LogSource,
    open: &OpenOptions,
    opts: ReplayOptions,
) -> Result<UnbalanceBaseline, ApiError> {
    let file = path.open(open).map_err(|e| baseline_error("", e))?;
    let opts = ReplayOptions {
        commission: None,
        ..opts
    };
    let d = diagnose_log(params, &file, opts, &mut |_| {})
        .map_err(|e| baseline_error(&path.shown(), e))?;
    if d.report.unbalance.measured.i2_over_i1 == [0.0, 0.0] {
        return Err(baseline_error(
            &path.shown(),
            "no positive-sequence current in that log (the motor never ran)",
        ));
    }
    Ok(d.report.unbalance.measured)
}

/// What `diagnose` replays a log with, its request resolved ([`plan_diagnose`]): the
/// parameter file, how the log is opened (its `[columns]`, the TDMS group) and the replay's
/// options with the healthy reference of the request's `baseline` filled in. The HMI's log
/// replay runs on it, so that it takes the same request as `diagnose`.
#[derive(Debug, Clone)]
pub struct DiagnosePlan {
    /// The parameter file.
    pub params: ParamFile,
    /// How the log (and each baseline log) is opened.
    pub open: OpenOptions,
    /// The replay's options (`unbalance_baseline` from the request's `baseline`).
    pub options: ReplayOptions,
}

/// Resolves a `diagnose` request on `log`: reads the parameter file and replays its
/// `baseline` logs into the healthy reference; what [`diagnose`] then replays `log` with.
///
/// # Errors
/// A bad parameter file or option ([`ApiError`]), a baseline log that cannot be replayed
/// or is `log` itself, each a one-line message.
pub fn plan_diagnose(
    params: ParamsSource<'_>,
    log: &LogSource,
    req: &DiagnoseRequest,
) -> Result<DiagnosePlan, ApiError> {
    let (params, columns) = load_params_for(params, log)?;
    let open = OpenOptions {
        group: req.group.clone(),
        columns,
    };
    let mut opts = req.options;
    if !req.baseline.is_empty() {
        let files = baseline_files(&req.baseline)?;
        if let Some(same) = files.iter().find(|f| same_file(f, log)) {
            return Err(baseline_error(
                &same.shown(),
                "that is the log being judged; give healthy logs of the same motor",
            ));
        }
        let runs = files
            .iter()
            .map(|f| baseline_of(&params, f, &open, opts))
            .collect::<Result<Vec<_>, _>>()?;
        opts.unbalance_baseline = HealthyReference::from_runs(&runs);
    }
    Ok(DiagnosePlan {
        params,
        open,
        options: opts,
    })
}

/// `diagnose`: replays `log` through the core with the parameter file `params`; the report
/// `--json` prints. `progress` gets the fraction of the work done: forward only, with the
/// rows replayed, and 1 only once the report is built.
///
/// # Errors
/// A bad parameter file, log or option ([`ApiError`]), each a one-line message.
pub fn diagnose(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    req: &DiagnoseRequest,
    progress: &mut dyn FnMut(f64),
) -> Result<monitor_replay::Diagnosed, ApiError> {
    let log = &log.into();
    let plan = plan_diagnose(params, log, req)?;
    let file = log.open(&plan.open)?;
    // Against the file's nominal values (nothing commissioned), the machine fitted to the
    // log's start tells a fault present from the first sample from the file's error.
    let fit = plan
        .options
        .commission
        .is_none()
        .then(|| machine_fit::fit(&plan.params, &file))
        .flatten();
    diagnose_log_fitted(&plan.params, &file, plan.options, fit, progress).map_err(|e| match e {
        // Log errors name the file already; the monitor's configuration does not.
        e @ ReplayError::Config { .. } => ApiError::Config {
            log: log.shown(),
            source: e,
        },
        e => e.into(),
    })
}

/// What `compare` and `explain` are asked (their shared options).
#[derive(Debug, Clone, Default)]
pub struct AnalysisRequest {
    /// `--effects`: effects already in the model, by name (the library's or a law's of
    /// `laws`).
    pub effects: Vec<String>,
    /// `--laws`: a user's law file; its laws are candidates beside the library's.
    pub laws: Option<PathBuf>,
    /// `--from` [s].
    pub from_s: Option<f64>,
    /// `--to` [s].
    pub to_s: Option<f64>,
    /// `--no-fit`: keep the base parameters as the file gives them.
    pub no_fit: bool,
    /// `--group` (TDMS).
    pub group: Option<String>,
    /// `explain --rotor-bars`.
    pub rotor_bars: Option<u32>,
}

/// Supply periods the analysed window of `compare` and `explain` must hold (0.5 s at
/// 50 Hz): fewer leave a transient's tail and the noise to judge the model by.
pub const MIN_ANALYSED_PERIODS: f64 = 25.0;

/// Reads the log for `compare`/`explain` and checks its analysed window.
///
/// # Errors
/// A bad parameter file or log; [`ApiError::ShortWindow`] for a window under
/// [`MIN_ANALYSED_PERIODS`] supply periods.
pub fn load_analysis(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    req: &AnalysisRequest,
    progress: &mut dyn FnMut(f64),
) -> Result<Analysis, ApiError> {
    let log = &log.into();
    let (params, columns) = load_params_for(params, log)?;
    let file = log.open(&OpenOptions {
        group: req.group.clone(),
        columns,
    })?;
    let opts = ReadOptions {
        from_s: req.from_s.unwrap_or(f64::NEG_INFINITY),
        to_s: req.to_s.unwrap_or(f64::INFINITY),
    };
    let a = Analysis::load_file(&file, params, opts, progress)?;
    let span = match (a.data.t_s.first(), a.data.t_s.last()) {
        (Some(t0), Some(t1)) => t1 - t0,
        _ => 0.0,
    };
    let least = MIN_ANALYSED_PERIODS / a.params.supply.f_hz;
    if span.is_nan() || span < least {
        return Err(ApiError::ShortWindow {
            log: log.shown(),
            span_s: span,
            f_hz: a.params.supply.f_hz,
            least_s: least,
        });
    }
    Ok(a)
}

impl AnalysisRequest {
    /// The analysis' options for the loaded log `a`: the law file read and checked against
    /// its parameter file, the effect names resolved against the library and the laws.
    ///
    /// # Errors
    /// [`ApiError::Laws`] (the law file), [`ApiError::UnknownEffect`] (a name).
    pub fn options(&self, a: &Analysis) -> Result<Options, ApiError> {
        let laws = laws::read_laws(self.laws.as_deref())?;
        laws::check_laws(&laws, &a.params)?;
        let registry = monitor_analysis::effects::Registry::with_laws(&laws);
        Ok(Options {
            effects: laws::effect_ids(&self.effects, &registry)?,
            fit_base: !self.no_fit,
            laws: registry,
        })
    }
}

/// `compare --json`'s document, its sentences spelled at the door
/// ([`monitor_words::compare::document`]) in the words of `spell` (the front end's: the
/// command line's flags, Python's keywords).
///
/// # Errors
/// As [`load_analysis`], and an effect the log cannot carry.
pub fn compare(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    req: &AnalysisRequest,
    spell: &dyn Spelling,
) -> Result<serde_json::Value, ApiError> {
    let a = load_analysis(params, log, req, &mut |_| {})?;
    let out = a.compare(&req.options(&a)?)?;
    Ok(monitor_words::compare::document(&out.report, spell))
}

/// `identify`'s result: the identification and the parameter file it writes.
#[derive(Debug, Clone)]
pub struct Identified {
    /// The estimates, the errors, the solver's report.
    pub identification: monitor_analysis::identify::Identification,
    /// The identified parameter file's text (with the start file's `[columns]`).
    pub toml: String,
}

impl Identified {
    /// The identified parameter file's text without the start file's `[columns]` table
    /// (`sim-host identify` writes this one unless asked to keep the table): it reads logs
    /// with the standard column names, not only the DAQ's the start file mapped.
    pub fn toml_without_columns(&self) -> &str {
        monitor_analysis::identify::without_columns(&self.toml)
    }
}

/// `identify`: the circuit and the mechanics of the start file's machine from `log`
/// (`--from`/`--to` its window), or a refusal naming the likely cause
/// ([`monitor_analysis::identify::refusal`]).
///
/// # Errors
/// A bad parameter file or log; [`ApiError::WindowOrder`] for a window that ends before it
/// starts, a log the model cannot be driven by, or a refused identification.
pub fn identify(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    from_s: Option<f64>,
    to_s: Option<f64>,
    group: Option<String>,
    progress: &mut dyn FnMut(f64),
) -> Result<Identified, ApiError> {
    let log = &log.into();
    if let (Some(a), Some(b)) = (from_s, to_s) {
        if b <= a {
            return Err(ApiError::WindowOrder { from_s: a, to_s: b });
        }
    }
    // The file is read once: its text is the identified file's template.
    let (start_text, start_name) = params_text(params, log)?;
    let (start, columns) = load_params(ParamsSource::Toml {
        text: &start_text,
        origin: &start_name,
    })
    .map_err(|e| swapped(params, log).unwrap_or(e))?;
    let file = log.open(&OpenOptions { group, columns })?;
    let mut rows: Vec<monitor_io::log::Row> = Vec::new();
    file.for_each_row(&mut |f| progress(0.1 * f), &mut rows)?;
    let samples = monitor_analysis::identify::Samples::from_rows(
        &rows,
        file.channels(),
        from_s.unwrap_or(f64::NEG_INFINITY),
        to_s.unwrap_or(f64::INFINITY),
    )
    .map_err(|e| cannot_identify(log, e))?;
    drop(rows);
    let id =
        monitor_analysis::identify::identify(&start, &samples, &mut |f| progress(0.1 + 0.9 * f))
            .map_err(|e| cannot_identify(log, e))?;
    if let Some(why) = monitor_analysis::identify::refusal(&start, &samples, &id) {
        return Err(ApiError::Identify {
            what: "identify",
            log: log.shown(),
            why: IdentifyWhy::Refused(why),
        });
    }
    let toml = monitor_analysis::identify::to_toml(&id, &start_text, &start_name, &log.shown());
    Ok(Identified {
        identification: id,
        toml,
    })
}

/// [`ApiError::Identify`]: the identification cannot run on `log`.
fn cannot_identify(log: &LogSource, why: monitor_analysis::identify::IdentifyError) -> ApiError {
    ApiError::Identify {
        what: "cannot identify from",
        log: log.shown(),
        why: IdentifyWhy::Failed(why),
    }
}

/// `params from-nameplate`: the estimate and its parameter file's text, with the
/// `[columns]` table of `columns_from` carried over (`--columns-from`).
///
/// # Errors
/// [`ApiError::Nameplate`] for a refused nameplate (naming the field); [`ApiError::Option`]
/// naming `columns_from` for a bad `[columns]` there.
pub fn params_from_nameplate(
    n: &monitor_io::nameplate::Nameplate,
    columns_from: Option<&Path>,
) -> Result<(monitor_io::nameplate::NameplateEstimate, String), ApiError> {
    let estimate = monitor_io::nameplate::estimate(n)?;
    let mut toml = estimate.to_toml();
    if let Some(from) = columns_from {
        let table = monitor_io::params::load_columns_table(from)?;
        // Checked as every command that reads a log checks it.
        ColumnMapping::from_table(&table, estimate.poles / 2).map_err(|m| {
            OptionError::new(
                OptionField::ColumnsFrom,
                from.display().to_string(),
                format!("[columns] {m}"),
            )
        })?;
        toml.push_str(&format!(
            "\n# The log's channels and units, from {}.\n[columns]\n{}",
            from.display(),
            monitor_io::params::columns_entries_toml(&table)
        ));
    }
    Ok((estimate, toml))
}

/// `params from-nameplate --json`'s document (`out`: where the file was written, if it was).
pub fn nameplate_document(
    estimate: &monitor_io::nameplate::NameplateEstimate,
    toml: &str,
    out: Option<&Path>,
) -> serde_json::Value {
    serde_json::json!({
        "nameplate": estimate.nameplate,
        "poles": estimate.poles,
        "poles_inferred": estimate.poles_inferred,
        "slip": estimate.slip,
        "values": estimate.values,
        "out": out.map(|p| p.display().to_string()),
        "toml": toml,
    })
}
