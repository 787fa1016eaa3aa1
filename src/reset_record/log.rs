//! The reset log: every reset counted and the ends of failed runs kept in flash, for a
//! board nobody watched with a probe, with its wear bounded for a year of a boot every
//! second.
//!
//! The reset record lives in RAM ([`super::ResetRecord`]) and is lost with the supply. At
//! every boot the firmware counts one item in this log ([`record_boot`]): a **full entry**
//! (152 bytes: a sequence number, the reset's source and kind, how the previous run ended,
//! the 128-byte reset record) for a failed run, or a **count mark** (8 bytes: the reset's
//! kind, a count) for everything else: a power-on, a brown-out, the reset button, and a
//! failed run beyond the rate limit. The boot prints the newest entries and the totals on
//! the ST-LINK's virtual COM port ([`super::report`]).
//!
//! **The rate limit.** Between two "up" marks (a run that sampled for 10 minutes,
//! `crate::liveness::LONG_UP_AFTER_MS`; the next boot writes the mark) at most
//! [`FULL_ENTRIES`] failed runs get a full entry; later ones are counted as marks (their
//! kind, flagged failed). A boot loop therefore writes 8 bytes a boot, whatever fails.
//!
//! **Pages.** [`PAGES`] pages of bank 2 (`board::RESET_LOG_FLASH_OFFSET`), used in turn: a
//! page starts with a header ([`HEADER_LEN`] bytes: its sequence number, the totals of every
//! count and the entries since the last "up" so far, the entry numbering), then items
//! follow, 8-byte aligned. When the page in use is full, the next page in turn is erased and
//! starts with the totals carried over: the counts are never lost with an erased page, the
//! oldest entries are.
//!
//! **Counts wait in RAM.** A count is not written at its boot but kept in RAM that survives
//! the reset ([`Pending`], in the boot block) until its write is due ([`record_boot`]): after
//! a power-on (RAM kept nothing: at once), after a run that was up (10 s of samples), after
//! the safe mode (which touches no flash, [`count_safe_mode`]), when [`FLUSH_AFTER`] boots
//! wait or the slots are full. A boot whose count waits reads no flash.
//!
//! **Wear.** A page holds [`MARKS_PER_PAGE`] (248) marks. A supply chattering at the
//! brown-out threshold ten times a second for a year (RAM kept) is 315 360 000 boots, one
//! mark every 64: 4 927 500 marks, 19 869 page fills over 16 pages, 1 242 erases a page
//! (with four kinds waiting at once, four marks a write, 4 967), within the 10 000 cycles a
//! page survives (DS12288); a count a boot wore it out in 46 days. A power-on's count is
//! written at once: a supply that collapses fully every second wears the log in 1.26 years
//! (31 536 000 marks, 7 948 erases a page).
//!
//! **Torn writes.** An item is 8-byte aligned and written once; a write a power loss cut
//! short leaves a torn item (neither erased nor valid): it is skipped, never read as an
//! entry or a count, never written over; a read that fails (an ECC double error in a torn
//! double word, which the checked reads report) ends the page (full from there). A page
//! whose header is torn or erased is not in use; the next page fill erases it again.

use super::{BootPhase, PreviousRun, ResetKind, ResetRecord, ResetSource, RESET_RECORD_LEN};
use monitor_core::record::{RecordFormat, RecordLayout};

/// Bytes of one entry (header, payload, CRC; a multiple of 8).
pub const ENTRY_LEN: usize = 152;
/// Bytes of a count mark.
pub const MARK_LEN: usize = 8;
/// Bytes of a page's header.
pub const HEADER_LEN: usize = 64;
/// Bytes of a log page (the G4's page in dual-bank mode).
pub const PAGE_LEN: usize = 2048;
/// Pages of the log (`board::LOG_PAGES`, where the flash map places them).
pub const PAGES: usize = crate::board::LOG_PAGES as usize;
// A log page is a record page: the log's pages end where the records begin (`board`).
const _: () = assert!(
    PAGE_LEN as u32 == crate::board::RECORD_PAGE_SIZE,
    "a reset log page must be the records' page size"
);
/// Count marks a page holds.
pub const MARKS_PER_PAGE: usize = (PAGE_LEN - HEADER_LEN) / MARK_LEN;
/// Full entries a page holds.
pub const ENTRIES_PER_PAGE: usize = (PAGE_LEN - HEADER_LEN) / ENTRY_LEN;
/// Failed runs that get a full entry between two "up" marks (module docs).
pub const FULL_ENTRIES: u32 = 4;
/// Counts the log keeps: one for each [`ResetKind`], then the "up" marks.
pub const COUNTS: usize = 7;
/// The count of "up" marks in [`Totals::counts`].
const UP: usize = 6;

