//! Why the previous run ended: a small record in RAM that survives a reset.
//!
//! The panic handler (and thread mode, when the sample path has stalled long enough that
//! the watchdog is about to reset the MCU) writes a [`ResetRecord`] into a RAM area the
//! start-up code leaves alone (cortex-m-rt's `.uninit` section). The next boot reads it:
//! a valid record (magic, then a CRC-32 over the rest) is logged and shown, then erased;
//! anything else (power-on garbage, an erased record) means "no reason recorded". So a
//! panic, a stalled sample path and a hang without either no longer all read "watchdog
//! reset".
//!
//! The record is read together with the reset flags of `RCC_CSR` ([`ResetSource`]): a
//! stalled sample path or a set-up that did not finish ends in a watchdog reset, so such
//! a record is reported as the cause only after a watchdog reset; after a reset by the
//! button, a brown-out or a power-on the boot says that a stall was recorded and that
//! this other reset came first ([`PreviousRun::ResetDuring`]). A panic ends in a watchdog
//! reset or in the panic handler's software reset (before the watchdog runs); it is
//! reported whatever reset followed.
//!
//! Panics through `defmt::panic!` (the HAL's assertions with its `defmt` feature, the
//! firmware's `defmt::unwrap!`) do not hand their message to the handler (it is in the
//! defmt log); their record names the firmware's [`BootPhase`] at the time and the address
//! the handler was called from ([`ResetRecord::defmt_panic`]).
//!
//! # RecordLayout ([`RESET_RECORD_LEN`] = 128 bytes, little endian, version 3)
//!
//! Header, CRC, reader and writer are the project's one record format
//! ([`monitor_core::record`], [`FORMAT`]); the length field holds the payload's bytes (116).
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `b"DMRR"` |
//! | 4..6 | version, `u16` (3) |
//! | 6..8 | payload length, `u16` (116) |
//! | 8 | cause: 1 = panic, 2 = sample path stalled, 3 = a set-up step did not finish, 4 = a `defmt` panic, 5 = a HardFault or an unhandled exception, 6 = a set-up step overran its deadline, 7 = the crystal failed (clock security system) |
//! | 9 | message length (0..=[`MESSAGE_LEN`]) |
//! | 10 | file length (0..=[`FILE_LEN`]) |
//! | 11 | the brown-out reset level in force when the record was written (`FLASH_OPTR.BOR_LEV`, 0..=4; 255 = not recorded; [`crate::supply::BorLevel`]) |
//! | 12..16 | line (panic), stall time in ms (stall), phase (set-up), return address (`defmt` panic), stacked PC (HardFault), deadline in ms (set-up deadline), `u32` |
//! | 16..20 | the run's self-check findings (`crate::self_check::Findings`: a bit for each register that did not hold what the firmware wrote, and for a clock that fell back), `u32` |
//! | 20..84 | message, UTF-8, zero padded |
//! | 84..124 | file (the end of the path), UTF-8, zero padded |
//! | 124..128 | CRC-32/ISO-HDLC of bytes 0..124 ([`monitor_core::record::crc32`]) |
//!
//! Versions 1 (no version and length fields, the cause at byte 4, a 48-byte file) and 2
//! (no findings, a 44-byte file) are not read: the record lives in RAM across one reset of
//! the same firmware, so a record of a former layout can only be met once, right after
//! flashing this one, and then reads as "no reason recorded" (its header is not this
//! format's).

use crate::supply::BorLevel;
use monitor_core::record::{RecordFormat, RecordLayout, CRC_LEN, HEADER_LEN};

/// Encoded length of a record, bytes.
pub const RESET_RECORD_LEN: usize = 128;
/// Longest message kept, bytes (longer ones are cut at a character boundary).
pub const MESSAGE_LEN: usize = 64;
/// Longest file path kept, bytes (longer paths keep their end: the file name).
pub const FILE_LEN: usize = 40;
/// The byte of a record that holds no brown-out level.
const NO_BOR_LEVEL: u8 = 0xFF;

/// The reset record's format: magic `DMRR`, version 3, [`RESET_RECORD_LEN`] bytes.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMRR",
    current: RecordLayout {
        version: 3,
        stored_len: RESET_RECORD_LEN,
        length: (RESET_RECORD_LEN - HEADER_LEN - CRC_LEN) as u16,
    },
    older: &[],
};
// The fields fill the payload: 4 bytes of cause and lengths, the number, the findings,
// the texts.
const _: () = assert!(HEADER_LEN + 12 + MESSAGE_LEN + FILE_LEN + CRC_LEN == RESET_RECORD_LEN);

