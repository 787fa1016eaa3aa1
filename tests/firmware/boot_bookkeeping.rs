//! The boot's bookkeeping across resets (`drive_monitor::boot_block`, `app::period`'s up
//! mark): thread mode marks the run **up** after 10 s of samples flowing with the watchdog
//! petted, and **long up** after 10 minutes, each once; the up mark ends the count of failed
//! boots in a row (the safe mode's), the long up mark gives the reset log's rate limit its
//! full entries back. Thread mode's own period (`app::period`) runs here on a board whose
//! `mark_up` does what the firmware's does (`src/firmware/reset_ram.rs`: the boot block
//! decoded, `BootBlock::marked_up`, encoded), and the next boot reads the block as the start
//! does (`BootHistory::of`).

use drive_monitor::app::{
    period, AcquisitionPause, MonitorStatus, PeriodInput, Settings, Supervisor, ThreadHw,
    ThreadState, PANEL_PERIOD_MS,
};
use drive_monitor::boot_block::{BootBlock, BootHistory, BOOT_BLOCK_LEN, SAFE_MODE_AFTER};
use drive_monitor::flash_record::{RecordPage, RecordStore, RECORD_LEN};
use drive_monitor::liveness::{LONG_UP_AFTER_MS, UP_AFTER_MS};
use drive_monitor::panel::PanelLamps;
use drive_monitor::reset_record::log::{self, BootRecord, LogFlash, Written, PAGES, PAGE_LEN};
use drive_monitor::reset_record::{PreviousRun, ResetKind, ResetRecord, ResetSource};
use drive_monitor::supply::ReferenceAdc;

/// No flash for the commissioning record (no run is started here).
struct NoStore;

impl RecordStore for NoStore {
    type Error = ();
    fn read(&mut self, _: RecordPage, _: &mut [u8; RECORD_LEN]) -> Result<(), ()> {
        Err(())
    }
    fn erase(&mut self, _: RecordPage) -> Result<(), ()> {
        Err(())
    }
    fn write(&mut self, _: RecordPage, _: &[u8; RECORD_LEN]) -> Result<(), ()> {
        Err(())
    }
}

struct NoPause;

impl AcquisitionPause for NoPause {
    fn pause(&mut self) -> bool {
        false
    }
    fn resume(&mut self) {}
}

/// No VREFINT (thread mode is handed none).
struct NoReference;

impl ReferenceAdc for NoReference {
    fn calibration(&self) -> u16 {
        0
    }
    fn enable(&mut self) {}
    fn wait_us(&mut self, _: u32) {}
    fn start(&mut self) {}
    fn result(&mut self) -> Option<u16> {
        None
    }
}

/// Thread mode's board: the boot block in RAM, marked up as the firmware marks it.
struct Board {
    block: [u8; BOOT_BLOCK_LEN],
    pets: u32,
    store: NoStore,
    pause: NoPause,
}

impl ThreadHw for Board {
    type Store = NoStore;
    type Pause = NoPause;
    type Reference = NoReference;
    fn pet_watchdog(&mut self) {
        self.pets += 1;
    }
    fn store_and_pause(&mut self) -> (&mut NoStore, &mut NoPause) {
        (&mut self.store, &mut self.pause)
    }
    fn reference(&mut self) -> Option<&mut NoReference> {
        None
    }
    fn show(&mut self, _: &PanelLamps) {}
    fn write_record(&mut self, _: Option<ResetRecord>) {}
    fn mark_up(&mut self, long: bool) {
        // What `reset_ram::mark_up` does on the board.
        if let Some(b) = BootBlock::decode(&self.block) {
            self.block = b.marked_up(long).encode();
        }
    }
}

/// A run booted after `failed_boots` failed boots in a row, its thread mode run for
/// `periods` periods of 50 ms; samples flow (10 kHz) except during `stalls` ([from, to) in
/// ms). Returns the periods' marks (time, long) and the boot block it leaves.
fn run(
    failed_boots: u8,
    periods: u32,
    stalls: &[(u32, u32)],
) -> (Vec<(u32, bool)>, [u8; BOOT_BLOCK_LEN]) {
    let settings = Settings::DEFAULT;
    let mut supervisor =
        Supervisor::new(&settings, PreviousRun::Clean, 0, MonitorStatus::default());
    let mut state = ThreadState::default();
    let start = BootBlock {
        failed_boots,
        ..BootBlock::default()
    };
    let mut board = Board {
        block: start.encode(),
        pets: 0,
        store: NoStore,
        pause: NoPause,
    };
    let mut samples = 0u32;
    let mut marks = Vec::new();
    for k in 1..=periods {
        let now_ms = k * PANEL_PERIOD_MS;
        let stalled = stalls.iter().any(|&(a, b)| (a..b).contains(&now_ms));
        let status = (!stalled).then(|| {
            samples += settings.sample_rate_hz / 1000 * PANEL_PERIOD_MS;
            MonitorStatus {
                samples,
                ..MonitorStatus::default()
            }
        });
        let input = PeriodInput {
            now_ms,
            status,
            ..PeriodInput::default()
        };
        let out = period(&mut supervisor, &mut state, input, &mut board);
        if let Some(long) = out.marked_up {
            marks.push((now_ms, long));
        }
    }
    assert!(board.pets > 0);
    (marks, board.block)
}

