//! The firmware's boot composition (`drive_monitor::boot::boot`, what `src/firmware.rs` calls
//! with the two flash pages it read): the motor record → the machine in force → its sample
//! path, isolator and encoder set-up; the commissioning record → the thresholds and the
//! isolation baseline; the supervisor. Each failure takes its defined fallback and says so
//! (`drive_monitor::boot`'s table): a good record, an erased page, a corrupt CRC, a machine
//! the sample rate or the isolation rejects, the encoder's settings applied.

use super::*;
use drive_monitor::app::isolation_summary;
use drive_monitor::boot::{Booted, CalibrationMissing};
use drive_monitor::motor_source::{self, EncoderSetup, MachineSource};
use monitor_core::motor_record::{MotorRecord, RecordError};
use monitor_core::reference::MOTOR_3HP;
use monitor_core::ConfigCheck;

/// The 3 hp machine (not the built-in default, so a fallback cannot pass for it) with a
/// 2500-line encoder.
fn record_3hp() -> MotorRecord {
    MotorRecord {
        // The record carries the equations' values; which Lm the file holds (`lm_at`)
        // is the host's saturation law's alone and not in it.
        motor: monitor_core::MotorParameters {
            lm_at: None,
            ..MOTOR_3HP.motor
        },
        supply: MOTOR_3HP.supply,
        current_full_scale_a: 25.0,
        voltage_full_scale_v: board::VOLTAGE_FULL_SCALE_V,
        current_offset_counts: [2040.0, 2050.0, 2047.5],
        voltage_offset_counts: [board::MID_SCALE_CODE; 3],
        encoder_lines: 2500,
        encoder_reversed: false,
        encoder_pull_up: true,
    }
}

/// The boot on a motor page holding `bytes`, with `flash` as the commissioning page.
fn boot_on(bytes: &[u8], mut flash: FakeFlash) -> Booted<FlashError> {
    let page = motor_page(bytes);
    drive_monitor::boot::boot(&page, &mut flash, &SETTINGS, PreviousRun::Clean, 0)
        .expect("the built-in default is always accepted")
}

/// The RUN lamp at 1.7 s after boot with samples flowing: the default-motor mark holds it
/// lit for the first 2 s of every 10 s; without it the lamp is dark then, commissioned
/// (1 Hz blink) or not (double flash).
fn default_mark_shown(booted: &Booted<FlashError>) -> bool {
    let mut supervisor = booted.supervisor;
    let mut status = booted.path.status();
    status.samples = 10_000;
    supervisor.tick(1_700, Some(status), false).lamps.run
}

#[test]
fn a_good_record_is_the_machine_of_the_path_the_isolator_and_the_encoder() {
    let rec = record_3hp();
    let booted = boot_on(&rec.to_bytes(), FakeFlash::erased());
    let m = booted.machine;
    assert_eq!(m.source, MachineSource::Flash);
    assert_eq!(m.record, rec);
    assert_eq!(m.isolation, Ok(()));
    assert_eq!(m.encoder, motor_source::encoder_setup(&rec, 10_000));
    let cfg = booted.path.monitor().config();
    assert_eq!(cfg.encoder.counts_per_rev, 10_000);
    assert_eq!(cfg.limits.i_max, 2.5 * 25.0);
    assert_eq!(cfg.motor, MOTOR_3HP.motor.model());
    assert_eq!(
        booted.path.sampler().front_end().current[0].offset_code,
        2040.0
    );
    // The supervisor isolates against the record's machine, not the built-in one.
    let follower = booted.supervisor.isolation.as_ref().expect("an isolator");
    let expected = motor_source::isolator(&rec).expect("the record's isolator");
    assert_eq!(
        follower.isolator().torque_base_nm(),
        expected.torque_base_nm()
    );
    assert!(!default_mark_shown(&booted));
    assert_eq!(
        booted.calibration,
        Err(CalibrationMissing::Record(RecordError::Erased))
    );
}

#[test]
fn an_erased_page_or_a_corrupt_crc_boots_the_built_in_default_with_its_mark() {
    let mut corrupt = record_3hp().to_bytes();
    corrupt[40] ^= 0x01;
    for (bytes, why, line) in [
        (
            &[][..],
            RecordError::Erased,
            "built-in default motor (no record)",
        ),
        (
            &corrupt[..],
            RecordError::Crc,
            "built-in default motor (record CRC bad)",
        ),
    ] {
        let booted = boot_on(bytes, FakeFlash::holding(&old_record()));
        let m = booted.machine;
        assert_eq!(m.source, MachineSource::Default(why));
        assert_eq!(m.source.describe(), line);
        assert_eq!(m.record, motor_source::default_record());
        assert_eq!(m.isolation, Ok(()));
        assert_eq!(
            booted.path.monitor().config(),
            SamplePath::for_board(FS).unwrap().monitor().config()
        );
        assert!(default_mark_shown(&booted), "{why:?}");
        // The stored calibration is put into force whatever machine is monitored.
        assert_eq!(booted.calibration, Ok(old_record()));
        assert!(booted.path.status().commissioned);
    }
}

