//! The reset log in flash (`drive_monitor::reset_record::log`) and the boot report on the
//! virtual COM port (`boot_report`): every reset counted, the ends of failed runs
//! kept across a power loss and a torn write, the rate limit that bounds the wear to more
//! than a year of a boot every second, and the text a technician reads without a probe.

use drive_monitor::boot_report::{
    boot_line, entry_line, list_line, previous_line, safe_mode_line, totals_line,
};
use drive_monitor::reset_record::log::{
    self, BootRecord, Ended, Entry, LogFlash, Pending, Written, ENTRY_LEN, FLUSH_AFTER,
    FULL_ENTRIES, MARKS_PER_PAGE, PAGES, PAGE_LEN, PENDING_SLOTS,
};
use drive_monitor::reset_record::{BootPhase, PreviousRun, ResetKind, ResetRecord, ResetSource};

/// The log's pages, with a power loss after `cut` bytes of the next write, a double word
/// whose reads fail (an ECC double error) and each page's erases counted.
#[derive(Clone)]
struct Pages {
    pages: Vec<Vec<u8>>,
    cut: Option<usize>,
    unreadable: Option<(usize, usize)>,
    erases: Vec<u32>,
    reads: u64,
}

#[derive(Debug, PartialEq)]
struct Lost;

impl Pages {
    fn erased() -> Self {
        Self {
            pages: vec![vec![0xFF; PAGE_LEN]; PAGES],
            cut: None,
            unreadable: None,
            erases: vec![0; PAGES],
            reads: 0,
        }
    }
}

impl LogFlash for Pages {
    type Error = Lost;
    fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), Lost> {
        self.reads += 1;
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
        self.erases[page] += 1;
        self.pages[page].fill(0xFF);
        if self.unreadable.is_some_and(|(p, _)| p == page) {
            self.unreadable = None;
        }
        Ok(())
    }
    fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), Lost> {
        assert_eq!(offset % 8, 0, "items are 8-byte aligned");
        assert!(
            self.pages[page][offset..offset + bytes.len()]
                .iter()
                .all(|b| *b == 0xFF),
            "a write over bytes that are not erased"
        );
        let n = self.cut.take().unwrap_or(bytes.len());
        self.pages[page][offset..offset + n].copy_from_slice(&bytes[..n]);
        if n < bytes.len() {
            return Err(Lost);
        }
        Ok(())
    }
}

/// The boot's item with nothing waiting in RAM (the tests of the log's pages, written as
/// after a power-on: every item goes to flash at once).
fn record(flash: &mut Pages, boot: &BootRecord) -> Result<Written, Lost> {
    let mut pending = Pending::EMPTY;
    log::record_boot(flash, boot, &mut pending)
}

fn panic_at(line: u32) -> ResetRecord {
    ResetRecord::panic("index out of bounds", "src/app.rs", line)
}

/// A boot after a run that ended in a panic at `line` (the watchdog's reset).
fn failed(line: u32) -> BootRecord {
    BootRecord {
        previous: PreviousRun::Recorded(panic_at(line)),
        source: ResetSource::IndependentWatchdog,
        kind: ResetKind::Watchdog,
        previous_long_up: false,
        previous_up: false,
        ram_kept: false,
        safe_mode: false,
    }
}

/// A boot after a clean run reset by `kind`'s source.
fn clean(kind: ResetKind) -> BootRecord {
    let source = match kind {
        ResetKind::PowerOn | ResetKind::BrownOut => ResetSource::PowerOnOrBrownOut,
        ResetKind::Pin => ResetSource::Pin,
        ResetKind::Watchdog => ResetSource::IndependentWatchdog,
        ResetKind::Software => ResetSource::Software,
        ResetKind::Other => ResetSource::Unknown,
    };
    BootRecord {
        previous: PreviousRun::Clean,
        source,
        kind,
        previous_long_up: false,
        previous_up: false,
        ram_kept: false,
        safe_mode: false,
    }
}

fn newest(flash: &mut Pages) -> Vec<u32> {
    let (entries, n) = log::newest::<_, 30>(flash);
    entries.iter().take(n).flatten().map(|e| e.seq).collect()
}