/// What ended the previous run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetCause {
    /// A panic: the message and where it was raised.
    Panic,
    /// No samples arrived and the restarts did not help; the watchdog reset the MCU.
    SampleStall,
    /// A set-up step (its [`BootPhase`] in the message) did not finish before the watchdog
    /// reset the MCU: the HAL's set-up waits on registers without a bound, so the record is
    /// written before the step and cleared after it ([`ResetRecord::setup`]).
    SetupTimeout,
    /// A panic through `defmt::panic!` (the HAL, `defmt::unwrap!`): the [`BootPhase`] in the
    /// message, the address the panic handler was called from in the number.
    DefmtPanic,
    /// A HardFault (or an exception or interrupt without a handler): the faulting
    /// instruction's address (the stacked PC) in the number, the stacked LR and the fault
    /// status registers (`CFSR`, `HFSR`, `BFAR`) in the message, as hexadecimal text
    /// ([`ResetRecord::hard_fault`]).
    HardFault,
    /// A set-up step of the ADCs did not finish within its deadline
    /// ([`crate::setup_guard::SETUP_DEADLINE_MS`]): the set-up guard wrote the step's name
    /// into the message and the deadline into the number, then reset the MCU by software
    /// ([`ResetRecord::setup_deadline`]).
    SetupDeadline,
    /// The clock security system saw the crystal (HSE) fail while it clocked the PLL: the
    /// hardware switched to the 16 MHz HSI, the NMI handler wrote this record and the
    /// watchdog reset the MCU; the next boot runs on the HSI without trying the crystal
    /// ([`PreviousRun::clock_failed`]).
    ClockFailure,
}

impl ResetCause {
    /// The record's byte for the cause.
    const fn code(self) -> u8 {
        match self {
            ResetCause::Panic => 1,
            ResetCause::SampleStall => 2,
            ResetCause::SetupTimeout => 3,
            ResetCause::DefmtPanic => 4,
            ResetCause::HardFault => 5,
            ResetCause::SetupDeadline => 6,
            ResetCause::ClockFailure => 7,
        }
    }

    /// The cause of a record's byte.
    const fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(ResetCause::Panic),
            2 => Some(ResetCause::SampleStall),
            3 => Some(ResetCause::SetupTimeout),
            4 => Some(ResetCause::DefmtPanic),
            5 => Some(ResetCause::HardFault),
            6 => Some(ResetCause::SetupDeadline),
            7 => Some(ResetCause::ClockFailure),
            _ => None,
        }
    }

    /// Whether the cause ends in a watchdog reset (and only then is reported as the cause).
    pub const fn ends_in_watchdog_reset(self) -> bool {
        matches!(self, ResetCause::SampleStall | ResetCause::SetupTimeout)
    }
}

/// What the firmware is doing, for a `defmt` panic's record and a set-up step's (the
/// firmware keeps the current phase in a static; [`BootPhase::name`] goes into the record).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BootPhase {
    /// Clocks, the watchdog, the reset record, the motor record.
    Boot,
    /// The flash driver and the records in flash.
    Flash,
    /// The ADCs' set-up: power-up, calibration, enable, the rings.
    AdcSetup,
    /// The sample path runs.
    Sampling,
    /// The acquisition's recovery after an overrun or a DMA error.
    Recovery,
    /// The clock set-up: the crystal's and the PLL's bounded starts, then embassy-stm32's
    /// `init` (whose own waits have no bound).
    Clock,
}

impl BootPhase {
    /// All phases.
    pub const ALL: [BootPhase; 6] = [
        BootPhase::Boot,
        BootPhase::Flash,
        BootPhase::AdcSetup,
        BootPhase::Sampling,
        BootPhase::Recovery,
        BootPhase::Clock,
    ];

    /// The phase's name in logs and records.
    pub const fn name(self) -> &'static str {
        match self {
            BootPhase::Boot => "boot",
            BootPhase::Flash => "flash",
            BootPhase::AdcSetup => "adc-setup",
            BootPhase::Sampling => "sampling",
            BootPhase::Recovery => "recovery",
            BootPhase::Clock => "clock",
        }
    }

    /// The phase's number (its index in [`BootPhase::ALL`]), for a static.
    pub const fn number(self) -> u8 {
        self as u8
    }

    /// The phase of a number (`None` out of range).
    pub fn from_number(n: u8) -> Option<BootPhase> {
        BootPhase::ALL.get(usize::from(n)).copied()
    }
}

