//! The ladder's reasons as values with the numbers that decided: why a candidate was not
//! kept ([`Refusal`]), why a fitted step is not physical ([`WhyNotPhysical`]), and why the
//! ladder stopped ([`StopReason`]). The ladder decides by matching on them; the words a
//! crew reads are spelled from them at the door (`monitor-words`).

use monitor_laws::EffectId;
use serde::Serialize;

/// Why a candidate of a round was not kept (JSON `last_round[].refusal`, beside the
/// sentence `because`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Refusal {
    /// Its model could not be run through the fit series' held-back windows: it diverged.
    Diverged,
    /// A value of the step is not physical, one reason per value.
    NotPhysical {
        /// The reasons.
        why: Vec<WhyNotPhysical>,
    },
    /// It removes `share` of the held-back error beyond the noise floor (each parameter
    /// costing [`crate::explain::PARAM_PENALTY`]), less than the test's `asks`
    /// ([`super::rules::STEP_MIN`]).
    BelowTest {
        /// The share removed (0..1).
        share: f64,
        /// The share the test asks (0..1).
        asks: f64,
    },
    /// The model with it could not be run through the whole log: it diverged there.
    DivergedOnWholeLog,
    /// The whole-log error would rise, `from` -> `to` (only the held-back windows
    /// improved).
    WholeLogRises {
        /// The model's whole-log error before the step.
        from: f64,
        /// With the candidate.
        to: f64,
    },
    /// A candidate before it in the round's order was kept.
    BetterKept,
}

impl Refusal {
    /// Whether the candidate's own fit failed it (it diverged, or its values are not
    /// physical), rather than the step's test: such a candidate never came close to
    /// passing.
    pub fn fit_failed(&self) -> bool {
        matches!(
            self,
            Refusal::Diverged | Refusal::DivergedOnWholeLog | Refusal::NotPhysical { .. }
        )
    }
}

/// Why a fitted step is not physical: one value and the range it left.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WhyNotPhysical {
    /// An added effect's value outside its physical range (`why`: the effect's declared
    /// range, in its own words, [`crate::effects::FitSetup::implausible`]).
    Effect {
        /// The effect.
        effect: EffectId,
        /// The value and its range.
        why: String,
    },
    /// An added effect's value at a bound of its fit: no minimum the log shows.
    AtBound {
        /// The effect.
        effect: EffectId,
        /// The parameter's name.
        parameter: String,
        /// Its fitted value.
        value: f64,
        /// Its unit.
        unit: String,
        /// The fit's lower bound.
        low: f64,
        /// The fit's upper bound.
        high: f64,
    },
    /// An added effect's values contradicted by a measurement of the log (`why`: the
    /// effect's words, [`crate::effects::EffectModel::contradicted_by`]).
    Contradicted {
        /// The effect.
        effect: EffectId,
        /// The measurement and what it says.
        why: String,
    },
    /// A base parameter the step takes out of its physical range (`why`: the value and
    /// its range).
    Base {
        /// The value and its range.
        why: String,
    },
    /// A base rung's factor on the user's file outside a machine's physical range.
    BaseFactor {
        /// The parameter (`Rs`, `Rr`, `Lls, Llr`, `Lm`, `J`).
        parameter: &'static str,
        /// The factor.
        factor: f64,
        /// The smallest physical factor.
        low: f64,
        /// The largest.
        high: f64,
        /// Where the range comes from.
        basis: &'static str,
    },
}

/// Why the ladder stopped, with the numbers that decided (JSON `stopped_reason`, beside
/// the sentence `stopped_because`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StopReason {
    /// The whole-log and the held-back error are both within `band` of their floors.
    NoiseFloor {
        /// The whole-log error.
        error: f64,
        /// Its noise floor.
        noise_floor: f64,
        /// The held-back error.
        heldback_error: f64,
        /// Its noise floor.
        heldback_noise_floor: f64,
        /// The band ([`super::rules::FLOOR_BAND`]).
        band: f64,
    },
    /// No plausible candidate passed the step's test.
    NothingHelps {
        /// The whole-log error.
        error: f64,
        /// Its noise floor.
        noise_floor: f64,
        /// The held-back error.
        heldback_error: f64,
        /// Its noise floor.
        heldback_noise_floor: f64,
        /// The candidate that came closest to passing: the plausible one of the last round
        /// with the largest test statistic, else the first tried (`None`: none could be
        /// fitted).
        best: Option<Tried>,
        /// What the error left is, as far as the ladder can tell.
        left: WhatIsLeft,
    },
    /// Every effect of the library is in the model.
    LibraryExhausted,
    /// The log has no voltages: the model cannot run.
    NoVoltages,
    /// The data-quality stage does not trust the log (its reasons are the report's
    /// `data_quality.not_trusted_because`).
    Untrusted,
}

impl StopReason {
    /// Which stop it is (JSON `stop`).
    pub fn stop(&self) -> Stop {
        match self {
            StopReason::NoiseFloor { .. } => Stop::NoiseFloor,
            StopReason::NothingHelps { .. } => Stop::NothingHelps,
            StopReason::LibraryExhausted => Stop::LibraryExhausted,
            StopReason::NoVoltages => Stop::NoModel,
            StopReason::Untrusted => Stop::Untrusted,
        }
    }
}

/// What the error a ladder could not explain further is, as far as it can tell.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WhatIsLeft {
    /// The effects were tried on a refitted base and every effect of the library could be
    /// fitted: beyond the library (or below what the log can show).
    BeyondLibrary,
    /// Not explained by the effects that could be fitted; `effects` could not be.
    NotTried {
        /// The effects not fitted on this log.
        effects: Vec<EffectId>,
    },
    /// Not explained by the library's effects on the file's base parameters (the base
    /// rung was not a candidate).
    OnTheFileBase,
}

/// A candidate of the last round that was not kept, and why (JSON `last_round`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tried {
    /// True for the base rung (the base parameters refitted; `added` is then empty).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub base: bool,
    /// The effect (with what it needed first, as in [`super::report::LadderStep::added`]).
    pub added: Vec<EffectId>,
    /// Its held-back error.
    pub heldback_error: f64,
    /// Its test statistic ([`super::report::LadderStep::significance`]).
    pub significance: f64,
    /// Why it was not kept.
    pub refusal: Refusal,
}

/// Why the ladder stopped (JSON `stop`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The error is within the noise-floor band on the whole log and the held-back part.
    NoiseFloor,
    /// No plausible candidate passed the step's test.
    NothingHelps,
    /// Every effect of the library is in the model.
    LibraryExhausted,
    /// The model cannot run on the log (no voltages).
    NoModel,
    /// The data-quality stage does not trust the log: nothing is claimed from it.
    Untrusted,
}