/// The entry's format: magic `DMRL`, version 2, [`ENTRY_LEN`] bytes.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMRL",
    current: RecordLayout {
        version: 2,
        stored_len: ENTRY_LEN,
        length: (ENTRY_LEN - 12) as u16,
    },
    older: &[],
};

/// A page header's format: magic `DMLP`, version 1, [`HEADER_LEN`] bytes.
pub const HEADER_FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMLP",
    current: RecordLayout {
        version: 1,
        stored_len: HEADER_LEN,
        length: (HEADER_LEN - 12) as u16,
    },
    older: &[],
};

/// A count mark's tag byte.
const MARK_TAG: u8 = b'C';
/// A mark's flag: the boot entered the safe mode.
const MARK_SAFE_MODE: u8 = 0x80;
/// A mark's flag: the run it counts failed (counted, not entered: the rate limit).
const MARK_FAILED: u8 = 0x40;

// Items stay 8-byte aligned; a page holds the header and 13 entries.
const _: () = assert!(ENTRY_LEN.is_multiple_of(8) && HEADER_LEN.is_multiple_of(8) && MARK_LEN == 8);
const _: () = assert!(ENTRIES_PER_PAGE == 13 && MARKS_PER_PAGE == 248);
const _: () = assert!(COUNTS == ResetKind::ALL.len() + 1);

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
    /// The reset's kind (a power-on told from a brown-out).
    pub kind: ResetKind,
    /// How the run ended.
    pub ended: Ended,
    /// The phase a run that hung had marked last (`None`: not known, or no hang).
    pub phase: Option<BootPhase>,
    /// The boot that wrote it entered the safe mode.
    pub safe_mode: bool,
    /// The reset record (`None` for a watchdog reset with no record).
    pub record: Option<ResetRecord>,
}

