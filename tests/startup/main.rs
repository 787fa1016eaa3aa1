//! The start of every run (`drive_monitor::startup::start`, the code `src/firmware.rs`'s
//! `main` runs first) on a register model of the board (`model.rs`): the debug freeze and
//! the watchdog before anything else, the phase mark before `init`, the clock's bounded
//! waits and fallbacks, the clock security system, the self-check's read-back, the failed
//! boots in a row and the safe mode, and what the boot hands the supervisor.

mod model;
mod safe_mode;

use drive_monitor::app::{MonitorStatus, Settings, Supervisor, PANEL_PERIOD_MS};
use drive_monitor::boot_block::{BootBlock, ResetKind};
use drive_monitor::clock::{ClockSource, HSE_STARTUP_TIMEOUT_MS};
use drive_monitor::reset_record::{BootPhase, PreviousRun, ResetRecord};
use drive_monitor::self_check::CheckId;
use drive_monitor::startup::{self, BootFacts, BootNote, SafeModeReason};
use drive_monitor::supply::BorCheck;
use drive_monitor::watchdog::{BOOT_BUDGET_MS, BOOT_SETTING, LSI_MAX_HZ};
use model::{Board, Op, CSSON, DBGMCU_APB1FZR1, DBGMCU_APB2FZR, FLASH_OPTR, IWDGRSTF, RCC_CR};

fn boot(board: &mut Board) -> BootFacts {
    startup::start(board).1
}

/// The freeze (TIM1 bit 11 and TIM15 bit 16 of `DBGMCU_APB2FZR`, the IWDG bit 12 of
/// `DBGMCU_APB1FZR1`, other bits as they were), then the watchdog running with the boot's
/// timeout, both before the reset flags are read and long before `init`.
#[test]
fn the_boot_freezes_the_halt_and_starts_the_watchdog_before_anything_else() {
    let mut board = Board::power_on();
    board.regs.insert(DBGMCU_APB1FZR1, 0x4);
    let facts = boot(&mut board);
    assert_eq!(board.reg(DBGMCU_APB1FZR1), 0x4 | 1 << 12);
    assert_eq!(board.reg(DBGMCU_APB2FZR), 1 << 11 | 1 << 16);
    assert_eq!(board.ops[0], Op::WriteFreeze);
    assert_eq!(board.ops[1], Op::WatchdogRunning);
    assert!(board.position(Op::WatchdogRunning) < board.position(Op::Init));
    // The boot's setting written while unlocked, then a reload.
    assert_eq!(board.iwdg.setting, Some(BOOT_SETTING));
    assert_eq!(board.iwdg.locked_writes, 0);
    assert!(board.iwdg.reloads >= 1);
    // The reload after the new setting reached the LSI domain (3 polls here), not before,
    // and no poll more than that took.
    assert_eq!(board.iwdg.reloads_while_updating, 0);
    assert_eq!((board.iwdg.polls_updating, board.iwdg.polls), (3, 4));
    // An update that never ends: the wait gives up after its bound, then the reload.
    let mut stuck = Board::power_on();
    stuck.iwdg_update_polls = u32::MAX;
    boot(&mut stuck);
    assert_eq!(stuck.iwdg.polls, startup::IWDG_UPDATE_POLLS + 1);
    assert!(BOOT_SETTING.timeout_ms(LSI_MAX_HZ) >= BOOT_BUDGET_MS);
    assert!(facts.findings.is_clean(), "{:?}", facts.findings);
    assert_eq!(facts.clock, Some(ClockSource::Hse));
    assert_eq!(facts.history.kind, ResetKind::PowerOn);
}

