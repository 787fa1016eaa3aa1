//! The board's scaling, encoder filter, pin names, lamp table and VDDA.
use super::*;

#[test]
fn mid_scale_is_zero_and_rails_are_full_scale() {
    let v = ChannelScale::VOLTAGE;
    assert!(v.apply(2047).abs() < 0.2 && v.apply(2048).abs() < 0.2);
    assert!((v.apply(0) + 400.0).abs() < 1e-3);
    assert!((v.apply(4095) - 400.0).abs() < 1e-3);
    let i = ChannelScale::CURRENT;
    assert!((i.apply(4095) - 10.0).abs() < 1e-4);
}

#[test]
fn code_of_inverts_apply_within_half_lsb() {
    let v = ChannelScale::VOLTAGE;
    for k in -39..=39 {
        let x = k as f32 * 10.0;
        let back = v.apply(v.code_of(x));
        assert!(
            (back - x).abs() <= VOLT_PER_LSB / 2.0 + 1e-3,
            "{x} -> {back}"
        );
    }
    assert_eq!(v.code_of(1e6), ADC_MAX_CODE);
    assert_eq!(v.code_of(-1e6), 0);
    // No code for a value that is not finite, nor through a scale of no gain: the zero's
    // code, 2047 (mid-scale's 2047.5 truncated), not a rail.
    for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(v.code_of(x), 2047, "{x}");
    }
    let dead = ChannelScale {
        per_lsb: 0.0,
        ..ChannelScale::CURRENT
    };
    assert_eq!((dead.code_of(5.0), dead.code_of(-5.0)), (2047, 2047));
    assert!(is_saturated_code(0) && is_saturated_code(4095) && !is_saturated_code(1));
}

#[test]
fn the_encoder_filter_keeps_a_quarter_of_the_shortest_edge_interval() {
    // 1024 lines at 50 rev/s: 204 800 edges/s, 4.88 us apart; a quarter is 1.22 us,
    // 207.5 clocks at 170 MHz: the longest filter within it is fDTS/32 x 6 = 192.
    assert_eq!(encoder_input_filter(1024, 50.0, 170_000_000), 14);
    // Twice the speed: 103.8 clocks -> fDTS/16 x 6 = 96 (11).
    assert_eq!(encoder_input_filter(1024, 100.0, 170_000_000), 11);
    // A slow encoder gets the longest filter, an impossible one none.
    assert_eq!(encoder_input_filter(100, 10.0, 170_000_000), 15);
    assert_eq!(encoder_input_filter(60_000, 1_000.0, 170_000_000), 0);
    assert_eq!(encoder_input_filter(0, 50.0, 170_000_000), 0);
    assert_eq!(encoder_input_filter(1024, f32::NAN, 170_000_000), 0);
    assert!(INPUT_FILTER_CLOCKS.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn pin_names_parse_and_print_back() {
    let pb12 = GpioPin {
        port: Port::B,
        number: 12,
    };
    assert_eq!(GpioPin::parse("PB12"), Some(pb12));
    assert_eq!(pb12.to_string(), "PB12");
    for bad in ["", "P", "PA", "PB16", "PB20", "PH1", "XA1", "PA1x", "pa1"] {
        assert_eq!(GpioPin::parse(bad), None, "{bad}");
    }
    for port in ['A', 'B', 'C', 'D', 'E', 'F', 'G'] {
        for n in 0..16 {
            let name = format!("P{port}{n}");
            assert_eq!(GpioPin::parse(&name).unwrap().to_string(), name);
        }
    }
}

#[test]
fn the_lamp_table_has_one_pin_per_lamp_in_panel_order() {
    for (k, lamp) in Lamp::ALL.into_iter().enumerate() {
        assert_eq!(lamp as usize, k);
        assert!(!lamp.label().is_empty() && lamp.meaning().starts_with(lamp.label()));
        for other in Lamp::ALL.into_iter().skip(k + 1) {
            assert_ne!(lamp.pin(), other.pin(), "{lamp:?} and {other:?}");
        }
    }
    assert_eq!(Lamp::ALL.first(), Some(&Lamp::Run));
    assert_eq!(Lamp::ALL.last(), Some(&Lamp::Fault));
    assert_eq!(Lamp::ALL.get(1..5), Some(&Lamp::RESIDUALS[..]));
}

#[test]
fn vdda_from_vrefint_follows_the_reference_manuals_formula() {
    // A typical calibration word (1.212 V at 3.0 V: 1655 codes) read at 3.3 V.
    let cal = 1655;
    let code = (f32::from(cal) * 3.0 / 3.3).round() as u16;
    let v = vdda_from_vrefint(code, cal).unwrap_or(0.0);
    assert!((v - 3.3).abs() < 0.005, "{v}");
    assert_eq!(ReferenceCheck::of(code, cal), ReferenceCheck::InBand(v));
    // A sagging 3.0 V supply: out of band, readings distrusted.
    let low = ReferenceCheck::of(cal, cal);
    assert_eq!(low, ReferenceCheck::OutOfBand(3.0));
    assert!(low.distrusts_readings());
    assert_eq!(ReferenceCheck::of(0, cal), ReferenceCheck::Unreadable);
    assert_eq!(
        ReferenceCheck::of(ADC_MAX_CODE, cal),
        ReferenceCheck::Unreadable
    );
    assert_eq!(ReferenceCheck::of(1500, 0), ReferenceCheck::Unreadable);
}