/// The watchdog is petted from the first period with samples (50 ms): the run is up 10 s
/// later, long up 10 minutes later, each marked once.
#[test]
fn the_run_is_marked_up_after_10_s_of_samples_and_long_up_after_10_minutes() {
    let first_pet = PANEL_PERIOD_MS;
    let (marks, block) = run(
        0,
        (first_pet + LONG_UP_AFTER_MS) / PANEL_PERIOD_MS + 10,
        &[],
    );
    assert_eq!(
        marks,
        [
            (first_pet + UP_AFTER_MS, false),
            (first_pet + LONG_UP_AFTER_MS, true)
        ]
    );
    assert_eq!((UP_AFTER_MS, LONG_UP_AFTER_MS), (10_000, 600_000));
    let b = BootBlock::decode(&block).unwrap();
    assert!(b.up && b.long_up);
    // One period short of 10 s: not up, the block as the boot left it.
    let (marks, block) = run(3, (first_pet + UP_AFTER_MS) / PANEL_PERIOD_MS - 1, &[]);
    assert_eq!(marks, []);
    assert_eq!(BootBlock::decode(&block).unwrap().failed_boots, 3);
}

/// A stall stops the watchdog's pets: the 10 s count again from when samples flow again.
#[test]
fn a_stall_starts_the_10_s_again() {
    let (marks, _) = run(0, 30_000 / PANEL_PERIOD_MS, &[(8_000, 8_300)]);
    let up: Vec<u32> = marks.iter().filter(|m| !m.1).map(|m| m.0).collect();
    assert_eq!(up.len(), 1, "{marks:?}");
    assert!(
        up[0] >= 8_300 + UP_AFTER_MS - PANEL_PERIOD_MS && up[0] <= 8_300 + UP_AFTER_MS + 200,
        "{marks:?}"
    );
}

/// What the up mark resets: after four failed boots a run that got up and then failed
/// (the watchdog) is the first of a new count, not the fifth; without the mark it is the
/// fifth and the next boot is the safe mode's.
#[test]
fn the_up_mark_ends_the_count_of_failed_boots() {
    let hung = PreviousRun::WatchdogReset { phase: None };
    let wd = ResetSource::IndependentWatchdog;
    let four = SAFE_MODE_AFTER - 1;
    let (_, up) = run(four, (PANEL_PERIOD_MS + UP_AFTER_MS) / PANEL_PERIOD_MS, &[]);
    let after_up = BootHistory::of(BootBlock::decode(&up), wd, &hung);
    assert_eq!((after_up.failed_boots, after_up.safe_mode()), (0, false));
    let (_, not_up) = run(four, UP_AFTER_MS / PANEL_PERIOD_MS - 1, &[]);
    let after = BootHistory::of(BootBlock::decode(&not_up), wd, &hung);
    assert_eq!(
        (after.failed_boots, after.safe_mode()),
        (SAFE_MODE_AFTER, true)
    );
    // Up is not long up: the reset log's "up" mark is not due.
    assert!(!after_up.previous_long_up);
}

/// The log's pages in memory.
struct Pages(Vec<Vec<u8>>);

impl LogFlash for Pages {
    type Error = ();
    fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), ()> {
        buf.copy_from_slice(&self.0[page][offset..offset + buf.len()]);
        Ok(())
    }
    fn erase(&mut self, page: usize) -> Result<(), ()> {
        self.0[page].fill(0xFF);
        Ok(())
    }
    fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), ()> {
        self.0[page][offset..offset + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }
}

