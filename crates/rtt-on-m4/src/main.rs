//! A stalled log reader against the sample path, on the Cortex-M4F instruction set (QEMU
//! `mps2-an386`, `-icount shift=0`, semihosting): `cargo qemu-rtt` (`tools/fwtool`).
//!
//! The firmware logs through defmt-rtt 1.3 with `disable-blocking-mode` (root
//! `Cargo.toml`). This program runs the same logger (same crates, same feature, the
//! firmware's profile) with the up channel in blocking mode, as probe-rs sets it when it
//! attaches, and a reader that never reads (the read offset stays 0: a stalled
//! `cargo fw-run | sim-host hmi --stdin`, a detached probe), against a sample loop at the
//! firmware's 10 kHz:
//!
//! - the sample path is the SysTick exception every [`INSTRUCTIONS_PER_SAMPLE`] = 17 000
//!   instructions (QEMU's `-icount shift=0` runs one instruction per virtual nanosecond;
//!   17 000 are the G474's cycles in 100 us at 170 MHz, counted as one instruction each),
//!   its work a loop of 562 instructions (per sample on the board, `cargo qemu-core`:
//!   the core's 244 and the sampling path's 318 ahead of it, with the clip and encoder
//!   checks);
//! - thread mode logs the firmware's status line with its format string (the core's
//!   `monitor_core::status_line::FORMAT`; `tests/firmware/logging_never_blocks.rs` checks that the two
//!   are the same).
//!
//! Two phases of [`SAMPLES_PER_PHASE`] samples, 1 s of the board each: the status line
//! every 1 000 samples (100 ms, the firmware's status rate), then status lines back to
//! back (thread mode does nothing else: the most time the logger can hold interrupts off).
//! Each sample's lateness is measured against CMSDK TIMER0 (free running, independent of
//! SysTick). On the board the sample task reads each sample from a DMA ring of two; a
//! sample taken a whole period late has lost its successor, so the verdict is: every sample
//! taken, and each less than one period after its trigger.
//!
//! Prints `name=value` lines and exits 0 when the build's expectation holds:
//!
//! - `nonblocking` (the default, the firmware's setting): no sample lost, and log lines
//!   lost: defmt-rtt's non-blocking write does not look at the reader, it overwrites the
//!   unread buffer (a reader coming back finds the newest bytes, a torn frame first);
//! - `contention` with it (defmt-rtt's `drop-on-contention`, not the firmware's: measured
//!   for comparison, `cargo qemu-rtt --drop-on-contention`): the same, the logger masking no
//!   interrupt and dropping whole frames that do not fit;
//! - neither (`--no-default-features`, defmt-rtt's default: the control, `cargo qemu-rtt
//!   --blocking`): the logger waits for the reader with interrupts masked once the buffer is
//!   full, and the samples stop; the CMSDK watchdog, whose interrupt QEMU's mps2 wires to
//!   NMI (which masking cannot stop), ends the run and reports where the samples stopped.
#![no_std]
#![no_main]

use qemu_semihosting as semihosting;
use qemu_semihosting::println;
#[path = "../../../src/clock.rs"]
#[allow(dead_code)]
mod clock;
mod hw;

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering::Relaxed};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use defmt_rtt as _;

/// The sample period in instructions: the G474's HCLK (the firmware's clock tree,
/// `src/clock.rs`, compiled here from its own file) over the firmware's 10 kHz.
const INSTRUCTIONS_PER_SAMPLE: u32 = clock::HCLK_HZ / 10_000;
/// One second of the board's samples.
const SAMPLES_PER_PHASE: u32 = 10_000;
/// The firmware's status line: every 100 ms (its thread mode's period 50 ms, every second
/// period), 1 000 samples.
const STATUS_EVERY: u32 = 1_000;
/// Iterations of the sample path's stand-in loop (two instructions each: 562 in all).
const PATH_LOOP: u32 = 281;
/// The watchdog's NMI after this many TIMER0 ticks (0.6 s of QEMU's virtual time at 25 MHz,
/// about 3.5 s of the board's: both phases take 2 s).
const WATCHDOG_TICKS: u32 = 15_000_000;

