//! Host harness for the drive monitor (the library; the command line is `src/main.rs` and
//! `src/cli/`). The modules in their layers, lowest first: a module uses only modules of
//! lower layers (`tests/architecture.rs` checks every import), and the crate root, below
//! them all, holds only [`one_line`].
//!
//! - layer 1: [`params`]: the parameter file, and the sensor ranges derived from it;
//! - layer 2: [`log`]: measurement logs (the one reader and writer, the data-quality stage,
//!   the sample-rate estimate); [`nameplate`]: a parameter file estimated from a motor's
//!   nameplate (`params from-nameplate`);
//! - layer 3: [`sim`]: the induction-motor simulator with fault and effect injection;
//!   [`replay`]: logs through the no_std core (`diagnose`);
//! - layer 4: [`analysis`]: the model-vs-measurement workflow (`compare`, `explain`);
//! - layer 5: [`experiment`]: a simulated motor replayed through the core as it runs;
//!   [`identify`]: the motor's parameters from a log of the healthy motor (`identify`);
//! - layer 6: [`fault_signatures`]: the paper's Table 1 end to end (`table1`);
//!   [`service_profile`]: the healthy service profile of the false-alarm and
//!   detection-limit studies; [`api`]: one call per command, for the command line and
//!   the Python package;
//! - layer 7: [`demo`]: the main job (`demo`); [`fleet`]: many motors' logs, one row each
//!   (`fleet`);
//! - layer 8: [`bench`](mod@bench): the simulator, core and isolation figures of `bench`;
//!   [`hmi`]: the live terminal HMI's model and its three sources (`hmi`).
//!
//! The vocabulary (faults, effect names, phases, motor parameters, reference machines)
//! is the core's (`monitor_core`), shared with the firmware. Functions return values and
//! `thiserror` errors; rendering (text, JSON, HTML, plots) is the binary's.

pub mod analysis;
pub mod api;
pub mod bench;
pub mod demo;
pub mod experiment;
pub mod fault_signatures;
pub mod fleet;
pub mod hmi;
pub mod identify;
pub mod log;
pub mod nameplate;
pub mod params;
pub mod replay;
pub mod service_profile;
pub mod sim;

/// Folds a multi-line message onto one line (CLI errors are one line).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
