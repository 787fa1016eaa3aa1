//! Replay of a measurement log through the no_std core: exactly the code the firmware
//! runs ([`monitor_core::Monitor`]), fed row by row; what `sim-host diagnose` runs
//! ([`diagnose_file`]).
//!
//! The host converts each CSV row into a core [`Sample`](monitor_core::Sample)
//! ([`LogSampler`], the host's counterpart of the firmware's ADC sampler): voltages and
//! currents as f32, the encoder count (from `enc_count`, or synthesised by integrating
//! `wm_rad_s` on a 4096-count disc when the log has only a speed column), and a 1 MHz
//! timestamp.
//! Logs without voltages or without speed cannot feed the residuals (every residual of
//! eq. 37 needs Vqs or omega_r); for those only the negative-sequence analysis runs, on an
//! angle from an SRF-PLL locked to the currents, and the report says what was skipped and
//! why. The faulty phase is named by the core's one method
//! ([`monitor_core::sequence::suspect_phase`]), with the slip estimated from the current
//! magnitude where the log has no speed.
//!
//! Every row reaches the replay through the data-quality stage ([`monitor_io::log::quality`],
//! [`diagnose_file`], [`diagnose_rows`]): times in seconds, repeated and backward rows
//! dropped, gaps passed on with their real elapsed time (the core bridges the short ones
//! and restarts its estimators after the long ones), bad cells flagged (the core holds
//! them out, the current-only analysis skips them). What the stage found is the report's
//! `data_quality`; what commissioning did is its `commissioning` ([`commission`]).

mod baseline;
mod diagnose;
mod error;
mod events;
mod fields;
mod isolation;
mod isolation_name;
mod lamps;
mod options;
mod progress;
mod quality;
mod range;
mod replay;
mod report;
mod rotor;
mod sampler;
mod sequences;
mod stage;
mod temperature;
mod timeline;
mod trig;
mod turn_calibration;
pub mod verdict;
mod winding;
mod windows;

pub use baseline::{HealthyReference, UnbalanceBaseline, BASELINE_I1_TOLERANCE};
pub use error::ReplayError;
pub use replay::{Replay, ReplayObserver};
pub use sampler::{COUNTS_PER_REV, TICK_HZ};
pub use sequences::FILLED_SAMPLES;
pub use verdict::measured::{watched_phase, winding_against, WINDING_WATCH_PROBABILITY};
pub use verdict::{MIN_FAULT_CHANGE, MIN_JUDGED_S};
pub use windows::SENSOR_PHASE_MIN_RATIO;

pub use diagnose::{
    diagnose_file, diagnose_file_observed, diagnose_log, diagnose_log_fitted, diagnose_rows,
    Diagnosed,
};
pub use events::{IsolationEvent, LOAD_MOVE_FRACTION, MAX_EVENTS};
pub use isolation::said::{
    CoreSaid, IsolationSaid, JointEvidence, Nearest, NotIsolatedWhy, SensorKind, Stale, MOVED_FAR,
    MOVED_SAID_FROM,
};
pub use isolation::serialize_state;
pub use isolation::{
    state_name, DetectionLimit, FaultCandidate, GroupWhy, IsolationBaseline, IsolationGroup,
    IsolationName, IsolationReport, NameGiven, ResistanceReading, NOMINAL_UNCERTAINTY,
};
pub use lamps::commission::{
    grace_s, min_learned_s, CommissionAdvice, CommissioningOutcome, CommissioningReport,
    FirstPointMisfit, NotLearned, NotLearnedWhy, QuasiSteadyPoint, RangeDeparture, RangeNote,
    RangeQuantity, Thresholds, MIN_LEARNED_S,
};
pub use lamps::{Detection, HeldUnsettled};
pub use options::{
    angle_source_name, monitor_config_for_log, serialize_angle_source, CommissionWindow, LoadModel,
    ParallelPaths, ReplayOptions, TimelineStep, TurnLevelOptions, PARALLEL_PATHS,
};
pub use report::DiagnoseReport;
pub use rotor::{
    band_of, blackman_harris, LoadSource, LoadUnknown, MeasuredPoint, RatedLoadPoint, RotorBand,
    RotorCannot, RotorLoad, RotorReport, SlipSource, BLACKMAN_HARRIS_4, EDGE_SPREAD_DB,
    FAULT_EDGE_DB, MAIN_LOBE_HALF_BINS, MAX_SLIP, MAX_SLIP_OVER_RATED, MAX_STRETCH_S,
    MCSA_MIN_LOAD, MIN_BINS, MIN_SLIP, PAIR_SNR_DB, SLIP_STEADY,
};
pub use sampler::LogSampler;
pub use temperature::{ChannelDropped, ChannelUse, TemperatureReport};
/// The temperature channel's limits (module `temperature`): what a reading may be and do.
pub mod temperature_limits {
    pub use crate::temperature::{
        DISAGREE_K, DISAGREE_S, GAP_S, JUMP_SLACK_K, MAX_HEATING_K_PER_S, PLAUSIBLE_C, STUCK_S,
    };
}
pub use fields::{
    field_given, OptionError, OptionField, OptionSpec, OptionValue, Takes, DIAGNOSE_OPTIONS,
};
pub use timeline::{MonitorState, MovedWhy, Panel, TimelinePoint};
pub use verdict::machine_fit::{FitParameter, FittedChange, StartFit};
pub use verdict::{Detail, FileMisfit, FindingReport, Rule, SkippedAnalysis, Verdict};
pub use winding::level::{LabelledRun, LevelBasis, ShortedTurns, TurnCalibration, TurnReach};
pub use winding::{
    segments, Against, BaselineSource, OperatingPointSource, PhaseNotJudged, PhaseProbabilities,
    SequenceSegment, UnbalanceReport, Widened, BALANCED_RATIO, DEFAULT_SPREAD_CURRENTS,
    DEFAULT_SPREAD_VOLTAGES, HEALTHY_RUN_DIFFERENCE_CURRENTS, HEALTHY_RUN_DIFFERENCE_VOLTAGES,
    NO_BASELINE_SPREAD, NO_BASELINE_SPREAD_VOLTAGES, WINDING_FAULT_PROBABILITY, WITHIN_LOG_SPREAD,
};
pub use windows::{SensorPhaseReport, SequenceWindow, WINDOW_PERIODS};