/// Samples taken in this phase (written by the sample path only).
static SAMPLES: AtomicU32 = AtomicU32::new(0);
/// TIMER0 at the phase's start (it counts down).
static T0: AtomicU32 = AtomicU32::new(0);
/// TIMER0 ticks per sample period.
static PERIOD_TICKS: AtomicU32 = AtomicU32::new(1);
/// The latest any sample was taken after its trigger, TIMER0 ticks.
static MAX_LATE: AtomicU32 = AtomicU32::new(0);
/// Triggers that passed by the phase's last sample, by TIMER0.
static TRIGGERS: AtomicU32 = AtomicU32::new(0);
/// The phase's last sample was taken.
static DONE: AtomicBool = AtomicBool::new(false);
/// Which phase runs (for the watchdog's report).
static PHASE: AtomicU32 = AtomicU32::new(0);

/// The sample path: one sample per SysTick, its lateness against TIMER0, 562 instructions
/// of work; the last sample of the phase stops SysTick.
#[exception]
fn SysTick() {
    let elapsed = T0.load(Relaxed).wrapping_sub(hw::timer0());
    let k = SAMPLES.load(Relaxed);
    let period = PERIOD_TICKS.load(Relaxed);
    let late = elapsed.saturating_sub((k + 1) * period);
    if late > MAX_LATE.load(Relaxed) {
        MAX_LATE.store(late, Relaxed);
    }
    hw::known_loop(PATH_LOOP);
    SAMPLES.store(k + 1, Relaxed);
    if k + 1 == SAMPLES_PER_PHASE {
        hw::stop_systick();
        TRIGGERS.store(elapsed / period, Relaxed);
        DONE.store(true, Relaxed);
    }
}

/// The watchdog's interrupt: the run hung (with the control's blocking logger: waiting for
/// the reader with interrupts masked). Reports where the samples stopped and exits.
///
/// # Safety
/// cortex-m-rt's requirement for an NMI handler: it does not return (it exits QEMU).
#[exception]
unsafe fn NonMaskableInt() {
    println!("phase={}", PHASE.load(Relaxed));
    println!("samples_before_stall={}", SAMPLES.load(Relaxed));
    println!("stalled=true");
    let expected = cfg!(not(feature = "nonblocking"));
    println!(
        "result={}",
        if expected {
            "pass (the control stalls)"
        } else {
            "FAIL"
        }
    );
    semihosting::exit(expected)
}

/// What one phase measured.
struct StallPhase {
    samples: u32,
    triggers: u32,
    max_late_ticks: u32,
    lines: u32,
    /// Bytes the logger wrote into the buffer.
    bytes: u32,
    /// Lines the logger dropped whole (the write offset did not move).
    dropped: u32,
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        semihosting::exit(false)
    };
    hw::start_timer0();
    let (systick_per_instr, timer_per_instr) = hw::calibrate(&mut cp.SYST);
    let reload = (INSTRUCTIONS_PER_SAMPLE as f32 * systick_per_instr + 0.5) as u32;
    let period_ticks = (reload as f32 / systick_per_instr * timer_per_instr + 0.5) as u32;
    if reload < 2 || period_ticks < 2 {
        println!("error=SysTick or TIMER0 do not advance (run QEMU with -icount shift=0)");
        semihosting::exit(false);
    }
    PERIOD_TICKS.store(period_ticks, Relaxed);
    let instructions_per_tick = 1.0 / timer_per_instr;
    println!(
        "period_instructions={:.0}",
        reload as f32 / systick_per_instr
    );
    println!("rtt_buffer_bytes={}", hw::rtt_size());
    // probe-rs attaching: the up channel in blocking mode; nobody reads it from now on.
    hw::rtt_set_blocking();
    hw::arm_watchdog(WATCHDOG_TICKS);
    cp.SYST.set_reload(reload - 1);
    let status = run_phase(&mut cp.SYST, 1, false);
    let flood = run_phase(&mut cp.SYST, 2, true);
    hw::disarm_watchdog();
    let mut ok = true;
    for (name, p) in [("status_rate", &status), ("flood", &flood)] {
        ok &= report(name, p, period_ticks, instructions_per_tick);
    }
    let kept = hw::rtt_write();
    println!("bytes_a_reader_finds={}", kept);
    println!("result={}", if ok { "pass" } else { "FAIL" });
    semihosting::exit(ok)
}

