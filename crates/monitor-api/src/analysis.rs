//! Model against measurement, from `monitor-analysis`: the prepared log ([`Analysis`],
//! [`Prepared`]), the reports of compare, explain and its ladder ([`CompareReport`],
//! [`ExplainReport`], [`LadderReport`], with where the error lives, [`Leftover`]), the
//! current spectrum ([`McsaReport`]) and the identification ([`Identification`]); the
//! modules [`metrics`] and [`identify`] for the charts and the text the command line draws
//! from them. This list is what a front end
//! may use.

pub use monitor_analysis::compare::{CompareOutput, CompareReport};
pub use monitor_analysis::effects::{sig, Registry};
pub use monitor_analysis::explain::ladder::{
    BaseChange, FinalFit, LadderProgress, LadderReport, LadderStep, Stratum, Tried, FLOOR_BAND,
    STEP_MIN,
};
pub use monitor_analysis::explain::{ExplainOutput, ExplainReport, Standing, EXPLAINS_MIN};
pub use monitor_analysis::identify::{self, Identification};
pub use monitor_analysis::leftover::Leftover;
pub use monitor_analysis::metrics::{self, WorstWindow};
pub use monitor_analysis::prep::Prepared;
pub use monitor_analysis::rotor_asymmetry::McsaReport;
pub use monitor_analysis::simplified_model::Prediction;
pub use monitor_analysis::{parse_effect, Analysis, EffectId, Options};
