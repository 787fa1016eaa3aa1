//! The workspace's crates as the architecture test names them: the `src/` folders checked
//! for import circles ([`CRATE_SOURCES`]) and the crates' names in code ([`WORKSPACE_CRATES`]).

/// The `src/` folders that must be among those checked for import circles (which are
/// found from the workspace's packages, [`super::files::crate_sources`]): every library crate of the
/// host and the firmware, the tests' shared scenarios, and the command line.
pub const CRATE_SOURCES: [&str; 13] = [
    "src/",
    "crates/monitor-core/src/",
    "crates/monitor-io/src/",
    "crates/monitor-laws/src/",
    "crates/monitor-sim/src/",
    "crates/monitor-replay/src/",
    "crates/monitor-analysis/src/",
    "crates/monitor-studies/src/",
    "crates/monitor-api/src/",
    "crates/monitor-store/src/",
    "crates/monitor-words/src/",
    "crates/monitor-testkit/src/",
    "sim-host/src/",
];

/// The workspace's crates by the names code uses (every package, checked by
/// `the_crate_list_names_every_package` in `tests/testkit/architecture.rs`).
pub const WORKSPACE_CRATES: [&str; 18] = [
    "drive_monitor",
    "sim_host",
    "monitor_core",
    "monitor_io",
    "monitor_laws",
    "monitor_sim",
    "monitor_replay",
    "monitor_analysis",
    "monitor_studies",
    "monitor_api",
    "monitor_words",
    "monitor_store",
    "monitor_testkit",
    "core_on_m4",
    "rtt_on_m4",
    "qemu_semihosting",
    "drive_monitor_python",
    "fwtool",
];
