//! The reset log in flash (`drive_monitor::reset_record::log`) and the boot report on the
//! virtual COM port (`reset_record::report`): the last ends of a run survive a power loss
//! and a torn write; the text a technician reads without a probe.

use drive_monitor::reset_record::log::{self, Ended, Entry, LogFlash, ENTRY_LEN, PAGE_LEN};
use drive_monitor::reset_record::report::{boot_line, entry_line, previous_line};
use drive_monitor::reset_record::{PreviousRun, ResetRecord, ResetSource};

/// The log's two pages, with a power loss after `cut` bytes of the next write, and slots
/// whose reads fail (an ECC double error).
#[derive(Clone)]
struct Pages {
    pages: [Vec<u8>; 2],
    cut: Option<usize>,
    unreadable: Option<(usize, usize)>,
    erases: u32,
}

#[derive(Debug, PartialEq)]
struct Lost;

impl Pages {
    fn erased() -> Self {
        Self {
            pages: [vec![0xFF; PAGE_LEN], vec![0xFF; PAGE_LEN]],
            cut: None,
            unreadable: None,
            erases: 0,
        }
    }
}

impl LogFlash for Pages {
    type Error = Lost;
    fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), Lost> {
        if self
            .unreadable
            .is_some_and(|(p, o)| p == page && (offset..offset + buf.len()).contains(&o))
        {
            return Err(Lost);
        }
        buf.copy_from_slice(&self.pages[page][offset..offset + buf.len()]);
        Ok(())
    }
    fn erase(&mut self, page: usize) -> Result<(), Lost> {
        self.erases += 1;
        self.pages[page].fill(0xFF);
        Ok(())
    }
    fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), Lost> {
        assert!(
            self.pages[page][offset..offset + bytes.len()]
                .iter()
                .all(|b| *b == 0xFF),
            "a write over a slot that is not erased"
        );
        let n = self.cut.take().unwrap_or(bytes.len());
        self.pages[page][offset..offset + n].copy_from_slice(&bytes[..n]);
        if n < bytes.len() {
            return Err(Lost);
        }
        Ok(())
    }
}

fn panic_at(line: u32) -> ResetRecord {
    ResetRecord::panic("index out of bounds", "src/app.rs", line)
}

fn append(flash: &mut Pages, line: u32) -> Result<Entry, Lost> {
    log::append(
        flash,
        ResetSource::IndependentWatchdog,
        Ended::Recorded,
        Some(panic_at(line)),
    )
}

fn newest(flash: &mut Pages) -> Vec<u32> {
    let (entries, n) = log::newest::<_, 30>(flash);
    entries.iter().take(n).flatten().map(|e| e.seq).collect()
}

/// 13 entries a page; the 14th goes to the other page; the 27th erases the older page:
/// the newer page's 13 and the new one stay, newest first.
#[test]
fn the_log_keeps_the_newest_entries_across_both_pages() {
    assert_eq!(log::SLOTS_PER_PAGE, 13);
    assert_eq!(ENTRY_LEN % 8, 0);
    let mut flash = Pages::erased();
    for k in 1..=27 {
        let e = append(&mut flash, 100 + k).unwrap();
        assert_eq!(e.seq, k);
    }
    assert_eq!(flash.erases, 2);
    assert_eq!(newest(&mut flash), (14..=27).rev().collect::<Vec<u32>>());
    let (four, n) = log::newest::<_, 4>(&mut flash);
    assert_eq!(n, 4);
    let first = four[0].unwrap();
    assert_eq!((first.seq, first.record), (27, Some(panic_at(127))));
    assert_eq!(first.source, ResetSource::IndependentWatchdog);
}

/// A power loss in the middle of an entry's write: the torn slot is no entry, the ones
/// before it stay, and the next boot writes after it (never over it).
#[test]
fn a_torn_write_loses_only_its_own_entry() {
    let mut flash = Pages::erased();
    for k in 1..=3 {
        append(&mut flash, k).unwrap();
    }
    flash.cut = Some(60);
    assert_eq!(append(&mut flash, 4), Err(Lost));
    assert_eq!(newest(&mut flash), [3, 2, 1]);
    // The next boot: after the torn slot (the writer asserts it writes only erased bytes).
    let e = append(&mut flash, 5).unwrap();
    assert_eq!(e.seq, 4);
    assert_eq!(newest(&mut flash), [4, 3, 2, 1]);
    let torn = &flash.pages[0][3 * ENTRY_LEN..4 * ENTRY_LEN];
    assert!(torn.iter().any(|b| *b != 0xFF) && Entry::decode(torn).is_none());
}

/// A slot whose read fails (an ECC double error in a torn double word): its page counts as
/// full from there, the next entry goes to the other page, the readable entries stay.
#[test]
fn an_unreadable_slot_sends_the_next_entry_to_the_other_page() {
    let mut flash = Pages::erased();
    for k in 1..=5 {
        append(&mut flash, k).unwrap();
    }
    flash.unreadable = Some((0, 3 * ENTRY_LEN + 16));
    assert_eq!(newest(&mut flash), [3, 2, 1]);
    let e = append(&mut flash, 6).unwrap();
    assert_eq!(e.seq, 4);
    assert_eq!(Entry::decode(&flash.pages[1][..ENTRY_LEN]), Some(e));
}

/// What the boot writes on USART2, word for word.
#[test]
fn the_boot_report_reads_without_a_probe() {
    let boot = boot_line(
        "0.1.0",
        ResetSource::IndependentWatchdog,
        0,
        "24 MHz crystal (HSE)",
    );
    assert_eq!(
        boot.as_bytes(),
        b"drive-monitor 0.1.0 boot: reset by watchdog, brown-out level 0, clock 24 MHz crystal (HSE)\r\n"
    );
    let prev = PreviousRun::Recorded(panic_at(42));
    assert_eq!(
        previous_line(&prev).as_bytes(),
        b"previous run: ended in a panic: index out of bounds src/app.rs (42)\r\n"
    );
    assert_eq!(
        previous_line(&PreviousRun::WatchdogReset).as_bytes(),
        b"previous run: watchdog reset with no reason recorded (the firmware hung)\r\n"
    );
    let fault =
        ResetRecord::hard_fault(None, 0x0800_1A2C, 0x0800_0F01, 0x0000_0400, 0x4000_0000, 0);
    let entry = Entry {
        seq: 7,
        source: ResetSource::IndependentWatchdog,
        ended: Ended::Recorded,
        record: Some(fault),
    };
    assert_eq!(
        entry_line(&entry).as_bytes(),
        b"log #7: reset by watchdog: a hard fault: lr=0x08000F01 cfsr=0x00000400 hfsr=0x40000000 bfar=0x00000000 hard fault at 0x08001A2C\r\n"
    );
    let clock = Entry {
        seq: 8,
        source: ResetSource::IndependentWatchdog,
        ended: Ended::Recorded,
        record: Some(ResetRecord::clock_failure()),
    };
    assert_eq!(
        entry_line(&clock).as_bytes(),
        b"log #8: reset by watchdog: a clock failure: crystal failed (clock security system) (0)\r\n"
    );
}
