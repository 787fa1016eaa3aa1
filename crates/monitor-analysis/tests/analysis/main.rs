//! The analysis library's tests, one test binary (issue 89): each module was a file of its
//! own in `tests/`, and each file was a binary of its own linking the workspace. One area:
//! `cargo test -p monitor-analysis --test analysis refit_base::` (the module's name and
//! `::`, a filter of the one binary). The full physics sweeps (`MONITOR_FULL_SWEEPS=1`,
//! `monitor_testkit::analysis_common`; `.ci/run` runs them):
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test -p monitor-analysis --test analysis -- analysis_dynamics:: analysis_effects:: rotor_asymmetry:: mcsa_short_records:: noise_floor:: refit_base:: fit_bounds::
//! ```
//! The tests share one process: none sets an environment variable or the working folder.

// Shared by several areas: the scenarios and the analysis run on them.
mod analysis_common;

mod analysis_dynamics;
mod analysis_effects;
mod analysis_plausibility;
mod analysis_probe;
mod effect_parameters;
mod faulty_phase;
mod fit_bounds;
mod identify;
mod identify_third_party;
mod laws_once;
mod load_step_location;
mod mcsa_short_records;
mod noise_floor;
mod refit_base;
mod rotor_asymmetry;
