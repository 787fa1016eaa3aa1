//! The boot report on the ST-LINK's virtual COM port (USART2 TX on PA2, 115 200 8N1) and the
//! reset log in flash (`drive_monitor::reset_record::{log, report}`): what a technician
//! reads without a probe.

use defmt::error;
use drive_monitor::clock::ClockSource;
use drive_monitor::reset_record::{log, report, PreviousRun, ResetSource};
use drive_monitor::supply::BorCheck;
use embassy_stm32::usart::{Config as UsartConfig, UartTx};
use embassy_stm32::{peripherals, Peri};

use super::flash::{BoardFlash, LogPages};
use super::logs;

/// The record a technician reads without a probe: the previous run's end appended to the
/// reset log in flash (refused below the brown-out goal; before sampling starts, so the
/// erase holds nothing up), then the boot report and the log's four newest entries as text
/// on the ST-LINK's virtual COM port (USART2 TX on PA2, 115 200 8N1;
/// `drive_monitor::reset_record::report`).
pub(super) fn report_boot(
    flash: &mut BoardFlash,
    bor: BorCheck,
    (usart, tx): (
        Peri<'static, peripherals::USART2>,
        Peri<'static, peripherals::PA2>,
    ),
    (previous, reset_source): (PreviousRun, ResetSource),
    source: ClockSource,
) {
    let mut pages = LogPages { flash, bor };
    let appended = log::Entry::of(&previous)
        .map(|(ended, record)| log::append(&mut pages, reset_source, ended, record).map(|e| e.seq));
    logs::log_reset_log(appended);
    let Ok(mut vcp) = UartTx::new_blocking(usart, tx, UsartConfig::default()) else {
        error!("virtual COM port: USART2 not configured: no boot report there");
        return;
    };
    let clock = match source {
        ClockSource::Hse => "24 MHz crystal (HSE)",
        _ => "internal oscillator (HSI, +-1 %)",
    };
    let version = env!("CARGO_PKG_VERSION");
    let bor = bor.status_number();
    let mut lines = [
        report::boot_line(version, reset_source, bor, clock),
        report::previous_line(&previous),
    ]
    .into_iter()
    .chain(
        log::newest::<_, 4>(&mut pages)
            .0
            .into_iter()
            .flatten()
            .map(|e| report::entry_line(&e)),
    );
    if lines
        .try_for_each(|l| vcp.blocking_write(l.as_bytes()))
        .is_err()
    {
        error!("virtual COM port: write failed");
    }
    let _ = vcp.blocking_flush();
}