/// The boot block is marked with the clock phase before `init` (whose waits have no
/// bound): when `init` hangs and the watchdog resets, the next boot says where.
#[test]
fn the_clock_phase_is_marked_before_init_and_a_hang_there_is_placed_at_the_next_boot() {
    let mut board = Board::power_on();
    boot(&mut board);
    let at_init = BootBlock::decode(&board.block_at_init.unwrap()).unwrap();
    assert_eq!(at_init.phase, Some(BootPhase::Clock));
    assert!(board.position(Op::BootBlock) < board.position(Op::Init));
    // After `init` the mark moves on.
    let after = BootBlock::decode(&board.boot_block).unwrap();
    assert_eq!(after.phase, Some(BootPhase::Boot));
    // `init` hung: the RAM as it was then, a watchdog reset.
    let mut hung = board.reset(IWDGRSTF);
    hung.boot_block = board.block_at_init.unwrap();
    let next = boot(&mut hung);
    assert_eq!(
        next.previous,
        PreviousRun::WatchdogReset {
            phase: Some(BootPhase::Clock)
        }
    );
    assert_eq!(next.history.failed_boots, 1);
    assert!(next
        .notes()
        .any(|n| n == BootNote::PreviousRun(next.reset_source, next.previous)));
}

/// `RCC_CR.CSSON` after `init` with the crystal, never on the HSI; read back by the
/// self-check, which finds a write that did not take.
#[test]
fn the_clock_security_system_is_on_with_the_crystal_only_and_read_back() {
    let mut board = Board::power_on();
    let facts = boot(&mut board);
    assert_eq!(board.reg(RCC_CR) & CSSON, CSSON);
    assert!(board.position(Op::Init) < board.position(Op::Css(true)));
    assert!(!facts
        .findings
        .mismatched()
        .any(|c| c == CheckId::ClockSecurity));
    // No crystal: the HSI, no CSS.
    let mut dead = Board::power_on();
    dead.crystal_ready_after_us = None;
    let facts = boot(&mut dead);
    assert_eq!(facts.clock, Some(ClockSource::Hsi));
    assert_eq!(dead.reg(RCC_CR) & CSSON, 0);
    assert!(!dead.ops.contains(&Op::Css(true)));
    // A write that does not take is a finding.
    let mut stuck = Board::power_on();
    stuck.css_stuck_off = true;
    let facts = boot(&mut stuck);
    assert_eq!(
        facts.findings.mismatched().collect::<Vec<_>>(),
        [CheckId::ClockSecurity]
    );
    assert!(facts
        .notes()
        .any(|n| n == BootNote::Mismatch(CheckId::ClockSecurity)));
}

/// A crystal that never starts costs the boot its bound (100 ms), then the HSI; a finding.
/// A clock failure in the previous run keeps the crystal off without trying it.
#[test]
fn a_crystal_that_does_not_start_costs_its_bound_and_is_a_finding() {
    let mut dead = Board::power_on();
    dead.crystal_ready_after_us = None;
    let facts = boot(&mut dead);
    assert!(facts.findings.crystal_did_not_start());
    assert!(!facts.findings.pll_did_not_lock());
    assert_eq!(dead.hse_on_at_us, None, "the crystal switched off again");
    let spent_ms = dead.now_us / 1_000;
    assert!(
        (u64::from(HSE_STARTUP_TIMEOUT_MS)..u64::from(HSE_STARTUP_TIMEOUT_MS) + 5)
            .contains(&spent_ms),
        "{spent_ms} ms"
    );
    assert_eq!(dead.init_with, Some(Some(ClockSource::Hsi)));
    // A crystal that starts in 2 ms costs 2 ms, the PLL's lock and its switch-off some tens
    // of microseconds; `init` finds the PLL off (`PLLRDY` clear), as it expects to.
    let mut good = Board::power_on();
    boot(&mut good);
    assert!(good.now_us < 2_200, "{} us", good.now_us);
    assert!(!good.pll_ready_at_init);
    // The clock security system's record: the crystal is not tried again.
    let mut after_failure = good.reset(IWDGRSTF);
    after_failure.reset_ram = ResetRecord::clock_failure().encode();
    let facts = boot(&mut after_failure);
    assert_eq!(facts.clock, Some(ClockSource::HsiAfterFailure));
    assert_eq!(after_failure.hse_on_at_us, None);
    assert_eq!(after_failure.reg(RCC_CR) & CSSON, 0);
}

