//! The integration tests of `monitor-sim`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-sim --test sim -- <module>::`.

mod sim_effects;
mod sim_energy;
mod sim_sensors;
mod sim_steady;
