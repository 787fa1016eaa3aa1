//! Host harness for the drive monitor (the library; the command line is `src/main.rs` and
//! `src/cli/`).
//!
//! - [`sim`]: the induction-motor simulator with fault and effect injection;
//! - [`log`]: measurement logs (the one reader and writer, the sample-rate estimate);
//! - [`params`]: the parameter file;
//! - [`replay`]: logs through the no_std core (`diagnose`);
//! - [`experiment`]: a simulated motor replayed through the core as it runs (the runs
//!   below);
//! - [`fault_signatures`]: the paper's Table 1 end to end (`table1`);
//! - [`service_profile`]: the healthy service profile of the false-alarm and
//!   detection-limit studies;
//! - [`demo`]: the main job (`demo`);
//! - [`hmi`]: the live terminal HMI's model and its three sources (`hmi`);
//! - [`analysis`]: the model-vs-measurement workflow (`compare`, `explain`);
//! - [`bench`](mod@bench): the simulator and core figures of `bench`.
//!
//! The vocabulary (faults, effect names, phases, motor parameters, reference machines)
//! is the core's (`monitor_core`), shared with the firmware. Functions return values and
//! `thiserror` errors; rendering (text, JSON, HTML, plots) is the binary's.

pub mod analysis;
pub mod bench;
pub mod demo;
pub mod experiment;
pub mod fault_signatures;
pub mod hmi;
pub mod log;
pub mod params;
pub mod replay;
pub mod service_profile;
pub mod sim;

/// Folds a multi-line message onto one line (CLI errors are one line).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