/// A PLL that does not lock from the crystal: bounded, then the HSI (a finding); one that
/// locks from neither: the safe mode on the reset clock.
#[test]
fn a_pll_that_does_not_lock_falls_back_to_the_hsi_and_from_neither_to_the_safe_mode() {
    let mut board = Board::power_on();
    board.pll_from_hse_us = None;
    let facts = boot(&mut board);
    assert_eq!(facts.clock, Some(ClockSource::Hsi));
    assert!(facts.findings.pll_did_not_lock() && !facts.findings.crystal_did_not_start());
    assert_eq!(board.init_with, Some(Some(ClockSource::Hsi)));
    assert!(board.now_us < 10_000, "bounded: {} us", board.now_us);
    let mut neither = Board::power_on();
    neither.pll_from_hse_us = None;
    neither.pll_from_hsi_us = None;
    let facts = boot(&mut neither);
    assert_eq!(facts.safe_mode, Some(SafeModeReason::PllDidNotLock));
    assert_eq!((facts.clock, neither.init_with), (None, Some(None)));
    assert!(facts
        .notes()
        .any(|n| n == BootNote::SafeMode(SafeModeReason::PllDidNotLock)));
}

/// The previous run's stack overflow, the failed boots in a row and the self-check's
/// findings are in the boot's notes (what the firmware logs), in order.
#[test]
fn the_stack_overflow_and_the_findings_are_in_the_boots_notes() {
    let mut board = Board::power_on();
    boot(&mut board);
    let mut next = board.reset(IWDGRSTF);
    next.painted = true;
    next.stack_overflowed = true;
    next.regs.insert(FLASH_OPTR, model::OPTR_GOOD & !(1 << 25));
    let facts = boot(&mut next);
    assert!(facts.stack_overflowed);
    let notes: Vec<BootNote> = facts.notes().collect();
    assert_eq!(notes[0], BootNote::Clock(Some(ClockSource::Hse)));
    assert!(notes.contains(&BootNote::StackOverflowed), "{notes:?}");
    assert!(notes.contains(&BootNote::Mismatch(CheckId::CcmSramKept)));
    assert!(notes.contains(&BootNote::BrownOut(BorCheck::of_optr(model::OPTR_GOOD))));
    // Painted now: the next boot finds no overflow.
    let mut third = next.reset(IWDGRSTF);
    third.painted = next.painted;
    assert!(!boot(&mut third)
        .notes()
        .any(|n| n == BootNote::StackOverflowed));
}

/// What the supervisor's panel marks comes from the boot: the clock on the HSI (RUN lit
/// from 5 s to 7 s of every 10 s) and the brown-out level below the goal (from 2.5 s to
/// 4.5 s).
#[test]
fn the_supervisor_marks_the_hsi_and_a_brown_out_level_below_the_goal() {
    let run_lamp = |facts: &BootFacts| {
        let mut s = Supervisor::new(
            &Settings::DEFAULT,
            PreviousRun::Clean,
            0,
            MonitorStatus::default(),
        );
        facts.configure(&mut s);
        (0..200u32)
            .map(|k| {
                let status = MonitorStatus {
                    samples: (k + 1) * 500,
                    ..MonitorStatus::default()
                };
                s.tick(k * PANEL_PERIOD_MS, Some(status), false).lamps.run
            })
            .collect::<Vec<bool>>()
    };
    let good = boot(&mut Board::power_on());
    let mut low = Board::power_on();
    low.regs.insert(FLASH_OPTR, 0xFFEF_F8AA);
    low.crystal_ready_after_us = None;
    let low = boot(&mut low);
    assert!(!low.bor.allows_flash_writes());
    assert!(low
        .findings
        .mismatched()
        .any(|c| c == CheckId::BrownOutLevel));
    let (plain, marked) = (run_lamp(&good), run_lamp(&low));
    // Ticks of 50 ms: 2.5..4.5 s is ticks 50..90, 5..7 s ticks 100..140.
    assert!(marked[50..90].iter().all(|on| *on), "{marked:?}");
    assert!(marked[100..140].iter().all(|on| *on), "{marked:?}");
    assert!(!plain[50..90].iter().all(|on| *on));
    assert!(!plain[100..140].iter().all(|on| *on));
}
