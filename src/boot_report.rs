//! The boot report as plain text for the ST-LINK's virtual COM port (USART2, PA2, 115 200
//! baud 8N1 on the NUCLEO-G474RE): a technician without a probe reads why the board
//! reset, the brown-out level, the clock and the reset log's newest entries with any
//! terminal. Built without `core::fmt` (no float or generic formatting pulled into the
//! firmware): fixed-size lines ([`ReportLine`]) of words and decimal or hexadecimal numbers.

use crate::clock::ClockSource;
use crate::reset_record::log::{Ended, Entry, Totals};
use crate::reset_record::{PreviousRun, ResetCause, ResetKind, ResetRecord, ResetSource};
use crate::self_check::CheckId;
use crate::startup::{BootFacts, SafeModeReason};

/// Bytes of one line at most (longer text is cut).
pub const LINE_LEN: usize = 192;

/// One line of text, `\r\n` ended by [`ReportLine::end`].
#[derive(Clone, Copy, Debug)]
pub struct ReportLine {
    buf: [u8; LINE_LEN],
    len: usize,
}

impl Default for ReportLine {
    fn default() -> Self {
        Self {
            buf: [0; LINE_LEN],
            len: 0,
        }
    }
}

impl ReportLine {
    /// Appends `s` (what does not fit is cut).
    pub fn push(&mut self, s: &str) -> &mut Self {
        for &b in s.as_bytes() {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = b;
                self.len += 1;
            }
        }
        self
    }

    /// Appends `v` in decimal.
    pub fn number(&mut self, v: u32) -> &mut Self {
        let mut digits = [0u8; 10];
        let mut n = 0;
        let mut x = v;
        loop {
            if let Some(d) = digits.get_mut(n) {
                *d = b'0' + (x % 10) as u8;
            }
            n += 1;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        for k in (0..n).rev() {
            let d = digits.get(k).copied().unwrap_or(b'0');
            self.push(core::str::from_utf8(&[d]).unwrap_or("?"));
        }
        self
    }

    /// Appends `v` as `0x` and eight hexadecimal digits.
    pub fn hex(&mut self, v: u32) -> &mut Self {
        self.push("0x");
        for k in 0..8 {
            let nibble = ((v >> (28 - 4 * k)) & 0xF) as u8;
            let d = if nibble < 10 {
                b'0' + nibble
            } else {
                b'A' + nibble - 10
            };
            self.push(core::str::from_utf8(&[d]).unwrap_or("?"));
        }
        self
    }

    /// Ends the line (`\r\n`, as a terminal wants it).
    pub fn end(&mut self) -> &mut Self {
        self.push("\r\n")
    }

    /// The text so far.
    pub fn as_bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

/// A cause's words.
pub fn cause_name(c: ResetCause) -> &'static str {
    match c {
        ResetCause::Panic => "a panic",
        ResetCause::SampleStall => "a stalled sample path",
        ResetCause::SetupTimeout => "a set-up that did not finish",
        ResetCause::DefmtPanic => "a defmt panic",
        ResetCause::HardFault => "a hard fault",
        ResetCause::SetupDeadline => "a set-up step past its deadline",
        ResetCause::ClockFailure => "a clock failure",
    }
}

/// `record`'s cause, message, file and number.
fn push_record(line: &mut ReportLine, r: &ResetRecord) {
    line.push(cause_name(r.cause()));
    line.push(": ").push(r.message());
    if !r.file().is_empty() {
        line.push(" ").push(r.file());
    }
    match r.cause() {
        ResetCause::HardFault | ResetCause::DefmtPanic => {
            line.push(" at ").hex(r.line_or_ms());
        }
        _ => {
            line.push(" (").number(r.line_or_ms()).push(")");
        }
    }
}

/// The boot's first line: `drive-monitor VERSION boot: reset by SOURCE, brown-out level N,
/// clock NAME`.
pub fn boot_line(version: &str, source: ResetSource, bor: u8, clock: &str) -> ReportLine {
    let mut l = ReportLine::default();
    l.push("drive-monitor ")
        .push(version)
        .push(" boot: reset by ");
    l.push(source.name())
        .push(", brown-out level ")
        .number(u32::from(bor));
    l.push(", clock ").push(clock).end();
    l
}

/// The previous run's end as the boot read it.
pub fn previous_line(previous: &PreviousRun) -> ReportLine {
    let mut l = ReportLine::default();
    l.push("previous run: ");
    match previous {
        PreviousRun::Clean => {
            l.push("no failure recorded");
        }
        PreviousRun::WatchdogReset { phase } => {
            l.push("watchdog reset with no reason recorded (the firmware hung");
            if let Some(p) = phase {
                l.push(" in its ").push(p.name()).push(" phase");
            }
            l.push(")");
        }
        PreviousRun::Recorded(r) => {
            l.push("ended in ");
            push_record(&mut l, r);
        }
        PreviousRun::ResetDuring { record, source } => {
            push_record(&mut l, record);
            l.push(", then a ").push(source.name()).push(" reset");
        }
    }
    l.end();
    l
}

