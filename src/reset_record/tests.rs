//! The reset record's tests: encoding, the reset flags, what the next boot reports.

use super::*;

#[test]
fn a_panic_round_trips_and_long_texts_keep_their_useful_end() {
    let rec = ResetRecord::panic("index out of bounds", "src/app.rs", 42);
    let back = ResetRecord::decode(&rec.encode()).unwrap();
    assert_eq!(back, rec);
    assert_eq!(
        (back.cause(), back.message(), back.file(), back.line_or_ms()),
        (ResetCause::Panic, "index out of bounds", "src/app.rs", 42)
    );
    let long_path =
        "/home/someone/.cargo/registry/src/index/embassy-stm32-0.6.0/src/adc/ringbuffered.rs";
    // 81 bytes; byte 64 is inside a character, so the cut falls before it.
    let long_msg = format!("a{}", "é".repeat(40));
    let rec = ResetRecord::panic(&long_msg, long_path, 7);
    let back = ResetRecord::decode(&rec.encode()).unwrap();
    assert_eq!(back.message(), format!("a{}", "é".repeat(31)));
    assert!(back.file().ends_with("src/adc/ringbuffered.rs"));
    assert!(back.file().len() <= FILE_LEN);
    let stall = ResetRecord::sample_stall(300);
    assert_eq!(ResetRecord::decode(&stall.encode()), Some(stall));
}

#[test]
fn anything_but_an_intact_record_reads_as_none() {
    let good = ResetRecord::panic("boom", "src/main.rs", 1).encode();
    for bit in 0..RESET_RECORD_LEN * 8 {
        let mut bad = good;
        bad[bit / 8] ^= 1 << (bit % 8);
        assert_eq!(ResetRecord::decode(&bad), None, "bit {bit}");
    }
    assert_eq!(ResetRecord::decode(&[0; RESET_RECORD_LEN]), None);
    assert_eq!(ResetRecord::decode(&[0xA5; RESET_RECORD_LEN]), None);
    let wd = ResetSource::IndependentWatchdog;
    assert_eq!(
        PreviousRun::at_boot(&[0; RESET_RECORD_LEN], wd),
        PreviousRun::WatchdogReset { phase: None }
    );
    assert_eq!(
        PreviousRun::at_boot(&[0; RESET_RECORD_LEN], ResetSource::Pin),
        PreviousRun::Clean
    );
    assert!(matches!(
        PreviousRun::at_boot(&good, wd),
        PreviousRun::Recorded(r) if r.cause() == ResetCause::Panic
    ));
}

#[test]
fn the_reset_flags_name_the_source_most_specific_first() {
    // RCC_CSR flags (RM0440): OBL 25, PIN 26, BOR 27, SFT 28, IWDG 29, WWDG 30, LPWR 31.
    let (obl, pin, bor, sft, iwdg, wwdg, lpwr) = (
        1 << 25,
        1 << 26,
        1 << 27,
        1 << 28,
        1 << 29,
        1 << 30,
        1u32 << 31,
    );
    let table = [
        (0, ResetSource::Unknown),
        (pin, ResetSource::Pin),
        // A power-on sets the brown-out and the pin flags.
        (pin | bor, ResetSource::PowerOnOrBrownOut),
        // Every internal reset pulses NRST: the pin flag comes with it.
        (pin | iwdg, ResetSource::IndependentWatchdog),
        (pin | sft, ResetSource::Software),
        (pin | wwdg, ResetSource::WindowWatchdog),
        (pin | obl, ResetSource::OptionBytes),
        (pin | lpwr, ResetSource::LowPower),
        // The LSI bits (0, 1) and RMVF (23) are not reset flags.
        (pin | 0b11 | 1 << 23, ResetSource::Pin),
        (pin | bor | iwdg, ResetSource::IndependentWatchdog),
    ];
    for (csr, source) in table {
        assert_eq!(ResetSource::from_csr(csr), source, "{csr:#010x}");
    }
}