impl Entry {
    /// What the log keeps of the previous run as the boot read it (`None` for a clean one,
    /// which is counted, not entered): how it ended, its record, the phase of a hang.
    pub fn of(previous: &PreviousRun) -> Option<(Ended, Option<ResetRecord>, Option<BootPhase>)> {
        match *previous {
            PreviousRun::Clean => None,
            PreviousRun::Recorded(r) => Some((Ended::Recorded, Some(r), None)),
            PreviousRun::WatchdogReset { phase } => Some((Ended::WatchdogReset, None, phase)),
            PreviousRun::ResetDuring { record, .. } => {
                Some((Ended::ResetDuring, Some(record), None))
            }
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
        w.u8(self.kind.index() as u8 | if self.safe_mode { MARK_SAFE_MODE } else { 0 });
        w.u8(self.phase.map_or(0xFF, BootPhase::number));
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
        let kind = r.u8().ok()?;
        let phase = BootPhase::from_number(r.u8().ok()?);
        let record = ResetRecord::decode(&r.take::<RESET_RECORD_LEN>().ok()?);
        Some(Entry {
            seq,
            source,
            kind: *ResetKind::ALL.get(usize::from(kind & 0x0F))?,
            ended,
            phase,
            safe_mode: kind & MARK_SAFE_MODE != 0,
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

/// A count mark: `count` more of `what` (a [`ResetKind`]'s index, or [`UP`]) with its
/// flags.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Mark {
    what: usize,
    count: u16,
    failed: bool,
    safe_mode: bool,
}

impl Mark {
    /// The mark's second byte: what it counts and its flags.
    fn flags_byte(&self) -> u8 {
        self.what as u8
            | (u8::from(self.failed) * MARK_FAILED)
            | (u8::from(self.safe_mode) * MARK_SAFE_MODE)
    }

    fn encode(&self) -> [u8; MARK_LEN] {
        let [c0, c1] = self.count.to_le_bytes();
        let head = [MARK_TAG, self.flags_byte(), c0, c1];
        let [k0, k1, k2, k3] = (!u32::from_le_bytes(head)).to_le_bytes();
        let [h0, h1, h2, h3] = head;
        [h0, h1, h2, h3, k0, k1, k2, k3]
    }

    fn decode(bytes: &[u8; MARK_LEN]) -> Option<Mark> {
        let [h0, h1, h2, h3, k0, k1, k2, k3] = *bytes;
        let head = u32::from_le_bytes([h0, h1, h2, h3]);
        if h0 != MARK_TAG || !head != u32::from_le_bytes([k0, k1, k2, k3]) {
            return None;
        }
        let what = usize::from(h1 & 0x0F);
        (what < COUNTS).then_some(Mark {
            what,
            count: u16::from_le_bytes([h2, h3]),
            failed: h1 & MARK_FAILED != 0,
            safe_mode: h1 & MARK_SAFE_MODE != 0,
        })
    }
}

/// Everything the log has counted since it was first written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Totals {
    /// Resets by kind ([`ResetKind::index`]) and, last, the runs that were up for 10 minutes.
    pub counts: [u32; COUNTS],
    /// Failed runs counted but not entered (beyond the rate limit).
    pub failed_not_entered: u32,
    /// Boots that entered the safe mode.
    pub safe_modes: u32,
    /// Full entries written since the last "up" mark (the rate limit's count).
    pub entries_since_up: u32,
    /// The newest entry's sequence number (0: none yet).
    pub last_entry: u32,
}

impl Totals {
    /// Resets of `kind` counted.
    pub fn resets(&self, kind: ResetKind) -> u32 {
        self.counts.get(kind.index()).copied().unwrap_or(0)
    }

    /// Runs that were up for 10 minutes.
    pub fn ups(&self) -> u32 {
        self.counts.get(UP).copied().unwrap_or(0)
    }

    fn add_mark(&mut self, m: &Mark) {
        if let Some(c) = self.counts.get_mut(m.what) {
            *c = c.wrapping_add(u32::from(m.count));
        }
        if m.what == UP {
            self.entries_since_up = 0;
        }
        if m.failed {
            self.failed_not_entered = self.failed_not_entered.wrapping_add(u32::from(m.count));
        }
        if m.safe_mode {
            self.safe_modes = self.safe_modes.wrapping_add(u32::from(m.count));
        }
    }

    fn add_entry(&mut self, e: &Entry) {
        if let Some(c) = self.counts.get_mut(e.kind.index()) {
            *c = c.wrapping_add(1);
        }
        self.entries_since_up = self.entries_since_up.saturating_add(1);
        self.last_entry = self.last_entry.max(e.seq);
        if e.safe_mode {
            self.safe_modes = self.safe_modes.wrapping_add(1);
        }
    }

    fn encode_header(&self, page_seq: u32) -> [u8; HEADER_LEN] {
        let mut w = HEADER_FORMAT.writer::<HEADER_LEN>();
        w.u32(page_seq);
        w.u32(self.entries_since_up);
        w.u32(self.last_entry);
        w.u32(self.failed_not_entered);
        w.u32(self.safe_modes);
        for c in self.counts {
            w.u32(c);
        }
        w.bytes(&[0; 4]);
        w.finish()
    }

    fn decode_header(bytes: &[u8]) -> Option<(u32, Totals)> {
        let mut r = HEADER_FORMAT.open(bytes).ok()?;
        let page_seq = r.u32().ok()?;
        let mut t = Totals {
            entries_since_up: r.u32().ok()?,
            last_entry: r.u32().ok()?,
            failed_not_entered: r.u32().ok()?,
            safe_modes: r.u32().ok()?,
            ..Totals::default()
        };
        for c in t.counts.iter_mut() {
            *c = r.u32().ok()?;
        }
        Some((page_seq, t))
    }
}

/// The log's pages: the board's flash (checked reads, erases and writes refused below the
/// brown-out goal), byte arrays in the host tests.
pub trait LogFlash {
    /// A failed read, erase or write.
    type Error;
    /// Reads `buf.len()` bytes at `offset` of page `page` (0..[`PAGES`]).
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

/// Slots of counts kept in RAM ([`Pending`]).
pub const PENDING_SLOTS: usize = 4;
/// Bytes of [`Pending`] in the boot block.
pub const PENDING_LEN: usize = 4 * PENDING_SLOTS;
/// Boots counted in RAM after which the boot writes them ([`record_boot`], module docs).
pub const FLUSH_AFTER: u32 = 64;

/// Counts not yet in flash, kept in RAM that survives a reset (the boot block,
/// `crate::boot_block`): up to [`PENDING_SLOTS`] marks, each a reset's kind with its flags
/// and a count. A boot adds its count here instead of writing it ([`record_boot`]) unless
/// something makes the write due; the counts then go to flash together, one mark a slot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pending {
    slots: [Mark; PENDING_SLOTS],
}

impl Pending {
    /// Nothing pending.
    pub const EMPTY: Pending = Pending {
        slots: [Mark {
            what: 0,
            count: 0,
            failed: false,
            safe_mode: false,
        }; PENDING_SLOTS],
    };

    /// One more reset of `kind` (`failed`: the run it follows failed; `safe_mode`: this
    /// boot entered the safe mode), in the slot of the same kind and flags or a free one;
    /// `false` when every slot holds another (nothing counted).
    pub fn add(&mut self, kind: ResetKind, failed: bool, safe_mode: bool) -> bool {
        let what = kind.index();
        let same = |m: &Mark| m.what == what && m.failed == failed && m.safe_mode == safe_mode;
        let slot = match self.slots.iter().position(|m| m.count > 0 && same(m)) {
            Some(i) => self.slots.get_mut(i),
            None => self.slots.iter_mut().find(|m| m.count == 0),
        };
        match slot {
            Some(m) if m.count < u16::MAX => {
                *m = Mark {
                    what,
                    count: m.count + 1,
                    failed,
                    safe_mode,
                };
                true
            }
            _ => false,
        }
    }

    /// The boots counted.
    pub fn count(&self) -> u32 {
        self.slots.iter().map(|m| u32::from(m.count)).sum()
    }

    /// Whether a boot that entered the safe mode is among them (the next boot writes them).
    pub fn holds_safe_mode(&self) -> bool {
        self.slots.iter().any(|m| m.count > 0 && m.safe_mode)
    }

    /// The marks to write, one a slot in use.
    fn marks(&self) -> impl Iterator<Item = Mark> + '_ {
        self.slots.iter().copied().filter(|m| m.count > 0)
    }

    /// `totals` with these counts added (what the boot report shows).
    pub fn added_to(&self, mut totals: Totals) -> Totals {
        for m in self.marks() {
            totals.add_mark(&m);
        }
        totals
    }

    /// The bytes kept in the boot block: a slot is its kind and flags (a mark's second
    /// byte), a reserved byte and the count (little-endian); a free slot's count is 0.
    pub fn encode(&self) -> [u8; PENDING_LEN] {
        let mut out = [0u8; PENDING_LEN];
        for (m, b) in self.slots.iter().zip(out.chunks_exact_mut(4)) {
            let [c0, c1] = m.count.to_le_bytes();
            b.copy_from_slice(&[m.flags_byte(), 0, c0, c1]);
        }
        out
    }

    /// The counts in `bytes` ([`Pending::encode`]); a slot naming no count is free.
    pub fn decode(bytes: &[u8; PENDING_LEN]) -> Pending {
        let mut p = Pending::EMPTY;
        for (m, b) in p.slots.iter_mut().zip(bytes.chunks_exact(4)) {
            if let [h1, _, c0, c1] = *b {
                let what = usize::from(h1 & 0x0F);
                let count = u16::from_le_bytes([c0, c1]);
                if what < ResetKind::ALL.len() && count > 0 {
                    *m = Mark {
                        what,
                        count,
                        failed: h1 & MARK_FAILED != 0,
                        safe_mode: h1 & MARK_SAFE_MODE != 0,
                    };
                }
            }
        }
        p
    }
}

/// The safe mode's boot counted in RAM (`pending`): its reset's kind, whether the run it
/// follows failed, flagged safe mode. No flash is read or written (the safe mode does not
/// depend on the log); the next boot that is not the safe mode's writes it
/// ([`record_boot`]). `false` when every slot holds another count (this one is lost).
pub fn count_safe_mode(pending: &mut Pending, boot: &BootRecord) -> bool {
    pending.add(boot.kind, Entry::of(&boot.previous).is_some(), true)
}

mod pages;
pub use pages::{newest, record_boot, totals, BootRecord, Written};
