//! The safe mode on the board (`drive_monitor::startup::SafeModeReason`): after failed
//! boots in a row, or a PLL that locks from no source, the firmware does not try again. On
//! the reset clock (the 16 MHz HSI, no PLL) it records why (the reset log in flash, the
//! boot report on the virtual COM port), then blinks the reason's code on the FAULT lamp
//! (`PanelLamps::safe_mode`) and pets the watchdog: a board that stays in the safe mode
//! until a person presses the reset button or cycles the power, instead of resetting for
//! ever. Nothing is sampled.

use drive_monitor::app::PANEL_PERIOD_MS;
use drive_monitor::board::pins::Board;
use drive_monitor::flash_ecc::CheckedFlash;
use drive_monitor::panel::PanelLamps;
use drive_monitor::startup::{BootFacts, SafeModeReason};
use embassy_stm32::flash::Flash;
use embassy_time::{Duration, Instant, Timer};

use super::flash::{BoardFlash, Driver};
use super::{dual_bank_flash, start_watchdog, vcp, PanelPins};

/// The safe mode (module docs), for ever.
pub(super) async fn run(
    p: embassy_stm32::Peripherals,
    facts: &BootFacts,
    reason: SafeModeReason,
) -> ! {
    let b = Board::take(p);
    let mut wdg = start_watchdog(b.iwdg);
    let mut lamps = PanelPins::new(b.lamps);
    let flash = dual_bank_flash().then(|| Flash::new_blocking(b.flash));
    let mut flash = BoardFlash(CheckedFlash::new(Driver(flash)));
    vcp::report_boot(&mut flash, b.vcp, facts);
    let start = Instant::now();
    let period = Duration::from_millis(u64::from(PANEL_PERIOD_MS));
    loop {
        let t_ms = start.elapsed().as_millis() as u32;
        lamps.show(&PanelLamps::safe_mode(reason.code(), t_ms));
        wdg.pet();
        Timer::after(period).await;
    }
}