#[test]
fn a_stall_or_setup_record_is_the_cause_only_after_a_watchdog_reset() {
    let wd = ResetSource::IndependentWatchdog;
    for rec in [
        ResetRecord::sample_stall(300),
        ResetRecord::setup(BootPhase::AdcSetup),
    ] {
        let bytes = rec.encode();
        assert_eq!(PreviousRun::at_boot(&bytes, wd), PreviousRun::Recorded(rec));
        for source in [
            ResetSource::Pin,
            ResetSource::PowerOnOrBrownOut,
            ResetSource::Software,
            ResetSource::Unknown,
        ] {
            let previous = PreviousRun::at_boot(&bytes, source);
            assert_eq!(
                previous,
                PreviousRun::ResetDuring {
                    record: rec,
                    source
                }
            );
            assert!(previous.failed());
        }
    }
    // A panic is reported whatever reset followed it (the watchdog or the handler's
    // software reset, or the button while the panel showed it).
    let panic = ResetRecord::panic("boom", "src/main.rs", 1);
    for source in [wd, ResetSource::Software, ResetSource::Pin] {
        assert_eq!(
            PreviousRun::at_boot(&panic.encode(), source),
            PreviousRun::Recorded(panic)
        );
    }
    let defmt = ResetRecord::defmt_panic(BootPhase::AdcSetup, 0x0800_1234);
    let back = ResetRecord::decode(&defmt.encode()).unwrap();
    assert_eq!(
        (back.cause(), back.message(), back.line_or_ms()),
        (ResetCause::DefmtPanic, "adc-setup", 0x0800_1234)
    );
    for phase in BootPhase::ALL {
        assert_eq!(BootPhase::from_number(phase.number()), Some(phase));
    }
    assert_eq!(BootPhase::from_number(BootPhase::ALL.len() as u8), None);
}

#[test]
fn the_record_a_panic_leaves_is_the_record_the_next_boot_reports() {
    use std::sync::Mutex;
    // The no-init RAM of the reset record.
    static RAM: Mutex<[u8; RESET_RECORD_LEN]> = Mutex::new([0x5A; RESET_RECORD_LEN]);
    let others = std::panic::take_hook();
    // The host's panic handler does what the firmware's does with its PanicInfo: the
    // static message and the location through `ResetRecord::on_panic` into the RAM.
    std::panic::set_hook(Box::new(|info| {
        let message = info.payload().downcast_ref::<&str>().copied();
        let location = info.location().map(|l| (l.file(), l.line()));
        *RAM.lock().unwrap() = ResetRecord::on_panic(message, location).encode();
    }));
    let line = line!() + 1;
    let literal = std::panic::catch_unwind(|| panic!("sample ring misaligned"));
    let ram_literal = *RAM.lock().unwrap();
    let formatted = std::panic::catch_unwind(|| panic!("index {}", std::hint::black_box(7)));
    let ram_formatted = *RAM.lock().unwrap();
    std::panic::set_hook(others);
    assert!(literal.is_err() && formatted.is_err());
    // The next boot (after the handler's software reset or the watchdog's).
    for source in [ResetSource::Software, ResetSource::IndependentWatchdog] {
        let PreviousRun::Recorded(rec) = PreviousRun::at_boot(&ram_literal, source) else {
            panic!("no record after a panic");
        };
        assert_eq!(
            (rec.cause(), rec.message(), rec.file(), rec.line_or_ms()),
            (
                ResetCause::Panic,
                "sample ring misaligned",
                "src/reset_record/tests.rs",
                line
            )
        );
    }
    let PreviousRun::Recorded(rec) = PreviousRun::at_boot(&ram_formatted, ResetSource::Software)
    else {
        panic!("no record after a formatted panic");
    };
    assert_eq!(
        (rec.message(), rec.line_or_ms()),
        ("(formatted message)", line + 2)
    );
}

/// `ResetRecord::panic("index out of bounds", "src/app.rs", 42)` as the former code wrote
/// it (version 1: no version or length field, the cause at byte 4).
const WRITTEN_BEFORE: &str = "444d525201130a002a000000696e646578206f7574206f6620626f756e64730000000000000000000000000000000000000000000000000000000000000000000000000000000000000000007372632f6170702e72730000000000000000000000000000000000000000000000000000000000000000000000000000621ead5a";

