//! No silent boot loop: runs that fail before they are up are counted across the resets
//! (the boot block in RAM), and after five in a row the boot enters the safe mode on the
//! reset clock, which blinks its code; the reset button ends it.

use super::boot;
use super::model::{Board, BORRSTF, IWDGRSTF, PINRSTF};
use drive_monitor::boot_block::{BootBlock, ResetKind, SAFE_MODE_AFTER};
use drive_monitor::panel::{read_blink_code, PanelLamps};
use drive_monitor::reset_record::{PreviousRun, ResetRecord};
use drive_monitor::startup::{BootNote, SafeModeReason};

/// The run after each boot hangs before it is up (the watchdog resets the MCU).
#[test]
fn five_failed_boots_in_a_row_enter_the_safe_mode_and_the_reset_button_ends_it() {
    let mut board = Board::power_on();
    let mut seen = Vec::new();
    for _ in 0..=SAFE_MODE_AFTER {
        let facts = boot(&mut board);
        seen.push((facts.history.failed_boots, facts.safe_mode.is_some()));
        // The boot's log counts the failed boots from the second on.
        let n = facts.history.failed_boots;
        assert_eq!(
            facts.notes().any(|note| note == BootNote::FailedBoots(n)),
            n > 1,
            "{n}"
        );
        if facts.safe_mode.is_some() {
            assert_eq!(
                facts.safe_mode,
                Some(SafeModeReason::BootLoop { failed_boots: 5 })
            );
            assert_eq!(facts.clock, None);
            assert_eq!(board.init_with, Some(None), "the reset clock, no PLL");
            break;
        }
        // The run hangs: the watchdog resets, RAM kept.
        board = board.reset(IWDGRSTF);
    }
    assert_eq!(
        seen,
        [
            (0, false),
            (1, false),
            (2, false),
            (3, false),
            (4, false),
            (5, true)
        ]
    );
    // In the safe mode the board waits for a person: the reset button starts again.
    let mut pressed = board.reset(PINRSTF);
    let facts = boot(&mut pressed);
    assert_eq!(facts.previous, PreviousRun::Clean);
    assert_eq!((facts.history.failed_boots, facts.safe_mode), (0, None));
    assert_eq!(facts.history.kind, ResetKind::Pin);
}

/// A run that was up before it failed is no boot loop; a brown-out (RAM kept) is counted as
/// one, not as a power-on.
#[test]
fn a_run_that_was_up_starts_the_count_again() {
    let mut board = Board::power_on();
    for _ in 0..4 {
        boot(&mut board);
        board = board.reset(IWDGRSTF);
    }
    assert_eq!(boot(&mut board).history.failed_boots, 4);
    // This run gets up (thread mode marks the block), then fails.
    let up = BootBlock::decode(&board.boot_block)
        .unwrap()
        .marked_up(false);
    board.boot_block = up.encode();
    let mut next = board.reset(IWDGRSTF);
    let facts = boot(&mut next);
    assert_eq!((facts.history.failed_boots, facts.safe_mode), (0, None));
    let mut dip = next.reset(BORRSTF);
    assert_eq!(boot(&mut dip).history.kind, ResetKind::BrownOut);
}

/// The safe mode's lamps: the FAULT lamp blinks the reason's code, the pattern is none of
/// the others (RUN dark, r1 and r4 lit).
#[test]
fn the_safe_mode_blinks_its_code() {
    for reason in [
        SafeModeReason::BootLoop { failed_boots: 5 },
        SafeModeReason::PllDidNotLock,
    ] {
        let trace: Vec<bool> = (0..20_000u32)
            .step_by(50)
            .map(|t| PanelLamps::safe_mode(reason.code(), t).fault)
            .collect();
        assert_eq!(
            read_blink_code(&trace, 50),
            Some(reason.code()),
            "{reason:?}"
        );
        let lamps = PanelLamps::safe_mode(reason.code(), 0);
        assert!(!lamps.run && lamps.residuals == [true, false, false, true]);
        assert_ne!(lamps, PanelLamps::FAILED);
    }
    assert_ne!(
        SafeModeReason::BootLoop { failed_boots: 5 }.code(),
        SafeModeReason::PllDidNotLock.code()
    );
}

/// Four failed boots, then a run whose sample path stalls: its record is written, and the
/// reset button is pressed before the watchdog's reset. The boot reports the stall and the
/// reset (`ResetDuring`) but starts the count again (a person is at the board); the same
/// run ended by the watchdog is the fifth failed boot and the safe mode follows. A power-on
/// (RAM lost) ends the safe mode too.
#[test]
fn a_button_press_after_a_stall_starts_the_count_again() {
    let mut board = Board::power_on();
    for _ in 0..4 {
        boot(&mut board);
        board = board.reset(IWDGRSTF);
    }
    assert_eq!(boot(&mut board).history.failed_boots, 4);
    board.reset_ram = ResetRecord::sample_stall(300).encode();
    let mut pressed = board.reset(PINRSTF);
    let facts = boot(&mut pressed);
    assert!(matches!(facts.previous, PreviousRun::ResetDuring { .. }));
    assert_eq!((facts.history.failed_boots, facts.safe_mode), (0, None));
    let mut by_watchdog = board.reset(IWDGRSTF);
    let facts = boot(&mut by_watchdog);
    assert_eq!(facts.history.failed_boots, SAFE_MODE_AFTER);
    assert!(facts.safe_mode.is_some());
    // The safe mode, then a power cycle: RAM lost, a normal boot.
    let mut cycled = Board::power_on();
    cycled.regs = by_watchdog.regs.clone();
    let facts = boot(&mut cycled);
    assert_eq!((facts.history.failed_boots, facts.safe_mode), (0, None));
    assert_eq!(facts.history.kind, ResetKind::PowerOn);
}
