//! `drive_monitor._native`: the Python package's bindings to the library the `sim-host`
//! command line runs (`monitor_api`, `monitor_api::fleet`). A log is a path, or in-memory
//! data with `__arrow_c_stream__` (imported through Arrow's C stream interface,
//! [`arrow_in`], and read by the library through the same path as a file); every function
//! returns the command's `--json` document as a string, so a result is the command line's,
//! key for key.
//!
//! The GIL is released while the Rust code runs; a panic never crosses into Python (it is
//! an `InternalError`); errors are the package's exception classes (imported below from
//! `drive_monitor/_errors.py`: a bad value a `ValueError`, a wrong type a `TypeError`),
//! carrying the command line's one-line message.

use monitor_api::replay::{Takes, DIAGNOSE_OPTIONS};
use monitor_api::{self as api, ApiError, ErrorKind, LogSource, ParamsSource};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

mod arrow_in;
mod fleet;
mod options;
mod store;

// The package's exception classes are Python classes (`drive_monitor/_errors.py`), so that
// each derives from the built-in class Python's convention asks for: a bad value is a
// `ValueError` (`ParamsError`, `LogError`, `OptionError`, `AnalysisError`), a value of the
// wrong type a `TypeError` (`OptionTypeError`, a subclass of `OptionError`), a bug a
// `RuntimeError` (`InternalError`); all derive from `DriveMonitorError`. PyO3's own classes
// (`create_exception!`) take one base, and these need two.
pyo3::import_exception!(drive_monitor._errors, DriveMonitorError);
pyo3::import_exception!(drive_monitor._errors, ParamsError);
pyo3::import_exception!(drive_monitor._errors, ParamsTypeError);
pyo3::import_exception!(drive_monitor._errors, LogError);
pyo3::import_exception!(drive_monitor._errors, LogTypeError);
pyo3::import_exception!(drive_monitor._errors, LogNotFoundError);
pyo3::import_exception!(drive_monitor._errors, ParamsNotFoundError);
pyo3::import_exception!(drive_monitor._errors, OptionError);
pyo3::import_exception!(drive_monitor._errors, OptionTypeError);
pyo3::import_exception!(drive_monitor._errors, AnalysisError);
pyo3::import_exception!(drive_monitor._errors, InternalError);

/// The error `e` (an [`OptionError`] of an option given a value of the wrong type) as an
/// [`OptionTypeError`] with the same message: `except TypeError` catches it, and `except
/// OptionError` still does.
fn wrong_type(py: Python<'_>, e: PyErr) -> PyErr {
    OptionTypeError::new_err(e.value(py).to_string())
}

/// Python's spelling of the library's fields: its keyword arguments, as its other messages
/// name them (`commission = 4:2`, `load = 'heavy'`).
struct PyWords;

impl monitor_api::words::Spelling for PyWords {
    fn option(&self, field: monitor_api::replay::OptionField, value: &str) -> String {
        if value.is_empty() {
            field.name().to_string()
        } else {
            format!("{} = {value}", field.name())
        }
    }

    /// A report's advice as a keyword argument to type: `commission='START:END'`,
    /// `load='viscous'`, `baseline=[...]`, `effects=['load_torque']`, `from_s=0.8`.
    fn hint(&self, field: monitor_api::replay::OptionField, value: &str) -> String {
        use monitor_api::replay::OptionField as F;
        let name = field.name();
        let list = |v: &str| {
            v.split(',')
                .map(|x| format!("'{}'", x.trim()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match (field, value) {
            (F::Baseline | F::Effects, "") => format!("{name}=[...]"),
            (_, "") => format!("{name}=..."),
            (F::Baseline | F::Effects, v) => format!("{name}=[{}]", list(v)),
            (F::Commission | F::Load | F::Group | F::Params | F::ColumnsFrom, v) => {
                format!("{name}='{v}'")
            }
            (_, v) => format!("{name}={v}"),
        }
    }

    /// `diagnose(..., baseline=[...])`.
    fn command_with(&self, command: &str, field: monitor_api::replay::OptionField) -> String {
        format!("{command}(..., {})", self.hint(field, ""))
    }
}

/// The exception of an [`ApiError`], its message in Python's words ([`PyWords`]); a law file
/// that does not exist is Python's `FileNotFoundError`.
fn to_py(e: ApiError) -> PyErr {
    let msg = e.spelled(&PyWords);
    if let ApiError::Laws(monitor_api::laws::LawError::NotFound { .. }) = e {
        return pyo3::exceptions::PyFileNotFoundError::new_err(msg);
    }
    // A file that does not exist is also Python's FileNotFoundError.
    match (e.kind(), e.is_not_found()) {
        (ErrorKind::Params, true) => return ParamsNotFoundError::new_err(msg),
        (ErrorKind::Log, true) => return LogNotFoundError::new_err(msg),
        _ => {}
    }
    match e.kind() {
        ErrorKind::Params => ParamsError::new_err(msg),
        ErrorKind::Log => LogError::new_err(msg),
        ErrorKind::Option => OptionError::new_err(msg),
        ErrorKind::Analysis => AnalysisError::new_err(msg),
    }
}

/// Runs `f` without the GIL, a panic turned into [`InternalError`].
fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T, PyErr> + Send) -> PyResult<T> {
    py.allow_threads(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|p| {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(InternalError::new_err(format!("internal error: {what}")))
        })
    })
}

