//! Host harness for the drive monitor (the library; the command line is `src/main.rs` and
//! `src/cli/`).
//!
//! - [`sim`]: the induction-motor simulator with fault and effect injection;
//! - [`log`]: measurement logs (the one reader and writer, the sample-rate estimate);
//! - [`params`]: the parameter file;
//! - [`replay`]: logs through the no_std core (`diagnose`);
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
pub mod fault_signatures;
pub mod hmi;
pub mod log;
pub mod params;
pub mod replay;
pub mod service_profile;
pub mod sim;

/// Errors of the runs that simulate a motor and replay it through the core (Table 1, the
/// service profile, the demo, the benchmarks).
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The simulator refused the scenario or diverged.
    #[error(transparent)]
    Sim(#[from] sim::SimError),
    /// The core refused the replay's configuration.
    #[error(transparent)]
    Replay(#[from] replay::ReplayError),
    /// Writing a file failed.
    #[error(transparent)]
    Log(#[from] log::LogError),
    /// Creating a temporary folder failed.
    #[error("cannot create a temporary folder: {0}")]
    Io(#[from] std::io::Error),
}

/// Folds a multi-line message onto one line (CLI errors are one line).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Asks the C allocator to keep freed memory for reuse instead of returning it to the
/// kernel (glibc on Linux; elsewhere nothing). Call it once at the start of a process,
/// before other threads start (the CLI's `main` and the benchmarks do).
///
/// Why: the analysis allocates and frees series of the log's length (tens of MB) many
/// times. glibc serves such blocks with `mmap` and returns them at `free`, and every
/// reuse then pays a page fault and the kernel's zeroing of each fresh page: a `perf`
/// profile of the 1 h analysis benchmark had 20-30 % of its CPU there
/// (`clear_page_erms`). Settings: one arena (`M_ARENA_MAX` 1; two worker threads contend
/// little), no `mmap` blocks (`M_MMAP_MAX` 0), and the heap's top trimmed only beyond
/// 2 GB (`M_TRIM_THRESHOLD`). The cost: the process keeps its peak memory until it exits
/// (the peak itself is the same to within a few per cent), which suits one-job CLI runs.
/// This is the crate's one `unsafe` block (the workspace denies `unsafe_code`).
#[allow(unsafe_code)]
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes the allocator's tuning parameters; it is called before
    // other threads exist (documented precondition of this function), and a refused
    // setting (return 0) leaves glibc's default in place, which is still correct.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
        libc::mallopt(libc::M_MMAP_MAX, 0);
        libc::mallopt(libc::M_TRIM_THRESHOLD, libc::c_int::MAX);
    }
}
