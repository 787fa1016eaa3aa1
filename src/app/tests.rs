//! The application's settings and the board's configuration.
use super::*;

#[test]
fn settings_out_of_range_are_named() {
    assert_eq!(Settings::DEFAULT.validate(), Ok(()));
    // 0; rates that do not divide the 1 MHz timestamp clock; 3 125 Hz and 40 Hz divide it
    // (320 and 25 000 ticks) but are no multiple of the 100 Hz status rate.
    for rate in [0, 7_000, 10_050, 3_000_000, 3_125, 40] {
        let s = Settings {
            sample_rate_hz: rate,
            ..Settings::DEFAULT
        };
        assert_eq!(s.validate(), Err(SettingsError::SampleRate), "{rate}");
    }
    for d in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let s = Settings {
            commissioning_duration_s: d,
            ..Settings::DEFAULT
        };
        assert_eq!(s.validate(), Err(SettingsError::CommissioningDuration));
    }
    let s = Settings {
        commissioning_stall_ms: 0,
        ..Settings::DEFAULT
    };
    assert_eq!(s.validate(), Err(SettingsError::CommissioningStall));
}

#[test]
fn board_config_is_valid() {
    let s = Settings::DEFAULT;
    assert!(board_monitor_config(s.sample_rate_hz).validate().is_ok());
    assert!(SamplePath::for_board(s.sample_rate_hz).is_ok());
    assert_eq!(s.status_every(), 100);
    // The stall time is shorter than the core's gate timeout (see the procedure).
    let gate_ms = board_monitor_config(s.sample_rate_hz).gate_timeout_s * 1000.0;
    assert!((s.commissioning_stall_ms as f32) < gate_ms);
}

#[test]
fn another_sample_rate_goes_through_the_same_configuration() {
    let path = SamplePath::for_board(20_000).unwrap();
    assert_eq!(path.monitor().config().sample_rate_hz, 20_000.0);
    assert_eq!(path.sampler().ticks_per_sample(), 50);
    assert!(SamplePath::for_board(7_000).is_err());
}

/// The supervisor hands the brown-out level's mark to the panel: with the level below the
/// goal the RUN lamp is lit from 2.5 s to 4.5 s of every 10 s (and dark just before), not
/// without.
#[test]
fn the_supervisor_shows_the_brown_out_mark_while_the_level_is_below_the_goal() {
    let run_lamp = |below: bool| {
        let mut s = Supervisor::new(
            &Settings::DEFAULT,
            PreviousRun::Clean,
            0,
            MonitorStatus::default(),
        );
        s.set_bor_below_goal(below);
        (0..200u32)
            .map(|k| {
                let status = MonitorStatus {
                    samples: (k + 1) * 500,
                    ..MonitorStatus::default()
                };
                s.tick(k * PANEL_PERIOD_MS, Some(status), false).lamps.run
            })
            .collect::<Vec<bool>>()
    };
    let marked = run_lamp(true);
    let plain = run_lamp(false);
    // Ticks of 50 ms: 2.5 s .. 4.5 s is ticks 50..90 (and 250..290 ten seconds later).
    assert!(marked[50..90].iter().all(|on| *on), "{marked:?}");
    assert!(marked[40..50].iter().all(|on| !on));
    assert!(!plain[50..90].iter().all(|on| *on));
}

/// The log names each command, each its own name, and says why one was refused, each
/// refusal its own: the sample path's refusals as the core gives them (a bad duration, a run
/// already active, a cancel of a run not learning), a report of an older run, a calibration
/// out of the core's range.
#[test]
fn each_command_is_named_and_each_refusal_says_why() {
    let record = CalibrationRecord::from(monitor_core::Calibration::default());
    let commands = [
        (Command::StartCommissioning { duration_s: 10.0 }, "start"),
        (Command::CancelCommissioning { run: 1 }, "cancel"),
        (
            Command::CalibrationStored {
                run: 1,
                stored: None,
            },
            "stored",
        ),
        (Command::SetCalibration(record), "set"),
        (Command::PauseAcquisition, "pause"),
        (Command::ReferenceGain(1.0), "reference"),
    ];
    for (k, (command, what)) in commands.iter().enumerate() {
        assert!(command.name().contains(what), "{command:?}");
        for (other, _) in &commands[k + 1..] {
            assert_ne!(command.name(), other.name(), "{command:?} {other:?}");
        }
    }
    let mut path = SamplePath::for_board(Settings::DEFAULT.sample_rate_hz).unwrap();
    let start = |d| Command::StartCommissioning { duration_s: d };
    let duration = path.command(start(-1.0)).unwrap_err();
    path.command(start(10.0)).unwrap();
    let busy = path.command(start(10.0)).unwrap_err();
    let not_learning = path
        .command(Command::CancelCommissioning { run: 99 })
        .unwrap_err();
    let bad = MonitorConfig {
        sample_rate_hz: 0.0,
        ..board_monitor_config(Settings::DEFAULT.sample_rate_hz)
    };
    let calibration = CommandError::Calibration(bad.validate().unwrap_err());
    let stale = CommandError::Commissioning(monitor_core::CommissioningError::StaleRun);
    let said = [
        (duration, "duration"),
        (busy, "active"),
        (stale, "older run"),
        (not_learning, "not learning"),
        (calibration, "range"),
    ];
    for (k, (error, why)) in said.iter().enumerate() {
        let text = error.describe();
        assert!(text.contains(why), "{error:?}: {text}");
        for (other, _) in &said[k + 1..] {
            assert_ne!(text, other.describe(), "{error:?} {other:?}");
        }
    }
}