#[test]
fn the_header_is_the_record_modules_and_the_former_layout_reads_as_no_record() {
    let rec = ResetRecord::panic("index out of bounds", "src/app.rs", 42);
    let bytes = rec.encode();
    assert_eq!(&bytes[..8], &[b'D', b'M', b'R', b'R', 3, 0, 116, 0]);
    assert_eq!(FORMAT.open(&bytes).map(|r| r.remaining()), Ok(116));
    let old: Vec<u8> = (0..WRITTEN_BEFORE.len() / 2)
        .map(|k| u8::from_str_radix(&WRITTEN_BEFORE[2 * k..2 * k + 2], 16).unwrap())
        .collect();
    let old: [u8; RESET_RECORD_LEN] = old.try_into().unwrap();
    // Intact under its own CRC, but another header: no reason recorded, no misread.
    assert_eq!(
        monitor_core::record::crc32(&old[..124]).to_le_bytes(),
        old[124..]
    );
    assert_eq!(ResetRecord::decode(&old), None);
    assert_eq!(
        PreviousRun::at_boot(&old, ResetSource::Software),
        PreviousRun::Clean
    );
}

#[test]
fn the_brown_out_level_goes_with_the_record() {
    use crate::supply::BorLevel;
    let rec = ResetRecord::sample_stall(300);
    assert_eq!(rec.bor_level(), None);
    let back = ResetRecord::decode(&rec.encode()).unwrap();
    assert_eq!(back.bor_level(), None);
    for level in BorLevel::ALL {
        let rec =
            ResetRecord::hard_fault(None, 0x0800_0100, 0, 0, 0, 0).with_bor_level(Some(level));
        let back = ResetRecord::decode(&rec.encode()).unwrap();
        assert_eq!((back.bor_level(), back), (Some(level), rec));
    }
}

/// The record's bytes as the module docs lay them out, built by hand (the record module's
/// writer, no `ResetRecord`): `cause` at byte 8, the lengths at 9 and 10, no brown-out
/// level, texts of `message_len` and `file_len` ASCII letters.
fn laid_out(cause: u8, message_len: u8, file_len: u8) -> [u8; RESET_RECORD_LEN] {
    let mut w = FORMAT.writer::<RESET_RECORD_LEN>();
    w.bytes(&[cause, message_len, file_len, 0xFF]);
    w.u32(42);
    w.u32(0);
    let mut message = [0u8; MESSAGE_LEN];
    message.fill(b'm');
    let mut file = [0u8; FILE_LEN];
    file.fill(b'f');
    w.bytes(&message);
    w.bytes(&file);
    w.finish()
}

/// Every cause is the module docs' byte 8 (1 = panic ... 7 = the crystal failed) and reads
/// back as itself; a byte of no cause (0, 8) is no record, though its CRC holds.
#[test]
fn every_cause_is_its_documented_byte_and_reads_back_as_itself() {
    let records = [
        (
            ResetRecord::panic("boom", "src/main.rs", 1),
            1,
            ResetCause::Panic,
        ),
        (ResetRecord::sample_stall(300), 2, ResetCause::SampleStall),
        (
            ResetRecord::setup(BootPhase::Flash),
            3,
            ResetCause::SetupTimeout,
        ),
        (
            ResetRecord::defmt_panic(BootPhase::Boot, 0x0800_0200),
            4,
            ResetCause::DefmtPanic,
        ),
        (
            ResetRecord::hard_fault(None, 0x0800_0100, 0, 0, 0, 0),
            5,
            ResetCause::HardFault,
        ),
        (
            ResetRecord::setup_deadline("adc1-calibration", 20),
            6,
            ResetCause::SetupDeadline,
        ),
        (ResetRecord::clock_failure(), 7, ResetCause::ClockFailure),
    ];
    for (rec, byte, cause) in records {
        let bytes = rec.encode();
        assert_eq!(bytes[8], byte, "{cause:?}");
        let back = ResetRecord::decode(&bytes);
        assert_eq!(back.map(|r| r.cause()), Some(cause));
        assert_eq!(back, Some(rec));
    }
    // The set-up record's number is the phase's index in `BootPhase::ALL` (Flash: 1).
    assert_eq!(ResetRecord::setup(BootPhase::Flash).line_or_ms(), 1);
    for cause in [1, 7] {
        assert!(
            ResetRecord::decode(&laid_out(cause, 4, 4)).is_some(),
            "{cause}"
        );
    }
    for no_cause in [0, 8, 0xFF] {
        assert_eq!(ResetRecord::decode(&laid_out(no_cause, 4, 4)), None);
    }
}