/// Every boot writes one item: an entry for a failed run, a count for the rest; the counts
/// by kind add up, power-ons told from brown-outs.
#[test]
fn every_reset_is_counted_and_failed_runs_are_entered() {
    let mut flash = Pages::erased();
    for kind in [
        ResetKind::PowerOn,
        ResetKind::Pin,
        ResetKind::BrownOut,
        ResetKind::PowerOn,
    ] {
        assert_eq!(
            record(&mut flash, &clean(kind)),
            Ok(Written::Counted { failed: false })
        );
    }
    assert_eq!(record(&mut flash, &failed(7)), Ok(Written::Entry(1)));
    // The layouts of the module docs: the page's header (magic `DMLP`, version 1, a payload
    // of 52 bytes), four counts of 8 bytes (`C`, the kind's index, the count, the check),
    // then the entry (magic `DMRL`, version 2, a payload of 140 bytes).
    let page = &flash.pages[0];
    assert_eq!(page[..8], *b"DMLP\x01\x00\x34\x00");
    let power_on = [b'C', 0, 1, 0];
    let check = (!u32::from_le_bytes(power_on)).to_le_bytes();
    assert_eq!(page[64..68], power_on);
    assert_eq!(page[68..72], check);
    assert_eq!(page[72..76], [b'C', 2, 1, 0], "the reset button's count");
    assert_eq!(page[96..104], *b"DMRL\x02\x00\x8c\x00");
    let t = log::totals(&mut flash);
    assert_eq!(t.resets(ResetKind::PowerOn), 2);
    assert_eq!(t.resets(ResetKind::Pin), 1);
    assert_eq!(t.resets(ResetKind::BrownOut), 1);
    assert_eq!(t.resets(ResetKind::Watchdog), 1);
    assert_eq!(
        (t.entries_since_up, t.last_entry, t.failed_not_entered),
        (1, 1, 0)
    );
    let (four, n) = log::newest::<_, 4>(&mut flash);
    assert_eq!(n, 1);
    let e = four[0].unwrap();
    assert_eq!(
        (e.seq, e.record, e.kind),
        (1, Some(panic_at(7)), ResetKind::Watchdog)
    );
}

/// The rate limit: a loop of 1 000 failed runs gets four full entries; the other 996 are
/// counted as failed (8 bytes each), none lost. A run that was up for 10 minutes (the next
/// boot's "up" mark) gives the entries back.
#[test]
fn the_rate_limit_enters_four_failed_runs_between_ups_and_counts_the_rest() {
    let mut flash = Pages::erased();
    let mut entered = 0;
    for k in 0..1_000 {
        match record(&mut flash, &failed(k)).unwrap() {
            Written::Entry(_) => entered += 1,
            Written::Counted { failed } => assert!(failed),
            w => panic!("{w:?}"),
        }
    }
    assert_eq!(entered, FULL_ENTRIES);
    let t = log::totals(&mut flash);
    assert_eq!(t.resets(ResetKind::Watchdog), 1_000);
    assert_eq!(t.failed_not_entered, 1_000 - FULL_ENTRIES);
    assert_eq!(newest(&mut flash), [4, 3, 2, 1]);
    // 4 entries (608 B) and 996 counts (7 968 B) on 2 048-byte pages: 5 pages, 5 erases.
    assert_eq!(flash.erases.iter().sum::<u32>(), 5);
    // Up for 10 minutes, then a failure: entered again (after the "up" mark).
    let mut after_up = failed(2_000);
    after_up.previous_long_up = true;
    assert_eq!(record(&mut flash, &after_up), Ok(Written::Entry(5)));
    let t = log::totals(&mut flash);
    assert_eq!((t.ups(), t.entries_since_up), (1, 1));
}

