//! The simulator as a front end drives it, from `monitor-sim`: a [`Scenario`] with its
//! faults, sensors, load and supply steps, run to a file ([`simulate_while`]) or watched
//! live ([`simulate_interactive`], the HMI). This list is what a front end may use.

pub use monitor_sim::{
    simulate_interactive, simulate_while, FaultSpec, LoadStep, Scenario, ScenarioEvent, SensorSpec,
    SimError, SimSummary, SupplyStep, UserLaws, Workload,
};
