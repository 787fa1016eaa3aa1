//! The fleet run from Python (`drive_monitor.fleet.diagnose_many` on Dask): the motor
//! table's checks, one log's row on a worker, and the check of the run's outputs.

use super::{json, run, to_py, ParamsError};
use pyo3::prelude::*;
use std::path::PathBuf;

/// One log's row of the fleet table (`sim-host fleet`), as JSON: the motor table's text
/// (`base` its folder, for its relative paths), the log at `log`, shown as `shown`.
#[pyfunction]
pub fn fleet_row(
    py: Python<'_>,
    table_toml: String,
    base: PathBuf,
    log: PathBuf,
    shown: String,
) -> PyResult<String> {
    run(py, || {
        let table =
            monitor_api::fleet::MotorTable::from_toml_str(&table_toml, "the motor table", &base)
                .map_err(|e| ParamsError::new_err(e.to_string()))?;
        json(&monitor_api::fleet::row_shown(&table, &log, &shown))
    })
}

/// The text of the motor table file at `path`, checked (its relative paths from `base`).
///
/// # Errors
/// [`ParamsError`] naming the file: it cannot be read, or it is not a motor table.
#[pyfunction]
pub fn fleet_read_table(path: PathBuf, base: PathBuf) -> PyResult<String> {
    let text = std::fs::read_to_string(&path).map_err(|source| {
        ParamsError::new_err(
            monitor_api::fleet::FleetError::Io {
                path: path.display().to_string(),
                source,
            }
            .to_string(),
        )
    })?;
    fleet_check_table(&text, &path.display().to_string(), base)?;
    Ok(text)
}

/// Checks a motor table's text (`shown` in messages; relative paths from `base`).
///
/// # Errors
/// [`ParamsError`] naming `shown` and what is wrong.
#[pyfunction]
pub fn fleet_check_table(text: &str, shown: &str, base: PathBuf) -> PyResult<()> {
    monitor_api::fleet::MotorTable::from_toml_str(text, shown, &base)
        .map(|_| ())
        .map_err(|e| ParamsError::new_err(e.to_string()))
}

/// Refuses a fleet run's `store` when it is a file the run reads (the motor table's file
/// `table_path`, a motor's parameter file or baseline, one of the local `logs`), before
/// anything is written.
///
/// # Errors
/// [`ParamsError`]: the motor table is not one; [`OptionError`]: "refusing to overwrite
/// the input ..." naming the input and the store.
#[pyfunction]
#[pyo3(signature = (table_toml, base, table_path, logs, store))]
pub fn fleet_check_outputs(
    table_toml: &str,
    base: PathBuf,
    table_path: Option<PathBuf>,
    logs: Vec<PathBuf>,
    store: PathBuf,
) -> PyResult<()> {
    let table = monitor_api::fleet::MotorTable::from_toml_str(table_toml, "the motor table", &base)
        .map_err(|e| ParamsError::new_err(e.to_string()))?;
    monitor_api::fleet::check_fleet_outputs(
        table_path.as_deref(),
        &table,
        &logs,
        &[monitor_api::files::NamedFile::new("store", &store)],
    )
    .map_err(|e| to_py(e.into()))
}

/// The fleet table's columns, in order.
#[pyfunction]
pub fn fleet_columns() -> Vec<&'static str> {
    monitor_api::fleet::COLUMNS.to_vec()
}

/// One log's fleet row, its store row and its time, as JSON `{"row": {...}, "stored":
/// {...} | null, "time": {"time_s", "source", "name_unmatched"} | null}` (on a worker):
/// `log` is the local file, `shown` its name in the rows (a URL) and the name its motor
/// and `time_from_name` read. The time comes from the log itself, else from its name, else
/// from `modified_s` (a remote file's modification time [s since 1970 UTC]) or the local
/// file's ([`monitor_api::fleet::log_time`], the order of `sim-host fleet --store`).
///
/// # Errors
/// A motor table that is not one ([`ParamsError`]).
#[pyfunction]
#[pyo3(signature = (table_toml, base, log, shown, modified_s=None))]
pub fn fleet_store_row_timed(
    py: Python<'_>,
    table_toml: String,
    base: PathBuf,
    log: PathBuf,
    shown: String,
    modified_s: Option<i64>,
) -> PyResult<String> {
    use monitor_api::fleet::LogTimeSource;
    run(py, || {
        let table =
            monitor_api::fleet::MotorTable::from_toml_str(&table_toml, "the motor table", &base)
                .map_err(|e| ParamsError::new_err(e.to_string()))?;
        let (row, doc) = monitor_api::fleet::row_and_report_shown(&table, &log, &shown);
        let motor = table.motor_of(std::path::Path::new(&shown));
        let time = motor.and_then(|m| {
            let mut t = monitor_api::fleet::log_time(m, &log, &shown).ok()?;
            if let (LogTimeSource::Modified, Some(s)) = (t.source, modified_s) {
                t.time_s = s;
            }
            Some(t)
        });
        let stored = motor
            .zip(time.as_ref())
            .zip(doc.as_ref())
            .and_then(|((m, t), d)| {
                let mut id = monitor_store::LogIdentity::of_file(&m.name, &log).ok()?;
                id.path = shown.clone();
                id.time_s = t.time_s;
                Some(
                    monitor_store::StoredRow::from_diagnose(&id, d)
                        .with_time_source(t.source.name()),
                )
            });
        let v = serde_json::json!({ "row": row, "stored": stored, "time": time });
        Ok(v.to_string())
    })
}

/// What a fleet run that stored logs has to say of their times, one line each
/// ([`monitor_api::fleet::time_warnings`]): `times_json` is a JSON list of `[motor, time]`
/// (the `time` of [`fleet_store_row_timed`]).
///
/// # Errors
/// [`ParamsError`]: the motor table is not one; [`super::OptionError`]: `times_json` is not
/// such a list.
#[pyfunction]
pub fn fleet_time_warnings(
    table_toml: &str,
    base: PathBuf,
    times_json: &str,
) -> PyResult<Vec<String>> {
    let table = monitor_api::fleet::MotorTable::from_toml_str(table_toml, "the motor table", &base)
        .map_err(|e| ParamsError::new_err(e.to_string()))?;
    let times: Vec<(String, monitor_api::fleet::LogTime)> = serde_json::from_str(times_json)
        .map_err(|e| super::OptionError::new_err(format!("fleet times: {e}")))?;
    Ok(monitor_api::fleet::time_warnings(&table, &times))
}
