//! The one-call interface's error ([`ApiError`]) and its kinds ([`ErrorKind`]). Each
//! variant names the option or field it is about ([`OptionField`]) in the library's words
//! (`Display`); a front end says it in its own ([`ApiError::spelled`]: the command line's
//! `--commission`, Python's keyword, `commission = 4:2`).

use monitor_analysis::AnalysisError;
use monitor_io::log::LogError;
use monitor_io::params::ParamError;
use monitor_replay::{OptionError, OptionField, ReplayError};
use monitor_words::{FieldNames, Spelling};

/// A failed call: one line naming the file, the field or the option, and its kind.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// The parameter file cannot be read, or is not one.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// The log cannot be read, or is not one.
    #[error(transparent)]
    Log(#[from] LogError),
    /// An option's value is refused (a window, a step, a baseline), naming the field.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The replay could not run (its configuration, an incomplete commissioning).
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The monitor cannot be configured for this log (its sample rate, the machine).
    #[error("{log}: {source}")]
    Config {
        /// How messages name the log.
        log: String,
        /// The replay's refusal ([`ReplayError::Config`]).
        source: ReplayError,
    },
    /// The analysis could not run on this log.
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// The parameter file given is a log (or the log a parameter file): the arguments look
    /// swapped.
    #[error("{}", self.spelled(&FieldNames))]
    Swapped {
        /// The path given as the parameter file.
        params: String,
        /// ", and LOG a parameter file" when the log given is a `.toml`, else empty.
        also: String,
    },
    /// The analysed window ends before it starts (`to_s <= from_s`) [s].
    #[error("{}", self.spelled(&FieldNames))]
    WindowOrder {
        /// The start [s].
        from_s: f64,
        /// The end [s].
        to_s: f64,
    },
    /// The analysed window is too short to judge the model by (under
    /// [`crate::MIN_ANALYSED_PERIODS`] supply periods).
    #[error("{}", self.spelled(&FieldNames))]
    ShortWindow {
        /// How messages name the log.
        log: String,
        /// The window's span [s].
        span_s: f64,
        /// The supply frequency [Hz].
        f_hz: f64,
        /// The least span [s].
        least_s: f64,
    },
    /// `identify` was given the parameter file's values, not its text or path (it writes
    /// the file it was given with the identified values).
    #[error("identify writes the parameter file it was given with the identified values: give its path or its TOML text")]
    ParamsTextNeeded,
    /// The identification could not run on this log, or refused its result.
    #[error("{what} {log}: {why}")]
    Identify {
        /// "cannot identify from" or "identify".
        what: &'static str,
        /// How messages name the log.
        log: String,
        /// Why, typed ([`IdentifyWhy`]; spelled at the door, `monitor_words::identify`).
        why: IdentifyWhy,
    },
    /// A labelled run for a turn calibration is wrong, or none named its phase.
    #[error("{0}")]
    Labels(String),
    /// A nameplate refused, naming its field.
    #[error(transparent)]
    Nameplate(#[from] monitor_io::nameplate::NameplateError),
    /// A scenario refused (naming the key) or a simulation that failed.
    #[error(transparent)]
    Simulation(#[from] monitor_sim::SimError),
    /// The simulation was interrupted.
    #[error("the simulation was interrupted")]
    Interrupted,
    /// An output is one of the call's inputs (naming both files and their fields);
    /// nothing was written.
    #[error(transparent)]
    Overwrite(#[from] monitor_io::log::OverwriteError),
    /// A user's law file refused (its first mistake, naming the law).
    #[error(transparent)]
    Laws(#[from] monitor_laws::LawError),
    /// An effect name neither the library nor the law file has.
    #[error("{}", self.spelled(&FieldNames))]
    UnknownEffect {
        /// The name given.
        name: String,
        /// Names spelled alike.
        near: Vec<String>,
        /// Every known name (the library's, then the laws').
        known: Vec<String>,
        /// True when a law file was given.
        laws: bool,
    },
    /// The scenario file cannot be read.
    #[error("cannot read the scenario {path}: {source}")]
    ScenarioIo {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// The kinds of [`ApiError`] (the Python package's exception classes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// [`ApiError::Params`], [`ApiError::Swapped`].
    Params,
    /// [`ApiError::Log`], and a replay's or an analysis' log error.
    Log,
    /// [`ApiError::Option`] and every refusal of what was asked (a window, a
    /// configuration, a nameplate, a scenario, labels, an output that is an input).
    Option,
    /// [`ApiError::Replay`] and [`ApiError::Analysis`].
    Analysis,
}

impl ApiError {
    /// Whether the error is a file that does not exist (a log's or a parameter file's):
    /// Python raises it as a `FileNotFoundError` too.
    pub fn is_not_found(&self) -> bool {
        let io = match self {
            ApiError::Log(LogError::Io { source, .. })
            | ApiError::Replay(ReplayError::Log(LogError::Io { source, .. }))
            | ApiError::Analysis(AnalysisError::Log(LogError::Io { source, .. }))
            | ApiError::Params(ParamError::Io { source, .. }) => Some(source),
            _ => None,
        };
        io.is_some_and(|e| e.kind() == std::io::ErrorKind::NotFound)
    }

    /// Which kind of error this is.
    pub fn kind(&self) -> ErrorKind {
        match self {
            ApiError::Params(_) | ApiError::Swapped { .. } => ErrorKind::Params,
            ApiError::Log(_) | ApiError::Replay(ReplayError::Log(_)) => ErrorKind::Log,
            ApiError::Analysis(AnalysisError::Log(_)) => ErrorKind::Log,
            ApiError::Replay(ReplayError::Option(_)) => ErrorKind::Option,
            ApiError::Replay(_) | ApiError::Analysis(_) => ErrorKind::Analysis,
            ApiError::Option(_)
            | ApiError::Config { .. }
            | ApiError::WindowOrder { .. }
            | ApiError::ShortWindow { .. }
            | ApiError::ParamsTextNeeded
            | ApiError::Identify { .. }
            | ApiError::Labels(_)
            | ApiError::Nameplate(_)
            | ApiError::Simulation(_)
            | ApiError::Interrupted
            | ApiError::Overwrite(_)
            | ApiError::Laws(_)
            | ApiError::UnknownEffect { .. }
            | ApiError::ScenarioIo { .. } => ErrorKind::Option,
        }
    }

    /// The message in a front end's words: `spell` names the options and fields it refers
    /// to (the command line as `--commission 4:2`, Python as its keyword,
    /// `commission = 4:2`); the library's own is `Display`'s ([`FieldNames`]).
    pub fn spelled(&self, spell: &dyn Spelling) -> String {
        match self {
            ApiError::Option(e) => monitor_words::option_error(e, spell),
            ApiError::Log(e)
            | ApiError::Replay(ReplayError::Log(e))
            | ApiError::Analysis(AnalysisError::Log(e)) => e.spelled(&|name| spell.key(name)),
            ApiError::Replay(e) => monitor_words::replay_error(e, spell),
            ApiError::Nameplate(e) => e.spelled(&|name| spell.key(name)),
            ApiError::Swapped { params, also } => format!(
                "{} is a log, not a parameter file{also}: the arguments look swapped (give {} LOG)",
                spell.option(OptionField::Params, params),
                spell.option(OptionField::Params, "P.toml")
            ),
            ApiError::WindowOrder { from_s, to_s } => format!(
                "{} ({to_s}) must be after {} ({from_s})",
                spell.option(OptionField::To, ""),
                spell.option(OptionField::From, "")
            ),
            ApiError::ShortWindow {
                log,
                span_s,
                f_hz,
                least_s,
            } => format!(
                "{log}: the analysed window is {span_s:.3} s ({:.1} supply periods): at least {least_s:.2} s ({:.0} periods) are needed to judge the model (widen {}/{})",
                span_s * f_hz,
                crate::MIN_ANALYSED_PERIODS,
                spell.option(OptionField::From, ""),
                spell.option(OptionField::To, "")
            ),
            ApiError::Identify { what, log, why } => {
                format!("{what} {log}: {}", why.spelled(spell))
            }
            ApiError::UnknownEffect {
                name,
                near,
                known,
                laws,
            } => monitor_words::laws::unknown_effect(name, near, known, *laws, spell),
            e => e.to_string(),
        }
    }
}

/// Why `identify` wrote no parameter file ([`ApiError::Identify`]): the identification could
/// not run, or it ran and its result was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum IdentifyWhy {
    /// It could not run on the log (no voltages, too short, irregular samples, ...).
    Failed(monitor_analysis::identify::IdentifyError),
    /// It ran and refused its result (a current out of range, a poor fit, a value no real
    /// machine has); no parameter file is written.
    Refused(monitor_analysis::identify::IdentifyRefusal),
}

impl IdentifyWhy {
    /// The reason in a front end's words (`spell` names the window's fields).
    pub fn spelled(&self, spell: &dyn Spelling) -> String {
        match self {
            IdentifyWhy::Failed(e) => monitor_words::identify::failed(e, spell),
            IdentifyWhy::Refused(r) => format!(
                "{}; no parameter file written",
                monitor_words::identify::refusal(r, spell)
            ),
        }
    }
}

impl std::fmt::Display for IdentifyWhy {
    /// In the library's own words ([`FieldNames`]).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.spelled(&FieldNames))
    }
}