/// A boot every second for a year, the worst case (RAM lost at every boot: nothing but
/// flash remembers): one count of 8 bytes a boot, 248 a page, 16 pages in turn. Run for
/// 40 000 boots and scaled to 31 536 000: every page's erases stay below the 10 000 cycles
/// a page survives (DS12288), and not one boot is lost from the counts.
#[test]
fn a_boot_every_second_for_a_year_wears_no_page_out() {
    let mut flash = Pages::erased();
    let boots = 40_000u32;
    for k in 0..boots {
        let kind = if k % 3 == 0 {
            ResetKind::BrownOut
        } else {
            ResetKind::PowerOn
        };
        record(&mut flash, &clean(kind)).unwrap();
    }
    let t = log::totals(&mut flash);
    assert_eq!(
        t.resets(ResetKind::PowerOn) + t.resets(ResetKind::BrownOut),
        boots
    );
    let most = *flash.erases.iter().max().unwrap();
    let least = *flash.erases.iter().min().unwrap();
    assert!(most - least <= 1, "{:?}", flash.erases);
    let year = 365 * 24 * 3_600u64;
    let per_page_year = u64::from(most) * year / u64::from(boots);
    assert!(
        per_page_year < 10_000,
        "{per_page_year} erases a page a year"
    );
    // The arithmetic of the docs: 31 536 000 / 248 / 16 = 7 948.
    assert_eq!(MARKS_PER_PAGE, 248);
    assert_eq!(year / MARKS_PER_PAGE as u64 / PAGES as u64, 7_947);
    // A loop of failed runs costs the same (four entries, then counts).
    let mut flash = Pages::erased();
    for k in 0..10_000 {
        record(&mut flash, &failed(k)).unwrap();
    }
    assert_eq!(flash.erases.iter().sum::<u32>(), 41);
}

/// A power loss in the middle of an entry's write, of a count's, of a new page's header:
/// the torn item is nothing, the items before it stay, the next boot writes after it.
#[test]
fn a_torn_write_loses_only_its_own_item() {
    let mut flash = Pages::erased();
    for k in 1..=3 {
        record(&mut flash, &failed(k)).unwrap();
    }
    flash.cut = Some(60);
    assert_eq!(record(&mut flash, &failed(4)), Err(Lost));
    assert_eq!(newest(&mut flash), [3, 2, 1]);
    // The next boot: after the torn entry (the model asserts it writes only erased bytes).
    assert_eq!(record(&mut flash, &failed(5)), Ok(Written::Entry(4)));
    assert_eq!(newest(&mut flash), [4, 3, 2, 1]);
    // A torn count.
    flash.cut = Some(3);
    assert_eq!(record(&mut flash, &clean(ResetKind::Pin)), Err(Lost));
    record(&mut flash, &clean(ResetKind::Pin)).unwrap();
    assert_eq!(log::totals(&mut flash).resets(ResetKind::Pin), 1);
    // Fill the page; the next page's header torn: the counts so far stay (the full page is
    // still the one in use), the next boot erases that page again.
    let mut flash = Pages::erased();
    for _ in 0..MARKS_PER_PAGE {
        record(&mut flash, &clean(ResetKind::PowerOn)).unwrap();
    }
    flash.cut = Some(20);
    assert_eq!(record(&mut flash, &clean(ResetKind::PowerOn)), Err(Lost));
    assert_eq!(log::totals(&mut flash).resets(ResetKind::PowerOn), 248);
    record(&mut flash, &clean(ResetKind::PowerOn)).unwrap();
    assert_eq!(log::totals(&mut flash).resets(ResetKind::PowerOn), 249);
    assert_eq!(flash.erases[1], 2);
}

