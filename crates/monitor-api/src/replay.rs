//! The replay of a log through the core, from `monitor-replay`: its options
//! ([`ReplayOptions`], the typed values [`CommissionWindow`], [`TimelineStep`],
//! [`LoadModel`]), the report a front end renders ([`DiagnoseReport`] and its parts), the
//! words a front end spells fields in ([`Spelling`], [`Words`]) and the step-by-step
//! [`Replay`] the HMI watches. This list is what a front end may use.

pub use monitor_replay::verdict::{against_text, fault_text, why_watched};
pub use monitor_replay::{
    angle_source_name, describe_against, diagnose_file, diagnose_file_observed, state_name,
    Against, CommissionWindow, CommissioningOutcome, CommissioningReport, DetectionLimit,
    DiagnoseReport, Diagnosed, FaultCandidate, FindingReport, IsolationEvent, IsolationName,
    IsolationReport, LoadModel, OptionError, OptionField, OptionSpec, OptionValue, Panel,
    ParallelPaths, Replay, ReplayError, ReplayObserver, ReplayOptions, RotorBand, Spelling, Takes,
    TemperatureReport, TimelinePoint, TimelineStep, TurnCalibration, TurnLevelOptions,
    UnbalanceReport, Verdict, Words, DIAGNOSE_OPTIONS, MAX_EVENTS, MIN_FAULT_CHANGE,
};
