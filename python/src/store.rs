//! The store of the motors' history from Python (`drive_monitor.trend`, the Dask fleet
//! run's `store=`): the workers make the rows, the client appends them in one place.

use super::{run, LogError, OptionError};
use monitor_store::trend::TrendOptions;
use monitor_store::{Appended, LogIdentity, Store, StoredRow};
use pyo3::prelude::*;
use std::path::PathBuf;

fn store_err(e: monitor_store::HistoryError) -> PyErr {
    LogError::new_err(e.to_string())
}

/// One log's fleet row and its store row, as JSON `{"row": {...}, "stored": {...} | null}`
/// (on a worker): `log` is the local file, `shown` its name in the rows (a URL), `time_s`
/// its start where known (else the local file's modification time).
///
/// # Errors
/// A motor table that is not one ([`super::ParamsError`]).
#[pyfunction]
#[pyo3(signature = (table_toml, base, log, shown, time_s=None))]
pub fn fleet_store_row(
    py: Python<'_>,
    table_toml: String,
    base: PathBuf,
    log: PathBuf,
    shown: String,
    time_s: Option<i64>,
) -> PyResult<String> {
    run(py, || {
        let table =
            monitor_api::fleet::MotorTable::from_toml_str(&table_toml, "the motor table", &base)
                .map_err(|e| super::ParamsError::new_err(e.to_string()))?;
        let (mut row, doc) = monitor_api::fleet::row_and_report(&table, &log);
        row.file = shown.clone();
        let id = LogIdentity::of_file(&row.motor, &log).ok().map(|mut id| {
            id.path = shown;
            if let Some(t) = time_s {
                id.time_s = t;
            }
            id
        });
        let stored = id
            .zip(doc.as_ref())
            .filter(|(id, _)| !id.motor.is_empty())
            .map(|(id, d)| StoredRow::from_diagnose(&id, d));
        let v = serde_json::json!({ "row": row, "stored": stored });
        Ok(v.to_string())
    })
}

/// Appends the rows (a JSON list of store rows) to the store at `store`, one transaction
/// each; returns (stored, already stored).
///
/// # Errors
/// [`LogError`]: the store cannot be opened or written; [`OptionError`]: a row is not one.
#[pyfunction]
pub fn store_append(py: Python<'_>, store: PathBuf, rows_json: String) -> PyResult<(usize, usize)> {
    run(py, || {
        let v: serde_json::Value = serde_json::from_str(&rows_json)
            .map_err(|e| OptionError::new_err(format!("store rows: not JSON: {e}")))?;
        let rows = v
            .as_array()
            .ok_or_else(|| OptionError::new_err("store rows: not a list"))?;
        let mut s = Store::open(&store).map_err(store_err)?;
        s.sync_mirror().map_err(store_err)?;
        let (mut stored, mut skipped) = (0, 0);
        for r in rows {
            let row = StoredRow::from_json(r)
                .ok_or_else(|| OptionError::new_err(format!("store rows: not a store row: {r}")))?;
            match s.append(&row).map_err(store_err)? {
                Appended::Stored => stored += 1,
                Appended::AlreadyStored => skipped += 1,
            }
        }
        Ok((stored, skipped))
    })
}

/// The store's rows and their trend, as JSON `{"rows": [...], "motors": [...]}` (`motors`
/// spelled by `monitor_words::trend`, as `sim-host trend --json`'s).
///
/// # Errors
/// [`LogError`]: no store there, or not a store; [`OptionError`]: a bad date or window.
/// `reference_until`: the baseline, each motor's logs up to the end of that UTC day
/// (`sim-host trend --reference-until`).
#[pyfunction]
#[pyo3(signature = (store, motor=None, since=None, window_days=14.0, k=3.0, reference_until=None))]
pub fn store_trend(
    py: Python<'_>,
    store: PathBuf,
    motor: Option<String>,
    since: Option<String>,
    window_days: f64,
    k: f64,
    reference_until: Option<String>,
) -> PyResult<String> {
    run(py, || {
        if !(window_days.is_finite() && window_days > 0.0 && k.is_finite() && k > 0.0) {
            return Err(OptionError::new_err(format!(
                "window_days and k must be positive, got {window_days} and {k}"
            )));
        }
        let since_s = match &since {
            Some(d) => Some(monitor_store::parse_day(d).ok_or_else(|| {
                OptionError::new_err(format!(
                    "since {d}: not a date; give the UTC day as YYYY-MM-DD"
                ))
            })?),
            None => None,
        };
        let until_s = match &reference_until {
            Some(d) => Some(
                monitor_store::parse_day(d)
                    .ok_or_else(|| {
                        OptionError::new_err(format!(
                            "reference_until {d}: not a date; give the UTC day as YYYY-MM-DD"
                        ))
                    })?
                    .saturating_add(86_400),
            ),
            None => None,
        };
        let s = Store::open_existing(&store).map_err(store_err)?;
        let rows = s.rows(motor.as_deref(), since_s).map_err(store_err)?;
        let opts = TrendOptions {
            window_days,
            k_scatter: k,
            reference_until_s: until_s,
            ..TrendOptions::default()
        };
        let motors = monitor_store::trend::trend(&rows, &opts);
        // The sentences are the words door's, beside the engine's typed reasons.
        let motors = monitor_api::words::trend::spelled(&motors);
        Ok(serde_json::json!({ "rows": rows, "motors": motors }).to_string())
    })
}

/// The store's columns, in order.
#[pyfunction]
pub fn store_columns() -> Vec<&'static str> {
    monitor_store::COLUMNS.iter().map(|c| c.name).collect()
}
