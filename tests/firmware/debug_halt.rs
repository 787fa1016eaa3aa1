//! A debugger's halt against what the firmware freezes (`drive_monitor::debug_halt`), on a
//! model of the board's clocks: during a halt of the core each of TIM1 (the trigger, and
//! with it the ADCs' conversions and the DMA), TIM15 (embassy-time: the sample task's
//! timeout) and the IWDG runs on unless frozen. After the halt the model says whether the
//! DMA lapped the ring (it wrote more samples than the ring holds beyond the unread ones),
//! whether the sample task's wait timed out (a recovery) and whether the watchdog reset
//! the MCU. That the start sets the freeze and starts the watchdog before anything else is
//! run on a register model in `tests/startup/`.

use drive_monitor::acquisition::SAMPLES_PER_HALF;
use drive_monitor::app::WATCHDOG_TIMEOUT_MS;
use drive_monitor::debug_halt::{Freeze, FreezeRegisters, FROZEN};
use drive_monitor::liveness::AdcWait;

const FS: u32 = 10_000;

#[derive(Debug, PartialEq, Eq)]
struct AfterHalt {
    lapped: bool,
    recovered: bool,
    reset: bool,
}

/// A halt of `halt_ms` with `freeze`, the sample task waiting for the next half (none
/// unread: the worst case is a full ring's room, two halves) and the watchdog petted just
/// before.
fn halt(freeze: Freeze, halt_ms: u32) -> AfterHalt {
    let samples_during = if freeze.trigger {
        0
    } else {
        halt_ms * FS / 1_000
    };
    let ring_samples = 2 * SAMPLES_PER_HALF as u32;
    // The task's wait began at most one half before the halt.
    let waited_us = if freeze.time_base { 0 } else { halt_ms * 1_000 };
    let timeout_us = AdcWait::new(FS).timeout_us();
    AfterHalt {
        lapped: samples_during > ring_samples,
        recovered: waited_us >= timeout_us,
        reset: !freeze.watchdog && halt_ms >= WATCHDOG_TIMEOUT_MS,
    }
}

/// What a halt stops, read from the values the boot writes into `DBGMCU_APB1FZR1` and
/// `DBGMCU_APB2FZR` (`Freeze::registers_after` on registers that held `read`), decoded with
/// RM0440's bit positions written out here: TIM1 bit 11 and TIM15 bit 16 of `APB2FZR`, the
/// IWDG bit 12 of `APB1FZR1`.
fn written(read: FreezeRegisters) -> Freeze {
    let after = FROZEN.registers_after(read);
    Freeze {
        trigger: after.apb2fzr & (1 << 11) != 0,
        time_base: after.apb2fzr & (1 << 16) != 0,
        watchdog: after.apb1fzr1 & (1 << 12) != 0,
    }
}

#[test]
fn a_breakpoint_stops_sampling_cleanly_and_resumes_without_a_recovery() {
    // From the reset values (0) and from registers a debugger left with other bits set.
    let reset = FreezeRegisters {
        apb1fzr1: 0,
        apb2fzr: 0,
    };
    let other = FreezeRegisters {
        apb1fzr1: 0x0000_0004,
        apb2fzr: 0x0004_0000,
    };
    assert_eq!(
        FROZEN.registers_after(other).apb1fzr1 & 0x4,
        0x4,
        "the other stop bits are left as read"
    );
    for read in [reset, other] {
        for halt_ms in [1, 100, 2_000, 60_000] {
            assert_eq!(
                halt(written(read), halt_ms),
                AfterHalt {
                    lapped: false,
                    recovered: false,
                    reset: false
                },
                "{halt_ms} ms"
            );
        }
    }
    // Each part of the freeze is needed: without it the halt laps the ring, times the
    // wait out or resets the MCU.
    let without_trigger = Freeze {
        trigger: false,
        ..FROZEN
    };
    assert!(halt(without_trigger, 100).lapped);
    let without_time = Freeze {
        time_base: false,
        ..FROZEN
    };
    assert!(halt(without_time, 100).recovered);
    let without_watchdog = Freeze {
        watchdog: false,
        ..FROZEN
    };
    assert!(halt(without_watchdog, 2_000).reset);
}
