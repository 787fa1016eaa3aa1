//! The reset log: the last reset records in flash, for a board nobody watched with a
//! probe. The reset record lives in RAM ([`super::ResetRecord`]) and is lost with the
//! supply; at every boot after a failed run (a record, or a watchdog reset with none) the
//! firmware appends what the boot read to this log, two 2 KiB pages of bank 2 below the
//! motor record's (`board::RESET_LOG_FLASH_OFFSET`), 13 entries a page, so the last 13 to
//! 26 ends of a run survive a power loss; the boot prints the newest on the ST-LINK's
//! virtual COM port ([`super::report`]).
//!
//! **An entry** ([`ENTRY_LEN`] = 152 bytes, a multiple of the G4's 8-byte write unit) is
//! a format of the core's one record module ([`monitor_core::record`]: magic `DMRL`,
//! version 1, length, CRC-32): a sequence number, the reset's source, what the boot
//! concluded ([`Ended`]) and the 128-byte reset record as it was in RAM.
//!
//! **Torn writes.** A slot is erased (every byte `0xFF`), valid (its CRC holds) or torn (a
//! write a power loss cut short: neither). The writer appends after the last slot that is
//! not erased, so a torn slot is never written over and never read as an entry; a page
//! whose read fails (an ECC double error in a torn double word, which the checked reads
//! report) counts as full. When the page in use is full, the other page (the older
//! entries) is erased and written from its first slot: the newer page's entries stay.

use super::{PreviousRun, ResetRecord, ResetSource, RESET_RECORD_LEN};
use monitor_core::record::{RecordFormat, RecordLayout};

/// Bytes of one entry (header, payload, CRC; a multiple of 8).
pub const ENTRY_LEN: usize = 152;
/// Bytes of a log page (the G4's page in dual-bank mode).
pub const PAGE_LEN: usize = 2048;
/// Entries a page holds.
pub const SLOTS_PER_PAGE: usize = PAGE_LEN / ENTRY_LEN;
/// Pages of the log.
pub const PAGES: usize = 2;

/// The entry's format: magic `DMRL`, version 1, [`ENTRY_LEN`] bytes.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMRL",
    current: RecordLayout {
        version: 1,
        stored_len: ENTRY_LEN,
        length: (ENTRY_LEN - 12) as u16,
    },
    older: &[],
};

/// How the previous run ended, as the boot concluded ([`PreviousRun`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    /// A record says why (`PreviousRun::Recorded`).
    Recorded,
    /// The watchdog reset the MCU and nothing recorded why: a hang.
    WatchdogReset,
    /// A stall or set-up record, then another reset before the watchdog's.
    ResetDuring,
}

/// One entry of the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Its place in the log (1, 2, ...; the newest has the highest).
    pub seq: u32,
    /// What reset the MCU.
    pub source: ResetSource,
    /// How the run ended.
    pub ended: Ended,
    /// The reset record (`None` for a watchdog reset with no record).
    pub record: Option<ResetRecord>,
}

impl Entry {
    /// What the log keeps of the previous run as the boot read it (`None` for a clean one,
    /// which is not logged).
    pub fn of(previous: &PreviousRun) -> Option<(Ended, Option<ResetRecord>)> {
        match *previous {
            PreviousRun::Clean => None,
            PreviousRun::Recorded(r) => Some((Ended::Recorded, Some(r))),
            PreviousRun::WatchdogReset => Some((Ended::WatchdogReset, None)),
            PreviousRun::ResetDuring { record, .. } => Some((Ended::ResetDuring, Some(record))),
        }
    }

    /// The stored bytes.
    pub fn encode(&self) -> [u8; ENTRY_LEN] {
        let mut w = FORMAT.writer::<ENTRY_LEN>();
        w.u32(self.seq);
        w.u8(source_code(self.source));
        w.u8(match self.ended {
            Ended::Recorded => 1,
            Ended::WatchdogReset => 2,
            Ended::ResetDuring => 3,
        });
        w.bytes(&[0; 2]);
        w.bytes(&self.record.map_or([0; RESET_RECORD_LEN], |r| r.encode()));
        w.bytes(&[0; 4]);
        w.finish()
    }

    /// The entry in `bytes`, or `None` (erased, torn, another format).
    pub fn decode(bytes: &[u8]) -> Option<Entry> {
        let mut r = FORMAT.open(bytes).ok()?;
        let seq = r.u32().ok()?;
        let source = source_of(r.u8().ok()?);
        let ended = match r.u8().ok()? {
            1 => Ended::Recorded,
            2 => Ended::WatchdogReset,
            3 => Ended::ResetDuring,
            _ => return None,
        };
        r.take::<2>().ok()?;
        let record = ResetRecord::decode(&r.take::<RESET_RECORD_LEN>().ok()?);
        Some(Entry {
            seq,
            source,
            ended,
            record,
        })
    }
}

