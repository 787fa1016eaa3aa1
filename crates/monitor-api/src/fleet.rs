//! Many motors' logs judged at once (`sim-host fleet`, and the Python package's
//! `drive_monitor.fleet.diagnose_many` on Dask): a motor table says which parameter file,
//! commissioning window and healthy baseline belong to which motor, and which logs are its;
//! each log gives one row ([`FleetRow`]), a bad file a row with its error.
//!
//! The motor table (TOML), paths relative to the table's folder:
//!
//! ```toml
//! [[motor]]
//! name = "pump_7"
//! params = "params/pump_7.toml"    # the motor's parameter file ([columns] included)
//! logs = "pump_7_*"                # which logs are this motor's: a pattern on the file name
//! commission = [2.0, 4.0]          # optional: --commission START:END
//! baseline = ["healthy/pump_7"]    # optional: healthy logs or folders (a request's baseline)
//! load = "unknown"                 # optional: "unknown" (default) or "viscous"
//! time_from_name = "pump_7_%Y%m%d_%H%M"  # optional: the log's date in its file name
//! ```
//!
//! A log belongs to the first motor whose pattern matches its file name (`*` any text, `?`
//! one character). A log's time in the motors' history comes from the log itself where it
//! can, else from its name by `time_from_name`, else from the file's modification time
//! ([`time`]: [`log_time`], [`time_from_name`]).
//!
//! What a run writes (the history store) may not be a file it reads
//! ([`check_fleet_outputs`], checked before anything is written).

use crate::{diagnose, ApiError, DiagnoseRequest, LogSource, ParamsSource};

pub mod time;
use monitor_io::log::{check_outputs, NamedFile, OverwriteError};
use monitor_replay::{CommissionWindow, DiagnoseReport, IsolationEvent, LoadModel, ReplayOptions};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
pub use time::{log_time, time_from_name, time_warnings, LogTime, LogTimeSource};

/// One motor of the table.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MotorEntry {
    /// The motor's name (the rows' `motor`).
    pub name: String,
    /// Its parameter file.
    pub params: PathBuf,
    /// The pattern its logs' file names match.
    pub logs: String,
    /// Its commissioning window [s], if the logs are judged against one (checked as the
    /// table is read: `[2.0, 1.0]` is refused there).
    #[serde(default)]
    pub commission: Option<CommissionWindow>,
    /// Healthy logs of it (files or folders).
    #[serde(default)]
    pub baseline: Vec<PathBuf>,
    /// What is known of its load: `unknown` (default) or `viscous`.
    #[serde(default)]
    pub load: Option<MotorLoad>,
    /// The date and time in its logs' file names, a chrono strftime pattern
    /// (`pump_7_%Y%m%d_%H%M`; [`time_from_name`] says what is accepted): a log's time in the
    /// history where the log itself says none (no time column of timestamps, no TDMS
    /// `wf_start_time`); a name it does not match falls back to the file's modification
    /// time, and the run says so ([`time_warnings`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_from_name: Option<String>,
}

/// What is known of a motor's load (the table's `load`, lower case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MotorLoad {
    /// An unknown input (real service): [`LoadModel::Unknown`].
    Unknown,
    /// The paper's fixed viscous load: [`LoadModel::Viscous`].
    Viscous,
}

impl MotorLoad {
    /// The replay's load model.
    pub fn model(self) -> LoadModel {
        match self {
            MotorLoad::Unknown => LoadModel::Unknown,
            MotorLoad::Viscous => LoadModel::Viscous,
        }
    }
}

/// The motor table.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MotorTable {
    /// The motors, in the order their patterns are tried.
    pub motor: Vec<MotorEntry>,
}

