//! The zero that drifts: the offsets re-trimmed whenever the shaft stands and the currents
//! are zero (`offset_trim`, through the sample path's front end), and the reference's
//! correction right for a front end whose zero is biased at VDDA / 2 (`board::ZeroBias`).

use super::*;
use drive_monitor::board::{CurrentCode, VoltageCode};
use drive_monitor::board::{ZeroBias, MID_SCALE_CODE, VOLT_PER_LSB, ZERO_BIAS};
use drive_monitor::offset_trim::{TrimKind, TRIM_SAMPLES};
use drive_monitor::sampling::Clipped;

/// VDDA at commissioning and now [V]: a 2.7 % drift.
const AT_COMMISSIONING: f32 = 3.30;
const NOW: f32 = 3.21;

/// One 50 Hz period of va (300 V peak around 0 V) read at VDDA [`NOW`] by a front end
/// whose zero is biased as `bias`: the swing scaled by the drift, the zero too for an
/// absolute bias.
fn va_codes(bias: ZeroBias) -> Vec<u16> {
    let drift = AT_COMMISSIONING / NOW;
    (0..200)
        .map(|k| {
            let x = 300.0 * (std::f32::consts::TAU * 50.0 * k as f32 / FS as f32).sin();
            let zero = match bias {
                ZeroBias::HalfVdda => MID_SCALE_CODE,
                ZeroBias::Absolute => MID_SCALE_CODE * drift,
            };
            (zero + x / VOLT_PER_LSB * drift).round() as u16
        })
        .collect()
}

/// The readings' mean (the DC a zero error leaves) and peak over the period [V].
fn read(path: &SamplePath, codes: &[u16]) -> (f32, f32) {
    let scale = path.sampler().front_end().voltage[0];
    let values: Vec<f32> = codes.iter().map(|c| scale.apply(*c)).collect();
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let peak = values.iter().fold(0.0f32, |m, v| m.max(*v));
    (mean, peak)
}

/// The board's front end has its zero at VDDA / 2: corrected for the drift, the zero stays
/// at 0 V and the peak at 300 V. Corrected as if the zero were absolute, the readings move
/// by about 11 V (57 codes), as the review measured. An absolute zero needs the other
/// correction, which the bias selects.
#[test]
fn the_reference_correction_keeps_a_zero_biased_at_half_vdda_where_it_is() {
    assert_eq!(ZERO_BIAS, ZeroBias::HalfVdda);
    let gain = NOW / AT_COMMISSIONING;
    for bias in [ZeroBias::HalfVdda, ZeroBias::Absolute] {
        let codes = va_codes(bias);
        let mut path = SamplePath::for_board(FS).unwrap();
        path.set_zero_bias(bias);
        path.set_reference_gain(gain);
        let (mean, peak) = read(&path, &codes);
        assert!(mean.abs() < 0.3, "{bias:?}: the zero reads {mean} V");
        assert!(
            (peak - 300.0).abs() < 1.0,
            "{bias:?}: the peak reads {peak} V"
        );
        // The other correction on the same front end.
        let other = match bias {
            ZeroBias::HalfVdda => ZeroBias::Absolute,
            ZeroBias::Absolute => ZeroBias::HalfVdda,
        };
        path.set_zero_bias(other);
        let (mean, _) = read(&path, &codes);
        assert!(
            mean.abs() > 10.0,
            "{bias:?} corrected as {other:?}: {mean} V"
        );
    }
}

/// A frame with every channel at `zero` codes (nothing on the inputs) and the encoder at
/// `count`.
fn still(zero: u16, count: u16) -> RawFrame {
    RawFrame {
        v: [VoltageCode(zero); 3],
        i: [CurrentCode(zero); 3],
        encoder_count: count,
        clipped: Clipped::NONE,
        encoder_rejects: 0,
    }
}

