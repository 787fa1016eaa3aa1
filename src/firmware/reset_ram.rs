//! What survives a reset in RAM: the reset record (`drive_monitor::reset_record`: why the
//! previous run ended) and the boot block (`drive_monitor::boot_block`: the phase mark,
//! the failed boots in a row) in cortex-m-rt's `.uninit` section, and the phase the
//! firmware is in ([`PHASE`]), which the fault path writes into the record. The boot reads
//! both (`drive_monitor::startup`); the sample task, thread mode and the fault path
//! (`failure.rs`) write them.

use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicU32, AtomicU8, Ordering};

use drive_monitor::boot_block::{BootBlock, Pending, BOOT_BLOCK_LEN};
use drive_monitor::reset_record::{log, BootPhase, ResetRecord, RESET_RECORD_LEN};
use drive_monitor::startup::BootFacts;
use drive_monitor::supply::BorLevel;

/// What the firmware is doing ([`BootPhase::number`]), for the record of a `defmt` panic.
pub(super) static PHASE: AtomicU8 = AtomicU8::new(0);

/// The run's self-check findings (`drive_monitor::self_check::Findings`), which every
/// reset record of the run carries ([`record`]).
pub(super) static FINDINGS: AtomicU32 = AtomicU32::new(0);

/// Records `phase` as what the firmware is doing now ([`PHASE`]).
pub(super) fn set_phase(phase: BootPhase) {
    PHASE.store(phase.number(), Ordering::Relaxed);
}

/// Records `phase` ([`set_phase`]) and marks it in the boot block, which survives a
/// reset: a hang from here on is placed by the next boot. In a critical section (thread
/// mode and the sample task both mark).
pub(super) fn mark_phase(phase: BootPhase) {
    set_phase(phase);
    cortex_m::interrupt::free(|_| {
        if let Some(block) = BootBlock::decode(&read_boot_block()) {
            write_boot_block(&block.in_phase(phase).encode());
        }
    });
}

/// Marks the run up in the boot block (the failed boots in a row end; `long`: up for the
/// reset log's "up" mark), in a critical section.
pub(super) fn mark_up(long: bool) {
    cortex_m::interrupt::free(|_| {
        if let Some(block) = BootBlock::decode(&read_boot_block()) {
            write_boot_block(&block.marked_up(long).encode());
        }
    });
}

/// Keeps the reset log's counts not yet in flash (`pending`) in the boot block, in a
/// critical section (`drive_monitor::reset_record::log::record_boot` and `count_safe_mode`
/// decide them at boot).
pub(super) fn set_pending(pending: Pending) {
    cortex_m::interrupt::free(|_| {
        if let Some(block) = BootBlock::decode(&read_boot_block()) {
            write_boot_block(&BootBlock { pending, ..block }.encode());
        }
    });
}

/// The safe mode's boot counted in the boot block's RAM (`log::count_safe_mode`); no flash
/// is touched. Whether it was counted (`false`: every slot held another count).
pub(super) fn count_safe_mode(facts: &BootFacts) -> bool {
    let boot = log::BootRecord {
        previous: facts.previous,
        source: facts.reset_source,
        kind: facts.history.kind,
        previous_long_up: facts.history.previous_long_up,
        previous_up: facts.history.previous_up,
        ram_kept: facts.history.ram_kept,
        safe_mode: true,
    };
    let mut pending = facts.history.pending;
    let counted = log::count_safe_mode(&mut pending, &boot);
    set_pending(pending);
    counted
}

/// Writes `record` into the reset record with the brown-out level in force (`bor`,
/// `supply::bor_level`) and the run's self-check findings.
pub(super) fn record(record: ResetRecord, bor: Option<BorLevel>) {
    let record = record
        .with_bor_level(bor)
        .with_findings(FINDINGS.load(Ordering::Relaxed));
    write_reset_record(&record.encode());
}

/// The boot block: RAM in `.uninit`, as the reset record.
#[allow(unsafe_code)]
#[link_section = ".uninit.BOOT_BLOCK"]
static mut BOOT_BLOCK: MaybeUninit<[u8; BOOT_BLOCK_LEN]> = MaybeUninit::uninit();

/// The boot block's bytes (whatever they are: power-on garbage fails its check).
#[allow(unsafe_code)]
pub(super) fn read_boot_block() -> [u8; BOOT_BLOCK_LEN] {
    // SAFETY: as `read_reset_record`: a byte array read volatile through a raw pointer;
    // the writers are the boot, thread mode and the sample task, each in a critical
    // section ([`mark_phase`], [`mark_up`]) or before the tasks run.
    unsafe { core::ptr::read_volatile(core::ptr::addr_of!(BOOT_BLOCK).cast()) }
}

/// Overwrites the boot block.
#[allow(unsafe_code)]
pub(super) fn write_boot_block(bytes: &[u8; BOOT_BLOCK_LEN]) {
    // SAFETY: as `read_boot_block`.
    unsafe {
        core::ptr::write_volatile(
            core::ptr::addr_of_mut!(BOOT_BLOCK).cast::<[u8; BOOT_BLOCK_LEN]>(),
            *bytes,
        )
    }
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