/// Errors reading the motor table.
#[derive(Debug, thiserror::Error)]
pub enum FleetError {
    /// The file cannot be read.
    #[error("cannot read the motor table {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not a motor table.
    #[error("bad motor table {path}: {message}")]
    Toml {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A log given as a pattern (`*`, `?` or `[` in its file name) that names no file:
    /// the same words as the Python package's fleet run.
    #[error("logs: the pattern '{0}' matches no file")]
    NoMatch(String),
}

impl MotorTable {
    /// Reads a motor table; its relative paths are made relative to its folder.
    ///
    /// # Errors
    /// [`FleetError`] naming the file and what is wrong (an unknown key, a motor without
    /// `params`, a load that is neither `unknown` nor `viscous`, an empty table).
    pub fn load(path: &Path) -> Result<Self, FleetError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| FleetError::Io {
            path: shown.clone(),
            source,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::from_toml_str(&text, &shown, base)
    }

    /// Parses a motor table's text; relative paths are taken from `base`.
    ///
    /// # Errors
    /// As [`MotorTable::load`].
    pub fn from_toml_str(text: &str, shown: &str, base: &Path) -> Result<Self, FleetError> {
        let bad = |message: String| FleetError::Toml {
            path: shown.to_string(),
            message,
        };
        let mut t: MotorTable =
            toml::from_str(text).map_err(|e| bad(monitor_io::one_line(&e.to_string())))?;
        if t.motor.is_empty() {
            return Err(bad("no [[motor]] in it".into()));
        }
        for m in &mut t.motor {
            // (Its commissioning window was checked as it was read.)
            if let Some(p) = m
                .time_from_name
                .as_deref()
                .filter(|p| !time::time_pattern_ok(p))
            {
                return Err(bad(format!(
                    "motor {}: time_from_name \"{p}\" is not a date pattern: chrono's strftime specifiers with a year and a day (%Y%m%d, %Y-%m-%d_%H%M, ...) or %s",
                    m.name
                )));
            }
            m.params = from_base(base, &m.params);
            m.baseline = m.baseline.iter().map(|p| from_base(base, p)).collect();
        }
        Ok(t)
    }

