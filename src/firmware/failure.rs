//! The end of a failed run: the panic handlers (`core`'s and defmt's), the HardFault and
//! default exception handlers, and what all do (the panel's "monitor failed" pattern, the
//! reset record, the reset). Without the exception handlers a fault would end in
//! cortex-m-rt's endless loop: no record, and before the watchdog runs no reset at all.

use core::sync::atomic::Ordering;

use defmt::{error, warn};
use drive_monitor::app::WATCHDOG_TIMEOUT_MS;
use drive_monitor::board::{Lamp, Port};
use drive_monitor::panel::PanelLamps;
use drive_monitor::reset_record::{BootPhase, ResetRecord};
use embassy_stm32::pac;

use super::supply::bor_level;
use super::{write_reset_record, PHASE, WATCHDOG_RUNNING};

/// A HardFault (a bus or memory fault, a usage fault escalated, an undefined instruction):
/// the stacked PC and LR and the fault status registers into the reset record, then
/// [`fail`]: the next boot reports where it happened.
#[cortex_m_rt::exception]
#[allow(unsafe_code)]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    cortex_m::interrupt::disable();
    // SAFETY: the System Control Block's fault status registers are read-only here; the
    // handler runs with interrupts off and never returns.
    let scb = unsafe { &*cortex_m::peripheral::SCB::PTR };
    let (cfsr, hfsr, bfar) = (scb.cfsr.read(), scb.hfsr.read(), scb.bfar.read());
    let record = ResetRecord::hard_fault(None, frame.pc(), frame.lr(), cfsr, hfsr, bfar);
    fail(record)
}

/// An exception or interrupt without a handler: its number into the reset record, then
/// [`fail`] (cortex-m-rt's default would spin for ever).
#[cortex_m_rt::exception]
#[allow(unsafe_code)]
unsafe fn DefaultHandler(irqn: i16) {
    cortex_m::interrupt::disable();
    // SAFETY: as in `HardFault`.
    let scb = unsafe { &*cortex_m::peripheral::SCB::PTR };
    let (cfsr, hfsr, bfar) = (scb.cfsr.read(), scb.hfsr.read(), scb.bfar.read());
    let lr = cortex_m::register::lr::read();
    let record = ResetRecord::hard_fault(Some(irqn), 0, lr, cfsr, hfsr, bfar);
    fail(record)
}

/// Panic: the reason into the reset record (RAM that survives the reset), then [`fail`].
/// Only the static part of the message and the location are kept: formatting the full
/// message would pull core::fmt (float formatting alone is ~10 KiB of flash).
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    let location = info.location().map(|l| (l.file(), l.line()));
    fail(ResetRecord::on_panic(info.message().as_str(), location))
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
    fail(ResetRecord::defmt_panic(phase, return_address))
}

/// The end of a failed run: the panel's "monitor failed" pattern on the lamp pins of the
/// lamp table, `record` (with the brown-out level in force) into the reset record and the
/// log, then the reset: the watchdog's
/// (no longer petted) after `WATCHDOG_TIMEOUT_MS`, or, when it does not run yet, a
/// software reset after the same time. The next boot reads the record, logs it and shows
/// the failed pattern for 5 s before monitoring again.
fn fail(record: ResetRecord) -> ! {
    // Direct register writes: the HAL objects may be in any state. GPIO clocks are
    // enabled by `embassy_stm32::init` for every port.
    use pac::gpio::vals::Moder;
    for lamp in Lamp::ALL {
        let pin = lamp.pin();
        let port = match pin.port {
            Port::A => pac::GPIOA,
            Port::B => pac::GPIOB,
            Port::C => pac::GPIOC,
            Port::D => pac::GPIOD,
            Port::E => pac::GPIOE,
            Port::F => pac::GPIOF,
            Port::G => pac::GPIOG,
        };
        let n = usize::from(pin.number);
        port.moder().modify(|w| w.set_moder(n, Moder::OUTPUT));
        if PanelLamps::FAILED.is_on(lamp) {
            port.bsrr().write(|w| w.set_bs(n, true));
        } else {
            port.bsrr().write(|w| w.set_br(n, true));
        }
    }
    write_reset_record(&record.with_bor_level(bor_level()).encode());
    error!(
        "MONITOR FAILED: {=str} at {=str}:{=u32}",
        record.message(),
        record.file(),
        record.line_or_ms()
    );
    if !WATCHDOG_RUNNING.load(Ordering::Relaxed) {
        warn!("watchdog not running yet: software reset");
    }
    // The watchdog's time at the full clock (longer at the 16 MHz reset clock): the failed
    // pattern shows, then the watchdog or the software reset ends the run.
    cortex_m::asm::delay(WATCHDOG_TIMEOUT_MS * 170_000);
    cortex_m::peripheral::SCB::sys_reset()
}