/// A reset source's byte in an entry.
fn source_code(s: ResetSource) -> u8 {
    match s {
        ResetSource::IndependentWatchdog => 1,
        ResetSource::WindowWatchdog => 2,
        ResetSource::Software => 3,
        ResetSource::OptionBytes => 4,
        ResetSource::LowPower => 5,
        ResetSource::PowerOnOrBrownOut => 6,
        ResetSource::Pin => 7,
        ResetSource::Unknown => 0,
    }
}

/// The reset source of an entry's byte.
fn source_of(code: u8) -> ResetSource {
    match code {
        1 => ResetSource::IndependentWatchdog,
        2 => ResetSource::WindowWatchdog,
        3 => ResetSource::Software,
        4 => ResetSource::OptionBytes,
        5 => ResetSource::LowPower,
        6 => ResetSource::PowerOnOrBrownOut,
        7 => ResetSource::Pin,
        _ => ResetSource::Unknown,
    }
}

/// The log's two flash pages: the board's flash (checked reads, erases and writes refused
/// below the brown-out goal), a byte array in the host tests.
pub trait LogFlash {
    /// A failed read, erase or write.
    type Error;
    /// Reads `buf.len()` bytes at `offset` of page `page` (0 or 1).
    ///
    /// # Errors
    /// When the read fails (an ECC double error in a torn double word among others).
    fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), Self::Error>;
    /// Erases page `page`.
    ///
    /// # Errors
    /// When the erase fails or is refused.
    fn erase(&mut self, page: usize) -> Result<(), Self::Error>;
    /// Writes `bytes` at `offset` of page `page` (erased there).
    ///
    /// # Errors
    /// When the write fails or is refused.
    fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), Self::Error>;
}

/// What a page holds: its valid entries' newest sequence number and the first slot after
/// its last written one (`SLOTS_PER_PAGE`: full, or unreadable from there).
#[derive(Clone, Copy, Debug, Default)]
struct PageScan {
    newest: Option<u32>,
    next_free: usize,
}

/// Scans page `page`, calling `each` on its valid entries.
fn scan<F: LogFlash>(flash: &mut F, page: usize, mut each: impl FnMut(Entry)) -> PageScan {
    let mut out = PageScan::default();
    for slot in 0..SLOTS_PER_PAGE {
        let mut buf = [0u8; ENTRY_LEN];
        if flash.read(page, slot * ENTRY_LEN, &mut buf).is_err() {
            // Unreadable from here (a torn double word's ECC error): the page is full.
            out.next_free = SLOTS_PER_PAGE;
            return out;
        }
        if buf.iter().all(|b| *b == 0xFF) {
            continue;
        }
        out.next_free = slot + 1;
        if let Some(e) = Entry::decode(&buf) {
            out.newest = out.newest.max(Some(e.seq));
            each(e);
        }
    }
    out
}

/// Appends the previous run's end (`ended`, `record`) after a reset by `source` to the log
/// in `flash` (module docs: after the newest entry's slot, or in the other page, erased,
/// when that page is full). Returns the entry written.
///
/// # Errors
/// The flash's error when the erase or the write failed (or was refused).
pub fn append<F: LogFlash>(
    flash: &mut F,
    source: ResetSource,
    ended: Ended,
    record: Option<ResetRecord>,
) -> Result<Entry, F::Error> {
    let pages = [scan(flash, 0, |_| {}), scan(flash, 1, |_| {})];
    let [p0, p1] = pages;
    // The page in use holds the newest entry (page 0 on an empty log).
    let current = usize::from(p1.newest > p0.newest);
    let newest = p0.newest.max(p1.newest).unwrap_or(0);
    let at = if current == 0 { p0 } else { p1 };
    let (page, slot) = if at.next_free < SLOTS_PER_PAGE {
        (current, at.next_free)
    } else {
        let other = 1 - current;
        flash.erase(other)?;
        (other, 0)
    };
    let entry = Entry {
        seq: newest.wrapping_add(1),
        source,
        ended,
        record,
    };
    flash.write(page, slot * ENTRY_LEN, &entry.encode())?;
    Ok(entry)
}

/// The newest `N` entries of the log, newest first (fewer when the log holds fewer).
pub fn newest<F: LogFlash, const N: usize>(flash: &mut F) -> ([Option<Entry>; N], usize) {
    let mut out: [Option<Entry>; N] = [None; N];
    for page in 0..PAGES {
        scan(flash, page, |e| {
            // Insert keeping the newest first, the oldest dropped.
            let mut carry = Some(e);
            for slot in out.iter_mut() {
                match (carry, *slot) {
                    (Some(c), Some(s)) if c.seq > s.seq => {
                        *slot = Some(c);
                        carry = Some(s);
                    }
                    (Some(c), None) => {
                        *slot = Some(c);
                        carry = None;
                    }
                    _ => {}
                }
            }
        });
    }
    let n = out.iter().filter(|e| e.is_some()).count();
    (out, n)
}
