//! The log's pages read and appended to (the module docs of `reset_record::log`): a page's
//! scan, the page in use, an item appended after its last one or at the start of the next
//! page in turn, and what a boot writes.

use super::{
    Entry, LogFlash, Mark, Pending, Totals, ENTRY_LEN, FLUSH_AFTER, FULL_ENTRIES, HEADER_LEN,
    MARK_LEN, PAGES, PAGE_LEN, PENDING_SLOTS, UP,
};
use crate::reset_record::{PreviousRun, ResetKind, ResetSource};

/// What a scan found of a page with a valid header.
#[derive(Clone, Copy, Debug)]
struct PageScan {
    /// The page's sequence number (the page in use has the highest).
    seq: u32,
    /// The totals: the header's and the page's items'.
    totals: Totals,
    /// The first byte after the page's last item ([`PAGE_LEN`]: full, or unreadable from
    /// there).
    next_free: usize,
}

/// Scans page `page` (`None`: its header is not valid), calling `each` on its valid
/// entries. The page is read whole (one read of [`PAGE_LEN`] bytes); when that read fails
/// (an ECC double error somewhere in it), again a double word at a time, and the page ends
/// at the first that fails.
fn scan<F: LogFlash>(flash: &mut F, page: usize, mut each: impl FnMut(Entry)) -> Option<PageScan> {
    let mut bytes = [0xFFu8; PAGE_LEN];
    let readable = match flash.read(page, 0, &mut bytes) {
        Ok(()) => PAGE_LEN,
        Err(_) => read_until_error(flash, page, &mut bytes),
    };
    let (seq, mut totals) = Totals::decode_header(bytes.get(..HEADER_LEN)?)?;
    let mut at = HEADER_LEN;
    while at + MARK_LEN <= PAGE_LEN {
        if at + MARK_LEN > readable {
            // Unreadable from here (a torn double word's ECC error): the page is full.
            at = PAGE_LEN;
            break;
        }
        let dw = bytes.get(at..at + MARK_LEN).unwrap_or(&[]);
        if dw.iter().all(|b| *b == 0xFF) {
            break;
        }
        if dw.starts_with(&super::FORMAT.magic) {
            if at + ENTRY_LEN > readable {
                at = PAGE_LEN;
                break;
            }
            if let Some(e) = bytes.get(at..at + ENTRY_LEN).and_then(Entry::decode) {
                totals.add_entry(&e);
                each(e);
            }
            at += ENTRY_LEN;
        } else {
            let mark = <[u8; MARK_LEN]>::try_from(dw).ok();
            if let Some(m) = mark.as_ref().and_then(Mark::decode) {
                totals.add_mark(&m);
            }
            // A torn item is skipped a double word at a time, never written over.
            at += MARK_LEN;
        }
    }
    Some(PageScan {
        seq,
        totals,
        next_free: at,
    })
}

/// Reads page `page` into `bytes` a double word at a time up to the first read that fails;
/// the bytes read (a multiple of [`MARK_LEN`]).
fn read_until_error<F: LogFlash>(flash: &mut F, page: usize, bytes: &mut [u8; PAGE_LEN]) -> usize {
    let mut at = 0;
    for dw in bytes.chunks_exact_mut(MARK_LEN) {
        if flash.read(page, at, dw).is_err() {
            return at;
        }
        at += MARK_LEN;
    }
    at
}

/// The sequence number in page `page`'s header (`None`: the header is not valid, or its
/// read failed).
fn header_seq<F: LogFlash>(flash: &mut F, page: usize) -> Option<u32> {
    let mut header = [0u8; HEADER_LEN];
    flash.read(page, 0, &mut header).ok()?;
    Totals::decode_header(&header).map(|(seq, _)| seq)
}

