//! The options of `diagnose` from Python's keywords, each read by what its row of the
//! library's one description takes ([`DIAGNOSE_OPTIONS`], [`Takes`]): a value of the wrong
//! type is refused naming the keyword, the type given and the one expected.

use crate::{to_py, wrong_type};
use monitor_api::replay::{self, OptionSpec, OptionValue, Takes, DIAGNOSE_OPTIONS};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyString};
use std::path::PathBuf;

/// The Python type of `v` as a message names it, with its article (`a float`, `an int`).
fn a_type(v: &Bound<'_, PyAny>) -> String {
    let name = v
        .get_type()
        .name()
        .map_or_else(|_| "?".to_string(), |n| n.to_string());
    let article = if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {name}")
}

/// A keyword's value as the option of `spec` takes it ([`Takes`]): a window as
/// `"START:END"` or a pair of numbers, a name (`str`), a number (an `int` or a `float`,
/// numpy's too), a whole number (an `int`, or any integer with `__index__` but a bool), a
/// flag (`bool`), or a JSON file as its path or its dict (read here). A value of another
/// type is refused in the option's words as an `OptionTypeError` (a `TypeError`), naming
/// the type given and the one expected (`parallel_paths = 2.5: a float, not an int (a whole
/// number)`); a value of the right type that is not one the option takes (a window of three
/// values, a file that is not JSON) as an `OptionError` (a `ValueError`): never rounded,
/// parsed from text or read as a bool. Every option of [`DIAGNOSE_OPTIONS`] goes through
/// here, so a new one is checked by its [`Takes`] alone.
fn option_value(spec: &OptionSpec, v: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
    let shown = v.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
    let bad = |why: &str| to_py(replay::OptionError::new(spec.field, shown.clone(), why).into());
    // A value of the wrong type: the same message, an `OptionTypeError` (a `TypeError`).
    let bad_type = |why: &str| wrong_type(v.py(), bad(why));
    let got = a_type(v);
    let wrong = |expected: &str| bad_type(&format!("{got}, not {expected}"));
    // A bool is an int to Python, and a float has `__int__`: neither is taken for a count.
    let is_bool = v.is_instance_of::<PyBool>();
    let has = |a: &str| v.hasattr(a).unwrap_or(false);
    let is_whole = !is_bool && !v.is_instance_of::<PyFloat>() && has("__index__");
    let is_number = !is_bool && !v.is_instance_of::<PyString>() && (is_whole || has("__float__"));
    Ok(match spec.takes {
        Takes::Window => {
            if v.is_instance_of::<PyString>() {
                return Ok(OptionValue::Text(v.extract()?));
            }
            let how =
                "give (start_s, end_s) or 'START:END' in seconds, e.g. (1.5, 2.4) or '1.5:2.4'";
            let pair: Vec<Bound<'_, PyAny>> = v
                .extract()
                .map_err(|_| bad_type(&format!("{got}, not a pair of numbers or a str; {how}")))?;
            let [a, b] = pair.as_slice() else {
                return Err(bad(&format!("two values, the start and the end; {how}")));
            };
            let number = |x: &Bound<'_, PyAny>| {
                (!x.is_instance_of::<PyBool>())
                    .then(|| x.extract::<f64>().ok())
                    .flatten()
            };
            match (number(a), number(b)) {
                (Some(a), Some(b)) => OptionValue::Pair(a, b),
                _ => return Err(bad_type(&format!("not numbers; {how}"))),
            }
        }
        Takes::Choice(_) if v.is_instance_of::<PyString>() => OptionValue::Text(v.extract()?),
        Takes::Choice(names) => {
            return Err(wrong(&format!("a str: give one of {}", names.join(", "))))
        }
        Takes::Seconds if is_number => OptionValue::Number(v.extract()?),
        Takes::Seconds => return Err(wrong("a number of seconds (an int or a float)")),
        Takes::Count if is_whole => OptionValue::Whole(
            v.extract()
                .map_err(|_| bad("too large for a whole number"))?,
        ),
        Takes::Count => return Err(wrong("an int (a whole number)")),
        Takes::Flag if is_bool => OptionValue::Flag(v.extract()?),
        Takes::Flag => return Err(wrong("a bool: give True or False")),
        Takes::JsonFile => json_file(v, bad, bad_type)?,
    })
}

/// A JSON option's value: its dict (as JSON text), or the path of its file (read here);
/// refused in the option's words otherwise: by `bad_type` when it is neither a dict nor a
/// path, by `bad` when it cannot be read or is not JSON.
fn json_file(
    v: &Bound<'_, PyAny>,
    bad: impl Fn(&str) -> PyErr,
    bad_type: impl Fn(&str) -> PyErr,
) -> PyResult<OptionValue> {
    if v.is_instance_of::<PyDict>() {
        let text = v
            .py()
            .import("json")
            .and_then(|j| j.call_method1("dumps", (v,)))
            .and_then(|t| t.extract::<String>())
            .map_err(|e| bad(&format!("not JSON: {e}")))?;
        return Ok(OptionValue::Text(text));
    }
    let path: PathBuf = v.extract().map_err(|_| {
        bad_type(&format!(
            "{}, not a path (str or os.PathLike) or a dict",
            a_type(v)
        ))
    })?;
    std::fs::read_to_string(&path)
        .map(OptionValue::Text)
        .map_err(|e| bad(&format!("cannot read {}: {e}", path.display())))
}

/// The request's replay options from Python's keywords, each by the library's one
/// description ([`DIAGNOSE_OPTIONS`], [`ReplayOptions::set`](replay::ReplayOptions::set)):
/// an option not given, or given as `None`, keeps the one default
/// (`ReplayOptions::default`, the command line's too).
pub(crate) fn replay_options(
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<replay::ReplayOptions> {
    let mut opts = replay::ReplayOptions::default();
    for (k, v) in options.into_iter().flat_map(|d| d.iter()) {
        let name: String = k.extract()?;
        let Some(spec) = DIAGNOSE_OPTIONS.iter().find(|s| s.field.name() == name) else {
            let known: Vec<&str> = DIAGNOSE_OPTIONS.iter().map(|s| s.field.name()).collect();
            let meant = monitor_api::files::near_names(&name, &known)
                .first()
                .map(|n| format!("; did you mean '{n}'?"))
                .unwrap_or_default();
            return Err(PyTypeError::new_err(format!(
                "diagnose() got an unexpected keyword argument '{name}'{meant}"
            )));
        };
        if !v.is_none() {
            let value = option_value(spec, &v)?;
            opts.set(spec.field, value).map_err(|e| to_py(e.into()))?;
        }
    }
    Ok(opts)
}
