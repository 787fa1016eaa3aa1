//! The application's settings and the board's configuration.
use super::*;

#[test]
fn settings_out_of_range_are_named() {
    assert_eq!(Settings::DEFAULT.validate(), Ok(()));
    for rate in [0, 7_000, 10_050, 3_000_000] {
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
