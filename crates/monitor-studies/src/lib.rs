//! Simulated studies through the no_std core: a simulated motor replayed through the core
//! as it runs, and the studies built on it.
//!
//! - [`experiment`]: one simulated scenario through the core, sample by sample;
//! - [`fault_signatures`]: the paper's Table 1 end to end (`table1`);
//! - [`service_profile`]: the healthy service profile of the false-alarm and
//!   detection-limit studies;
//! - [`demo`]: the main job (`demo`);
//! - [`bench`](mod@bench): the simulator, core and isolation figures of `bench`.
//!
//! Inside the crate the modules use each other in that order (a later one uses earlier
//! ones only).

pub mod bench;
pub mod demo;
pub mod experiment;
pub mod fault_signatures;
pub mod service_profile;