#[test]
fn a_machine_the_sample_rate_rejects_falls_back_to_the_default() {
    // 1.5 kHz supply: a valid record, but the core needs 8 samples per supply period at
    // least (12 kHz > the firmware's 10 kHz).
    let mut rec = record_3hp();
    rec.supply.f_hz = 1_500.0;
    assert!(MotorRecord::parse(&rec.to_bytes()).is_ok());
    let booted = boot_on(&rec.to_bytes(), FakeFlash::erased());
    assert_eq!(
        booted.machine.source,
        MachineSource::Default(RecordError::Invalid)
    );
    assert_eq!(booted.machine.record, motor_source::default_record());
    assert!(default_mark_shown(&booted));
}

#[test]
fn a_machine_the_isolation_rejects_is_monitored_by_the_lamps_with_nothing_isolated() {
    // Lm of 1e-25 H: a valid record and a machine the monitor runs, but Lm^2 is below the
    // smallest f32, so the isolation's torque scale is zero and it refuses the machine.
    let mut rec = record_3hp();
    rec.motor.lm_h = 1e-25;
    let booted = boot_on(&rec.to_bytes(), FakeFlash::holding(&old_record()));
    let m = booted.machine;
    assert_eq!(m.source, MachineSource::Flash, "the record's machine stays");
    assert_eq!(
        m.isolation.map_err(|e| e.check),
        Err(ConfigCheck::IsolationTorqueBase)
    );
    assert_eq!(booted.path.monitor().config().motor.lm_h, 1e-25);
    assert!(booted.supervisor.isolation.is_none());
    assert!(!booted.baseline_restored);
    // The status line says the isolation did not judge; the panel shows no default mark.
    assert_eq!(
        isolation_summary(booted.supervisor.isolation()).0,
        "not-judged"
    );
    assert!(!default_mark_shown(&booted));
}

#[test]
fn the_encoder_settings_of_the_record_are_applied() {
    let rec = MotorRecord {
        encoder_reversed: true,
        encoder_pull_up: false,
        ..record_3hp()
    };
    let booted = boot_on(&rec.to_bytes(), FakeFlash::erased());
    assert_eq!(
        booted.machine.encoder,
        EncoderSetup {
            counts_per_rev: 10_000,
            invert_a: true,
            input_filter: 9,
            pull_up: false,
            max_step_per_trigger: 9,
        }
    );
    // The built-in default's: 1024 lines counting up, pull-ups on.
    let booted = boot_on(&[], FakeFlash::erased());
    assert_eq!(
        booted.machine.encoder,
        EncoderSetup {
            counts_per_rev: 4096,
            invert_a: false,
            input_filter: 14,
            pull_up: true,
            max_step_per_trigger: 4,
        }
    );
}

#[test]
fn a_stored_isolation_baseline_is_restored_for_the_records_machine() {
    // A commissioning record with an isolation baseline (version 3, as a run stores it).
    let baseline = monitor_core::isolation::Baseline {
        mean: monitor_core::isolation::ParityResiduals {
            voltage_d: 0.01,
            voltage_q: -0.02,
            torque: 0.005,
        },
        ..Default::default()
    };
    let stored = CalibrationRecord {
        isolation: Some(baseline),
        ..old_record()
    };
    let booted = boot_on(&record_3hp().to_bytes(), FakeFlash::holding(&stored));
    assert_eq!(booted.calibration, Ok(stored));
    assert!(booted.baseline_restored);
    assert!(booted.path.status().commissioned);
    assert_eq!(booted.supervisor.isolation_baseline(), Some(baseline));
    // The same record with the isolation refused: the thresholds, no baseline.
    let mut rec = record_3hp();
    rec.motor.lm_h = 1e-25;
    let booted = boot_on(&rec.to_bytes(), FakeFlash::holding(&stored));
    assert_eq!(booted.calibration, Ok(stored));
    assert!(!booted.baseline_restored);
    assert_eq!(booted.supervisor.isolation_baseline(), None);
}

