//! Allocator tuning for the processes that run the analysis: the `sim-host` binary
//! (`mod alloc_tuning;` in `src/main.rs`) and the analysis benchmark (`benches/analysis.rs`,
//! through `#[path]`). Not a module of the library: a library must not change a
//! process-wide setting of the program that links it.

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
/// This is the package's one `unsafe` block (the workspace denies `unsafe_code`).
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