/// A parameter file: a path, or (with `is_text`) its TOML text.
fn params_source<'a>(params: &'a str, is_text: bool) -> ParamsSource<'a> {
    if is_text {
        ParamsSource::Toml {
            text: params,
            origin: "the parameter dict",
        }
    } else {
        ParamsSource::Path(std::path::Path::new(params))
    }
}

/// A log: the path `log` when `origin` is `None`, else the in-memory data `log` (an object
/// with `__arrow_c_stream__`) that messages call `origin`.
fn log_source(log: &Bound<'_, PyAny>, origin: Option<&str>) -> PyResult<LogSource> {
    match origin {
        None => Ok(LogSource::File(log.extract::<PathBuf>()?)),
        Some(origin) => {
            let data =
                arrow_in::memory_log(log, origin).map_err(|e| LogError::new_err(e.to_string()))?;
            Ok(LogSource::data(data, origin))
        }
    }
}

fn json<T: serde::Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| InternalError::new_err(e.to_string()))
}

/// The effects named: the library's, checked here with near matches
/// ([`api::files::near_names`]) when no law file is given; with one, the library resolves
/// them against the laws too (an unknown name is then an `OptionError` of the request).
fn effects_of(names: &[String], laws: bool) -> PyResult<Vec<String>> {
    if !laws {
        let known: Vec<&str> = monitor_core::EffectKind::ALL
            .iter()
            .map(|e| e.name())
            .collect();
        for n in names {
            if monitor_core::EffectKind::from_name(n).is_none() {
                return Err(OptionError::new_err(not_in_library("effect", n, &known)));
            }
        }
    }
    Ok(names.to_vec())
}

