//! The boot report on the ST-LINK's virtual COM port (USART2 TX on PA2, 115 200 8N1) and the
//! reset log in flash (`drive_monitor::reset_record::log`, `drive_monitor::boot_report`): what a technician
//! reads without a probe.

use defmt::error;
use drive_monitor::boot_report as report;
use drive_monitor::reset_record::log;
use drive_monitor::startup::BootFacts;
use embassy_stm32::usart::{Config as UsartConfig, UartTx};
use embassy_stm32::{peripherals, Peri};

use super::flash::{BoardFlash, LogPages};
use super::{logs, reset_ram};

/// The record a technician reads without a probe: the boot's item in the reset log in flash
/// (`log::record_boot`: a full entry for a failed run within the rate limit, else a count,
/// kept in the boot block's RAM until its write is due; refused below the brown-out goal;
/// before sampling starts, so an erase holds nothing up),
/// then the boot report, the self-check's findings, the safe mode, the log's counts and its
/// four newest entries as text on the ST-LINK's virtual COM port (USART2 TX on PA2,
/// 115 200 8N1; `drive_monitor::boot_report`).
pub(super) fn report_boot(
    flash: &mut BoardFlash,
    (usart, tx): (
        Peri<'static, peripherals::USART2>,
        Peri<'static, peripherals::PA2>,
    ),
    facts: &BootFacts,
) {
    let mut pages = LogPages {
        flash,
        bor: facts.bor,
    };
    let boot = log::BootRecord {
        previous: facts.previous,
        source: facts.reset_source,
        kind: facts.history.kind,
        previous_long_up: facts.history.previous_long_up,
        previous_up: facts.history.previous_up,
        ram_kept: facts.history.ram_kept,
        safe_mode: false,
    };
    let mut pending = facts.history.pending;
    logs::log_reset_log(log::record_boot(&mut pages, &boot, &mut pending));
    reset_ram::set_pending(pending);
    let Ok(mut vcp) = UartTx::new_blocking(usart, tx, UsartConfig::default()) else {
        error!("virtual COM port: USART2 not configured: no boot report there");
        return;
    };
    let head = report::head_lines(env!("CARGO_PKG_VERSION"), facts);
    let totals = report::totals_line(&pending.added_to(log::totals(&mut pages)));
    let waiting = report::pending_line(pending.count());
    let mut lines = head
        .into_iter()
        .flatten()
        .chain([totals])
        .chain(waiting)
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

/// The safe mode's report on the virtual COM port (`report::safe_mode_report`): the boot
/// line, the previous run, the findings, the safe mode's line and that the reset log is not
/// read. No flash is touched: the safe mode does not depend on the log's scan.
pub(super) fn report_safe_mode(
    (usart, tx): (
        Peri<'static, peripherals::USART2>,
        Peri<'static, peripherals::PA2>,
    ),
    facts: &BootFacts,
) {
    let Ok(mut vcp) = UartTx::new_blocking(usart, tx, UsartConfig::default()) else {
        error!("virtual COM port: USART2 not configured: no boot report there");
        return;
    };
    let lines = report::safe_mode_report(env!("CARGO_PKG_VERSION"), facts);
    if lines
        .iter()
        .flatten()
        .try_for_each(|l| vcp.blocking_write(l.as_bytes()))
        .is_err()
    {
        error!("virtual COM port: write failed");
    }
    let _ = vcp.blocking_flush();
}