/// A double word whose read fails (an ECC double error in a torn double word): its page is
/// full from there, the next item starts the next page, the counts before it stay.
#[test]
fn an_unreadable_double_word_ends_its_page() {
    let mut flash = Pages::erased();
    for k in 1..=3 {
        record(&mut flash, &failed(k)).unwrap();
    }
    flash.unreadable = Some((0, 64 + 2 * ENTRY_LEN + 16));
    assert_eq!(newest(&mut flash), [2, 1]);
    let e = record(&mut flash, &failed(4)).unwrap();
    assert_eq!(e, Written::Entry(3));
    assert_eq!(
        Entry::decode(&flash.pages[1][64..64 + ENTRY_LEN]).map(|e| e.seq),
        Some(3)
    );
    assert_eq!(log::totals(&mut flash).resets(ResetKind::Watchdog), 3);
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
        previous_line(&PreviousRun::WatchdogReset { phase: None }).as_bytes(),
        b"previous run: watchdog reset with no reason recorded (the firmware hung)\r\n"
    );
    assert_eq!(
        previous_line(&PreviousRun::WatchdogReset {
            phase: Some(BootPhase::Clock)
        })
        .as_bytes(),
        b"previous run: watchdog reset with no reason recorded (the firmware hung in its clock phase)\r\n"
    );
    let fault =
        ResetRecord::hard_fault(None, 0x0800_1A2C, 0x0800_0F01, 0x0000_0400, 0x4000_0000, 0);
    let entry = Entry {
        seq: 7,
        source: ResetSource::IndependentWatchdog,
        kind: ResetKind::Watchdog,
        ended: Ended::Recorded,
        phase: None,
        safe_mode: false,
        record: Some(fault),
    };
    assert_eq!(
        entry_line(&entry).as_bytes(),
        b"log #7: reset by watchdog: a hard fault: lr=0x08000F01 cfsr=0x00000400 hfsr=0x40000000 bfar=0x00000000 hard fault at 0x08001A2C\r\n"
    );
    let hung = Entry {
        seq: 8,
        ended: Ended::WatchdogReset,
        phase: Some(BootPhase::Clock),
        safe_mode: true,
        record: None,
        ..entry
    };
    assert_eq!(
        entry_line(&hung).as_bytes(),
        b"log #8: reset by watchdog: watchdog reset with no reason recorded (hung in its clock phase); safe mode\r\n"
    );
    let mut flash = Pages::erased();
    record(&mut flash, &clean(ResetKind::PowerOn)).unwrap();
    record(&mut flash, &failed(1)).unwrap();
    assert_eq!(
        totals_line(&log::totals(&mut flash)).as_bytes(),
        b"resets: power-on 1, brown-out 0, reset button 0, watchdog 1, software 0, other 0; up 10 min 0; failed runs counted, not entered 0; safe mode 0\r\n"
    );
    let found = list_line(
        "self-check: did not take: ",
        ["RCC_CR.CSSON", "FLASH_OPTR.BOR_LEV"].into_iter(),
    );
    assert_eq!(
        found.unwrap().as_bytes(),
        b"self-check: did not take: RCC_CR.CSSON, FLASH_OPTR.BOR_LEV\r\n"
    );
    assert!(list_line("self-check: did not take: ", [].into_iter()).is_none());
    assert_eq!(
        safe_mode_line(1, "boots in a row failed before the monitor was up").as_bytes(),
        b"SAFE MODE (code 1): boots in a row failed before the monitor was up; not monitoring; press the reset button to try again\r\n"
    );
}

/// A brown-out: RAM kept, the previous run clean and not up.
fn brown_out() -> BootRecord {
    BootRecord {
        previous: PreviousRun::Clean,
        source: ResetSource::PowerOnOrBrownOut,
        kind: ResetKind::BrownOut,
        previous_long_up: false,
        previous_up: false,
        ram_kept: true,
        safe_mode: false,
    }
}

/// A supply chattering at the brown-out threshold ten times a second for a year (RAM kept at
/// every reset, no run up): 315 360 000 boots. Each is counted in RAM and read no flash; every
/// `FLUSH_AFTER` (64) boots one mark goes to flash. Run for 64 x 248 x 16 boots and scaled
/// to the year: each page erased 1 241 times a year, within the 10 000 cycles a page
/// survives; not one boot lost from the counts. Written a boot at a time (the rule before),
/// the same year erased each page 79 476 times: worn out in 46 days.
#[test]
fn a_year_of_brown_out_chatter_wears_no_page_out() {
    let mut flash = Pages::erased();
    let mut pending = Pending::EMPTY;
    let boots = FLUSH_AFTER * (MARKS_PER_PAGE * PAGES) as u32;
    let mut written = 0;
    for _ in 0..boots {
        let reads = flash.reads;
        match log::record_boot(&mut flash, &brown_out(), &mut pending).unwrap() {
            Written::Pending { failed: false } => {
                assert_eq!(flash.reads, reads, "a boot with nothing due read the flash");
            }
            Written::Counted { failed: false } => written += 1,
            w => panic!("{w:?}"),
        }
    }
    assert_eq!(written, boots / FLUSH_AFTER);
    let t = pending.added_to(log::totals(&mut flash));
    assert_eq!(t.resets(ResetKind::BrownOut), boots);
    let most = u64::from(*flash.erases.iter().max().unwrap());
    let year_at_10_hz = 10 * 365 * 24 * 3_600u64;
    let per_page_year = most * year_at_10_hz / u64::from(boots);
    assert_eq!(per_page_year, 1_241);
    // The docs' arithmetic: 315 360 000 / 64 / 248 / 16 = 1 241.8; with every slot holding
    // another kind (four marks a write), 4 967; a boot at a time, 79 476 (10 000 in 45.9
    // days).
    let pages = (MARKS_PER_PAGE * PAGES) as u64;
    let flush = u64::from(FLUSH_AFTER);
    assert_eq!(year_at_10_hz / flush / pages, 1_241);
    assert_eq!(year_at_10_hz * PENDING_SLOTS as u64 / flush / pages, 4_967);
    assert_eq!(year_at_10_hz / pages, 79_475);
}

