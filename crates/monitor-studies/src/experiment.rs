//! A simulated motor replayed through the core as the simulator makes its rows: what the
//! paper's Table 1 ([`crate::fault_signatures`]), the service profile
//! ([`crate::service_profile`]) and the demo ([`crate::demo`]) run, and their error.

use monitor_core::MonitorOutput;
use monitor_io::log::Row;
use monitor_io::params::ParamFile;
use monitor_replay::{Replay, ReplayOptions};
use monitor_sim::{simulate, Scenario};

/// Errors of the runs that simulate a motor and replay it through the core (Table 1, the
/// service profile, the demo, the benchmarks).
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The simulator refused the scenario or diverged.
    #[error(transparent)]
    Sim(#[from] monitor_sim::SimError),
    /// The core refused the replay's configuration.
    #[error(transparent)]
    Replay(#[from] monitor_replay::ReplayError),
    /// Writing a file failed.
    #[error(transparent)]
    Log(#[from] monitor_io::log::LogError),
    /// Creating a temporary folder failed.
    #[error("cannot create a temporary folder: {0}")]
    Io(#[from] std::io::Error),
}

/// Simulates `scenario` on the machine `truth` and replays each row, as it is made,
/// through a [`Replay`] told the parameters `nominal` (the same file, or a nameplate's
/// values some tens of per cent off), at the scenario's sample rate with the scenario's
/// sensor channels; `on_output` sees every row with the monitor's output. Returns the
/// replay, for its report ([`Replay::finish`]) and state.
///
/// # Errors
/// [`ExperimentError::Replay`] when the core refuses the configuration,
/// [`ExperimentError::Sim`] when the simulator refuses the scenario or diverges.
pub fn simulate_and_replay(
    truth: &ParamFile,
    nominal: &ParamFile,
    scenario: &Scenario,
    opts: ReplayOptions,
    mut on_output: impl FnMut(&Row, &MonitorOutput),
) -> Result<Replay, ExperimentError> {
    let channels = scenario.sensors.channels();
    let mut replay = Replay::new(nominal, channels, scenario.sample_rate_hz, opts)?;
    simulate(truth, scenario, |row| {
        let out = replay.push(row);
        on_output(row, &out);
    })?;
    Ok(replay)
}