    /// The motor a log belongs to: the first whose pattern matches the log's file name.
    pub fn motor_of(&self, log: &Path) -> Option<&MotorEntry> {
        let name = log.file_name()?.to_string_lossy();
        self.motor.iter().find(|m| wildcard(&m.logs, &name))
    }
}

/// The logs of a fleet run: each path as given, but a path that names no file and holds a
/// pattern in its file name (`logs/pump_*.csv`, quoted past the shell, or a shell glob that
/// matched nothing and was passed on as it stands) is expanded to the files of its folder
/// whose names match it ([`wildcard`]), sorted.
///
/// # Errors
/// [`FleetError::NoMatch`] naming a pattern that matches no file (rather than a row per
/// pattern blaming the motor table).
pub fn expand_logs(logs: &[PathBuf]) -> Result<Vec<PathBuf>, FleetError> {
    let mut out = Vec::with_capacity(logs.len());
    for log in logs {
        let name = log.file_name().map(|n| n.to_string_lossy().into_owned());
        let pattern = name.filter(|n| n.contains(['*', '?', '[']));
        let Some(pattern) = pattern.filter(|_| !log.exists()) else {
            out.push(log.clone());
            continue;
        };
        let folder = match log.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut found: Vec<PathBuf> = std::fs::read_dir(&folder)
            .into_iter()
            .flatten()
            .flatten()
            .filter(|e| e.path().is_file())
            .filter(|e| wildcard(&pattern, &e.file_name().to_string_lossy()))
            .map(|e| log.with_file_name(e.file_name()))
            .collect();
        if found.is_empty() {
            return Err(FleetError::NoMatch(log.display().to_string()));
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

/// `p` taken from `base` when relative.
fn from_base(base: &Path, p: &Path) -> PathBuf {
    if p.is_relative() {
        base.join(p)
    } else {
        p.to_path_buf()
    }
}

/// Whether `text` matches `pattern` (`*` any run of characters, `?` one character).
pub fn wildcard(pattern: &str, text: &str) -> bool {
    let (p, t): (Vec<char>, Vec<char>) = (pattern.chars().collect(), text.chars().collect());
    // Iterative matching with one backtrack point for the last `*`.
    let (mut i, mut j, mut star, mut mark) = (0usize, 0usize, None::<usize>, 0usize);
    while j < t.len() {
        if i < p.len() && (p[i] == '?' || p[i] == t[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|c| *c == '*')
}

/// One log's row of the fleet table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FleetRow {
    /// The motor's name (empty when no motor's pattern matches the file).
    pub motor: String,
    /// The log.
    pub file: String,
    /// Rows read.
    pub rows: Option<u64>,
    /// The log's sample rate [Hz].
    pub rate_hz: Option<f64>,
    /// `fault`, `healthy`, `could_not_judge`, `watching`; null with an error.
    pub verdict: Option<String>,
    /// The fault the verdict names (a FAULT's or a watched one: Table 1's name,
    /// `shorted_turns`, `broken_bars`), if any.
    pub fault: Option<String>,
    /// Its size in its finding's unit (`size_unit`: a relative change, 0.5 is +50 %; for
    /// shorted turns the fraction of the phase's turns where one was sized, else the
    /// negative sequence's change over I1; for broken bars dB below the supply line).
    pub size: Option<f64>,
    /// The size's unit (`relative`, `turns_fraction`, `of_i1`, `db_below_line`).
    pub size_unit: Option<String>,
    /// Its phase (`a`, `b`, `c`), where it has one.
    pub phase: Option<String>,
    /// Its calibrated confidence, 0..1.
    pub confidence: Option<f64>,
    /// When the lamps first lit [s].
    pub first_detection_s: Option<f64>,
    /// How many load moves the log showed.
    pub load_moves: Option<u64>,
    /// The data-quality summary.
    pub data_quality: Option<String>,
    /// Shorted turns: the interval of the fraction of the phase's turns (low end), where
    /// a level was sized (`unbalance.shorted_turns`).
    pub turns_low: Option<f64>,
    /// Its high end.
    pub turns_high: Option<f64>,
    /// Where the level comes from: `physics` (the model, no labels) or `calibration`.
    pub turns_basis: Option<String>,
    /// What the residuals were judged against (`commissioning`, `parameter_file`), where
    /// they were judged.
    pub against: Option<String>,
    /// What a healthy verdict could not see on this log (the residuals' reach: without a
    /// commissioning window, a fault present from the start within the file's own
    /// uncertainty unless the machine fitted to the log's start is the file's), else null.
    pub not_seen: Option<String>,
    /// Why the log gave no verdict (a bad file, no motor, a bad option), else null.
    pub error: Option<String>,
}

impl FleetRow {
    /// The row of a log that gave no report.
    pub fn failed(motor: &str, file: &Path, error: String) -> Self {
        FleetRow {
            motor: motor.to_string(),
            file: file.display().to_string(),
            rows: None,
            rate_hz: None,
            verdict: None,
            fault: None,
            size: None,
            size_unit: None,
            phase: None,
            confidence: None,
            first_detection_s: None,
            load_moves: None,
            data_quality: None,
            turns_low: None,
            turns_high: None,
            turns_basis: None,
            against: None,
            not_seen: None,
            error: Some(error),
        }
    }

    /// The row of a report.
    pub fn of_report(motor: &str, file: &Path, r: &DiagnoseReport) -> Self {
        // The verdict's own finding: the fault, size, phase and confidence the verdict line
        // gives (a watched or a FAULT name; none for healthy or could not judge).
        let named = r.verdict_finding.as_ref().and_then(|f| f.named());
        // f32 figures as their shortest decimals (0.105, not 0.10517956316471100).
        let short = |x: f32| x.to_string().parse::<f64>().unwrap_or(f64::from(x));
        let (fault, size, phase, confidence) = match named {
            Some(n) => (
                Some(n.fault.name().to_string()),
                Some(monitor_replay::verdict::size_parts(n.size)),
                n.phase.map(|p| p.name().to_string()),
                Some(short(n.confidence)),
            ),
            None => (None, None, None, None),
        };
        // The level's interval where the verdict's size is it.
        let turns = r
            .unbalance
            .shorted_turns
            .filter(|_| size.is_some_and(|s| s.1 == "turns_fraction"));
        FleetRow {
            motor: motor.to_string(),
            file: file.display().to_string(),
            rows: Some(r.data_quality.rows_read),
            rate_hz: Some(r.data_quality.sample_rate_hz),
            verdict: Some(r.verdict.name().to_string()),
            fault,
            size: size.map(|s| short(s.0)),
            size_unit: size.map(|s| s.1.to_string()),
            phase,
            confidence,
            first_detection_s: r.first_detection_s,
            load_moves: Some(load_moves(r)),
            data_quality: Some(r.data_quality.summary()),
            turns_low: turns.map(|t| short(t.low)),
            turns_high: turns.map(|t| short(t.high)),
            turns_basis: turns.map(|t| {
                match t.basis {
                    monitor_replay::LevelBasis::Physics => "physics",
                    monitor_replay::LevelBasis::Calibration => "calibration",
                }
                .to_string()
            }),
            against: r
                .findings
                .iter()
                .find(|f| {
                    f.source() == monitor_core::verdict::FindingSource::Residuals
                        && !f.judged_nothing()
                })
                .map(|f| f.finding.against.name().to_string()),
            not_seen: crate::words::diagnose::machine_fit::not_seen(r),
            error: None,
        }
    }
}

/// The load moves the isolation saw in `r`.
fn load_moves(r: &DiagnoseReport) -> u64 {
    r.isolation
        .events
        .iter()
        .filter(|e| matches!(e, IsolationEvent::LoadMoved { .. }))
        .count() as u64
}

/// The row of one log: its motor from `table`, diagnosed with that motor's file, window,
/// baseline and load. Never fails: an error is the row's `error`.
pub fn row(table: &MotorTable, log: &Path) -> FleetRow {
    match table.motor_of(log) {
        Some(m) => row_for(m, log),
        None => FleetRow::failed(
            "",
            log,
            "no motor of the table matches this file's name".to_string(),
        ),
    }
}

/// The row of `log` (shown as `shown`: a URL it was fetched from, say), its motor found by
/// `shown`'s file name.
pub fn row_shown(table: &MotorTable, log: &Path, shown: &str) -> FleetRow {
    let mut r = match table.motor_of(Path::new(shown)) {
        Some(m) => row_for(m, log),
        None => FleetRow::failed(
            "",
            log,
            "no motor of the table matches this file's name".to_string(),
        ),
    };
    r.file = shown.to_string();
    if let Some(e) = &mut r.error {
        *e = e.replace(&log.display().to_string(), shown);
    }
    r
}

/// The row of one log as [`row`] gives it, and the diagnosis's JSON document (the one
/// `diagnose --json` prints; `None` where the log gave no report): what a store of the
/// motor's history keeps (`monitor_store::StoredRow::from_diagnose`).
pub fn row_and_report(table: &MotorTable, log: &Path) -> (FleetRow, Option<serde_json::Value>) {
    row_and_report_shown(table, log, &log.display().to_string())
}

/// [`row_and_report`] of `log` shown as `shown` (a URL it was fetched from, say): its motor
/// found by `shown`'s file name, the row's `file` and error naming `shown`.
pub fn row_and_report_shown(
    table: &MotorTable,
    log: &Path,
    shown: &str,
) -> (FleetRow, Option<serde_json::Value>) {
    let Some(m) = table.motor_of(Path::new(shown)) else {
        return (row_shown(table, log, shown), None);
    };
    let (mut row, doc) =
        match diagnose(ParamsSource::Path(&m.params), log, &request(m), &mut |_| {}) {
            Ok(d) => (
                FleetRow::of_report(&m.name, log, &d.report),
                Some(monitor_words::diagnose::document(
                    &d.report,
                    &monitor_words::FieldNames,
                )),
            ),
            Err(e) => (FleetRow::failed(&m.name, log, one_line_error(&e)), None),
        };
    let local = log.display().to_string();
    row.file = shown.to_string();
    if let Some(e) = &mut row.error {
        *e = e.replace(&local, shown);
    }
    (row, doc)
}

/// The diagnosis request of motor `m`'s logs.
fn request(m: &MotorEntry) -> DiagnoseRequest {
    DiagnoseRequest {
        options: ReplayOptions {
            commission: m.commission,
            load: m.load.map_or(LoadModel::Unknown, MotorLoad::model),
            ..ReplayOptions::default()
        },
        baseline: m.baseline.iter().map(LogSource::from).collect(),
        group: None,
    }
}

/// The row of `log` as motor `m`'s.
pub fn row_for(m: &MotorEntry, log: &Path) -> FleetRow {
    match diagnose(ParamsSource::Path(&m.params), log, &request(m), &mut |_| {}) {
        Ok(d) => FleetRow::of_report(&m.name, log, &d.report),
        Err(e) => FleetRow::failed(&m.name, log, one_line_error(&e)),
    }
}

/// Refuses a fleet run's `outputs` (the history store, a result file) that are one of the
/// files it reads: the motor table's file `table_file` (when it is one), each motor's
/// parameter file and baseline logs (or folders), and the `logs`. Call it before anything
/// is written.
///
/// # Errors
/// [`OverwriteError`] naming the input and the output (and their fields: `motors`,
/// `params`, `baseline`, `logs`, and the outputs' own).
pub fn check_fleet_outputs(
    table_file: Option<&Path>,
    table: &MotorTable,
    logs: &[PathBuf],
    outputs: &[NamedFile<'_>],
) -> Result<(), OverwriteError> {
    // The table's file is named `motors` (the Python keyword; the command line's first
    // argument): the field is left empty where the outputs name none, so that the
    // command line's message names the paths alone.
    let named = |field: &'static str| {
        if outputs.iter().all(|o| o.field.is_empty()) {
            ""
        } else {
            field
        }
    };
    let mut inputs: Vec<NamedFile<'_>> = table_file
        .map(|t| NamedFile::new(named("motors"), t))
        .into_iter()
        .collect();
    for m in &table.motor {
        inputs.push(NamedFile::new(named("params"), &m.params));
        inputs.extend(
            m.baseline
                .iter()
                .map(|b| NamedFile::new(named("baseline"), b)),
        );
    }
    inputs.extend(logs.iter().map(|l| NamedFile::new(named("logs"), l)));
    check_outputs(&inputs, outputs)
}

fn one_line_error(e: &ApiError) -> String {
    monitor_io::one_line(&e.to_string())
}

/// The columns of the fleet table, in order (the CSV's header).
pub const COLUMNS: [&str; 19] = [
    "motor",
    "file",
    "rows",
    "rate_hz",
    "verdict",
    "fault",
    "size",
    "size_unit",
    "phase",
    "confidence",
    "first_detection_s",
    "load_moves",
    "data_quality",
    "turns_low",
    "turns_high",
    "turns_basis",
    "against",
    "not_seen",
    "error",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_and_the_table() {
        assert!(wildcard("pump_7_*", "pump_7_2026-11-01.csv"));
        assert!(wildcard("*.csv", "a.csv"));
        assert!(wildcard("p?mp*", "pump"));
        assert!(!wildcard("pump_7_*", "pump_8_x.csv"));
        assert!(!wildcard("a*b", "acbx"));
        let t = MotorTable::from_toml_str(
            "[[motor]]\nname = \"m\"\nparams = \"p.toml\"\nlogs = \"m_*\"\ncommission = [1.0, 2.0]\n",
            "t.toml",
            Path::new("/x"),
        )
        .unwrap();
        assert_eq!(t.motor[0].params, Path::new("/x/p.toml"));
        assert!(t.motor_of(Path::new("/logs/m_1.csv")).is_some());
        assert!(t.motor_of(Path::new("/logs/n_1.csv")).is_none());
        for bad in [
            "[[motor]]\nname = \"m\"\nparams = \"p\"\nlogs = \"*\"\nload = \"heavy\"\n",
            "[[motor]]\nname = \"m\"\nparams = \"p\"\nlogs = \"*\"\ncommission = [2.0, 1.0]\n",
            "[[motor]]\nname = \"m\"\nparams = \"p\"\nlogs = \"*\"\ncolour = 1\n",
            "",
        ] {
            let e = MotorTable::from_toml_str(bad, "t.toml", Path::new(".")).unwrap_err();
            assert!(e.to_string().starts_with("bad motor table t.toml"), "{e}");
        }
    }
}