/// The record: the cause, a message, and a location (panic) or a duration (stall).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResetRecord {
    cause: ResetCause,
    /// `FLASH_OPTR.BOR_LEV` when written ([`NO_BOR_LEVEL`]: not recorded).
    bor: u8,
    number: u32,
    /// The run's self-check findings (`crate::self_check::Findings`'s bits).
    findings: u32,
    message: Text<MESSAGE_LEN>,
    file: Text<FILE_LEN>,
}

/// Up to `N` bytes of UTF-8 text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Text<const N: usize> {
    bytes: [u8; N],
    len: u8,
}

impl<const N: usize> Text<N> {
    /// `s`, cut to at most `N` bytes at a character boundary: its start, or with
    /// `keep_end` its end.
    fn new(s: &str, keep_end: bool) -> Self {
        let mut from = 0;
        let mut to = s.len();
        if s.len() > N {
            if keep_end {
                from = s.len() - N;
                while !s.is_char_boundary(from) {
                    from += 1;
                }
            } else {
                to = N;
                while !s.is_char_boundary(to) {
                    to -= 1;
                }
            }
        }
        let kept = s.get(from..to).unwrap_or("").as_bytes();
        let mut bytes = [0u8; N];
        for (dst, src) in bytes.iter_mut().zip(kept) {
            *dst = *src;
        }
        Self {
            bytes,
            len: kept.len().min(N) as u8,
        }
    }

    fn from_bytes(bytes: &[u8], len: u8) -> Option<Self> {
        let mut out = Self { bytes: [0; N], len };
        for (dst, src) in out.bytes.iter_mut().zip(bytes) {
            *dst = *src;
        }
        core::str::from_utf8(out.bytes.get(..usize::from(len))?).ok()?;
        Some(out)
    }

    fn as_str(&self) -> &str {
        let bytes = self.bytes.get(..usize::from(self.len)).unwrap_or(&[]);
        core::str::from_utf8(bytes).unwrap_or("")
    }
}

impl ResetRecord {
    /// A panic with `message` at `file`:`line`.
    pub fn panic(message: &str, file: &str, line: u32) -> Self {
        Self {
            cause: ResetCause::Panic,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: line,
            message: Text::new(message, false),
            file: Text::new(file, true),
        }
    }

    /// The record a panic with `message` (`None`: a formatted message, which is not kept:
    /// formatting would pull `core::fmt` into the firmware) at `location` (file, line)
    /// leaves in the reset record's RAM: what the panic handler writes, and what the next
    /// boot reports ([`PreviousRun::at_boot`]).
    pub fn on_panic(message: Option<&str>, location: Option<(&str, u32)>) -> Self {
        let (file, line) = location.unwrap_or(("?", 0));
        Self::panic(message.unwrap_or("(formatted message)"), file, line)
    }

    /// A panic through `defmt::panic!` in `phase`, the handler called from `return_address`
    /// (look it up with `addr2line -e` on the ELF; the message is in the defmt log).
    pub fn defmt_panic(phase: BootPhase, return_address: u32) -> Self {
        Self {
            cause: ResetCause::DefmtPanic,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: return_address,
            message: Text::new(phase.name(), false),
            file: Text::new("", true),
        }
    }

    /// A HardFault (`exception` "hard fault"; or "exception N" for an exception or
    /// interrupt without a handler, `irqn` its number) at the stacked `pc`, with the
    /// stacked `lr` and the fault status registers `cfsr`, `hfsr`, `bfar` (ARMv7-M ARM
    /// B3.2.15-B3.2.18) written into the message as `lr=0x........ cfsr=0x........
    /// hfsr=0x........ bfar=0x........` (hexadecimal digits, no formatting machinery: the
    /// handler runs in any state). Look the PC up with `addr2line -e` on the ELF.
    pub fn hard_fault(
        irqn: Option<i16>,
        pc: u32,
        lr: u32,
        cfsr: u32,
        hfsr: u32,
        bfar: u32,
    ) -> Self {
        let mut message = [0u8; 61];
        for (k, (name, v)) in [
            ("lr=0x", lr),
            (" cfsr=0x", cfsr),
            (" hfsr=0x", hfsr),
            (" bfar=0x", bfar),
        ]
        .into_iter()
        .enumerate()
        {
            // Each field: its name (5 or 8 bytes) and 8 digits; fixed places.
            let at = if k == 0 { 0 } else { 13 + 16 * (k - 1) };
            let digits = hex8(v);
            for (dst, src) in message
                .iter_mut()
                .skip(at)
                .zip(name.as_bytes().iter().chain(digits.iter()))
            {
                *dst = *src;
            }
        }
        let message = core::str::from_utf8(&message).unwrap_or("");
        // The exception's number in decimal (-15..=255), or "hard fault".
        let mut file = *b"exception -000";
        let file = match irqn {
            None => "hard fault",
            Some(k) => {
                let v = k.unsigned_abs();
                let sign = if k < 0 { b'-' } else { b' ' };
                let digits = [
                    sign,
                    b'0' + (v / 100 % 10) as u8,
                    b'0' + (v / 10 % 10) as u8,
                    b'0' + (v % 10) as u8,
                ];
                for (dst, src) in file.iter_mut().skip(10).zip(digits) {
                    *dst = src;
                }
                core::str::from_utf8(&file).unwrap_or("exception")
            }
        };
        Self {
            cause: ResetCause::HardFault,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: pc,
            message: Text::new(message, false),
            file: Text::new(file, true),
        }
    }

