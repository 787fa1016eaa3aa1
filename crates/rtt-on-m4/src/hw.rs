//! The hardware of QEMU's `mps2-an386` this program uses: CMSDK TIMER0 as a free-running
//! clock, the CMSDK watchdog (its interrupt is wired to NMI), SysTick, and defmt-rtt's
//! control block (`_SEGGER_RTT`) read and set as a debug probe would.

use core::ptr::{addr_of, read_volatile, write_volatile};

/// CMSDK APB TIMER0: `CTRL` at +0, `VALUE` at +4, `RELOAD` at +8 (a 32-bit down counter).
const TIMER0: usize = 0x4000_0000;
/// CMSDK APB watchdog: `LOAD` +0, `CONTROL` +8 (bit 0 the interrupt), `LOCK` +0xC00.
const WATCHDOG: usize = 0x4000_8000;
/// The watchdog's unlock key.
const UNLOCK: u32 = 0x1ACC_E551;

fn write(addr: usize, value: u32) {
    // SAFETY: a memory-mapped register of mps2-an386, written with a volatile store.
    unsafe { write_volatile(addr as *mut u32, value) }
}

fn read(addr: usize) -> u32 {
    // SAFETY: a memory-mapped register of mps2-an386, read with a volatile load.
    unsafe { read_volatile(addr as *const u32) }
}

/// Starts TIMER0 from `u32::MAX`, counting down, no interrupt.
pub fn start_timer0() {
    write(TIMER0 + 8, u32::MAX);
    write(TIMER0 + 4, u32::MAX);
    write(TIMER0, 1);
}

/// TIMER0's value (it counts down).
pub fn timer0() -> u32 {
    read(TIMER0 + 4)
}

/// The watchdog's interrupt (NMI) after `ticks`.
pub fn arm_watchdog(ticks: u32) {
    write(WATCHDOG + 0xC00, UNLOCK);
    write(WATCHDOG, ticks);
    write(WATCHDOG + 8, 1);
}

/// The watchdog stopped.
pub fn disarm_watchdog() {
    write(WATCHDOG + 8, 0);
}

/// SysTick's counter and interrupt off (from the sample path's last sample).
pub fn stop_systick() {
    // SAFETY: SysTick's control register; thread mode does not touch it while it runs.
    let mut syst = unsafe { cortex_m::Peripherals::steal() }.SYST;
    syst.disable_interrupt();
    syst.disable_counter();
}

/// A loop of exactly `2 * n` instructions (`subs`, `bne`) plus a few around it.
pub fn known_loop(n: u32) {
    // SAFETY: pure register arithmetic.
    unsafe {
        core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) n => _, options(nomem, nostack));
    }
}

/// SysTick ticks and TIMER0 ticks per instruction, from a loop of known length (SysTick
/// left running from its 24-bit maximum, no interrupt).
pub fn calibrate(syst: &mut cortex_m::peripheral::SYST) -> (f32, f32) {
    syst.set_clock_source(super::SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    let measure = |n: u32| {
        let (s0, t0) = (cortex_m::peripheral::SYST::get_current(), timer0());
        known_loop(core::hint::black_box(n));
        let (s1, t1) = (cortex_m::peripheral::SYST::get_current(), timer0());
        (
            (s0.wrapping_sub(s1) & 0x00FF_FFFF) as f32,
            t0.wrapping_sub(t1) as f32,
        )
    };
    const N: u32 = 200_000;
    let (s_long, t_long) = measure(N);
    let (s_short, t_short) = measure(1);
    syst.disable_counter();
    let instructions = 2.0 * (N - 1) as f32;
    (
        (s_long - s_short) / instructions,
        (t_long - t_short) / instructions,
    )
}

/// defmt-rtt's control block: the id (16 bytes), the channel counts, then the one up
/// channel's name, buffer, size, write offset, read offset and flags (`u32` each).
#[repr(C)]
struct RttHeader {
    id: [u8; 16],
    max_up: u32,
    max_down: u32,
    name: u32,
    buffer: u32,
    size: u32,
    write: u32,
    read: u32,
    flags: u32,
}

extern "C" {
    /// defmt-rtt's `#[no_mangle] static _SEGGER_RTT`.
    static mut _SEGGER_RTT: RttHeader;
}

fn header() -> *mut RttHeader {
    core::ptr::addr_of_mut!(_SEGGER_RTT)
}

/// The up channel's buffer size [bytes] (defmt-rtt's `DEFMT_RTT_BUFFER_SIZE`, 1024 unless
/// set, as in the firmware).
pub fn rtt_size() -> u32 {
    // SAFETY: a volatile read of the control block's field, as a probe reads it.
    unsafe { read_volatile(addr_of!((*header()).size)) }
}

/// The up channel's write offset.
pub fn rtt_write() -> u32 {
    // SAFETY: as above.
    unsafe { read_volatile(addr_of!((*header()).write)) }
}

/// The up channel in blocking mode (`SEGGER_RTT_MODE_BLOCK_IF_FIFO_FULL`, 2), as probe-rs
/// sets it when it attaches; its read offset is left where it is (0: nothing read).
pub fn rtt_set_blocking() {
    // SAFETY: a volatile write of the control block's flags, as a probe writes it; the
    // logger only reads them.
    unsafe {
        let flags = core::ptr::addr_of_mut!((*header()).flags);
        write_volatile(flags, (read_volatile(flags) & !3) | 2);
    }
}