/// One entry of the reset log: `log #SEQ: reset by SOURCE: ...`.
pub fn entry_line(e: &Entry) -> ReportLine {
    let mut l = ReportLine::default();
    l.push("log #")
        .number(e.seq)
        .push(": reset by ")
        .push(e.source.name())
        .push(": ");
    match (e.ended, &e.record) {
        (Ended::WatchdogReset, _) | (_, None) => {
            l.push("watchdog reset with no reason recorded");
            if let Some(p) = e.phase {
                l.push(" (hung in its ").push(p.name()).push(" phase)");
            }
        }
        (Ended::Recorded, Some(r)) => push_record(&mut l, r),
        (Ended::ResetDuring, Some(r)) => {
            push_record(&mut l, r);
            l.push(", another reset came first");
        }
    }
    if e.safe_mode {
        l.push("; safe mode");
    }
    l.end();
    l
}

/// The log's counts: `resets: power-on N, brown-out N, reset button N, watchdog N, software
/// N, other N; up 10 min N; failed runs counted, not entered N; safe mode N`.
pub fn totals_line(t: &Totals) -> ReportLine {
    let mut l = ReportLine::default();
    l.push("resets:");
    for (k, kind) in ResetKind::ALL.iter().enumerate() {
        l.push(if k == 0 { " " } else { ", " })
            .push(kind.name())
            .push(" ")
            .number(t.resets(*kind));
    }
    l.push("; up 10 min ").number(t.ups());
    l.push("; failed runs counted, not entered ")
        .number(t.failed_not_entered);
    l.push("; safe mode ").number(t.safe_modes).end();
    l
}

/// `reset log: N resets counted in RAM, not yet written` when `n` > 0 (the totals above
/// include them; `log::Pending`).
pub fn pending_line(n: u32) -> Option<ReportLine> {
    let mut l = ReportLine::default();
    l.push("reset log: ")
        .number(n)
        .push(" resets counted in RAM, not yet written")
        .end();
    (n > 0).then_some(l)
}

/// `head` and the `items`, comma separated (the self-check's findings: `self-check: did not
/// take: RCC_CR.CSSON, FLASH_OPTR.BOR_LEV`); `None` without items.
pub fn list_line<'a>(head: &str, items: impl Iterator<Item = &'a str>) -> Option<ReportLine> {
    let mut l = ReportLine::default();
    l.push(head);
    let mut any = false;
    for item in items {
        if any {
            l.push(", ");
        }
        l.push(item);
        any = true;
    }
    l.end();
    any.then_some(l)
}

/// The safe mode's line: `SAFE MODE (code N): WHY; not monitoring; press the reset button to
/// try again`.
pub fn safe_mode_line(code: u8, why: &str) -> ReportLine {
    let mut l = ReportLine::default();
    l.push("SAFE MODE (code ")
        .number(u32::from(code))
        .push("): ")
        .push(why)
        .push("; not monitoring; press the reset button to try again")
        .end();
    l
}

/// The report's first lines for a boot that found `facts` (firmware `version`): the boot
/// line (the reset's source, the brown-out level, the clock), the previous run's end, the
/// self-check's findings and the safe mode's line (the last two when there are any).
pub fn head_lines(version: &str, facts: &BootFacts) -> [Option<ReportLine>; 4] {
    let clock = match facts.clock {
        Some(ClockSource::Hse) => "24 MHz crystal (HSE)",
        Some(_) => "internal oscillator (HSI, +-1 %)",
        None => "16 MHz reset clock (safe mode)",
    };
    let findings = list_line(
        "self-check: did not take: ",
        facts.findings.mismatched().map(CheckId::name),
    );
    let safe = facts.safe_mode.map(|reason| {
        let why = match reason {
            SafeModeReason::BootLoop { .. } => "boots in a row failed before the monitor was up",
            SafeModeReason::PllDidNotLock => "the PLL did not lock",
        };
        safe_mode_line(reason.code(), why)
    });
    [
        Some(boot_line(
            version,
            facts.reset_source,
            facts.bor.status_number(),
            clock,
        )),
        Some(previous_line(&facts.previous)),
        findings,
        safe,
    ]
}

/// The safe mode's report (`facts.safe_mode` set): [`head_lines`], then a line saying the
/// reset log in flash is neither read nor written: the safe mode touches no flash, so a
/// fault in the log's scan (what it would escape) cannot follow it there.
pub fn safe_mode_report(version: &str, facts: &BootFacts) -> [Option<ReportLine>; 5] {
    let [a, b, c, d] = head_lines(version, facts);
    let mut log = ReportLine::default();
    log.push("reset log: not read in the safe mode (this boot is counted in RAM, written by the next run)")
        .end();
    [a, b, c, d, Some(log)]
}