/// The board's flash with a torn write: a double word whose ECC does not match at
/// `torn_at` (an offset from 0x0800_0000). A read over it raises the NMI, which runs the
/// firmware's decision (`flash_ecc::nmi_action` on the `FLASH_ECCR` value the hardware
/// shows): a record page's error is latched and the read completes with the wrong bytes; a
/// fault resets the MCU (`Err(NmiReset)`).
struct TornFlash<'a> {
    motor_page: Vec<u8>,
    torn_at: u32,
    latch: &'a drive_monitor::flash_ecc::EccLatch,
    reads: u32,
}

/// The NMI ended in the fault path: the MCU reset.
#[derive(Debug, PartialEq)]
struct NmiReset;

impl drive_monitor::flash_ecc::RawFlash for TornFlash<'_> {
    type Error = NmiReset;
    fn read_raw(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), NmiReset> {
        use drive_monitor::flash_ecc::{nmi_action, NmiAction, BANK_SIZE, ECCR_BK_ECC, ECCR_ECCD};
        self.reads += 1;
        let from = (offset - board::MOTOR_RECORD_FLASH_OFFSET) as usize;
        buf.copy_from_slice(&self.motor_page[from..from + buf.len()]);
        let end = offset + buf.len() as u32;
        if (offset..end).contains(&self.torn_at) {
            let at = (self.torn_at - offset) as usize;
            buf[at] ^= 0x5A;
            // Bank 2 (the record pages), the address within the bank.
            let eccr = ECCR_ECCD | ECCR_BK_ECC | (self.torn_at - BANK_SIZE);
            match nmi_action(eccr) {
                NmiAction::RecordPageEcc(e) => self.latch.latch(e),
                NmiAction::Fault | NmiAction::ClockFailure => return Err(NmiReset),
            }
        }
        Ok(())
    }
}

/// A torn write in the motor record's page (issue 51): the read raises an ECC double
/// error and the NMI. The firmware's handler latches it and returns; the checked read
/// (`CheckedFlash::read_or_erased`, what `read_motor_page` in `src/firmware.rs` calls)
/// rejects the page, marks it bad (not read again this run) and the boot runs the
/// built-in motor, with the default-motor mark, at the first boot: no reset, no loop.
#[test]
fn an_ecc_error_in_the_motor_page_falls_back_to_the_built_in_motor_and_boots() {
    use drive_monitor::flash_ecc::{CheckedFlash, EccLatch, ReadError};
    use monitor_core::motor_record::STORED_LEN;
    let latch = EccLatch::new();
    // A good 3 hp record whose page has a torn double word in its record bytes.
    let torn_at = board::MOTOR_RECORD_FLASH_OFFSET + 40;
    let mut flash = CheckedFlash::new(TornFlash {
        motor_page: motor_page(&record_3hp().to_bytes()),
        torn_at,
        latch: &latch,
        reads: 0,
    });
    let (page, read) = flash.read_or_erased::<STORED_LEN>(&latch, board::MOTOR_RECORD_FLASH_OFFSET);
    assert_eq!(
        read,
        Err(ReadError::Ecc(drive_monitor::flash_ecc::EccError {
            offset: torn_at
        }))
    );
    assert!(flash.is_bad(board::MOTOR_RECORD_FLASH_OFFSET));
    let booted = drive_monitor::boot::boot(
        &page,
        &mut FakeFlash::holding(&old_record()),
        &SETTINGS,
        PreviousRun::Clean,
        0,
    )
    .expect("the built-in default is always accepted");
    assert_eq!(
        booted.machine.source,
        MachineSource::Default(RecordError::Erased)
    );
    assert_eq!(booted.machine.record, motor_source::default_record());
    assert!(default_mark_shown(&booted));
    assert_eq!(booted.calibration, Ok(old_record()));
    // Marked bad: a second read does not touch the flash (no second NMI).
    let (_, again) = flash.read_or_erased::<STORED_LEN>(&latch, board::MOTOR_RECORD_FLASH_OFFSET);
    assert_eq!(again, Err(ReadError::MarkedBad));
    assert_eq!(flash.raw.reads, 1);
    // The same page without the torn word is the 3 hp machine (the fallback is the ECC's).
    let mut clean = CheckedFlash::new(TornFlash {
        motor_page: motor_page(&record_3hp().to_bytes()),
        torn_at: 0,
        latch: &latch,
        reads: 0,
    });
    let (page, read) = clean.read_or_erased::<STORED_LEN>(&latch, board::MOTOR_RECORD_FLASH_OFFSET);
    assert_eq!(read, Ok(()));
    let booted = boot_on(&page, FakeFlash::erased());
    assert_eq!(booted.machine.source, MachineSource::Flash);
}
