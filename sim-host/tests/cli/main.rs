//! The command line's tests, one test binary (issue 89): each module was a file of its own
//! in `tests/`, and each file was a binary of its own linking the whole workspace. One area:
//! `cargo test -p sim-host --test cli ladder_cli::` (the module's name and `::`, a filter of
//! the one binary). The full sweeps of the ladder (`MONITOR_FULL_SWEEPS=1`,
//! `monitor_testkit::analysis_common`; `.ci/run` runs them):
//! ```text
//! MONITOR_FULL_SWEEPS=1 cargo test -p sim-host --test cli -- ladder_matrix:: ladder_scenarios:: ladder_broken_bars:: ladder_third_party:: ladder_user_laws::
//! ```
//! The data the tests read stay in `tests/` beside this folder (`tests/data`,
//! `tests/golden`), found from `CARGO_MANIFEST_DIR`. The tests share one process: none sets
//! an environment variable or the working folder (each passes them to the child it spawns).

// Shared by several areas.
mod analysis_common;
mod chart_legend;

mod analysis_cli;
mod board_record;
mod board_record_json;
mod cli;
mod cli_golden;
mod cli_hardening;
mod column_mapping;
mod design_commands;
mod diagnose_interrupt;
mod diagnose_report;
mod explain_compare_cli;
mod explain_round_cli;
mod fleet_log_time;
mod fleet_patterns;
mod hmi;
mod hmi_small_terminal;
mod hmi_tmux;
mod identify;
mod identify_columns;
mod isolation;
mod ladder_broken_bars;
mod ladder_cli;
mod ladder_matrix;
mod ladder_scenarios;
mod ladder_third_party;
mod ladder_user_laws;
mod line_width;
mod log_formats;
mod nameplate;
mod no_verdict_from_too_little;
mod one_state;
mod one_verdict;
mod readme;
mod real_data;
mod real_recordings;
mod report_legends;
mod report_plots;
mod sim_scenario;
mod store_crash;
mod store_permission;
mod suggestions;
mod text_cells;
mod trend_itsc;
mod trend_view;
mod what_was_judged;
