//! The integration tests of `monitor-replay`, one test binary (issue 89): each module below was a
//! binary of its own (`tests/<module>.rs`), each linking the whole workspace. One
//! module's tests: `cargo test -p monitor-replay --test replay -- <module>::`.

mod commissioning_real_running;
mod high_resistance_month;
mod metamorphic;
mod no_flags_in_the_library;
mod progress;
mod real_recordings;
mod resistances;
mod rotor_in_diagnose;
mod rotor_where_mcsa_applies;
mod sensor_phase;
mod turn_fault;
mod turn_level;
mod turn_level_simulated;
mod winding_judged;
mod winding_reliability;
mod wiring_verdict;