/// The zero drifts by 36 codes (7 V, 0.18 A) over a year; the motor stops now and then: each
/// standstill of 0.1 s re-trims the zeros in force, so the readings' zero follows the drift
/// in steps. While the shaft turns nothing is re-trimmed.
#[test]
fn the_zero_is_re_trimmed_whenever_the_shaft_stands_and_the_currents_are_zero() {
    let mut path = SamplePath::for_board(FS).unwrap();
    let mut kinds = Vec::new();
    let mut feed = |path: &mut SamplePath, frame: &RawFrame| {
        if let Some(t) = path.trim_offsets(frame) {
            kinds.push(t.kind);
        }
        path.on_frame(frame);
    };
    for _ in 0..TRIM_SAMPLES {
        feed(&mut path, &still(2048, 0));
    }
    for (stop, zero) in [2060u16, 2072, 2084].into_iter().enumerate() {
        // Running: the count moves; then a standstill at the drifted zero.
        for k in 0..500u16 {
            feed(&mut path, &still(zero, k * 13));
        }
        let before = path.sampler().front_end().current[0].offset_code;
        for _ in 0..TRIM_SAMPLES {
            feed(&mut path, &still(zero, 7_000 + stop as u16));
        }
        let after = path.sampler().front_end().current[0].offset_code;
        assert!(before < f32::from(zero) - 5.0, "{stop}: {before}");
        assert_eq!(after, f32::from(zero), "stop {stop}");
    }
    assert_eq!(
        kinds,
        [
            TrimKind::StartUp,
            TrimKind::Retrim,
            TrimKind::Retrim,
            TrimKind::Retrim
        ]
    );
    // The zero in force reads 0 A at the drifted zero.
    let scale = path.sampler().front_end().current[0];
    assert!(scale.apply(2084).abs() < 1e-3);
}

/// With the reference's correction in force (VDDA 3.21 V now against 3.30 V at
/// commissioning), the start-up trim puts the zero read now into force, for either bias:
/// the front end keeps it at commissioning's reference (an absolute zero's code times the
/// gain, one at VDDA / 2 as it is), and the correction brings it back to the code read now,
/// which then reads 0 A.
#[test]
fn a_trim_under_the_reference_correction_puts_the_zero_read_now_in_force() {
    let gain = NOW / AT_COMMISSIONING;
    for bias in [ZeroBias::HalfVdda, ZeroBias::Absolute] {
        let mut path = SamplePath::for_board(FS).unwrap();
        path.set_zero_bias(bias);
        path.set_reference_gain(gain);
        let mut kinds = Vec::new();
        for _ in 0..TRIM_SAMPLES {
            kinds.extend(path.trim_offsets(&still(2100, 0)).map(|t| t.kind));
            path.on_frame(&still(2100, 0));
        }
        assert_eq!(kinds, [TrimKind::StartUp], "{bias:?}");
        for scale in path.sampler().front_end().current {
            let zero = scale.offset_code;
            assert!((zero - 2100.0).abs() < 0.01, "{bias:?}: {zero}");
            assert!(scale.apply(2100).abs() < 1e-3, "{bias:?}: {zero}");
        }
    }
}

/// A re-trim is reported (for the log) only when it moved a zero by half a code or more: a
/// standstill at the zero in force is not, one at a code beside it is.
#[test]
fn a_re_trim_is_reported_only_when_it_moved_a_zero() {
    let mut path = SamplePath::for_board(FS).unwrap();
    // Running (`running` samples, the count moving), then a standstill at `zero`: the trims
    // reported.
    let mut window = |running: u16, zero: u16| {
        let mut kinds = Vec::new();
        let frames = (0..running).map(|k| still(zero, k * 13));
        for frame in frames.chain((0..TRIM_SAMPLES).map(|_| still(zero, 7_000))) {
            kinds.extend(path.trim_offsets(&frame).map(|t| t.kind));
            path.on_frame(&frame);
        }
        kinds
    };
    assert_eq!(window(0, 2048), [TrimKind::StartUp]);
    assert_eq!(window(500, 2048), []);
    assert_eq!(window(500, 2049), [TrimKind::Retrim]);
}