/// When the counts in RAM go to flash: a power-on's at once (RAM keeps nothing); brown-outs
/// wait; a boot after a run that was up writes them all; a failed run's entry does not wait
/// nor write them; the safe mode counts in RAM and the next boot writes it; full slots are
/// written before a fifth kind; a write cut short keeps them in RAM.
#[test]
fn the_counts_in_ram_are_written_when_due() {
    let mut flash = Pages::erased();
    let mut pending = Pending::EMPTY;
    let boot = |flash: &mut Pages, pending: &mut Pending, b: BootRecord| {
        log::record_boot(flash, &b, pending)
    };
    let power_on = clean(ResetKind::PowerOn);
    assert_eq!(
        boot(&mut flash, &mut pending, power_on),
        Ok(Written::Counted { failed: false })
    );
    for _ in 0..3 {
        assert_eq!(
            boot(&mut flash, &mut pending, brown_out()),
            Ok(Written::Pending { failed: false })
        );
    }
    assert_eq!(log::totals(&mut flash).resets(ResetKind::BrownOut), 0);
    assert_eq!(pending.count(), 3);
    // A failed run: its entry now, the brown-outs still wait.
    let mut failed_run = failed(9);
    failed_run.ram_kept = true;
    assert_eq!(
        boot(&mut flash, &mut pending, failed_run),
        Ok(Written::Entry(1))
    );
    assert_eq!(pending.count(), 3);
    // After a run that was up (the button pressed after 10 s of samples): all written.
    let pressed = BootRecord {
        kind: ResetKind::Pin,
        source: ResetSource::Pin,
        previous_up: true,
        ..brown_out()
    };
    assert_eq!(
        boot(&mut flash, &mut pending, pressed),
        Ok(Written::Counted { failed: false })
    );
    let t = log::totals(&mut flash);
    assert_eq!(
        (
            t.resets(ResetKind::BrownOut),
            t.resets(ResetKind::Pin),
            pending.count()
        ),
        (3, 1, 0)
    );
    // The safe mode: counted in RAM, no flash; the next boot (the button) writes it.
    let reads = flash.reads;
    let safe = BootRecord {
        previous: PreviousRun::WatchdogReset { phase: None },
        source: ResetSource::IndependentWatchdog,
        kind: ResetKind::Watchdog,
        safe_mode: true,
        ..brown_out()
    };
    assert!(log::count_safe_mode(&mut pending, &safe));
    assert_eq!(flash.reads, reads);
    let after_safe = BootRecord {
        kind: ResetKind::Pin,
        source: ResetSource::Pin,
        ..brown_out()
    };
    assert_eq!(
        boot(&mut flash, &mut pending, after_safe),
        Ok(Written::Counted { failed: false })
    );
    let t = log::totals(&mut flash);
    assert_eq!((t.safe_modes, t.resets(ResetKind::Watchdog)), (1, 2));
    // The rate limit's entries spent (one so far): a failed run is then a count.
    for k in 1..FULL_ENTRIES {
        let mut f = failed(20 + k);
        f.ram_kept = true;
        assert!(matches!(
            boot(&mut flash, &mut pending, f),
            Ok(Written::Entry(_))
        ));
    }
    assert_eq!(pending.count(), 0);
    // Four kinds wait; a fifth writes them first and waits itself.
    for kind in [
        ResetKind::BrownOut,
        ResetKind::Pin,
        ResetKind::Software,
        ResetKind::Other,
    ] {
        let b = BootRecord {
            kind,
            ..brown_out()
        };
        assert_eq!(
            boot(&mut flash, &mut pending, b),
            Ok(Written::Pending { failed: false })
        );
    }
    let mut fifth = failed(10);
    fifth.ram_kept = true;
    let before = log::totals(&mut flash).resets(ResetKind::Other);
    assert_eq!(before, 0);
    assert!(matches!(
        boot(&mut flash, &mut pending, fifth),
        Ok(Written::Pending { failed: true })
    ));
    assert_eq!(log::totals(&mut flash).resets(ResetKind::Other), 1);
    // A write cut short (a power loss; RAM is lost with it on a board, here it is kept):
    // the counts stay in RAM, none half counted.
    let waiting = pending.count();
    let mut flash2 = flash.clone();
    flash2.cut = Some(4);
    assert_eq!(boot(&mut flash2, &mut pending, power_on), Err(Lost));
    assert_eq!(pending.count(), waiting + 1);
}

