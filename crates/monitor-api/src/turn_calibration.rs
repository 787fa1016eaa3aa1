//! `calibrate-turns`: a calibration of the shorted-turn level learned from labelled runs of
//! one motor (`monitor_replay::TurnCalibration`; `docs/isolation.md`, "How many turns").

use crate::{diagnose, ApiError, DiagnoseRequest, LogSource, ParamsSource};
use monitor_core::Phase;
use monitor_replay::{LabelledRun, TurnCalibration};
use std::path::Path;

/// One labelled run: the log, the shorted phase and the fraction of its turns (0..1).
#[derive(Debug, Clone)]
pub struct Labelled {
    /// The log.
    pub log: LogSource,
    /// The shorted phase.
    pub phase: Phase,
    /// The shorted fraction of its turns, 0..1.
    pub fraction: f32,
}

/// What was learned, and the labelled runs left out (each with why).
#[derive(Debug, Clone)]
pub struct Learned {
    /// The calibration.
    pub calibration: TurnCalibration,
    /// The runs read: `(log, loop ratio)`.
    pub used: Vec<(String, f32)>,
    /// The runs left out: the judgement named no phase, or another than the label's.
    pub left_out: Vec<String>,
}

/// Learns a calibration: each labelled log is diagnosed with `req` (its calibration
/// ignored: the model's reading is what is learned), and its loop ratio
/// (`unbalance.shorted_turns_physics.loop_ratio`) is kept where the judgement names the
/// label's phase.
///
/// # Errors
/// A bad parameter file, log or option ([`ApiError`]); [`ApiError::Option`] when no
/// labelled run names its phase, or a fraction is outside 0..1.
pub fn learn_turn_calibration(
    params: &Path,
    labelled: &[Labelled],
    req: &DiagnoseRequest,
) -> Result<Learned, ApiError> {
    let mut req = req.clone();
    req.options.turn_level.calibration = None;
    let (mut runs, mut used, mut left_out) = (Vec::new(), Vec::new(), Vec::new());
    for l in labelled {
        if !(l.fraction > 0.0 && l.fraction <= 1.0) {
            return Err(ApiError::Labels(format!(
                "{}: a shorted fraction of {} is outside 0..100 %",
                l.log.shown(),
                l.fraction
            )));
        }
        let d = diagnose(ParamsSource::Path(params), l.log.clone(), &req, &mut |_| {})?;
        match d.report.unbalance.shorted_turns_physics {
            Some(t) if t.phase == l.phase => {
                used.push((l.log.shown(), t.loop_ratio));
                runs.push(LabelledRun {
                    phase: l.phase,
                    fraction: l.fraction,
                    loop_ratio: t.loop_ratio,
                });
            }
            Some(t) => left_out.push(format!(
                "{}: named phase {}, labelled {}",
                l.log.shown(),
                t.phase.name(),
                l.phase.name()
            )),
            None => left_out.push(format!("{}: no phase named", l.log.shown())),
        }
    }
    let calibration = TurnCalibration::learn(&runs).ok_or_else(|| {
        ApiError::Labels("no labelled run named its phase: nothing to learn".to_string())
    })?;
    Ok(Learned {
        calibration,
        used,
        left_out,
    })
}