/// `effect 'load_torq' is not in the library; did you mean 'load_torque'? (the library's
/// effects: ...)`: the message for a name of `what` not among `known`.
fn not_in_library(what: &str, name: &str, known: &[&str]) -> String {
    let near = api::files::near_names(name, known);
    let meant = match near.as_slice() {
        [] => String::new(),
        names => format!(
            "; did you mean {}?",
            names
                .iter()
                .take(3)
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    };
    format!(
        "{what} '{name}' is not in the library{meant} (the library's {what}s: {})",
        known.join(", ")
    )
}

/// The options `diagnose` takes by name, from the library's one description
/// ([`DIAGNOSE_OPTIONS`]): `(name, annotation, default, doc)` each, in order; the package
/// builds `drive_monitor.diagnose`'s signature and docs from them.
#[pyfunction]
fn diagnose_options() -> Vec<(String, String, String, String)> {
    DIAGNOSE_OPTIONS
        .iter()
        .map(|s| {
            let annotation = match s.takes {
                Takes::Window => "Optional[Union[Tuple[float, float], str]]",
                Takes::Choice(_) => "Optional[str]",
                Takes::Seconds => "Optional[float]",
                Takes::Count => "Optional[int]",
                Takes::Flag => "bool",
                Takes::JsonFile => "Optional[Union[str, os.PathLike, Dict[str, Any]]]",
            };
            (
                s.field.name().to_string(),
                annotation.to_string(),
                s.default.to_string(),
                s.doc.split_whitespace().collect::<Vec<_>>().join(" "),
            )
        })
        .collect()
}

/// `diagnose --json` of the log at `log` with the parameter file `params`; its options by
/// name (`**options`: [`diagnose_options`]).
#[pyfunction]
#[pyo3(signature = (log, params, log_origin=None, params_is_text=false, baseline=Vec::new(), group=None, **options))]
#[allow(clippy::too_many_arguments)]
fn diagnose(
    py: Python<'_>,
    log: &Bound<'_, PyAny>,
    params: String,
    log_origin: Option<String>,
    params_is_text: bool,
    baseline: Vec<(Bound<'_, PyAny>, Option<String>)>,
    group: Option<String>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let req = api::DiagnoseRequest {
        options: options::replay_options(options)?,
        baseline: baseline
            .iter()
            .map(|(b, origin)| log_source(b, origin.as_deref()))
            .collect::<PyResult<_>>()?,
        group,
    };
    let log = log_source(log, log_origin.as_deref())?;
    run(py, || {
        let d = api::diagnose(
            params_source(&params, params_is_text),
            log,
            &req,
            &mut |_| {},
        )
        .map_err(to_py)?;
        json(&monitor_api::words::diagnose::document(&d.report, &PyWords))
    })
}

fn analysis_request(
    effects: &[String],
    laws: Option<PathBuf>,
    from_s: Option<f64>,
    to_s: Option<f64>,
    no_fit: bool,
    group: Option<String>,
    rotor_bars: Option<u32>,
) -> PyResult<api::AnalysisRequest> {
    Ok(api::AnalysisRequest {
        effects: effects_of(effects, laws.is_some())?,
        laws,
        from_s,
        to_s,
        no_fit,
        group,
        rotor_bars,
    })
}

/// `compare --json`.
#[pyfunction]
#[pyo3(signature = (log, params, log_origin=None, params_is_text=false, effects=Vec::new(), from_s=None, to_s=None, no_fit=false, group=None, laws=None))]
#[allow(clippy::too_many_arguments)]
fn compare(
    py: Python<'_>,
    log: &Bound<'_, PyAny>,
    params: String,
    log_origin: Option<String>,
    params_is_text: bool,
    effects: Vec<String>,
    from_s: Option<f64>,
    to_s: Option<f64>,
    no_fit: bool,
    group: Option<String>,
    laws: Option<PathBuf>,
) -> PyResult<String> {
    let req = analysis_request(&effects, laws, from_s, to_s, no_fit, group, None)?;
    let log = log_source(log, log_origin.as_deref())?;
    run(py, || {
        let doc = api::compare(params_source(&params, params_is_text), log, &req, &PyWords);
        json(&doc.map_err(to_py)?)
    })
}

/// `explain --json`, or with `ladder` `explain --ladder --json`.
#[pyfunction]
#[pyo3(signature = (log, params, log_origin=None, params_is_text=false, effects=Vec::new(), from_s=None, to_s=None, no_fit=false, group=None, rotor_bars=None, ladder=false, laws=None))]
#[allow(clippy::too_many_arguments)]
fn explain(
    py: Python<'_>,
    log: &Bound<'_, PyAny>,
    params: String,
    log_origin: Option<String>,
    params_is_text: bool,
    effects: Vec<String>,
    from_s: Option<f64>,
    to_s: Option<f64>,
    no_fit: bool,
    group: Option<String>,
    rotor_bars: Option<u32>,
    ladder: bool,
    laws: Option<PathBuf>,
) -> PyResult<String> {
    let req = analysis_request(&effects, laws, from_s, to_s, no_fit, group, rotor_bars)?;
    let log = log_source(log, log_origin.as_deref())?;
    run(py, || {
        let params = params_source(&params, params_is_text);
        let doc = if ladder {
            api::ladder(params, log, &req, &PyWords)
        } else {
            api::explain(params, log, &req, &PyWords)
        };
        json(&doc.map_err(to_py)?)
    })
}

/// `identify --json`: `{"identification": ..., "out": null, "toml": ...}`.
#[pyfunction]
#[pyo3(signature = (log, params, log_origin=None, params_is_text=false, from_s=None, to_s=None, group=None, keep_columns=false))]
#[allow(clippy::too_many_arguments)]
fn identify(
    py: Python<'_>,
    log: &Bound<'_, PyAny>,
    params: String,
    log_origin: Option<String>,
    params_is_text: bool,
    from_s: Option<f64>,
    to_s: Option<f64>,
    group: Option<String>,
    keep_columns: bool,
) -> PyResult<String> {
    let log = log_source(log, log_origin.as_deref())?;
    run(py, || {
        let id = api::identify(
            params_source(&params, params_is_text),
            log,
            from_s,
            to_s,
            group,
            &mut |_| {},
        )
        .map_err(to_py)?;
        // As `sim-host identify`: the start file's `[columns]` only when asked for.
        let toml = if keep_columns {
            id.toml.as_str()
        } else {
            id.toml_without_columns()
        };
        json(&serde_json::json!({
            "identification": id.identification,
            "out": null,
            "toml": toml,
        }))
    })
}

/// `params from-nameplate --json`.
#[pyfunction]
#[pyo3(signature = (power_kw, voltage_v, current_a, frequency_hz, speed_rpm, power_factor, efficiency, poles=None, connection="star", locked_rotor_ratio=None, nema_design="B", columns_from=None))]
#[allow(clippy::too_many_arguments)]
fn params_from_nameplate(
    py: Python<'_>,
    power_kw: f64,
    voltage_v: f64,
    current_a: f64,
    frequency_hz: f64,
    speed_rpm: f64,
    power_factor: f64,
    efficiency: f64,
    poles: Option<u32>,
    connection: &str,
    locked_rotor_ratio: Option<f64>,
    nema_design: &str,
    columns_from: Option<PathBuf>,
) -> PyResult<String> {
    use monitor_api::files::{Connection, Nameplate, NemaDesign};
    let connection = match connection {
        "star" => Connection::Star,
        "delta" => Connection::Delta,
        other => {
            return Err(OptionError::new_err(format!(
                "connection = '{other}': give 'star' or 'delta'"
            )))
        }
    };
    let design = match nema_design {
        "A" => NemaDesign::A,
        "B" => NemaDesign::B,
        "C" => NemaDesign::C,
        "D" => NemaDesign::D,
        other => {
            return Err(OptionError::new_err(format!(
                "nema_design = '{other}': give 'A', 'B', 'C' or 'D'"
            )))
        }
    };
    let n = Nameplate {
        power_kw,
        voltage_v,
        current_a,
        frequency_hz,
        speed_rpm,
        power_factor,
        efficiency,
        poles,
        connection,
        locked_rotor_ratio,
        design,
    };
    run(py, || {
        let (estimate, toml) =
            api::params_from_nameplate(&n, columns_from.as_deref()).map_err(to_py)?;
        json(&api::nameplate_document(&estimate, &toml, None))
    })
}

/// `simulate` into `out` (CSV, TDMS or Parquet by extension); the summary. `scenario` is
/// the scenario's TOML text, or with `scenario_is_text=false` its file's path. `out` is
/// checked against the parameter file and the scenario file first (the library's one
/// guard: nothing is written when it is one of them), then written atomically.
///
/// # Errors
/// [`OptionError`] when `out` is an input ("refusing to overwrite the input ..."); as
/// `monitor_api::simulate_to_file`.
#[pyfunction]
#[pyo3(signature = (params, scenario, out, params_is_text=false, scenario_is_text=true, laws=None))]
fn simulate(
    py: Python<'_>,
    params: String,
    scenario: String,
    out: PathBuf,
    params_is_text: bool,
    scenario_is_text: bool,
    laws: Option<PathBuf>,
) -> PyResult<String> {
    run(py, || {
        let scenario = if scenario_is_text {
            api::ScenarioSource::from(scenario.as_str())
        } else {
            api::ScenarioSource::Path(std::path::Path::new(&scenario))
        };
        let s = api::simulate_to_file_with_laws(
            params_source(&params, params_is_text),
            scenario,
            &out,
            laws.as_deref(),
        )
        .map_err(to_py)?;
        json(&s)
    })
}

/// The Rust extension of `drive_monitor`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DriveMonitorError", py.get_type::<DriveMonitorError>())?;
    m.add("ParamsError", py.get_type::<ParamsError>())?;
    m.add("ParamsTypeError", py.get_type::<ParamsTypeError>())?;
    m.add("LogError", py.get_type::<LogError>())?;
    m.add("LogTypeError", py.get_type::<LogTypeError>())?;
    m.add("LogNotFoundError", py.get_type::<LogNotFoundError>())?;
    m.add("ParamsNotFoundError", py.get_type::<ParamsNotFoundError>())?;
    m.add("OptionError", py.get_type::<OptionError>())?;
    m.add("OptionTypeError", py.get_type::<OptionTypeError>())?;
    m.add("AnalysisError", py.get_type::<AnalysisError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_options, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(explain, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(params_from_nameplate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_row, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_columns, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_read_table, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_check_table, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_check_outputs, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_store_row_timed, m)?)?;
    m.add_function(wrap_pyfunction!(fleet::fleet_time_warnings, m)?)?;
    m.add_function(wrap_pyfunction!(store::fleet_store_row, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_append, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_trend, m)?)?;
    m.add_function(wrap_pyfunction!(store::store_columns, m)?)?;
    Ok(())
}
