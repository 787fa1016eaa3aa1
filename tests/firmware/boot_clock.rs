//! The clock at boot (`drive_monitor::clock::ClockSource`): a clock failure's record makes
//! the next boot run on the HSI without trying the crystal; the log's timestamps. The
//! crystal's and the PLL's bounded starts before embassy-stm32's `init`, the fallback and
//! the clock security system's register are run on a register model in
//! `tests/startup/`.

fn firmware(file: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    std::fs::read_to_string(path).unwrap()
}

/// Every defmt frame has a timestamp (the time since boot in us, embassy-time's clock).
#[test]
fn the_log_has_timestamps() {
    let src = firmware("src/firmware.rs");
    let line = src
        .lines()
        .find(|l| l.starts_with("defmt::timestamp!("))
        .expect("a defmt timestamp in src/firmware.rs");
    assert!(
        line.contains("{=u64:us}") && line.contains("Instant::now()"),
        "{line}"
    );
}

/// The clock security system (CSS): on with the crystal only; its NMI is a clock failure
/// (before an ECC error, the NMI's other source); the record it leaves makes the next boot
/// take the HSI without trying the crystal, which the panel marks as it marks a crystal
/// that did not start.
#[test]
fn a_clock_failure_is_recorded_and_the_next_boot_runs_on_the_hsi() {
    use drive_monitor::clock::{boot_source, css_on, ClockSource};
    use drive_monitor::fault_path::{self, FaultBoard, FaultEnd, FaultGuard};
    use drive_monitor::flash_ecc::{nmi_cause, NmiAction, ECCR_ECCD};
    use drive_monitor::reset_record::{
        PreviousRun, ResetCause, ResetRecord, ResetSource, RESET_RECORD_LEN,
    };
    use drive_monitor::supply::BorLevel;

    assert!(css_on(ClockSource::Hse));
    assert!(!css_on(ClockSource::Hsi) && !css_on(ClockSource::HsiAfterFailure));
    // RCC_CIFR.CSSF is bit 8 (RM0440); with an ECC flag too, the clock comes first.
    assert_eq!(nmi_cause(1 << 8, 0), NmiAction::ClockFailure);
    assert_eq!(nmi_cause(1 << 8, ECCR_ECCD), NmiAction::ClockFailure);
    assert_eq!(nmi_cause(0, 0), NmiAction::Fault);

    /// The reset record's RAM.
    struct Ram([u8; RESET_RECORD_LEN]);
    impl FaultBoard for Ram {
        fn bor_level(&mut self) -> Option<BorLevel> {
            Some(BorLevel::Level4)
        }
        fn findings(&mut self) -> u32 {
            drive_monitor::self_check::CRYSTAL_DID_NOT_START
        }
        fn write_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]) {
            self.0 = *bytes;
        }
        fn show_failed(&mut self) {}
    }
    let mut ram = Ram([0; RESET_RECORD_LEN]);
    let guard = FaultGuard::new();
    let end = fault_path::on_fault(&guard, &mut ram, ResetRecord::clock_failure());
    assert_eq!(end, FaultEnd::Recorded);
    // The watchdog resets (not petted any more); the next boot reads the record.
    let previous = PreviousRun::at_boot(&ram.0, ResetSource::IndependentWatchdog);
    let PreviousRun::Recorded(rec) = previous else {
        panic!("{previous:?}");
    };
    assert_eq!(rec.cause(), ResetCause::ClockFailure);
    // The run's self-check findings go with the record.
    assert_eq!(
        rec.findings(),
        drive_monitor::self_check::CRYSTAL_DID_NOT_START
    );
    assert!(previous.clock_failed());
    let mut tried = false;
    let source = boot_source(previous.clock_failed(), || {
        tried = true;
        ClockSource::Hse
    });
    assert_eq!(source, ClockSource::HsiAfterFailure);
    assert!(!tried, "the crystal that failed is not started again");
    assert_eq!(source.sysclk_hz(), 170_000_000);
    // A clean boot tries the crystal.
    let clean = PreviousRun::at_boot(&[0; RESET_RECORD_LEN], ResetSource::PowerOnOrBrownOut);
    assert!(!clean.clock_failed());
    assert_eq!(
        boot_source(clean.clock_failed(), || ClockSource::Hse),
        ClockSource::Hse
    );
}
