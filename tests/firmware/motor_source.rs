//! The firmware's choice of machine at boot (`drive_monitor::motor_source`): a valid record
//! from `monitor_core::motor_record` is used; a corrupt, truncated, old or missing one falls
//! back to the built-in default, and the boot line says which.

use drive_monitor::app::{board_monitor_config, DEFAULT_MACHINE};
use drive_monitor::board::FrontEnd;
use drive_monitor::motor_source::{self, MachineSource};
use monitor_core::motor_record::{MotorRecord, RecordError, STORED_LEN};
use monitor_core::reference::MOTOR_3HP;

fn other_motor() -> MotorRecord {
    MotorRecord {
        // The record carries the equations' values; which Lm the file holds (`lm_at`)
        // is the host's saturation law's alone and not in it.
        motor: monitor_core::MotorParameters {
            lm_at: None,
            ..MOTOR_3HP.motor
        },
        supply: MOTOR_3HP.supply,
        current_full_scale_a: 25.0,
        voltage_full_scale_v: 600.0,
        current_offset_counts: [2040.0, 2050.0, 2047.5],
        voltage_offset_counts: [2047.5; 3],
        encoder_lines: 2500,
        encoder_reversed: false,
        encoder_pull_up: true,
    }
}

fn page_with(bytes: &[u8]) -> [u8; 2048] {
    let mut page = [0xFF; 2048];
    page[..bytes.len()].copy_from_slice(bytes);
    page
}

#[test]
fn a_valid_record_is_used() {
    let (rec, source) = motor_source::select(&page_with(&other_motor().to_bytes()));
    assert_eq!(source, MachineSource::Flash);
    assert_eq!(rec.motor, other_motor().motor);
    assert_eq!(source.describe(), "motor record from flash");
    let cfg = motor_source::monitor_config(&rec, 10_000);
    assert_eq!(cfg.encoder.counts_per_rev, 10_000);
    assert_eq!(cfg.limits.i_max, 2.5 * 25.0);
    let fe = motor_source::front_end(&rec);
    assert_eq!(fe.current[0].offset_code, 2040.0);
    assert_eq!(fe.current[0].per_lsb, 50.0 / 4095.0);
}

#[test]
fn corrupt_truncated_old_or_missing_records_fall_back_to_the_default() {
    let good = other_motor().to_bytes();
    let mut flipped = good;
    flipped[20] ^= 0x01;
    let mut old = good;
    old[4] = 0; // version 0
    let cases: [(&[u8], RecordError); 4] = [
        (&flipped, RecordError::Crc),
        (&good[..STORED_LEN - 1], RecordError::Truncated),
        (&old, RecordError::Version(0)),
        (&[0xFF; 2048], RecordError::Erased),
    ];
    for (bytes, why) in cases {
        let (rec, source) = motor_source::select(bytes);
        assert_eq!(source, MachineSource::Default(why));
        assert!(source.is_default());
        assert!(source.describe().starts_with("built-in default motor"));
        assert_eq!(rec.motor, DEFAULT_MACHINE.motor);
    }
}

#[test]
fn the_default_record_is_the_built_in_configuration() {
    let rec = motor_source::default_record();
    assert_eq!(
        motor_source::monitor_config(&rec, 10_000),
        board_monitor_config(10_000)
    );
    assert_eq!(motor_source::front_end(&rec), FrontEnd::DEFAULT);
}