/// The report's line for counts in RAM: none when nothing waits.
#[test]
fn the_report_says_what_waits_in_ram() {
    assert!(log_report_pending(0).is_none());
    assert_eq!(
        log_report_pending(3).unwrap().as_bytes(),
        b"reset log: 3 resets counted in RAM, not yet written\r\n"
    );
}

fn log_report_pending(n: u32) -> Option<drive_monitor::boot_report::ReportLine> {
    drive_monitor::boot_report::pending_line(n)
}

/// The log's 16 pages sit where memory.x and docs/firmware.md say, 0x0807_6800..0x0807_E800,
/// and end where the commissioning record's second page begins (`board.rs` derives the
/// offset from `log::PAGES` and asserts this at compile time).
#[test]
fn the_logs_pages_end_where_the_records_begin() {
    use drive_monitor::board::{RECORD_B_FLASH_OFFSET, RESET_LOG_FLASH_OFFSET};
    assert_eq!(PAGES, 16);
    assert_eq!(0x0800_0000 + RESET_LOG_FLASH_OFFSET, 0x0807_6800);
    assert_eq!(
        RESET_LOG_FLASH_OFFSET + (PAGES * PAGE_LEN) as u32,
        RECORD_B_FLASH_OFFSET
    );
    assert_eq!(0x0800_0000 + RECORD_B_FLASH_OFFSET, 0x0807_E800);
}

/// Every field of an entry round trips, each reset source and each way a run ended told
/// apart (the entry's bytes 12 and 13, `source_code` and `Ended`'s byte).
#[test]
fn every_entry_round_trips_with_its_source_and_its_end() {
    let sources = [
        ResetSource::IndependentWatchdog,
        ResetSource::WindowWatchdog,
        ResetSource::Software,
        ResetSource::OptionBytes,
        ResetSource::LowPower,
        ResetSource::PowerOnOrBrownOut,
        ResetSource::Pin,
        ResetSource::Unknown,
    ];
    let mut bytes = Vec::new();
    for (k, source) in sources.into_iter().enumerate() {
        for ended in [Ended::Recorded, Ended::WatchdogReset, Ended::ResetDuring] {
            for safe_mode in [false, true] {
                let e = Entry {
                    seq: k as u32 + 1,
                    source,
                    kind: ResetKind::ALL[k % ResetKind::ALL.len()],
                    ended,
                    phase: Some(BootPhase::Clock),
                    safe_mode,
                    record: Some(panic_at(k as u32)),
                };
                let encoded = e.encode();
                assert_eq!(Entry::decode(&encoded), Some(e), "{e:?}");
                bytes.push((encoded[12], encoded[13]));
            }
        }
    }
    // Eight sources, three ends: 24 different pairs of bytes.
    bytes.sort_unstable();
    bytes.dedup();
    assert_eq!(bytes.len(), 24);
}

/// A count mark naming no count the log keeps (what = 7, beyond the six kinds and the "up"
/// marks), its check word valid: read as no mark, its flags not counted.
#[test]
fn a_mark_of_no_known_count_is_no_mark() {
    let mut flash = Pages::erased();
    record(&mut flash, &clean(ResetKind::PowerOn)).unwrap();
    let head = [b'C', 7 | 0x40, 1, 0];
    let check = (!u32::from_le_bytes(head)).to_le_bytes();
    flash.pages[0][72..76].copy_from_slice(&head);
    flash.pages[0][76..80].copy_from_slice(&check);
    let t = log::totals(&mut flash);
    assert_eq!((t.resets(ResetKind::PowerOn), t.failed_not_entered), (1, 0));
    // The same mark naming the watchdog (3) is one.
    let head = [b'C', 3 | 0x40, 1, 0];
    let check = (!u32::from_le_bytes(head)).to_le_bytes();
    flash.pages[0][80..84].copy_from_slice(&head);
    flash.pages[0][84..88].copy_from_slice(&check);
    let t = log::totals(&mut flash);
    assert_eq!(
        (t.resets(ResetKind::Watchdog), t.failed_not_entered),
        (1, 1)
    );
}
