//! A user's laws (`--laws FILE`, Python's `laws=`) for `compare`, `explain`, the ladder and
//! `simulate`: read and checked once, against the parameter file where a law needs the
//! machine (a no-load table), and the effect names a request gives resolved against the
//! library and the laws together.

use crate::ApiError;
use monitor_analysis::effects::Registry;
use monitor_analysis::EffectId;
use monitor_io::params::ParamFile;
use monitor_laws::LawProblem;
pub use monitor_laws::{BoundLaw, Law, LawError, LawFile};
use std::path::Path;
use std::sync::Arc;

/// The laws of the file at `path` (none without one).
///
/// # Errors
/// [`ApiError::Laws`]: the file's first mistake, in one line.
pub fn read_laws(path: Option<&Path>) -> Result<Vec<Arc<Law>>, ApiError> {
    match path {
        None => Ok(Vec::new()),
        Some(p) => Ok(LawFile::read(p)?.laws),
    }
}

/// Checks the laws that need the machine against the parameter file `params`: a no-load
/// table's voltages must fit its rated voltage and give a stator flux that rises with the
/// current with its Rs.
///
/// # Errors
/// [`ApiError::Laws`] naming the law and the problem.
pub fn check_laws(laws: &[Arc<Law>], params: &ParamFile) -> Result<(), ApiError> {
    for law in laws {
        let Some(t) = law.table() else { continue };
        t.curve(
            params.motor.rs_ohm,
            0.0,
            params.supply.v_ll_rms,
            params.supply.f_hz,
        )
        .map_err(|e| {
            ApiError::Laws(LawError::Law {
                path: match &law.origin {
                    monitor_laws::LawOrigin::File { path } => path.clone(),
                    monitor_laws::LawOrigin::Library => Default::default(),
                },
                law: law.id.name().to_string(),
                why: Box::new(LawProblem::Table(e)),
            })
        })?;
    }
    Ok(())
}

/// The effects named `names` in `registry` (the library's and the laws').
///
/// # Errors
/// [`ApiError::UnknownEffect`] for the first name neither has, with its near matches.
pub fn effect_ids(names: &[String], registry: &Registry) -> Result<Vec<EffectId>, ApiError> {
    names
        .iter()
        .map(|n| {
            let n = n.trim();
            registry.find(n).ok_or_else(|| {
                let known: Vec<&str> = registry.names().iter().map(|e| e.name()).collect();
                ApiError::UnknownEffect {
                    name: n.to_string(),
                    near: crate::files::near_names(n, &known)
                        .into_iter()
                        .take(3)
                        .map(str::to_string)
                        .collect(),
                    known: known.iter().map(|k| k.to_string()).collect(),
                    laws: !registry.laws().is_empty(),
                }
            })
        })
        .collect()
}