/// The lengths' bounds are inclusive (`0..=MESSAGE_LEN`, `0..=FILE_LEN`): a message of
/// exactly 64 bytes and a file of exactly 40 are kept whole; one byte more in a length
/// field is no record.
#[test]
fn texts_of_exactly_the_longest_length_are_kept_whole_and_one_more_is_no_record() {
    let message = "m".repeat(MESSAGE_LEN);
    let file = "f".repeat(FILE_LEN);
    let rec = ResetRecord::panic(&message, &file, 9);
    let back = ResetRecord::decode(&rec.encode()).expect("a record of full-length texts");
    assert_eq!(
        (back.message(), back.file()),
        (message.as_str(), file.as_str())
    );
    let (m, f) = (MESSAGE_LEN as u8, FILE_LEN as u8);
    let full = ResetRecord::decode(&laid_out(1, m, f)).expect("the longest lengths");
    assert_eq!((full.message().len(), full.file().len()), (64, 40));
    assert_eq!(ResetRecord::decode(&laid_out(1, m + 1, f)), None);
    assert_eq!(ResetRecord::decode(&laid_out(1, m, f + 1)), None);
}

/// The stacked LR and the fault status registers as 8 upper-case hexadecimal digits each,
/// at the fixed places the doc gives (`lr=0x........ cfsr=0x........ hfsr=0x........
/// bfar=0x........`): every digit 0-9 and A-F appears.
#[test]
fn the_fault_registers_are_written_as_upper_case_hexadecimal_digits() {
    let rec = ResetRecord::hard_fault(None, 0, 0x0123_4567, 0x89AB_CDEF, 0xFEDC_BA98, 0x7654_3210);
    assert_eq!(
        rec.message(),
        "lr=0x01234567 cfsr=0x89ABCDEF hfsr=0xFEDCBA98 bfar=0x76543210"
    );
}

/// An exception's number (IPSR - 16: UsageFault, exception 6, is -10; WWDG, the G474's
/// interrupt 0, is 0; FMAC, its last, RM0440's vector table position 101; 255 the bound)
/// is written in decimal, a sign and three digits.
#[test]
fn an_exceptions_number_is_written_as_a_sign_and_three_decimal_digits() {
    for (irqn, file) in [
        (Some(-10), "exception -010"),
        (Some(-1), "exception -001"),
        (Some(0), "exception  000"),
        (Some(101), "exception  101"),
        (Some(255), "exception  255"),
        (None, "hard fault"),
    ] {
        let rec = ResetRecord::hard_fault(irqn, 0x0800_0100, 0, 0, 0, 0);
        assert_eq!(rec.file(), file, "{irqn:?}");
    }
}

/// The counts kept in RAM (`log::Pending`): a slot naming no reset's kind (6, the log's
/// "up" count, 7, 15) or no count (0, its flags set) is free, so nothing of it is counted,
/// written or taken for a safe mode; a count goes to the slot that holds its kind and
/// flags, even with a free slot before it.
#[test]
fn a_pending_slot_naming_no_kind_or_no_count_is_free() {
    use log::{Pending, Totals, PENDING_LEN};
    let slot = |what: u8, count: u16| {
        let [c0, c1] = count.to_le_bytes();
        [what, 0, c0, c1]
    };
    let mut bytes = [0u8; PENDING_LEN];
    for (b, s) in bytes.chunks_exact_mut(4).zip([
        slot(6, 1),
        slot(7 | 0x40, 2),
        slot(15 | 0x80, 3),
        slot(ResetKind::Watchdog.index() as u8 | 0xC0, 0),
    ]) {
        b.copy_from_slice(&s);
    }
    let pending = Pending::decode(&bytes);
    assert_eq!(pending, Pending::EMPTY);
    assert_eq!(pending.count(), 0);
    assert!(!pending.holds_safe_mode());
    assert_eq!(pending.added_to(Totals::default()), Totals::default());
    // A free slot, then a power-on's (kind 0, no flags) count of 2: the next power-on
    // makes it 3, in its own slot; the free one stays free.
    let mut bytes = [0u8; PENDING_LEN];
    bytes[4..8].copy_from_slice(&slot(ResetKind::PowerOn.index() as u8, 2));
    let mut pending = Pending::decode(&bytes);
    assert!(pending.add(ResetKind::PowerOn, false, false));
    let mut want = [0u8; PENDING_LEN];
    want[4..8].copy_from_slice(&slot(ResetKind::PowerOn.index() as u8, 3));
    assert_eq!(pending.encode(), want);
}
