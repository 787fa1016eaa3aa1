//! Model vs measurement (the `compare`, `explain` and `identify` commands): where the paper's simplified model fails, which physical effect is
//! missing, and how much of the error adding it removes.
//!
//! Pipeline ([`Analysis::load`] then [`Analysis::compare`] / [`Analysis::explain`]):
//! 1. [`prep`]: stream the log, block-average to a ~2 kHz working series, build the
//!    voltage-model rotor-flux frame, split positive and negative sequences.
//! 2. [`simplified_model`]: drive the simplified model (eqs. 23-29) with the measured V_qs
//!    and i_f, predict I_qs, omega_r and the phase currents.
//! 3. [`fit`]: refit the base parameters the data identify (Ra, Ls, B+Bl, J; Kf = Lm^2/Lr
//!    stays nominal since only its ratio to J and B is observable) together with the
//!    configured effects' parameters, because nominal values are never exact.
//! 4. [`metrics`]: per-channel RMS errors, `normalized_rms_error`, worst windows with their
//!    operating condition and dominant error frequency, error spectrum, noise floor.
//! 5. [`compare`](Analysis::compare): the configured model's errors; [`explain`](Analysis::explain):
//!    every library effect ([`effects`]) not yet in the model is added and fitted in turn;
//!    candidates are ranked by the error on held-back time windows (the fit never sees
//!    them), so a parameter that only fits noise does not win. When the best candidate
//!    explains less than [`explain::EXPLAINED_MIN`] of the held-back error, or the error is
//!    already within [`explain::NOISE_MARGIN`] x the noise floor, the answer is
//!    `unexplained: true`.
//! 6. [`unbalance`]: the negative-sequence / faulty-phase analysis (current-only logs too).
//!
//! Two rotor-flux estimators exist in the workspace and are named apart: the monitor
//! (`diagnose`) uses the core's current model (`AngleSource::RotorFluxCurrentModel`: encoder
//! speed, nominal Rr and Lr); this analysis uses the voltage model ([`prep`]), which needs
//! neither the speed nor the rotor parameters, so that it can test them.
//!
//! Baseline and the always-present dynamics: a full-order machine always has rotor-flux and
//! stator-current dynamics; the paper's steady-state model does not. The baseline here is
//! eqs. (28)-(29) with the La dI_qs/dt term dropped (the form the parity equations (37)
//! use) and psi_r = Lm i_f. On steady data neither matters (the baseline is exact in steady
//! state in this frame), so `explain` names nothing; where starts or supply steps dominate
//! the log, `flux_dynamics` / `current_dynamics` are the honest answer. Use `--from` to
//! leave a start-up transient out when it is not of interest.

// Sample loops index several parallel series at once; iterators would obscure that.
#![allow(clippy::needless_range_loop)]

mod analysis;
mod base_range;
pub mod change_point;
pub mod compare;
pub mod effects;
pub mod explain;
pub mod fit;
pub mod identify;
pub mod leftover;
pub mod lm;
pub mod metrics;
pub mod prep;
pub mod refit;
pub mod rotor_asymmetry;
pub mod simplified_model;
pub mod strata;
pub mod transients;
pub mod unbalance;

pub use analysis::{
    known_effects, parse_effect, Analysis, AnalysisError, AnalysisFrame, DataInfo, FittedEffect,
    Options, ParamValue, MAX_FIT_SAMPLES, MAX_ITER,
};
pub use base_range::base_implausible;
/// An effect's or a law's identity (the library's and a user's alike).
pub use monitor_laws::EffectId;