    /// The record written before a set-up step of `phase` that waits on hardware without
    /// a bound, cleared when it finished: if the step hangs, the watchdog's reset is
    /// reported as that step's timeout.
    pub fn setup(phase: BootPhase) -> Self {
        Self {
            cause: ResetCause::SetupTimeout,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: u32::from(phase.number()),
            message: Text::new(phase.name(), false),
            file: Text::new("", true),
        }
    }

    /// A set-up step named `step` that had not finished when its deadline of `deadline_ms`
    /// ran out (the set-up guard's record, [`crate::setup_guard`]; a software reset
    /// follows).
    pub fn setup_deadline(step: &str, deadline_ms: u32) -> Self {
        Self {
            cause: ResetCause::SetupDeadline,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: deadline_ms,
            message: Text::new(step, false),
            file: Text::new("", true),
        }
    }

    /// The crystal failed while it clocked the PLL (the clock security system's NMI).
    pub fn clock_failure() -> Self {
        Self {
            cause: ResetCause::ClockFailure,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: 0,
            message: Text::new("crystal failed (clock security system)", false),
            file: Text::new("", true),
        }
    }

    /// A stalled sample path, `stalled_ms` without samples when recorded.
    pub fn sample_stall(stalled_ms: u32) -> Self {
        Self {
            cause: ResetCause::SampleStall,
            bor: NO_BOR_LEVEL,
            findings: 0,
            number: stalled_ms,
            message: Text::new("sample path stalled", false),
            file: Text::new("", true),
        }
    }

    /// The cause.
    pub fn cause(&self) -> ResetCause {
        self.cause
    }

    /// The message (possibly cut to [`MESSAGE_LEN`] bytes).
    pub fn message(&self) -> &str {
        self.message.as_str()
    }

    /// The file of a panic (its last [`FILE_LEN`] bytes); empty for a stall.
    pub fn file(&self) -> &str {
        self.file.as_str()
    }

    /// The line of a panic; the time without samples, ms, for a stall; the phase's number
    /// for a set-up timeout; the return address for a `defmt` panic; the stacked PC for a
    /// HardFault; the deadline, ms, for a set-up step that overran it.
    pub fn line_or_ms(&self) -> u32 {
        self.number
    }

    /// The record with the brown-out reset level in force (`FLASH_OPTR.BOR_LEV`, read
    /// when the record is written; `None`: unreadable).
    #[must_use]
    pub fn with_bor_level(mut self, level: Option<BorLevel>) -> Self {
        self.bor = level.map_or(NO_BOR_LEVEL, BorLevel::number);
        self
    }

    /// The record with the run's self-check findings (`crate::self_check::Findings`'s
    /// bits: the registers that did not hold what the firmware wrote, a clock that fell
    /// back), so that the next boot and the reset log say which remedy did not take.
    #[must_use]
    pub fn with_findings(mut self, findings: u32) -> Self {
        self.findings = findings;
        self
    }

    /// The run's self-check findings when the record was written (0: none).
    pub fn findings(&self) -> u32 {
        self.findings
    }

    /// The brown-out reset level in force when the record was written (`None`: not
    /// recorded).
    pub fn bor_level(&self) -> Option<BorLevel> {
        BorLevel::from_number(self.bor)
    }