/// Before any sample no fault is probable: the status names no candidate, top or second
/// (a fault of probability 0 is none).
#[test]
fn before_any_sample_the_status_names_no_candidate() {
    let status = SamplePath::for_board(Settings::DEFAULT.sample_rate_hz)
        .unwrap()
        .status();
    assert_eq!((status.top, status.second), (None, None));
}

/// The status's second candidate is the most probable fault after the top one, not the
/// first after it in [`Fault::ALL`]'s order, and of two equally probable the first, as the
/// top is: core outputs with three and four positive probabilities, the runner-up after
/// a less probable one, before and after the top.
#[test]
fn the_second_candidate_is_the_runner_up_not_the_first_named() {
    use monitor_core::{Fault, MonitorOutput};
    let f = Fault::ALL;
    let cases: [(&[f32], (usize, usize)); 4] = [
        (&[0.1, 0.3, 0.6], (2, 1)),
        (&[0.05, 0.6, 0.1, 0.25], (1, 3)),
        (&[0.2, 0.1, 0.3, 0.4], (3, 2)),
        (&[0.3, 0.4, 0.3], (1, 0)),
    ];
    for (given, (top, second)) in cases {
        let mut o = MonitorOutput::default();
        o.diagnosis.probabilities[..given.len()].copy_from_slice(given);
        let want = (Some((f[top], given[top])), Some((f[second], given[second])));
        assert_eq!(sample_path::candidates(&o), want, "{given:?}");
    }
}

/// A start-up offset out of bound flags its sensor in every status thread mode takes from
/// then on (the panel's "input invalid", the status line's `sens=`), the other sensor not;
/// a second trim with the other sensor out of bound adds it, and a channel in bound clears
/// nothing (the flag holds until the next boot).
#[test]
fn an_offset_out_of_bound_flags_its_sensor_in_every_status() {
    use crate::offset_trim::{ChannelTrim, TrimKind, TrimResult};
    let in_bound = ChannelTrim::Trimmed(2047.5);
    let mut trim = TrimResult {
        kind: TrimKind::StartUp,
        voltage: [in_bound; 3],
        current: [in_bound; 3],
    };
    let mut s = Supervisor::new(
        &Settings::DEFAULT,
        PreviousRun::Clean,
        0,
        MonitorStatus::default(),
    );
    let flags = |s: &mut Supervisor, k: u32| {
        let status = MonitorStatus {
            samples: (k + 1) * 500,
            ..MonitorStatus::default()
        };
        s.tick(k * PANEL_PERIOD_MS, Some(status), false);
        let f = s.latest().sensor_fault;
        (f.voltage, f.current)
    };
    s.set_offset_fault(&trim);
    assert_eq!(flags(&mut s, 0), (false, false));
    // Voltage b's zero 300 codes from mid-scale: beyond `MAX_OFFSET_CODES` (100).
    trim.voltage[1] = ChannelTrim::OutOfBound(2347.5);
    s.set_offset_fault(&trim);
    assert_eq!(flags(&mut s, 1), (true, false));
    assert_eq!(flags(&mut s, 2), (true, false));
    let current_only = TrimResult {
        current: [in_bound, in_bound, ChannelTrim::OutOfBound(1700.0)],
        voltage: [in_bound; 3],
        ..trim
    };
    s.set_offset_fault(&current_only);
    assert_eq!(flags(&mut s, 3), (true, true));
}

/// After a failed run the panel shows "monitor failed" for [`FAILED_BOOT_SHOW_MS`] (5 s)
/// from the boot and ends the show at the first tick at or after that, whatever the ticks'
/// phase against the boot and across the millisecond clock's wrap.
#[test]
fn the_failed_boots_show_ends_at_the_first_tick_after_five_seconds() {
    for boot_ms in [0u32, 3, u32::MAX - 1_000] {
        let mut s = Supervisor::new(
            &Settings::DEFAULT,
            PreviousRun::WatchdogReset { phase: None },
            boot_ms,
            MonitorStatus::default(),
        );
        for k in 0..200u32 {
            // Ticks 20 ms out of phase with the boot: none falls on 5 000 ms exactly.
            let since_boot = 20 + k * PANEL_PERIOD_MS;
            let status = MonitorStatus {
                samples: (k + 1) * 500,
                ..MonitorStatus::default()
            };
            let mode = s
                .tick(boot_ms.wrapping_add(since_boot), Some(status), false)
                .mode;
            let showing = since_boot < FAILED_BOOT_SHOW_MS;
            assert_eq!(mode == Mode::Failed, showing, "{boot_ms} + {since_boot} ms");
        }
    }
}

/// The VDDA of the record loaded at boot goes into force for the reference's correction:
/// the supervisor's correction holds it, and a later VDDA 2 % lower (in band) puts a gain
/// of 0.98 into force.
#[test]
fn the_records_vdda_goes_into_force_for_the_correction() {
    let mut record = CalibrationRecord::from(monitor_core::Calibration::default());
    record.vdda_v = Some(3.3);
    let mut s = Supervisor::new(
        &Settings::DEFAULT,
        PreviousRun::Clean,
        0,
        MonitorStatus::default(),
    );
    s.restore_reference(&record);
    assert_eq!(s.reference_correction().commissioned_v(), Some(3.3));
    s.observe_reference(crate::board::ReferenceCheck::InBand(3.234), 0);
    let status = MonitorStatus {
        samples: 500,
        ..MonitorStatus::default()
    };
    let gain = s.tick(PANEL_PERIOD_MS, Some(status), false).reference_gain;
    assert!(gain.is_some_and(|g| (g - 0.98).abs() < 1e-4), "{gain:?}");
    assert!((s.reference_correction().in_force() - 0.98).abs() < 1e-4);
}
