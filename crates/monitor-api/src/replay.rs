//! The replay of a log through the core, from `monitor-replay`: its options
//! ([`ReplayOptions`], the typed values [`CommissionWindow`], [`TimelineStep`],
//! [`LoadModel`]), the report a front end renders ([`DiagnoseReport`] and its parts: their
//! sentences are the door's, `monitor_api::words`) and the step-by-step [`Replay`] the HMI
//! watches. This list is what a front end may use.

pub use monitor_replay::{
    angle_source_name, diagnose_file, diagnose_file_observed, state_name, Against, ChannelDropped,
    ChannelUse, CommissionWindow, CommissioningOutcome, CommissioningReport, Detail,
    DetectionLimit, DiagnoseReport, Diagnosed, FaultCandidate, FindingReport, IsolationEvent,
    IsolationName, IsolationReport, IsolationSaid, LoadModel, MonitorState, MovedWhy, OptionError,
    OptionField, OptionSpec, OptionValue, Panel, ParallelPaths, RangeDeparture, RangeQuantity,
    Replay, ReplayError, ReplayObserver, ReplayOptions, RotorBand, Takes, TemperatureReport,
    Thresholds, TimelinePoint, TimelineStep, TurnCalibration, TurnLevelOptions, UnbalanceReport,
    Verdict, DIAGNOSE_OPTIONS, MAX_EVENTS, MIN_FAULT_CHANGE,
};
