//! The stack on the registers (`drive_monitor::stack`): painted at boot, an overflow of the
//! previous run found in its guard words first, the high-water mark read for the status
//! line. With flip-link (`.cargo/config.toml`) the stack lies at the bottom of RAM, below
//! the statics: an overflow faults at 0x2000_0000 instead of running over the DMA rings.

use core::mem::MaybeUninit;

use drive_monitor::stack::{self, GUARD_WORDS, PAINT, PAINTED, PAINT_MARGIN_BYTES, RAM_START};

extern "C" {
    /// cortex-m-rt's initial stack pointer (the top of the stack).
    static _stack_start: u32;
    /// cortex-m-rt's end of the statics (`.uninit`): the stack's bottom without flip-link.
    static _stack_end: u32;
}

/// [`PAINTED`] once this run painted its stack (RAM that survives a reset).
#[allow(unsafe_code)]
#[link_section = ".uninit.STACK_PAINTED"]
static mut STACK_PAINTED: MaybeUninit<u32> = MaybeUninit::uninit();

/// The stack region: its bottom and top addresses.
#[allow(unsafe_code)]
fn region() -> (u32, u32) {
    // Only the addresses of the linker's symbols are taken, never their content.
    let (top, end) = (
        core::ptr::addr_of!(_stack_start) as u32,
        core::ptr::addr_of!(_stack_end) as u32,
    );
    let first_static = core::ptr::addr_of!(STACK_PAINTED) as u32;
    (stack::region_bottom(top, first_static, RAM_START, end), top)
}

/// Word `i` of the stack region from its bottom, read volatile.
#[allow(unsafe_code)]
fn word(bottom: u32, i: usize) -> u32 {
    // SAFETY: an aligned word inside the stack region (RAM), read only.
    unsafe { core::ptr::read_volatile((bottom as usize + 4 * i) as *const u32) }
}

/// Whether the previous run's stack reached its region's bottom (its guard words no longer
/// painted: `stack::overflowed`), then paints the stack below the current frame for this run
/// and marks it painted. The first thing `main` does after the watchdog.
#[allow(unsafe_code)]
pub(super) fn check_and_paint() -> bool {
    let (bottom, _) = region();
    // SAFETY: the marker is a plain word in `.uninit`, read volatile (any content).
    let marker =
        unsafe { core::ptr::read_volatile(core::ptr::addr_of!(STACK_PAINTED).cast::<u32>()) };
    let mut guard = [0u32; GUARD_WORDS];
    for (i, g) in guard.iter_mut().enumerate() {
        *g = word(bottom, i);
    }
    let overflowed = stack::overflowed(marker, &guard);
    let sp = cortex_m::register::msp::read().saturating_sub(PAINT_MARGIN_BYTES);
    let mut at = bottom;
    while at + 4 <= sp {
        // SAFETY: an aligned word of the stack below the current frame (and its margin),
        // which nothing uses yet.
        unsafe { core::ptr::write_volatile(at as *mut u32, PAINT) };
        at += 4;
    }
    // SAFETY: the marker word, written volatile.
    unsafe {
        core::ptr::write_volatile(
            core::ptr::addr_of_mut!(STACK_PAINTED).cast::<u32>(),
            PAINTED,
        )
    };
    overflowed
}

/// The stack's high-water mark since boot [bytes] (`stack::high_water_bytes`).
pub(super) fn high_water_bytes() -> u32 {
    let (bottom, top) = region();
    let len = (top.saturating_sub(bottom) / 4) as usize;
    let untouched = stack::high_water_words(len, |i| word(bottom, i));
    stack::high_water_bytes(len, untouched)
}
