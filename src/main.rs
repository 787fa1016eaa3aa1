//! Firmware entry point for the NUCLEO-G474RE drive monitor.
//!
//! For `target_os = "none"` the program is in `firmware.rs` (tasks, peripherals, panic
//! handler). On the host this binary is a stub so that `cargo test` at the workspace root
//! builds; the testable logic is the `drive_monitor` library.
#![cfg_attr(target_os = "none", no_std, no_main)]
// No panics on the board (the sample task above all): as in the library and the core.
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

#[cfg(target_os = "none")]
mod firmware;

#[cfg(not(target_os = "none"))]
fn main() {
    println!("drive-monitor is firmware: build it with `cargo fw` (thumbv7em-none-eabihf).");
}