    /// The bytes to keep in RAM (layout in the module docs).
    pub fn encode(&self) -> [u8; RESET_RECORD_LEN] {
        let mut w = FORMAT.writer::<RESET_RECORD_LEN>();
        w.bytes(&[self.cause.code(), self.message.len, self.file.len, self.bor]);
        w.u32(self.number);
        w.u32(self.findings);
        w.bytes(&self.message.bytes);
        w.bytes(&self.file.bytes);
        w.finish()
    }

    /// The record in `bytes`, or `None` when they do not hold one (the record module's
    /// checks: magic, version, length, CRC; then an unknown cause, lengths out of range,
    /// text that is not UTF-8).
    pub fn decode(bytes: &[u8; RESET_RECORD_LEN]) -> Option<Self> {
        let mut r = FORMAT.open(bytes).ok()?;
        let [cause, message_len, file_len, bor] = r.take::<4>().ok()?;
        let cause = ResetCause::from_code(cause)?;
        if usize::from(message_len) > MESSAGE_LEN || usize::from(file_len) > FILE_LEN {
            return None;
        }
        let number = r.u32().ok()?;
        let findings = r.u32().ok()?;
        let message = r.take::<MESSAGE_LEN>().ok()?;
        let file = r.take::<FILE_LEN>().ok()?;
        Some(Self {
            cause,
            bor,
            number,
            findings,
            message: Text::from_bytes(&message, message_len)?,
            file: Text::from_bytes(&file, file_len)?,
        })
    }
}

/// `v` as 8 upper-case hexadecimal digits.
fn hex8(v: u32) -> [u8; 8] {
    let mut out = [b'0'; 8];
    for (k, d) in out.iter_mut().enumerate() {
        let nibble = (v >> (28 - 4 * k)) & 0xF;
        *d = if nibble < 10 {
            b'0' + nibble as u8
        } else {
            b'A' + (nibble as u8 - 10)
        };
    }
    out
}

/// What the previous run ended with, as the boot sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PreviousRun {
    /// A reset with no record and no watchdog reset (power-on, the button, a debugger).
    Clean,
    /// A record says why (a panic, a stalled sample path, a set-up that did not finish).
    Recorded(ResetRecord),
    /// The watchdog reset the MCU and nothing recorded why: the firmware hung.
    WatchdogReset {
        /// The boot phase the run had marked last (the phase mark that survives the reset,
        /// `crate::boot_block`; `None`: not known): a hang in the clock set-up says
        /// `Some(BootPhase::Clock)`.
        phase: Option<BootPhase>,
    },
    /// A record of a stall or an unfinished set-up was written, but `source`, not the
    /// watchdog, reset the MCU before it would have: the condition was seen, it is not
    /// known whether it would have cleared.
    ResetDuring {
        /// The record written (a stall or a set-up).
        record: ResetRecord,
        /// What reset the MCU instead of the watchdog.
        source: ResetSource,
    },
}

impl PreviousRun {
    /// From the record area's bytes and the reset flags' source.
    pub fn at_boot(record: &[u8; RESET_RECORD_LEN], source: ResetSource) -> Self {
        let watchdog = source == ResetSource::IndependentWatchdog;
        match ResetRecord::decode(record) {
            Some(rec) if rec.cause().ends_in_watchdog_reset() && !watchdog => {
                PreviousRun::ResetDuring {
                    record: rec,
                    source,
                }
            }
            Some(rec) => PreviousRun::Recorded(rec),
            None if watchdog => PreviousRun::WatchdogReset { phase: None },
            None => PreviousRun::Clean,
        }
    }

    /// The same, a watchdog reset with no record placed in `phase` (the phase mark the run
    /// left, `None`: not known).
    #[must_use]
    pub fn hung_in(self, phase: Option<BootPhase>) -> Self {
        match self {
            PreviousRun::WatchdogReset { .. } => PreviousRun::WatchdogReset { phase },
            other => other,
        }
    }

    /// The previous run ended in a clock failure (the clock security system's record):
    /// the boot runs on the HSI without trying the crystal again.
    pub fn clock_failed(&self) -> bool {
        matches!(self, PreviousRun::Recorded(r) if r.cause() == ResetCause::ClockFailure)
    }

    /// The previous run failed (the panel shows "monitor failed" for a while): a record or
    /// a watchdog reset; a stall cut short by another reset counts too (it was seen).
    pub fn failed(&self) -> bool {
        !matches!(self, PreviousRun::Clean)
    }
}

pub mod log;

mod source;
pub use source::{ResetKind, ResetSource};
#[cfg(test)]
mod tests;