/// What the long up mark resets: four failed runs took the log's full entries; a run long
/// up (10 minutes) gives them back at the next boot (`previous_long_up`, the log's "up"
/// mark), a run up for 10 s only does not.
#[test]
fn the_long_up_mark_gives_the_logs_entries_back() {
    let panic = PreviousRun::Recorded(ResetRecord::panic("x", "src/app.rs", 7));
    let boot = |pages: &mut Pages, left: Option<BootBlock>| {
        let source = ResetSource::IndependentWatchdog;
        let h = BootHistory::of(left, source, &panic);
        let record = BootRecord {
            previous: panic,
            source,
            kind: ResetKind::Watchdog,
            previous_long_up: h.previous_long_up,
            previous_up: h.previous_up,
            ram_kept: h.ram_kept,
            safe_mode: false,
        };
        let mut pending = h.pending;
        log::record_boot(pages, &record, &mut pending).unwrap()
    };
    let fresh = || {
        let mut pages = Pages(vec![vec![0xFF; PAGE_LEN]; PAGES]);
        for _ in 0..log::FULL_ENTRIES {
            assert!(matches!(boot(&mut pages, None), Written::Entry(_)));
        }
        pages
    };
    let long_periods = (PANEL_PERIOD_MS + LONG_UP_AFTER_MS) / PANEL_PERIOD_MS;
    let (_, long) = run(0, long_periods, &[]);
    let mut pages = fresh();
    assert!(matches!(
        boot(&mut pages, BootBlock::decode(&long)),
        Written::Entry(_)
    ));
    let (_, short) = run(0, long_periods - 1, &[]);
    let mut pages = fresh();
    // Up (10 s), not long up: a count, written now with whatever waited in RAM.
    assert_eq!(
        boot(&mut pages, BootBlock::decode(&short)),
        Written::Counted { failed: true }
    );
}

/// The safe mode's report is built from what the start found alone (no flash is passed, so
/// none is read), says the reset log is not read, and the safe mode's file on the board
/// reaches no flash: a fault in the log's scan cannot follow the board into the safe mode.
#[test]
fn the_safe_mode_does_not_depend_on_the_logs_scan() {
    use drive_monitor::boot_report as report;
    use drive_monitor::clock::ClockSource;
    use drive_monitor::self_check::Findings;
    use drive_monitor::startup::{BootFacts, SafeModeReason};
    use drive_monitor::supply::BorCheck;
    let hung = PreviousRun::WatchdogReset { phase: None };
    let wd = ResetSource::IndependentWatchdog;
    let four = BootBlock {
        failed_boots: SAFE_MODE_AFTER - 1,
        ..BootBlock::default()
    };
    let history = BootHistory::of(Some(four), wd, &hung);
    assert!(history.safe_mode());
    let facts = BootFacts {
        previous: hung,
        reset_source: wd,
        history,
        stack_overflowed: false,
        clock: None,
        findings: Findings::NONE,
        bor: BorCheck::of_optr(0xFFEF_F8AA | 4 << 8),
        safe_mode: Some(SafeModeReason::BootLoop {
            failed_boots: SAFE_MODE_AFTER,
        }),
    };
    let lines: Vec<String> = report::safe_mode_report("0.1.0", &facts)
        .iter()
        .flatten()
        .map(|l| String::from_utf8_lossy(l.as_bytes()).into_owned())
        .collect();
    assert!(
        lines[0].contains("16 MHz reset clock (safe mode)"),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("SAFE MODE (code 1)")),
        "{lines:?}"
    );
    assert_eq!(
        lines.last().map(|l| l.trim_end()),
        Some("reset log: not read in the safe mode (this boot is counted in RAM, written by the next run)"),
        "{lines:?}"
    );
    let _ = ClockSource::Hse;
    let src = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/firmware/safe_mode.rs"),
    )
    .unwrap();
    for word in [
        "Flash",
        "flash::",
        "report_boot",
        "LogPages",
        "record_boot",
        "log::",
    ] {
        let code: String = src
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect();
        assert!(
            !code.contains(word),
            "src/firmware/safe_mode.rs reaches {word}"
        );
    }
}

/// The status line is due every second period (`PeriodOutput::status_line`: 100 ms at the
/// 50 ms period): periods 2, 4, 6 and 8 of the first eight, whatever else the period does.
#[test]
fn the_status_line_is_due_every_second_period() {
    let settings = Settings::DEFAULT;
    let mut supervisor =
        Supervisor::new(&settings, PreviousRun::Clean, 0, MonitorStatus::default());
    let mut state = ThreadState::default();
    let mut board = Board {
        block: BootBlock::default().encode(),
        pets: 0,
        store: NoStore,
        pause: NoPause,
    };
    let due: Vec<u32> = (1..=8u32)
        .filter(|&k| {
            let input = PeriodInput {
                now_ms: k * PANEL_PERIOD_MS,
                ..PeriodInput::default()
            };
            period(&mut supervisor, &mut state, input, &mut board).status_line
        })
        .collect();
    assert_eq!(2 * PANEL_PERIOD_MS, 100);
    assert_eq!(due, [2, 4, 6, 8]);
}
