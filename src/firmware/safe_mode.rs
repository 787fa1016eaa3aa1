//! The safe mode on the board (`drive_monitor::startup::SafeModeReason`): after failed
//! boots in a row, or a PLL that locks from no source, the firmware does not try again. On
//! the reset clock (the 16 MHz HSI, no PLL) it says why (the boot report on the virtual COM
//! port), then blinks the reason's code on the FAULT lamp (`PanelLamps::safe_mode`) and pets
//! the watchdog: a board that stays in the safe mode until a person presses the reset
//! button or cycles the power, instead of resetting for ever. Nothing is sampled, and no
//! flash is touched: the reset log's scan, which a boot loop might come from, is not run
//! (`tests/firmware/boot_bookkeeping.rs` holds this file to that); the boot is counted in the boot
//! block's RAM, which the next run writes to the log.

use drive_monitor::app::PANEL_PERIOD_MS;
use drive_monitor::board::pins::Board;
use drive_monitor::panel::PanelLamps;
use drive_monitor::startup::{BootFacts, SafeModeReason};
use embassy_time::{Duration, Instant, Timer};

use super::{reset_ram, start_watchdog, vcp, PanelPins};

/// The safe mode (module docs), for ever.
pub(super) async fn run(
    p: embassy_stm32::Peripherals,
    facts: &BootFacts,
    reason: SafeModeReason,
) -> ! {
    let b = Board::take(p);
    let mut wdg = start_watchdog(b.iwdg);
    let mut lamps = PanelPins::new(b.lamps);
    if !reset_ram::count_safe_mode(facts) {
        defmt::warn!("reset log: the safe mode's boot not counted (the counts in RAM are full)");
    }
    vcp::report_safe_mode(b.vcp, facts);
    let start = Instant::now();
    let period = Duration::from_millis(u64::from(PANEL_PERIOD_MS));
    loop {
        let t_ms = start.elapsed().as_millis() as u32;
        lamps.show(&PanelLamps::safe_mode(reason.code(), t_ms));
        wdg.pet();
        Timer::after(period).await;
    }
}