/// The page in use (the valid header with the highest sequence number) and its scan: every
/// page's header read, then the one page scanned (a boot reads 16 headers and one page, not
/// the 16 pages).
fn locate<F: LogFlash>(flash: &mut F) -> Option<(usize, PageScan)> {
    let page = (0..PAGES)
        .filter_map(|page| header_seq(flash, page).map(|seq| (page, seq)))
        .max_by_key(|(_, seq)| *seq)?
        .0;
    scan(flash, page, |_| {}).map(|s| (page, s))
}

/// Appends `item` to the log whose page in use is `at` ([`locate`]): after its last item,
/// or, when it does not fit (or no page is in use), at the start of the next page in turn,
/// erased and headed with the totals so far.
fn append<F: LogFlash>(
    flash: &mut F,
    at: Option<(usize, PageScan)>,
    item: &[u8],
) -> Result<(), F::Error> {
    if let Some((page, s)) = at {
        if s.next_free + item.len() <= PAGE_LEN {
            return flash.write(page, s.next_free, item);
        }
    }
    let (next, seq, totals) = match at {
        Some((page, s)) => ((page + 1) % PAGES, s.seq.wrapping_add(1), s.totals),
        None => (0, 1, Totals::default()),
    };
    flash.erase(next)?;
    flash.write(next, 0, &totals.encode_header(seq))?;
    flash.write(next, HEADER_LEN, item)
}

/// What the boot writes for the reset it follows ([`record_boot`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BootRecord {
    /// Why the previous run ended.
    pub previous: PreviousRun,
    /// What reset the MCU.
    pub source: ResetSource,
    /// The reset's kind (`crate::boot_block::BootHistory::kind`).
    pub kind: ResetKind,
    /// The previous run was up for 10 minutes: the "up" mark first.
    pub previous_long_up: bool,
    /// The previous run was up (10 s of samples): the counts in RAM are written now.
    pub previous_up: bool,
    /// RAM survived the reset (the boot block was valid): counts can wait there. `false`
    /// (a power-on): this boot's count is written now, RAM keeps nothing.
    pub ram_kept: bool,
    /// This boot enters the safe mode.
    pub safe_mode: bool,
}

/// What [`record_boot`] did with the boot's item.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Written {
    /// A full entry, its sequence number.
    Entry(u32),
    /// A count mark, written with the counts that waited in RAM; `failed`: a failed run
    /// beyond the rate limit.
    Counted {
        /// The run counted had failed.
        failed: bool,
    },
    /// A count kept in RAM ([`Pending`]), not written yet.
    Pending {
        /// The run counted had failed.
        failed: bool,
    },
}

/// Writes the counts in RAM (`pending`), one mark a slot, as one item in the log whose page
/// in use is `at` ([`locate`]); empties them once written.
fn flush<F: LogFlash>(
    flash: &mut F,
    at: Option<(usize, PageScan)>,
    pending: &mut Pending,
) -> Result<(), F::Error> {
    let mut bytes = [0u8; MARK_LEN * PENDING_SLOTS];
    let mut len = 0;
    for (m, out) in pending.marks().zip(bytes.chunks_exact_mut(MARK_LEN)) {
        out.copy_from_slice(&m.encode());
        len += MARK_LEN;
    }
    if len > 0 {
        append(flash, at, bytes.get(..len).unwrap_or(&[]))?;
    }
    *pending = Pending::EMPTY;
    Ok(())
}

/// The "up" mark: the run before this boot was up long enough (the failed boots' count
/// ends there).
const UP_MARK: Mark = Mark {
    what: UP,
    count: 1,
    failed: false,
    safe_mode: false,
};

