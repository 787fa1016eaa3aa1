//! What survives a reset in RAM: the reset record (`drive_monitor::reset_record`: why the
//! previous run ended) in cortex-m-rt's `.uninit` section, and the phase the firmware is
//! in ([`PHASE`]), which the fault path writes into the record. The boot reads the record
//! (`logs::previous_run`); the sample task, the brown-out check and the fault path
//! (`failure.rs`) write it.

use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicU8, Ordering};

use drive_monitor::reset_record::{BootPhase, RESET_RECORD_LEN};

/// What the firmware is doing ([`BootPhase::number`]), for the record of a `defmt` panic.
pub(super) static PHASE: AtomicU8 = AtomicU8::new(0);

/// Records `phase` as what the firmware is doing now ([`PHASE`]).
pub(super) fn set_phase(phase: BootPhase) {
    PHASE.store(phase.number(), Ordering::Relaxed);
}

/// The reset record: RAM in cortex-m-rt's `.uninit` section, which the start-up code
/// neither zeroes nor initialises, so it keeps its content across a reset.
// The one placed item of the firmware: `.uninit` is cortex-m-rt's NOLOAD section in RAM.
#[allow(unsafe_code)]
#[link_section = ".uninit.RESET_RECORD"]
static mut RESET_RECORD: MaybeUninit<[u8; RESET_RECORD_LEN]> = MaybeUninit::uninit();

/// The reset record's bytes (whatever they are: power-on garbage fails the record's check).
#[allow(unsafe_code)]
pub(super) fn read_reset_record() -> [u8; RESET_RECORD_LEN] {
    // SAFETY: a plain byte array read through a raw pointer, volatile so the compiler makes
    // no assumption about its (possibly never written) content; the only other accesses
    // are the writes below, from thread mode and from the panic handler with interrupts
    // off, never concurrent with this read at boot.
    unsafe { core::ptr::read_volatile(core::ptr::addr_of!(RESET_RECORD).cast()) }
}

/// Overwrites the reset record.
#[allow(unsafe_code)]
pub(super) fn write_reset_record(bytes: &[u8; RESET_RECORD_LEN]) {
    // SAFETY: as in `read_reset_record`; thread mode and the panic handler (interrupts
    // off, never returns) are the only writers and cannot interleave with each other
    // except by the panic handler overwriting, which is what it should do.
    unsafe {
        core::ptr::write_volatile(
            core::ptr::addr_of_mut!(RESET_RECORD).cast::<[u8; RESET_RECORD_LEN]>(),
            *bytes,
        )
    }
}
