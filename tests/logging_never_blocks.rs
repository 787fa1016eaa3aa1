//! The sample path cannot be stalled by the log (issue 43). probe-rs puts the RTT channel in
//! blocking mode, and defmt-rtt would then wait, with interrupts off, for the host to read:
//! a slow reader (`cargo fw-run | sim-host hmi --stdin`) or a detached probe would hold the
//! sample task past its 2-sample DMA ring's 100-200 us of slack. Two facts keep it from
//! happening, checked here on the sources (no board can be attached on this machine):
//! 1. the firmware's defmt-rtt is built with `disable-blocking-mode` (a full RTT buffer
//!    drops log bytes and returns at once: `defmt-rtt` 1.3's `nonblocking_write`);
//! 2. the per-sample code (`app`, `sampling`, `liveness`, `recovery`) logs nothing: only the
//!    sample task's rare events (a recovery, a lapped ring) are logged, from the task, and
//!    each is one short frame.
//!
//! So a reader stalled for 1 s loses that second's log lines beyond the RTT buffer, never a
//! sample (not measured on a board: there is none here).

use std::path::Path;

fn read(p: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(p)).expect(p)
}

#[test]
fn rtt_is_non_blocking_for_the_firmware() {
    let manifest = read("Cargo.toml");
    let line = manifest
        .lines()
        .find(|l| l.trim_start().starts_with("defmt-rtt"))
        .expect("a defmt-rtt dependency");
    assert!(
        line.contains("disable-blocking-mode"),
        "defmt-rtt without disable-blocking-mode: {line}"
    );
}

#[test]
fn the_per_sample_code_logs_nothing() {
    let mut found = Vec::new();
    for f in [
        "src/app.rs",
        "src/sampling.rs",
        "src/liveness.rs",
        "src/recovery.rs",
    ] {
        for (k, l) in read(f).lines().enumerate() {
            let code = l.split("//").next().unwrap_or("");
            for m in [
                "info!(",
                "warn!(",
                "error!(",
                "debug!(",
                "trace!(",
                "println!(",
            ] {
                if code.contains(m) {
                    found.push(format!("{f}:{}: {}", k + 1, l.trim()));
                }
            }
        }
    }
    assert!(found.is_empty(), "logging in the sample path: {found:#?}");
}
