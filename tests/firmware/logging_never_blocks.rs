//! The sample path cannot be stalled by the log (issue 43). probe-rs puts the RTT channel in
//! blocking mode, and defmt-rtt would then wait, with interrupts off, for the host to read:
//! a slow reader (`cargo fw-run | sim-host hmi --stdin`) or a detached probe would hold the
//! sample task past its DMA ring's slack (300 us: src/acquisition.rs, the latency budget). Two facts keep it from
//! happening, checked here on the sources:
//! 1. the firmware's defmt-rtt is built with `disable-blocking-mode`: with a full RTT
//!    buffer it writes on over the unread bytes and returns at once (`defmt-rtt` 1.3's
//!    `nonblocking_write` does not look at the reader's offset), so the log loses its
//!    oldest unread bytes, never waits;
//! 2. the per-sample code (`app`, `sampling`, `liveness`, `recovery`) logs nothing: only the
//!    sample task's rare events (a recovery, a lapped ring) are logged, from the task, and
//!    each is one short frame.
//!
//! And it is measured: `cargo qemu-rtt` (`crates/rtt-on-m4`) runs the same logger with the
//! channel in blocking mode and a reader that never reads for 1 s of the board (10 status
//! lines, then status lines back to back) against a 10 kHz sample loop on the Cortex-M4F
//! instruction set under QEMU, and fails if a sample is lost or comes a period late;
//! `cargo qemu-rtt --blocking` (defmt-rtt's default mode) must lose them. The tests below
//! keep that program the firmware's: the same status line, the same logger and mode, and
//! CI runs both (docs/firmware.md, "Logging never stalls the sample path").

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
        "src/app/sample_path.rs",
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

/// The `info!` format string of `fn log_status` in `file` (the first string literal after
/// the function's first `info!(`).
fn status_format(file: &str) -> String {
    let src = read(file);
    let body = &src[src
        .find("fn log_status")
        .unwrap_or_else(|| panic!("fn log_status in {file}"))..];
    let call = &body[body.find("info!(").expect("info! in log_status")..];
    let open = call.find('"').expect("a format string") + 1;
    let close = open + call[open..].find('"').expect("its end");
    call[open..close].to_string()
}

#[test]
fn the_qemu_measurement_logs_the_firmwares_status_line() {
    assert_eq!(
        status_format("crates/rtt-on-m4/src/main.rs"),
        monitor_core::status_line::FORMAT,
        "crates/rtt-on-m4's log_status must print the firmware's status line (same fields, same sizes)"
    );
}

/// The versions of `package` in a Cargo.lock.
fn locked(lock: &str, package: &str) -> Vec<String> {
    let key = format!("name = \"{package}\"\nversion = \"");
    lock.match_indices(&key)
        .map(|(at, _)| {
            let v = &lock[at + key.len()..];
            v[..v.find('"').expect("end of the version")].to_string()
        })
        .collect()
}

#[test]
fn the_qemu_measurement_runs_the_firmwares_logger() {
    let manifest = read("crates/rtt-on-m4/Cargo.toml");
    assert!(
        manifest.contains("default = [\"nonblocking\"]")
            && manifest.contains("nonblocking = [\"defmt-rtt/disable-blocking-mode\"]"),
        "crates/rtt-on-m4 must build the firmware's non-blocking defmt-rtt by default"
    );
    let (root, qemu) = (read("Cargo.lock"), read("crates/rtt-on-m4/Cargo.lock"));
    for package in ["defmt", "defmt-rtt", "cortex-m", "critical-section"] {
        let (ours, firmware) = (locked(&qemu, package), locked(&root, package));
        assert!(
            !ours.is_empty() && ours.iter().all(|v| firmware.contains(v)),
            "{package}: crates/rtt-on-m4 locks {ours:?}, the firmware {firmware:?}"
        );
    }
    let ci = read(".ci/run");
    assert!(ci.contains("cargo qemu-rtt\n") && ci.contains("cargo qemu-rtt --blocking"));
}
