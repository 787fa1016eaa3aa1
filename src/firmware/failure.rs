//! The end of a failed run on the registers: the panic handlers (`core`'s and defmt's),
//! the HardFault, NMI and default exception handlers. What they do is
//! `drive_monitor::fault_path` (the guard, the reset record first, the panel's "monitor
//! failed" pattern, no log: a fault may have hit inside a `defmt` frame), the same code
//! the host tests run; here are only the register reads and the reset. The NMI handler
//! first asks `drive_monitor::flash_ecc::nmi_action`: a double ECC error in a record page
//! is latched and the read goes on (the boot falls back), anything else is a fault.

use core::sync::atomic::Ordering;

use drive_monitor::app::WATCHDOG_TIMEOUT_MS;
use drive_monitor::clock::CYCLES_PER_MS;
use drive_monitor::fault_path::{self, FaultBoard, FaultEnd, FaultGuard, FaultRegisters};
use drive_monitor::flash_ecc::{self, EccLatch, NmiAction};
use drive_monitor::panel::PanelLamps;
use drive_monitor::regs::MCU;
use drive_monitor::reset_record::{BootPhase, ResetRecord, RESET_RECORD_LEN};
use drive_monitor::supply::BorLevel;

use super::reset_ram::{write_reset_record, FINDINGS, PHASE};
use super::supply::bor_level;

/// Taken by the first fault of the run (`fault_path`): a second goes straight to reset.
static GUARD: FaultGuard = FaultGuard::new();
/// A double ECC error the NMI handler latched for the record page being read.
pub(super) static ECC: EccLatch = EccLatch::new();

/// The fault path's board: the reset record's RAM, `FLASH_OPTR` and the lamp pins.
struct FaultHardware;

impl FaultBoard for FaultHardware {
    fn bor_level(&mut self) -> Option<BorLevel> {
        bor_level()
    }

    fn findings(&mut self) -> u32 {
        FINDINGS.load(Ordering::Relaxed)
    }

    fn write_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]) {
        write_reset_record(bytes);
    }

    fn show_failed(&mut self) {
        // Direct register writes: the HAL objects may be in any state.
        MCU.show_lamps(|lamp| PanelLamps::FAILED.is_on(lamp));
    }
}

/// The fault status registers with the stacked `pc` and `lr`.
fn fault_registers(pc: u32, lr: u32) -> FaultRegisters {
    let status = MCU.fault_status();
    FaultRegisters {
        pc,
        lr,
        cfsr: status.cfsr,
        hfsr: status.hfsr,
        bfar: status.bfar,
    }
}

/// A HardFault (a bus or memory fault, a usage fault escalated, an undefined instruction):
/// the stacked PC and LR and the fault status registers into the reset record
/// (`fault_path::on_hard_fault`), then the reset: the next boot reports where it happened.
#[cortex_m_rt::exception]
#[allow(unsafe_code)]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    cortex_m::interrupt::disable();
    let regs = fault_registers(frame.pc(), frame.lr());
    end(fault_path::on_hard_fault(
        &GUARD,
        &mut FaultHardware,
        None,
        regs,
    ))
}

/// The NMI: a clock failure (the clock security system's `RCC_CIFR.CSSF`) is recorded and
/// ends in a reset onto the HSI; a double ECC error in a record page (`FLASH_ECCR.ECCD`
/// with the page's address) is latched and cleared, and the handler returns: the read
/// completes, the checked read rejects it and the boot falls back
/// (`drive_monitor::flash_ecc::nmi_cause`). Any other NMI is a fault.
#[cortex_m_rt::exception]
#[allow(unsafe_code)]
unsafe fn NonMaskableInt() {
    // SAFETY (cortex-m-rt asks for an `unsafe fn`: an NMI can preempt anything, even a
    // critical section): the handler touches only `FLASH_ECCR`, the `ECC` latch (an
    // atomic) and, for a fault, the fault path, which never returns.
    let (cifr, eccr) = MCU.nmi_sources();
    match flash_ecc::nmi_cause(cifr, eccr) {
        NmiAction::ClockFailure => {
            // The hardware runs SYSCLK from the HSI now. Clear CSSF (the NMI would pend
            // again), record the failure, reset: the next boot runs the PLL from the HSI.
            MCU.clear_clock_failure();
            cortex_m::interrupt::disable();
            end(fault_path::on_fault(
                &GUARD,
                &mut FaultHardware,
                ResetRecord::clock_failure(),
            ))
        }
        NmiAction::RecordPageEcc(e) => {
            ECC.latch(e);
            MCU.clear_ecc();
        }
        NmiAction::Fault => {
            cortex_m::interrupt::disable();
            let lr = cortex_m::register::lr::read();
            end(fault_path::on_hard_fault(
                &GUARD,
                &mut FaultHardware,
                Some(-14),
                fault_registers(0, lr),
            ))
        }
    }
}

/// An exception or interrupt without a handler: its number into the reset record, then
/// the reset (cortex-m-rt's default would spin for ever).
#[cortex_m_rt::exception]
#[allow(unsafe_code)]
unsafe fn DefaultHandler(irqn: i16) {
    cortex_m::interrupt::disable();
    let regs = fault_registers(0, cortex_m::register::lr::read());
    end(fault_path::on_hard_fault(
        &GUARD,
        &mut FaultHardware,
        Some(irqn),
        regs,
    ))
}

/// Panic: the reason into the reset record (RAM that survives the reset), then the reset.
/// Only the static part of the message and the location are kept: formatting the full
/// message would pull core::fmt (float formatting alone is ~10 KiB of flash).
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    let location = info.location().map(|l| (l.file(), l.line()));
    let record = ResetRecord::on_panic(info.message().as_str(), location);
    end(fault_path::on_fault(&GUARD, &mut FaultHardware, record))
}

/// A panic through `defmt::panic!` (the HAL with its `defmt` feature, `defmt::unwrap!`):
/// its message is already in the defmt log; the record keeps the phase and the address the
/// handler was called from. Without this handler defmt calls `core::panic!()` and the record
/// would name a line in defmt's source.
#[defmt::panic_handler]
fn defmt_panic() -> ! {
    cortex_m::interrupt::disable();
    let return_address = cortex_m::register::lr::read();
    let phase = BootPhase::from_number(PHASE.load(Ordering::Relaxed)).unwrap_or(BootPhase::Boot);
    let record = ResetRecord::defmt_panic(phase, return_address);
    end(fault_path::on_fault(&GUARD, &mut FaultHardware, record))
}

/// The reset after the fault path: at once for a fault inside it (the first record
/// stands); else after the watchdog's time (at the full clock; longer at the 16 MHz reset
/// clock) with the failed pattern showing: the watchdog, no longer petted, or the software
/// reset when it does not run yet. The next boot reads the record, logs it first and shows
/// the failed pattern for 5 s before monitoring again.
fn end(how: FaultEnd) -> ! {
    if how == FaultEnd::Recorded {
        cortex_m::asm::delay(WATCHDOG_TIMEOUT_MS * CYCLES_PER_MS);
    }
    cortex_m::peripheral::SCB::sys_reset()
}
