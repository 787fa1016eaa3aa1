//! Tests of the channel mapping ([`super`]): units, the `[columns]` table, suggestions.

use super::*;

#[test]
fn units_and_factors() {
    assert_eq!(
        ChannelUnit::parse(Column::Time, "ms"),
        Ok(ChannelUnit::Milliseconds)
    );
    assert_eq!(
        ChannelUnit::parse(Column::Time, "µs"),
        Ok(ChannelUnit::Microseconds)
    );
    assert_eq!(
        ChannelUnit::parse(Column::Time, "us"),
        Ok(ChannelUnit::Microseconds)
    );
    assert_eq!(
        ChannelUnit::parse(Column::Ia, "mA"),
        Ok(ChannelUnit::Milliamperes)
    );
    let e = ChannelUnit::parse(Column::Ia, "mV")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("'mV'") && e.contains("ia_A") && e.contains("A, mA"),
        "{e}"
    );
    assert!(ChannelUnit::parse(Column::Speed, "Hz").is_err());
    assert_eq!(
        ChannelUnit::Rpm.factor(2) * 1500.0,
        1500.0 * std::f64::consts::TAU / 60.0
    );
    // 50 Hz electrical on a 4-pole machine: 25 rev/s, 157.08 rad/s.
    assert!((ChannelUnit::ElectricalHz.factor(2) * 50.0 - 157.079_632_7).abs() < 1e-6);
    assert_eq!(ChannelUnit::Kilovolts.factor(2), 1000.0);
}

#[test]
fn a_channel_maps_to_one_column() {
    let mut m = ColumnMapping::new(2);
    m.set(Column::Ia, "I", None).unwrap();
    let e = m.set(Column::Ib, "I", None).unwrap_err();
    assert_eq!(
        e,
        ColumnsError::SameChannel {
            first: Column::Ia,
            second: Column::Ib,
            name: "I".into()
        }
    );
    assert!(
        e.to_string()
            .contains("ia_A and ib_A both name channel 'I'"),
        "{e}"
    );
    let e = m
        .set(Column::Va, "U1", Some(ChannelUnit::Amperes))
        .unwrap_err()
        .to_string();
    assert!(e.contains("va_V") && e.contains("'A'"), "{e}");
}

#[test]
fn a_table_of_the_parameter_file() {
    let entry = |name: &str, unit: Option<&str>| crate::params::ColumnEntry {
        name: Some(name.into()),
        unit: unit.map(Into::into),
        ..Default::default()
    };
    let mut t = ColumnsTable::new();
    t.insert("wm_rad_s".into(), entry("n", Some("Hz_el")));
    t.insert("ia_A".into(), entry("ib_A", None));
    let e = ColumnMapping::from_table(&t, 2).unwrap_err().to_string();
    assert!(e.contains("ia_A and ib_A both name channel 'ib_A'"), "{e}");
    // A swap of two phases is fine.
    t.insert("ib_A".into(), entry("ia_A", None));
    let m = ColumnMapping::from_table(&t, 2).unwrap();
    assert_eq!(m.name_of(Column::Ib), "ia_A");
    assert_eq!(m.unit_of(Column::Speed), Some(ChannelUnit::ElectricalHz));
    assert_eq!(m.name_of(Column::Time), "t_s");
}

#[test]
fn the_closest_channel() {
    let found: Vec<String> = ["t", "Ia", "Ib", "Ic", "Va", "Vb", "Vc", "speed_rpm"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(closest(Column::Ia, "ia_A", &found), Some("Ia"));
    assert_eq!(closest(Column::Ic, "ic_A", &found), Some("Ic"));
    assert_eq!(closest(Column::Time, "t_s", &found), Some("t"));
    assert_eq!(
        closest(Column::Speed, "wm_rad_s", &found),
        Some("speed_rpm")
    );
    assert_eq!(closest(Column::Encoder, "enc_count", &found), None);
    let other: Vec<String> = vec!["Time".into(), "Strom 1".into()];
    assert_eq!(closest(Column::Time, "t_s", &other), Some("Time"));
}

#[test]
fn the_near_names_of_a_misspelt_one() {
    let known = ["load_torque", "core_loss", "saturation", "rs_temperature"];
    assert_eq!(near_names("load_torq", &known), ["load_torque"]);
    assert_eq!(near_names("Load-Torque", &known), ["load_torque"]);
    assert_eq!(near_names("satration", &known), ["saturation"]);
    assert!(near_names("xyz", &known).is_empty());
}
