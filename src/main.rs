//! Firmware entry point for the NUCLEO-G474RE drive monitor.
//!
//! For `target_os = "none"` the program is in `firmware.rs` (tasks, peripherals, panic
//! handler). On the host this binary is a stub so that `cargo test` at the workspace root
//! builds; the testable logic is the `drive_monitor` library.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod firmware;

#[cfg(not(target_os = "none"))]
fn main() {
    println!("drive-monitor is firmware: build it with `cargo fw` (thumbv7em-none-eabihf).");
}