/// The boot's item (module docs of `reset_record::log`): the "up" mark when the previous
/// run was long up, a full entry for a failed run within the rate limit ([`FULL_ENTRIES`]
/// since the last "up"), else a count of the reset's kind, added to the counts in RAM
/// (`pending`). Those are written, one mark a slot, when the write is due: after a power-on
/// (RAM kept nothing), after a run that was up (10 s of samples: at most one write every
/// 10 s), after the safe mode, when [`FLUSH_AFTER`] boots are counted, or when the slots are
/// full. A clean boot with nothing due reads no flash at all.
///
/// # Errors
/// The flash's error when an erase or a write failed (or was refused); the counts stay in
/// `pending`.
pub fn record_boot<F: LogFlash>(
    flash: &mut F,
    boot: &BootRecord,
    pending: &mut Pending,
) -> Result<Written, F::Error> {
    let ended = Entry::of(&boot.previous);
    let failed = ended.is_some();
    let due =
        !boot.ram_kept || boot.previous_up || boot.previous_long_up || pending.holds_safe_mode();
    let mut counted = false;
    if !failed && !due {
        counted = pending.add(boot.kind, false, false);
        if counted && pending.count() < FLUSH_AFTER {
            return Ok(Written::Pending { failed: false });
        }
    }
    let mut at = locate(flash);
    if boot.previous_long_up {
        append(flash, at, &UP_MARK.encode())?;
        at = locate(flash);
    }
    let totals = at.map(|(_, s)| s.totals).unwrap_or_default();
    match ended {
        Some((ended, record, phase)) if totals.entries_since_up < FULL_ENTRIES => {
            let entry = Entry {
                seq: totals.last_entry.wrapping_add(1),
                source: boot.source,
                kind: boot.kind,
                ended,
                phase,
                safe_mode: boot.safe_mode,
                record,
            };
            append(flash, at, &entry.encode())?;
            if due {
                let at = locate(flash);
                flush(flash, at, pending)?;
            }
            Ok(Written::Entry(entry.seq))
        }
        _ => {
            if !counted && !pending.add(boot.kind, failed, boot.safe_mode) {
                // Every slot holds another count: those first, then this one.
                flush(flash, at, pending)?;
                at = locate(flash);
                pending.add(boot.kind, failed, boot.safe_mode);
            }
            if due || pending.count() >= FLUSH_AFTER {
                flush(flash, at, pending)?;
                Ok(Written::Counted { failed })
            } else {
                Ok(Written::Pending { failed })
            }
        }
    }
}

