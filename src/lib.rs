//! Drive monitor firmware: the hardware-independent part.
//!
//! This library holds everything of the firmware that does not touch a register, so it
//! builds and is tested on the host (`cargo test`):
//! - [`clock`]: the clock tree's settings and every rate and cycle count derived from them;
//! - [`acquisition`]: the ADCs' geometry (channels, oversampling, DMA ring, conversion
//!   time), shared with the host's model of the ADC and DMA, and the oversampling's mean;
//! - [`adc_rules`]: the ADC's register rules the HAL does not keep (set-only bits, the
//!   common prescaler, `DMAEN`, the first conversion after an idle, VREFINT's start-up);
//! - [`debug_halt`]: what a debugger's halt freezes (the trigger, the time base, the
//!   watchdog);
//! - [`under_the_hal`]: where the firmware writes registers under embassy-stm32, why, and
//!   the HAL version that was checked;
//! - [`watchdog`]: the watchdog started first, with a first timeout covering the boot;
//! - [`fault_path`]: the end of a failed run (guard, record, panel; no log);
//! - [`flash_ecc`]: the record pages' ECC double errors (the NMI's decision, the checked
//!   reads that mark a page bad);
//! - [`board`]: analog front-end scaling (ADC code -> volts/amperes), encoder and sample
//!   rate constants, the lamp table (each lamp's pin and meaning, once) and (target only)
//!   the pin map;
//! - [`sampling`]: one sample's six ADC codes + encoder count -> the core's `Sample`;
//! - [`motor_source`] and [`boot`]: the machine from the motor record (or the built-in
//!   default) and the boot's composition: sample path, isolator, encoder set-up, stored
//!   calibration and supervisor, each failure with its fallback;
//! - [`commissioning`]: the button -> learn -> store procedure around the core's
//!   commissioning runs;
//! - [`flash_record`]: the commissioning record (a format of the core's one record module,
//!   `monitor_core::record`) and storing it;
//! - [`liveness`]: timeouts on the ADC waits, the watch on the sample counter that pets
//!   the watchdog;
//! - [`recovery`]: the acquisition's recovery after an ADC overrun or a DMA error (the
//!   register sequence in the reference manual's order, over a trait the host rig fakes);
//! - [`ring_read`]: the sample task's read of one DMA half, every ring's channel checked
//!   before each read (the HAL's `read` never restarts a ring itself);
//! - [`reset_record`]: why the previous run ended (panic, stalled sample path), kept in
//!   RAM across the reset;
//! - [`setup_guard`]: the deadline on the ADCs' set-up (a step that does not finish is
//!   recorded and ends in a reset);
//! - [`stack`]: the painted stack's high-water mark and an overflow seen at the next boot;
//! - [`supply`]: the brown-out level in the option bytes and the periodic check of the
//!   ADC's reference (VDDA through VREFINT);
//! - [`offset_trim`]: each channel's zero measured at start-up with the motor off, bounded;
//! - [`clip_watch`]: whether clipping persists in steady running (the front end's range
//!   too small for the motor: the range state), in thread mode;
//! - [`boot_block`]: what the boot keeps in RAM across a reset besides the reset record
//!   (the phase mark, the failed boots in a row that lead to the safe mode);
//! - [`self_check`]: the boot's read-back of what the firmware wrote (the freeze, the clock
//!   security system, the option bytes, the encoder's timer, the ADCs' common register);
//! - [`regs`]: the register layer, every register the firmware touches beside the HAL's
//!   drivers, one method an access on stm32-metapac's blocks behind a bus the host tests
//!   point at memory of their own;
//! - [`startup`]: the start of every run on the registers (freeze, watchdog, the previous
//!   run, the stack, the clock with its bounded waits, the safe mode, the self-check), over
//!   a trait the host tests drive with a register model;
//! - [`panel`]: lamp patterns and blink codes;
//! - [`app`]: the glue: settings, the per-sample path, the status it hands thread mode,
//!   and thread mode's supervisor.
//!
//! The hardware tasks (ADC/DMA, encoder, flash, watchdog, panic handler) are in
//! `src/firmware.rs` (included by `src/main.rs`) and only exist for `target_os = "none"`.
#![cfg_attr(target_os = "none", no_std)]
// No panics on the board: the sample path and everything it calls must not unwrap, expect,
// panic or index out of bounds (the core's rule, here too).
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
// Tests may index, unwrap and panic: that is how they fail.
#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

pub mod acquisition;
pub mod adc_rules;
pub mod app;
pub mod board;
pub mod boot;
pub mod boot_block;
pub mod boot_report;
pub mod clip_watch;
pub mod clock;
pub mod commissioning;
pub mod debug_halt;
pub mod fault_path;
pub mod flash_ecc;
pub mod flash_record;
pub mod liveness;
pub mod motor_source;
pub mod offset_trim;
pub mod panel;
pub mod range_watch;
pub mod recovery;
pub mod regs;
pub mod reset_record;
pub mod ring_read;
pub mod sampling;
pub mod self_check;
pub mod setup_guard;
pub mod stack;
pub mod startup;
pub mod supply;
pub mod under_the_hal;
pub mod watchdog;
