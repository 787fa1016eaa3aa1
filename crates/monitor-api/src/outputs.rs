//! The calls that write a file the caller names (`simulate`'s `out`): each checks its
//! outputs against its inputs before anything is written (`monitor_io::log::check_outputs`,
//! the guard every front end shares) and writes atomically (a temporary file beside the
//! output, renamed over it when complete).

use crate::{load_params, ApiError, ParamsSource};
use monitor_io::log::{check_outputs, NamedFile};
use std::path::Path;

/// A scenario: its file, or its TOML text.
#[derive(Debug, Clone, Copy)]
pub enum ScenarioSource<'a> {
    /// A scenario file (read by the call; an output may not be it).
    Path(&'a Path),
    /// The file's text (`origin` names it in messages).
    Toml {
        /// The TOML text.
        text: &'a str,
        /// How messages name it.
        origin: &'a str,
    },
}

impl<'a> From<&'a str> for ScenarioSource<'a> {
    /// TOML text, named "the scenario" in messages.
    fn from(text: &'a str) -> Self {
        ScenarioSource::Toml {
            text,
            origin: "the scenario",
        }
    }
}

impl<'a> From<&'a String> for ScenarioSource<'a> {
    /// TOML text, named "the scenario" in messages.
    fn from(text: &'a String) -> Self {
        ScenarioSource::from(text.as_str())
    }
}

impl<'a> From<&'a Path> for ScenarioSource<'a> {
    /// A scenario file.
    fn from(path: &'a Path) -> Self {
        ScenarioSource::Path(path)
    }
}

/// The input files of a call (the parameter file and the scenario given as paths), named
/// by their fields.
fn input_files<'a>(params: &ParamsSource<'a>, scenario: &ScenarioSource<'a>) -> Vec<NamedFile<'a>> {
    let mut inputs = Vec::new();
    if let ParamsSource::Path(p) = params {
        inputs.push(NamedFile::new("params", p));
    }
    if let ScenarioSource::Path(p) = scenario {
        inputs.push(NamedFile::new("scenario", p));
    }
    inputs
}

/// `simulate` into the log `out` (its format by extension) with the parameter file
/// `params` and the scenario `scenario` (a file, or its TOML text: `&str` converts); the
/// run's summary. `out` is checked against the input files first (the same file by any
/// path, `./` spelling or link is refused, and nothing is written), then written whole or
/// not at all (a temporary file beside it, renamed over it when the run is complete).
///
/// # Errors
/// [`ApiError::Overwrite`] when `out` is the parameter file or the scenario; a bad
/// parameter file or scenario ([`ApiError::Simulation`] naming the key), a scenario file
/// that cannot be read ([`ApiError::ScenarioIo`]), a write error,
/// [`ApiError::Interrupted`].
pub fn simulate_to_file<'a>(
    params: ParamsSource<'_>,
    scenario: impl Into<ScenarioSource<'a>>,
    out: &Path,
) -> Result<monitor_sim::SimSummary, ApiError> {
    simulate_to_file_with_laws(params, scenario, out, None)
}

/// [`simulate_to_file`] with a user's law file (`simulate --laws`, Python's `laws=`): the run
/// injects each law at its parameters' start values.
///
/// # Errors
/// As [`simulate_to_file`], and [`ApiError::Laws`] for the law file (it may not be the
/// output either).
pub fn simulate_to_file_with_laws<'a>(
    params: ParamsSource<'_>,
    scenario: impl Into<ScenarioSource<'a>>,
    out: &Path,
    laws: Option<&Path>,
) -> Result<monitor_sim::SimSummary, ApiError> {
    let scenario = scenario.into();
    let mut inputs = input_files(&params, &scenario);
    if let Some(l) = laws {
        inputs.push(NamedFile::new("laws", l));
    }
    check_outputs(&inputs, &[NamedFile::new("out", out)])?;
    let (params, _) = load_params(params)?;
    let user_laws = crate::laws::read_laws(laws)?;
    crate::laws::check_laws(&user_laws, &params)?;
    let mut sc = match scenario {
        ScenarioSource::Toml { text, origin } => {
            monitor_sim::Scenario::from_toml_str(text, origin)?
        }
        ScenarioSource::Path(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| ApiError::ScenarioIo {
                path: p.display().to_string(),
                source: e,
            })?;
            monitor_sim::Scenario::from_toml_str(&text, &p.display().to_string())?
        }
    };
    sc.laws = monitor_sim::UserLaws(
        user_laws
            .into_iter()
            .map(monitor_laws::BoundLaw::at_start)
            .collect(),
    );
    let mut w = monitor_io::log::LogWriter::create(out, sc.sensors.channels())?;
    let mut err = None;
    let summary = monitor_sim::simulate_while(&params, &sc, |r| match w.write_row(r) {
        Ok(()) => std::ops::ControlFlow::Continue(()),
        Err(e) => {
            err = Some(e);
            std::ops::ControlFlow::Break(())
        }
    })?;
    if let Some(e) = err {
        return Err(e.into());
    }
    w.finish()?;
    summary.ok_or(ApiError::Interrupted)
}