/// Prints one phase's figures; true when no sample was lost, every sample came less than a
/// period late and log lines were lost (overwritten unread, or dropped whole).
fn report(name: &str, p: &StallPhase, period_ticks: u32, instructions_per_tick: f32) -> bool {
    let lost = p.triggers.saturating_sub(p.samples);
    let overwritten = p.bytes.saturating_sub(hw::rtt_size() - 1);
    println!("{}_samples={}", name, p.samples);
    println!("{}_samples_lost={}", name, lost);
    println!(
        "{}_max_late_instructions={:.0}",
        name,
        p.max_late_ticks as f32 * instructions_per_tick
    );
    println!("{}_log_lines={}", name, p.lines);
    println!("{}_log_lines_dropped={}", name, p.dropped);
    println!("{}_log_bytes_written={}", name, p.bytes);
    println!("{}_log_bytes_overwritten_unread={}", name, overwritten);
    let samples_ok = lost == 0 && p.samples == SAMPLES_PER_PHASE && p.max_late_ticks < period_ticks;
    samples_ok && (overwritten > 0 || p.dropped > 0)
}

/// One phase: SysTick samples until [`SAMPLES_PER_PHASE`]; thread mode logs the status
/// line every [`STATUS_EVERY`] sample periods by TIMER0, or back to back (`flood`), and
/// counts the bytes the logger wrote.
fn run_phase(syst: &mut cortex_m::peripheral::SYST, phase: u32, flood: bool) -> StallPhase {
    PHASE.store(phase, Relaxed);
    SAMPLES.store(0, Relaxed);
    MAX_LATE.store(0, Relaxed);
    DONE.store(false, Relaxed);
    T0.store(hw::timer0(), Relaxed);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    let (mut lines, mut bytes, mut dropped) = (0u32, 0u32, 0u32);
    let size = hw::rtt_size();
    let period = PERIOD_TICKS.load(Relaxed);
    while !DONE.load(Relaxed) {
        // The status line's moment: every 100 ms of the board, each a tenth of a period
        // later in the sample period than the one before (the board's thread-mode timer
        // runs apart from the sample trigger), so the ten lines meet the sample path at ten
        // phases.
        let due = lines * (STATUS_EVERY * period + period / 10);
        let elapsed = T0.load(Relaxed).wrapping_sub(hw::timer0());
        if flood || elapsed >= due {
            let before = hw::rtt_write();
            log_status(SAMPLES.load(Relaxed), lines);
            let written = (hw::rtt_write() + size - before) % size;
            bytes += written;
            dropped += u32::from(written == 0);
            lines += 1;
        }
    }
    StallPhase {
        samples: SAMPLES.load(Relaxed),
        triggers: TRIGGERS.load(Relaxed),
        max_late_ticks: MAX_LATE.load(Relaxed),
        lines,
        bytes,
        dropped,
    }
}

/// The firmware's status line (`monitor_core::status_line::FORMAT`: the same format string,
/// arguments of the same types) with values that change from line to line.
fn log_status(samples: u32, line: u32) {
    let x = line as f32 * 1e-3;
    let residuals = [0.0123 + x, -0.1, 0.25, -0.004];
    let lamps = [false, true, true, line.is_multiple_of(2)];
    let bands = [0.001, -0.01, 0.009, 0.0];
    let half = [0.006, 0.011, 0.012, 0.007];
    let zc: Option<bool> = None;
    defmt::info!(
        "r={} lamps={} fault={=bool} call={=str} top={=str}({=f32}) 2nd={=str}({=f32}) wm={=f32}rad/s zc_locked={} mode={=str} run={=u16}:{=u32}/{=u32} overruns={=u32} restarts={=u32} samples={=u32} max_cyc={=u32} iqs={=f32}A ids={=f32}A vqs={=f32}V f={=f32}Hz steady={=bool} eval={=bool} sens={=bool},{=bool},{=bool} mid={} half={} iso={=str} iso_change={=f32} iso_p={=f32} wind={=str} wind_i2={=f32} moved={=bool} rise={=f32}K vdda={=f32}V bor={=u8} clip={=u32} enc_rej={=u32} stack={=u32}B clip_range={=bool}",
        residuals,
        lamps,
        true,
        "watching",
        "rr",
        0.5 + x,
        "ls",
        0.25,
        150.5 - x,
        zc,
        "commissioned",
        2u16,
        4000u32,
        4000u32,
        0u32,
        0u32,
        samples,
        2310u32,
        4.25 + x,
        2.5,
        320.5,
        50.02,
        true,
        true,
        false,
        false,
        false,
        bands,
        half,
        "rr",
        0.48,
        0.93,
        "none",
        0.0,
        false,
        12.5,
        3.301,
        4u8,
        0u32,
        0u32,
        2344u32,
        false
    );
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    semihosting::write0(b"panic\n\0");
    semihosting::exit(false)
}
