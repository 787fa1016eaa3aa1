//! Drive monitor firmware: the hardware-independent part.
//!
//! This library holds everything of the firmware that does not touch a register, so it
//! builds and is tested on the host (`cargo test`):
//! - [`board`]: analog front-end scaling (ADC code -> volts/amperes), encoder and sample
//!   rate constants, and (target only) the pin map;
//! - [`sampling`]: one trigger's six ADC codes + encoder count -> the core's `Sample`;
//! - [`commissioning`]: button -> learn -> store state machine;
//! - [`flash_record`]: the commissioning record's encoding, version and CRC;
//! - [`panel`]: lamp mapping and blink codes;
//! - [`app`]: the glue that runs the core per sample and turns its output into lamps.
//!
//! The hardware tasks (ADC/DMA, encoder, flash, watchdog, panic handler) are in
//! `src/firmware.rs` (included by `src/main.rs`) and only exist for `target_os = "none"`.
#![cfg_attr(target_os = "none", no_std)]

pub mod app;
pub mod board;
pub mod commissioning;
pub mod flash_record;
pub mod panel;
pub mod sampling;