#[test]
fn the_boot_builds_the_sample_path_and_isolator_of_the_record() {
    use drive_monitor::app::{board_isolator, SamplePath};
    // The default record gives exactly the built-in board set-up.
    let default = motor_source::default_record();
    let path = motor_source::sample_path(&default, 10_000).expect("default path");
    let board = SamplePath::for_board(10_000).expect("board path");
    assert_eq!(path.monitor().config(), board.monitor().config());
    let iso = motor_source::isolator(&default).expect("default isolator");
    let built_in = board_isolator().expect("built-in isolator");
    assert_eq!(iso.torque_base_nm(), built_in.torque_base_nm());
    // Another motor's record gives its own configuration and its own isolator.
    let rec = other_motor();
    let path = motor_source::sample_path(&rec, 10_000).expect("record path");
    let cfg = path.monitor().config();
    assert_eq!(cfg.encoder.counts_per_rev, 10_000);
    assert_eq!(cfg.limits.i_max, 2.5 * 25.0);
    assert_ne!(cfg, board.monitor().config());
    // The 3 hp machine's torque base is not the 2.2 kW one's: the isolator judges the
    // record's machine.
    let iso = motor_source::isolator(&rec).expect("record isolator");
    let (a, b) = (iso.torque_base_nm(), built_in.torque_base_nm());
    assert!((a / b - 1.0).abs() > 0.05, "{a} vs {b}");
}

#[test]
fn the_encoder_timer_is_set_up_from_the_record() {
    use drive_monitor::motor_source::EncoderSetup;
    // The default: 1024 lines counting up, 4 poles at 50 Hz (up to 50 rev/s with the
    // margin): a quarter edge interval of 207 clocks, filter fDTS/32 x 6 (192 clocks, 14);
    // 4096 x 50 / 80 000 = 2.56 counts between two triggers: 3, + 1 = 4.
    assert_eq!(
        motor_source::encoder_setup(&motor_source::default_record(), 10_000),
        EncoderSetup {
            counts_per_rev: 4096,
            invert_a: false,
            input_filter: 14,
            pull_up: true,
            max_step_per_trigger: 4,
        }
    );
    // The 3 hp record, reversed: 2500 lines at up to 60 rev/s, 70.8 clocks: fDTS/8 x 8
    // (64 clocks, 9); the direction inverted in the timer, the line count the core's too;
    // 10 000 x 60 / 80 000 = 7.5 counts between two triggers: 8, + 1 = 9.
    let rec = MotorRecord {
        encoder_reversed: true,
        ..other_motor()
    };
    let setup = motor_source::encoder_setup(&rec, 10_000);
    assert_eq!(
        setup,
        EncoderSetup {
            counts_per_rev: 10_000,
            invert_a: true,
            input_filter: 9,
            pull_up: true,
            max_step_per_trigger: 9,
        }
    );
    assert_eq!(
        setup.counts_per_rev,
        motor_source::monitor_config(&rec, 10_000)
            .encoder
            .counts_per_rev
    );
    // The pull-ups as the record says, through the record's bytes (the flash page).
    let rec = MotorRecord {
        encoder_pull_up: false,
        ..other_motor()
    };
    let (read, source) = motor_source::select(&page_with(&rec.to_bytes()));
    assert_eq!(source, MachineSource::Flash);
    assert!(!motor_source::encoder_setup(&read, 10_000).pull_up);
}

/// The front end's linear limit per channel from the record: its full scale about the
/// channel's zero, 62 codes of the amplifier's headroom inside, within the rails.
#[test]
fn the_linear_ranges_follow_the_records_offsets() {
    use drive_monitor::acquisition::LinearRange;
    let r = motor_source::linear_ranges(&motor_source::default_record());
    // Zero at 2047.5: 0 + 62 and 4095 - 62.
    let mid = LinearRange {
        low: 62,
        high: 4033,
    };
    assert_eq!((r.voltage, r.current), ([mid; 3], [mid; 3]));
    // A current channel whose zero is at 2100: its negative full scale at 52.5 codes,
    // + 62 = 114.5 -> 115 (rounded); its positive one beyond the rail, 4095 - 62.
    let rec = MotorRecord {
        current_offset_counts: [2100.0, 2047.5, 1990.0],
        ..motor_source::default_record()
    };
    let r = motor_source::linear_ranges(&rec);
    assert_eq!(
        r.current[0],
        LinearRange {
            low: 115,
            high: 4033
        }
    );
    // A zero at 1990: low 62, high 1990 + 2047.5 - 62 = 3975.5 -> 3976.
    assert_eq!(
        r.current[2],
        LinearRange {
            low: 62,
            high: 3976
        }
    );
}
