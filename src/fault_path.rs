//! The end of a failed run, written once: what the HardFault, NMI and default handlers and
//! both panic handlers do (`src/firmware/failure.rs` reads the registers and calls
//! [`on_fault`]; the host tests run the same function on a fake board).
//!
//! A fault path that cannot fault again:
//! 1. **The guard first** ([`FaultGuard`]): the first fault takes it; a second one (a
//!    fault or a panic inside the fault path, or a panic from `defmt-rtt` "taken
//!    reentrantly" when the first fault hit inside a log frame) finds it taken and goes
//!    straight to the reset ([`FaultEnd::Reentered`]), the first record kept.
//! 2. **The record next**, before anything else: the reset record (RAM that survives the
//!    reset) with the brown-out level in force and the run's self-check findings.
//! 3. **Then the panel's "monitor failed" pattern** on the lamp pins.
//! 4. **No log.** The fault may have hit while a `defmt` frame was open (`defmt-rtt` holds
//!    a critical section and a "taken" flag for a frame): any `defmt` call from here could
//!    panic or write into a torn frame. The record is the report: the next boot logs it
//!    first ("previous run ended in ..."), which `cargo fw-run` shows when probe-rs lets
//!    the reset through (`--no-catch-reset --no-catch-hardfault`, docs/firmware.md).

use core::sync::atomic::{AtomicBool, Ordering};

use crate::reset_record::{ResetRecord, RESET_RECORD_LEN};
use crate::supply::BorLevel;

/// Whether a fault is being handled: taken once per run, never released (the run ends
/// in a reset).
#[derive(Debug)]
pub struct FaultGuard(AtomicBool);

impl FaultGuard {
    /// A guard no fault has taken.
    pub const fn new() -> Self {
        Self(AtomicBool::new(false))
    }

    /// Takes the guard: `true` for the first caller of the run, `false` for every later
    /// one (a fault inside the fault path).
    pub fn take(&self) -> bool {
        !self.0.swap(true, Ordering::SeqCst)
    }
}

impl Default for FaultGuard {
    fn default() -> Self {
        Self::new()
    }
}

/// What the fault path touches on the board: the firmware implements it on the registers
/// (the reset record's RAM, `FLASH_OPTR`, the lamp pins' GPIO registers), the host tests
/// on a fake.
pub trait FaultBoard {
    /// The brown-out level in force (`None`: a reserved value).
    fn bor_level(&mut self) -> Option<BorLevel>;
    /// The run's self-check findings (`crate::self_check::Findings`' bits), which the record
    /// carries.
    fn findings(&mut self) -> u32;
    /// Overwrites the reset record.
    fn write_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]);
    /// Shows the panel's "monitor failed" pattern on the lamp pins (plain register
    /// writes: the HAL's objects may be in any state).
    fn show_failed(&mut self);
}

/// How a fault's handling ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultEnd {
    /// The first fault: recorded and shown; the board waits the watchdog's time (the
    /// pattern visible), then resets.
    Recorded,
    /// A fault while the fault path ran: nothing written, reset at once (the first
    /// fault's record stands).
    Reentered,
}

/// The fault path for `record` (module docs): the guard, the record with the brown-out
/// level, the panel's pattern, and no log. The caller resets the MCU afterwards: at once
/// for [`FaultEnd::Reentered`], after the watchdog's time for [`FaultEnd::Recorded`].
pub fn on_fault(guard: &FaultGuard, board: &mut impl FaultBoard, record: ResetRecord) -> FaultEnd {
    if !guard.take() {
        return FaultEnd::Reentered;
    }
    let level = board.bor_level();
    let findings = board.findings();
    board.write_record(
        &record
            .with_bor_level(level)
            .with_findings(findings)
            .encode(),
    );
    board.show_failed();
    FaultEnd::Recorded
}

/// The fault status registers and the stacked frame a HardFault handler reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultRegisters {
    /// The stacked PC (0 for an exception without a frame).
    pub pc: u32,
    /// The stacked LR (or the handler's LR).
    pub lr: u32,
    /// `SCB.CFSR`.
    pub cfsr: u32,
    /// `SCB.HFSR`.
    pub hfsr: u32,
    /// `SCB.BFAR`.
    pub bfar: u32,
}

/// A HardFault (`irqn = None`) or an exception without a handler (`Some(irqn)`): its
/// record ([`ResetRecord::hard_fault`]) through [`on_fault`].
pub fn on_hard_fault(
    guard: &FaultGuard,
    board: &mut impl FaultBoard,
    irqn: Option<i16>,
    regs: FaultRegisters,
) -> FaultEnd {
    let record = ResetRecord::hard_fault(irqn, regs.pc, regs.lr, regs.cfsr, regs.hfsr, regs.bfar);
    on_fault(guard, board, record)
}
