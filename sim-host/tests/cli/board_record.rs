//! `sim-host board-record`: the host's writer and the core's parser (the one the firmware
//! runs) agree, and the command refuses bad input with one line.

use monitor_core::motor_record::{MotorRecord, RecordError, STORED_LEN};
use monitor_io::params::ParamFile;
use std::path::Path;
use std::process::{Command, Output};

fn sim_host(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("sim-host runs")
}

#[test]
fn round_trip_through_the_cli_gives_the_same_parameters() {
    let dir = tempfile::tempdir().expect("temp dir");
    // The 3 hp machine: not the firmware's built-in default, so a fallback cannot pass.
    let params = ParamFile::reference_3hp();
    std::fs::write(dir.path().join("p.toml"), params.to_toml_string()).expect("write");
    let out = sim_host(
        &[
            "board-record",
            "p.toml",
            "--out",
            "motor.bin",
            "--current-full-scale-a",
            "25",
            "--voltage-offset-counts",
            "2040.25",
            "--encoder-lines",
            "2500",
            "--encoder-reversed",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(dir.path().join("motor.bin")).expect("record written");
    assert_eq!(bytes.len(), STORED_LEN);
    let record = MotorRecord::parse(&bytes).expect("the core accepts the host's record");
    // The record carries the equations' values; which Lm the file holds (`lm_at`) is the
    // host's saturation law's alone and not in it.
    let motor = monitor_core::MotorParameters {
        lm_at: None,
        ..params.motor
    };
    assert_eq!(record.motor, motor);
    assert_eq!(record.supply, params.supply);
    assert_eq!(record.current_full_scale_a, 25.0);
    assert_eq!(record.voltage_full_scale_v, 400.0);
    assert_eq!(record.current_offset_counts, [2047.5; 3]);
    assert_eq!(record.voltage_offset_counts, [2040.25; 3]);
    assert_eq!(record.encoder_lines, 2500);
    assert!(record.encoder_reversed);
    assert!(record.encoder_pull_up, "pull-ups on unless asked off");

    // A flipped bit and a truncated file are refused by the same parser.
    let mut flipped = bytes.clone();
    flipped[40] ^= 0x10;
    assert_eq!(MotorRecord::parse(&flipped), Err(RecordError::Crc));
    assert_eq!(
        MotorRecord::parse(&bytes[..STORED_LEN - 2]),
        Err(RecordError::Truncated)
    );
}

#[test]
fn the_encoder_pull_ups_are_written_off_when_asked() {
    let dir = tempfile::tempdir().expect("temp dir");
    let params = ParamFile::reference_3hp();
    std::fs::write(dir.path().join("p.toml"), params.to_toml_string()).expect("write");
    let out = sim_host(
        &[
            "board-record",
            "p.toml",
            "--out",
            "motor.bin",
            "--encoder-no-pull-up",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(dir.path().join("motor.bin")).expect("record written");
    let record = MotorRecord::parse(&bytes).expect("the core accepts the host's record");
    assert!(!record.encoder_pull_up && !record.encoder_reversed);
    // Bit 1 of the encoder flags word at offset 126, version 1 as before.
    assert_eq!(bytes[126..128], [2, 0]);
    assert_eq!(bytes[4..6], [1, 0]);
}

#[test]
fn refuses_to_overwrite_the_input_and_bad_values_in_one_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let toml = ParamFile::reference_2p2kw().to_toml_string();
    std::fs::write(dir.path().join("p.toml"), &toml).expect("write");
    let out = sim_host(&["board-record", "p.toml", "--out", "p.toml"], dir.path());
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("overwrite"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("p.toml")).expect("read"),
        toml
    );

    let out = sim_host(
        &[
            "board-record",
            "p.toml",
            "--out",
            "m.bin",
            "--encoder-lines",
            "0",
        ],
        dir.path(),
    );
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(!dir.path().join("m.bin").exists());
}
