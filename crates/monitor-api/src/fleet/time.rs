//! When a fleet log was recorded, for the motors' history (`sim-host fleet --store`, the
//! Python fleet run's `store=`; docs/trend.md): from the log itself where it can be, the
//! file's modification time only as the last resort, and said so ([`log_time`],
//! [`time_warnings`]). In order:
//!
//! 1. `log`: a time column of timestamps (the parameter file's `[columns]`: `t_s = { name =
//!    "Time", unit = "timestamp" }`, or `iso8601`, `epoch_s` ...; a Parquet `TIMESTAMP`
//!    column): its first time;
//! 2. `tdms`: a TDMS channel's `wf_start_time`;
//! 3. `file_name`: the date and time in the file's name by the motor's `time_from_name`
//!    pattern ([`time_from_name`]);
//! 4. `modified`: the file's modification time (a copy without `cp -p` has the copy's).

use super::{MotorEntry, MotorTable};
use monitor_io::log::{LogFile, LogStartFrom, OpenOptions};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Where a log's time comes from (the store's `time_source`; JSON: its [`LogTimeSource::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LogTimeSource {
    /// A time column of timestamps: its first time.
    Log,
    /// A TDMS channel's `wf_start_time`.
    Tdms,
    /// The file's name, by the motor's `time_from_name`.
    FileName,
    /// The file's modification time: the last resort.
    Modified,
}

impl LogTimeSource {
    /// Its name in the store's `time_source` column: `log`, `tdms`, `file_name`, `modified`.
    pub fn name(self) -> &'static str {
        match self {
            LogTimeSource::Log => "log",
            LogTimeSource::Tdms => "tdms",
            LogTimeSource::FileName => "file_name",
            LogTimeSource::Modified => "modified",
        }
    }
}

/// A log's time and where it comes from (JSON: an object of its fields).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LogTime {
    /// The log's start [whole seconds since 1970-01-01 UTC, rounded down].
    pub time_s: i64,
    /// Where it comes from.
    pub source: LogTimeSource,
    /// The motor has a `time_from_name` pattern the log's file name does not match (its
    /// time then came from the next source).
    pub name_unmatched: bool,
}

/// The time of motor `m`'s log at `log`, its file name taken from `shown` (a URL the log
/// was fetched from, or the path itself), by the order of the module documentation. The
/// log is opened with the motor's parameter file's `[columns]`; a log or parameter file
/// that cannot be read gives its time from the next source (the diagnosis reports why).
///
/// # Errors
/// Only the last resort's: the file has no modification time (or cannot be read).
pub fn log_time(m: &MotorEntry, log: &Path, shown: &str) -> std::io::Result<LogTime> {
    if let Some(s) = start_in_log(m, log) {
        let source = match s.from {
            LogStartFrom::TimeColumn => LogTimeSource::Log,
            LogStartFrom::TdmsStartTime => LogTimeSource::Tdms,
        };
        return Ok(LogTime {
            time_s: s.utc_s.floor() as i64,
            source,
            name_unmatched: false,
        });
    }
    let name = Path::new(shown)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let from_name = m
        .time_from_name
        .as_deref()
        .map(|p| time_from_name(p, &name));
    if let Some(Some(time_s)) = from_name {
        return Ok(LogTime {
            time_s,
            source: LogTimeSource::FileName,
            name_unmatched: false,
        });
    }
    let modified = std::fs::metadata(log)?.modified()?;
    let time_s = match modified.duration_since(std::time::UNIX_EPOCH) {
        Ok(d) => d.as_secs() as i64,
        Err(e) => -(e.duration().as_secs_f64().ceil() as i64),
    };
    Ok(LogTime {
        time_s,
        source: LogTimeSource::Modified,
        name_unmatched: from_name.is_some(),
    })
}

/// The log's own start ([`LogFile::start_time`]), opened with the motor's `[columns]`.
fn start_in_log(m: &MotorEntry, log: &Path) -> Option<monitor_io::log::LogStart> {
    let (_, columns) = monitor_io::log::mapping::load_params(&m.params).ok()?;
    let opts = OpenOptions {
        group: None,
        columns,
    };
    let file = LogFile::open_with(log, &opts).ok()?;
    file.start_time()
        .ok()
        .flatten()
        .filter(|s| s.utc_s.is_finite())
}

/// Seconds since 1970-01-01 UTC of the date and time `pattern` reads in the file name
/// `name`, else `None`. The pattern is chrono's strftime syntax: literal text and
/// specifiers such as `%Y` (year), `%m`, `%d`, `%H`, `%M`, `%S`, `%y`, `%b`, `%j`, `%s`
/// (Unix seconds), `%z` (an offset); it must match the whole name without its extension
/// (`pump_7_%Y%m%d_%H%M` reads `pump_7_20261103_0600.csv`), or the whole name. A date
/// without a time of day is its midnight, an hour without minutes is on the hour; without
/// `%z` the time is UTC. `*` and `?` are not wildcards here (the table's `logs` pattern
/// says which logs are the motor's).
pub fn time_from_name(pattern: &str, name: &str) -> Option<i64> {
    let stem = Path::new(name).file_stem().map(|s| s.to_string_lossy());
    stem.and_then(|s| read_name(pattern, &s))
        .or_else(|| read_name(pattern, name))
}

/// [`time_from_name`] of one text.
fn read_name(pattern: &str, text: &str) -> Option<i64> {
    use chrono::format::{parse, Parsed, StrftimeItems};
    let mut p = Parsed::new();
    parse(&mut p, text, StrftimeItems::new(pattern)).ok()?;
    if let Some(t) = p.timestamp() {
        return Some(t);
    }
    if p.hour_mod_12().is_some() && p.minute().is_none() {
        p.set_minute(0).ok()?;
    }
    let date = p.to_naive_date().ok()?;
    let time = match p.hour_mod_12() {
        Some(_) => p.to_naive_time().ok()?,
        None => chrono::NaiveTime::MIN,
    };
    let offset = i64::from(p.offset().unwrap_or(0));
    Some(date.and_time(time).and_utc().timestamp() - offset)
}

/// Whether `pattern` is one [`time_from_name`] can use: chrono's strftime syntax (no
/// unknown `%` specifier) with a year and a day in it (`%Y`/`%y`/`%G`, and `%d`, `%j` or
/// `%e`), or Unix seconds (`%s`).
pub fn time_pattern_ok(pattern: &str) -> bool {
    use chrono::format::{Item, StrftimeItems};
    if StrftimeItems::new(pattern).any(|i| matches!(i, Item::Error)) {
        return false;
    }
    let has = |specs: &[&str]| specs.iter().any(|s| pattern.contains(s));
    has(&["%s"]) || (has(&["%Y", "%y", "%G"]) && has(&["%d", "%j", "%e", "%F"])) || has(&["%F"])
}

/// The UTC day `YYYY-MM-DD` of `time_s` seconds since 1970-01-01.
fn utc_day(time_s: i64) -> String {
    chrono::DateTime::from_timestamp(time_s, 0)
        .map_or_else(|| "?".to_string(), |t| t.date_naive().to_string())
}

/// What a run that stored `times` (each log's motor name and time) has to say of them, one
/// line each (for stderr): per motor with a `time_from_name` pattern, how many log names
/// did not match it; per motor whose logs (two or more) all took their files' modification
/// times and fall on one day, the loud warning (the history would lie: every log on one
/// day); else, the count of the logs whose times are modification times. Empty when every
/// time came from the logs themselves.
pub fn time_warnings(table: &MotorTable, times: &[(String, LogTime)]) -> Vec<String> {
    let mut out = Vec::new();
    let mut quiet = 0usize;
    for m in &table.motor {
        let own: Vec<&LogTime> = times
            .iter()
            .filter(|(n, _)| *n == m.name)
            .map(|(_, t)| t)
            .collect();
        let unmatched = own.iter().filter(|t| t.name_unmatched).count();
        if let (Some(p), true) = (&m.time_from_name, unmatched > 0) {
            out.push(format!(
                "warning: motor {}: the names of {unmatched} log(s) do not match time_from_name \"{p}\": their times come from the next source",
                m.name
            ));
        }
        let modified: Vec<i64> = own
            .iter()
            .filter(|t| t.source == LogTimeSource::Modified)
            .map(|t| t.time_s)
            .collect();
        let days: std::collections::BTreeSet<String> =
            modified.iter().map(|t| utc_day(*t)).collect();
        match days.iter().next() {
            Some(day) if modified.len() >= 2 && modified.len() == own.len() && days.len() == 1 => {
                out.push(format!(
                    "WARNING: motor {}: the times of {} logs are their files' modification times and all fall on {day}: copy logs with `cp -p`, give the log a time column, or set `time_from_name` in the motor table (docs/trend.md)",
                    m.name,
                    modified.len()
                ));
            }
            _ => quiet += modified.len(),
        }
    }
    if quiet > 0 {
        out.push(format!(
            "warning: the times of {quiet} log(s) are their files' modification times (no time column of timestamps, no TDMS wf_start_time, no time_from_name match): a copy without `cp -p` has the copy's time (docs/trend.md)"
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_in_file_names() {
        // 2026-11-03T06:00:00Z (`date -u -d 2026-11-03T06:00:00Z +%s`).
        let t = 1_793_685_600;
        let p = "pump_7_%Y%m%d_%H%M";
        assert_eq!(time_from_name(p, "pump_7_20261103_0600.csv"), Some(t));
        assert_eq!(
            time_from_name(p, "pump_7_20261103_0630.tdms"),
            Some(t + 1800)
        );
        assert_eq!(
            time_from_name("p_%Y-%m-%d", "p_2026-11-03.csv"),
            Some(t - 6 * 3600)
        );
        assert_eq!(time_from_name("p_%Y%m%d_%H", "p_20261103_06.csv"), Some(t));
        assert_eq!(
            time_from_name("p_%Y%m%dT%H%M%z", "p_20261103T0800+0200"),
            Some(t)
        );
        assert_eq!(time_from_name(p, "pump_7_latest.csv"), None);
        assert_eq!(time_from_name(p, "pump_7_20261303_0600.csv"), None);
        assert!(time_pattern_ok(p) && time_pattern_ok("x_%s") && time_pattern_ok("%F"));
        assert!(!time_pattern_ok("pump_%Q") && !time_pattern_ok("pump_%H%M"));
    }
}
