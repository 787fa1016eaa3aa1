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
        motor: MOTOR_3HP.motor,
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
    assert_eq!(m.encoder, motor_source::encoder_setup(&rec));
    let cfg = booted.path.monitor().config();
    assert_eq!(cfg.encoder.counts_per_rev, 10_000);
    assert_eq!(cfg.limits.i_max, 25.0);
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