/// Everything the log has counted (nothing for an empty log).
pub fn totals<F: LogFlash>(flash: &mut F) -> Totals {
    locate(flash).map(|(_, s)| s.totals).unwrap_or_default()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The log's pages, the reads of one double word failing (an ECC double error).
    struct EccErrorFlash {
        pages: [[u8; PAGE_LEN]; PAGES],
        unreadable: Option<(usize, usize)>,
    }

    impl LogFlash for EccErrorFlash {
        type Error = ();
        fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), ()> {
            let hit =
                |(p, o): (usize, usize)| p == page && (offset..offset + buf.len()).contains(&o);
            if self.unreadable.is_some_and(hit) {
                return Err(());
            }
            buf.copy_from_slice(&self.pages[page][offset..offset + buf.len()]);
            Ok(())
        }
        fn erase(&mut self, page: usize) -> Result<(), ()> {
            self.pages[page] = [0xFF; PAGE_LEN];
            Ok(())
        }
        fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), ()> {
            let at = &mut self.pages[page][offset..offset + bytes.len()];
            // Flash is written only where erased (RM0440: programming a double word not
            // erased is an error).
            assert!(at.iter().all(|b| *b == 0xFF), "written over {offset}");
            at.copy_from_slice(bytes);
            Ok(())
        }
    }

    /// A run that ended in a panic at `line` of `src/app.rs`.
    fn failed_run(line: u32) -> PreviousRun {
        let record =
            crate::reset_record::ResetRecord::panic("index out of bounds", "src/app.rs", line);
        PreviousRun::Recorded(record)
    }

    /// The entry numbered `seq` of a run that the watchdog ended in a panic.
    fn entry(seq: u32) -> Entry {
        let (ended, record, phase) = Entry::of(&failed_run(seq)).unwrap();
        Entry {
            seq,
            source: ResetSource::IndependentWatchdog,
            kind: ResetKind::Watchdog,
            ended,
            phase,
            safe_mode: false,
            record,
        }
    }

    /// A double word torn at the start of an item (its ECC failing, its bytes not erased)
    /// ends the page there: the page counts as full, its marks before it stay, and the next
    /// item starts the next page, never written over the torn double word.
    #[test]
    fn a_torn_double_word_at_an_items_start_ends_its_page() {
        let mut flash = EccErrorFlash {
            pages: [[0xFF; PAGE_LEN]; PAGES],
            unreadable: None,
        };
        let mark = Mark {
            what: ResetKind::Pin.index(),
            count: 1,
            failed: false,
            safe_mode: false,
        };
        append(&mut flash, None, &mark.encode()).unwrap();
        let torn = HEADER_LEN + MARK_LEN;
        flash.pages[0][torn..torn + MARK_LEN]
            .copy_from_slice(&[0x43, 0x02, 0, 0, 0, 0, 0xFF, 0xFF]);
        flash.unreadable = Some((0, torn));
        let (page, s) = locate(&mut flash).unwrap();
        assert_eq!(
            (page, s.next_free, s.totals.resets(ResetKind::Pin)),
            (0, PAGE_LEN, 1)
        );
        append(&mut flash, Some((page, s)), &mark.encode()).unwrap();
        let (page, s) = locate(&mut flash).unwrap();
        assert_eq!((page, s.next_free), (1, HEADER_LEN + MARK_LEN));
        assert_eq!(s.totals.resets(ResetKind::Pin), 2);
    }

    /// An entry that ends where an unreadable double word begins is read whole: counted,
    /// and the newest entry; the page is full from the torn double word on.
    #[test]
    fn an_entry_just_before_a_torn_double_word_is_kept() {
        let mut flash = EccErrorFlash {
            pages: [[0xFF; PAGE_LEN]; PAGES],
            unreadable: None,
        };
        let boot = BootRecord {
            previous: failed_run(7),
            source: ResetSource::IndependentWatchdog,
            kind: ResetKind::Watchdog,
            previous_long_up: false,
            previous_up: false,
            ram_kept: false,
            safe_mode: false,
        };
        let mut pending = Pending::EMPTY;
        let written = record_boot(&mut flash, &boot, &mut pending).unwrap();
        assert_eq!(written, Written::Entry(1));
        let torn = HEADER_LEN + ENTRY_LEN;
        flash.pages[0][torn] = 0x43;
        flash.unreadable = Some((0, torn));
        let (page, s) = locate(&mut flash).unwrap();
        assert_eq!((page, s.next_free), (0, PAGE_LEN));
        assert_eq!(s.totals.resets(ResetKind::Watchdog), 1);
        let (entries, n) = newest::<_, 2>(&mut flash);
        assert_eq!((n, entries[0].map(|e| e.seq)), (1, Some(1)));
    }

    /// Once the log has gone round its pages (the page in use is page 0 again, its oldest
    /// page the last), the newest entries still come newest first: by their numbers, not
    /// by the pages' order.
    #[test]
    fn after_the_log_goes_round_its_pages_the_newest_come_first() {
        let mut flash = EccErrorFlash {
            pages: [[0xFF; PAGE_LEN]; PAGES],
            unreadable: None,
        };
        let full = |page: usize, seq: u32| {
            let totals = Totals::default();
            let next_free = PAGE_LEN;
            Some((
                page,
                PageScan {
                    seq,
                    totals,
                    next_free,
                },
            ))
        };
        append(&mut flash, full(PAGES - 2, 0), &entry(1).encode()).unwrap();
        let at = locate(&mut flash);
        assert_eq!(at.map(|(page, _)| page), Some(PAGES - 1));
        append(&mut flash, at, &entry(2).encode()).unwrap();
        append(&mut flash, full(PAGES - 1, 1), &entry(3).encode()).unwrap();
        assert_eq!(locate(&mut flash).map(|(page, _)| page), Some(0));
        let (entries, n) = newest::<_, 3>(&mut flash);
        let seqs = entries.map(|e| e.map(|e| e.seq));
        assert_eq!((n, seqs), (3, [Some(3), Some(2), Some(1)]));
    }
}
