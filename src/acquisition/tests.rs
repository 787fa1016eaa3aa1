//! The acquisition's tests: geometry, latency budget, oversampling, filter, clip and
//! encoder checks.
use super::*;

#[test]
fn the_geometry_fits_the_period() {
    assert_eq!(RING_LEN, 144);
    assert_eq!(HALF_LEN, 24);
    assert_eq!(conversion_ns(), 870);
    assert!(sequence_ns() < 12_500);
    assert_eq!(trigger_rate_hz(10_000), 80_000);
    assert!(fits(10_000));
    // 20 kHz: 6.25 us between triggers, less than a sequence held up by VREFINT.
    assert!(!fits(20_000));
}

/// The ring's depth from the budget, against the sums by hand: one sample's work is
/// 918 + 211 + 784 + 100 = 2 013 instructions, 4 227.3, 4 228 cycles at 2.1; the frame
/// 9 400 x 268 / 201 = 12 533.3, 12 534 instructions, 26 321.4, 26 322 cycles; with 30 +
/// 400 + 1 500 + 2 000 a half's samples are processed at worst 34 480, 38 708 and 42 936
/// cycles after its request with 1, 2, 3 samples per half (the processing latency). The
/// depth follows from the lap case, the copy at 2.6 cycles an instruction.
#[test]
fn the_ring_depth_follows_from_the_latency_budget() {
    assert_eq!(sample_period_cycles(10_000), 17_000);
    assert_eq!(LOG_FRAME_INSTRUCTIONS, 12_534);
    assert_eq!(LOG_FRAME_CYCLES, 26_322);
    assert_eq!(worst_latency_cycles(1), 34_480);
    assert_eq!(worst_latency_cycles(2), 38_708);
    assert_eq!(worst_latency_cycles(3), 42_936);
    // The lap case (2.6 cycles an instruction): the frame 12 534 x 2.6 = 32 588.4, 32 589;
    // a sample's copy 100 x 2.6 = 260; with 3 930 of wake-up the copy is done 36 779,
    // 37 039 and 37 299 cycles after the request with 1, 2, 3 samples per half. The DMA
    // writes a half's first word again 9, 17, 25 triggers of 2 125 cycles after its start,
    // less two conversions of 147: 18 831, 35 831, 52 831 cycles after its completion.
    assert_eq!(LAP_FRAME_CYCLES, 32_589);
    assert_eq!(lap_latency_cycles(1), 36_779);
    assert_eq!(lap_latency_cycles(2), 37_039);
    assert_eq!(lap_latency_cycles(3), 37_299);
    assert_eq!(conversion_cycles(), 147);
    assert_eq!(lap_slack_cycles(10_000, 1), 18_831);
    assert_eq!(lap_slack_cycles(10_000, 2), 35_831);
    assert_eq!(lap_slack_cycles(10_000, 3), 52_831);
    assert!(!ring_fits(10_000, 1));
    assert!(!ring_fits(10_000, 2));
    assert!(ring_fits(10_000, 3));
    assert_eq!(SAMPLES_PER_HALF, 3);
    assert_eq!(DMA_HALF_LEN, 72);
    // A slower rate needs a shallower ring (5 kHz: 4 250 cycles a trigger, 37 956 of slack
    // with one sample per half against 36 779); a faster one a deeper one.
    assert_eq!(samples_per_half_for(5_000), 1);
    assert!(samples_per_half_for(20_000) > 3);
}

/// An inrush peak clipped on two of a sample's eight conversions: the mean is below
/// the rail (the former check on the mean, `is_saturated_code`, passes it), the check of
/// each conversion catches it; within the range nothing is flagged, at its edges both
/// ends are.
#[test]
fn a_clip_on_two_of_eight_conversions_is_caught_where_the_mean_is_not() {
    let mut half = [2048u16; HALF_LEN];
    for (k, seq) in half.chunks_exact_mut(CHANNELS).enumerate() {
        seq[1] = if k == 3 || k == 4 { 4095 } else { 3000 };
    }
    let mean = average_half(&half)[1];
    assert_eq!(mean, 3274, "(2 x 4095 + 6 x 3000) / 8");
    assert!(mean > 0 && mean < 4095, "the mean is no rail code");
    let rails = [LinearRange::RAILS; CHANNELS];
    let (sums, n, clipped) = sum_half_clipped(&half, &rails);
    assert!(clipped);
    assert_eq!((sums, n), sum_half(&half));
    // An amplifier that clips 62 codes before the rails: a conversion at 4040 is beyond
    // its linear range though no rail code.
    let amp = LinearRange {
        low: 62,
        high: 4033,
    };
    let mut near = [2048u16; HALF_LEN];
    near[7] = 4040;
    assert!(!sum_half_clipped(&near, &rails).2);
    assert!(sum_half_clipped(&near, &[amp; CHANNELS]).2);
    // Edges: `low` and `high` clip, one code inside does not; on every channel.
    for ch in 0..CHANNELS {
        for (code, clips) in [
            (62, true),
            (63, false),
            (4032, false),
            (4033, true),
            (0, true),
        ] {
            let mut h = [2048u16; HALF_LEN];
            h[CHANNELS * 5 + ch] = code;
            assert_eq!(
                sum_half_clipped(&h, &[amp; CHANNELS]).2,
                clips,
                "{ch} {code}"
            );
            assert_eq!(amp.clips(code), clips);
        }
    }
}

/// A clip is held through the filter's memory: the clipped sample and the 16 after it.
#[test]
fn a_clip_is_held_for_the_filters_memory() {
    let mut hold = ClipHold::default();
    assert_eq!(hold.step([false, false]), [false, false]);
    assert_eq!(hold.step([false, true]), [false, true]);
    let flagged = (0..40).take_while(|_| hold.step([false, false])[1]).count();
    assert_eq!(flagged, usize::from(CLIP_HOLD_SAMPLES));
    assert_eq!(hold.step([false, false]), [false, false]);
    // The filter's first stage keeps (3/4)^16 = 1.0 % of the clipped sample by then.
    assert!(0.75f64.powi(i32::from(CLIP_HOLD_SAMPLES)) < 0.011);
}

/// Motion up to the maximum speed passes; a glitch beyond it is rejected and the counts
/// stay those of the motion (a spike: two rejects, the motion's counts exactly; a lasting
/// jump: one, taken out of every later count); after a restart the first count is taken
/// as it is.
#[test]
fn encoder_steps_beyond_the_maximum_speed_are_rejected_and_do_not_move_the_count() {
    // 4 096 counts, twice a 4-pole machine's 25 rev/s, 80 kHz: 2.56 counts a trigger.
    assert_eq!(max_step_per_trigger(4_096, 50.0, 80_000), 4);
    assert_eq!(max_step_per_trigger(4_096, 0.0, 80_000), 1);
    assert_eq!(max_step_per_trigger(4_096, f32::NAN, 80_000), 1);
    let mut check = EncoderCheck::new(4);
    // 3 counts a trigger, wrapping the 16-bit counter: nothing rejected.
    let mut counts: Vec<u16> = (0..24u16).map(|k| 65_500u16.wrapping_add(3 * k)).collect();
    let before = counts.clone();
    assert_eq!(check.check_sample(&mut counts[..8]), 0);
    assert_eq!(check.check_sample(&mut counts[8..]), 0);
    assert_eq!(counts, before);
    // A spike of +200 on one count.
    let mut spike: Vec<u16> = (0..8u16).map(|k| 100 + 3 * k).collect();
    spike[4] += 200;
    let mut check = EncoderCheck::new(4);
    assert_eq!(check.check_sample(&mut spike), 2);
    assert_eq!(spike, [100, 103, 106, 109, 112, 115, 118, 121]);
    // A lasting jump of -500 (edges lost): one reject, the later counts shifted back.
    let mut jump: Vec<u16> = (0..8u16).map(|k| 1_000 + 3 * k).collect();
    for c in &mut jump[3..] {
        *c -= 500;
    }
    let mut check = EncoderCheck::new(4);
    assert_eq!(check.check_sample(&mut jump), 1);
    assert_eq!(
        jump,
        [1_000, 1_003, 1_006, 1_009, 1_012, 1_015, 1_018, 1_021]
    );
    // After a gap the shaft moved: the first count after a restart is no glitch (the
    // -500 of the lost edges stays taken out: +500).
    check.restart();
    let mut after = [9_000u16, 9_003];
    assert_eq!(check.check_sample(&mut after), 0);
    assert_eq!(after, [9_500, 9_503]);
}

/// A sample's count is the mean of its latched counts, across the counter's wrap and
/// backwards too.
#[test]
fn a_samples_count_is_the_mean_of_its_latched_counts() {
    assert_eq!(sample_count(&[100, 102, 104, 106, 108, 110, 112, 114]), 107);
    assert_eq!(sample_count(&[65_534, 65_535, 0, 1]), 0);
    assert_eq!(
        sample_count(&[3, 2, 1, 0, 65_535, 65_534, 65_533, 65_532]),
        0
    );
    assert_eq!(sample_count(&[7]), 7);
    assert_eq!(sample_count(&[]), 0);
}

#[test]
fn the_average_is_per_channel_and_rounds() {
    let mut half = [0u16; HALF_LEN];
    for (k, seq) in half.chunks_exact_mut(CHANNELS).enumerate() {
        seq.copy_from_slice(&[100 + k as u16, 2000, 4095 - (k as u16 % 2)]);
    }
    // a: 100..=107, mean 103.5 -> 104; c: 4095 and 4094 alternating, 4094.5 -> 4095.
    assert_eq!(average_half(&half), [104, 2000, 4095]);
    assert_eq!(average_half(&[]), [0, 0, 0]);
}

/// The filter against an independent model: a one-pole cascade in f64 on a 50 Hz
/// sinusoid plus a 4 kHz ripple; the 50 Hz amplitude is kept (the gain restored), the
/// ripple falls to the cascade's gain, and the encoder count is held back 4 samples.
#[test]
fn the_filter_keeps_the_fundamental_and_takes_the_ripple_out() {
    let fs = 10_000.0_f64;
    let mut f = PwmFilter::new(10_000, 50.0);
    let (mut out50, mut out_ripple) = (Vec::new(), Vec::new());
    for k in 0..4_000u32 {
        let t = f64::from(k) / fs;
        let fund = 1000.0 * (std::f64::consts::TAU * 50.0 * t).sin();
        let ripple = 300.0 * (std::f64::consts::TAU * 4_000.0 * t).sin();
        let code = |x: f64| ((2048.0 + x) * 8.0).round() as u32;
        let sum = code(fund + ripple);
        let (v, _, count) = f.step([sum; 3], [code(0.0); 3], 8, k as u16);
        if k >= 4 {
            assert_eq!(count, (k - 4) as u16);
        }
        if k >= 2_000 {
            out50.push((t, f64::from(v[0]) - 2048.0));
            out_ripple.push(f64::from(v[0]) - 2048.0);
        }
    }
    // The 50 Hz amplitude by a DFT over the last 0.2 s (10 periods).
    let (mut re, mut im) = (0.0, 0.0);
    for &(t, y) in &out50 {
        re += 2.0 * y * (std::f64::consts::TAU * 50.0 * t).cos() / out50.len() as f64;
        im += 2.0 * y * (std::f64::consts::TAU * 50.0 * t).sin() / out50.len() as f64;
    }
    let amp = (re * re + im * im).sqrt();
    assert!((amp - 1000.0).abs() < 2.0, "{amp}");
    // The ripple left: the cascade's gain at 4 kHz, |a/(1 - (1-a) e^{-jw})| for a =
    // 1/4 and 1/2 at w = 0.8 pi: 0.150 x 0.348 = 0.052 (x the gain restored, 1.007).
    let ripple_gain = |a: f64| {
        let w = std::f64::consts::TAU * 0.4;
        let (re, im) = (1.0 - (1.0 - a) * w.cos(), (1.0 - a) * w.sin());
        a / (re * re + im * im).sqrt()
    };
    let expected = 300.0 * ripple_gain(0.25) * ripple_gain(0.5);
    let residual: Vec<f64> = out50
        .iter()
        .map(|&(t, y)| y - amp * ((std::f64::consts::TAU * 50.0 * t) + re.atan2(im)).sin())
        .collect();
    let peak = residual.iter().fold(0.0f64, |m, r| m.max(r.abs()));
    assert!(
        peak < expected * 1.1 + 1.5 && peak > expected * 0.8,
        "{peak} against {expected}"
    );
    assert_eq!(out_ripple.len(), 2_000);
}

/// A sinusoid at a multiple of the sample rate (what folds onto DC and the
/// fundamental) averages to nothing; one at 50 Hz passes.
#[test]
fn the_average_nulls_multiples_of_the_sample_rate() {
    let ft = 80_000.0_f64;
    for f in [10_000.0, 20_000.0, 40_000.0] {
        let mut half = [0u16; HALF_LEN];
        for (k, seq) in half.chunks_exact_mut(CHANNELS).enumerate() {
            let x = 2048.0 + 1000.0 * (std::f64::consts::TAU * f * k as f64 / ft + 0.3).sin();
            seq.fill(x.round() as u16);
        }
        let avg = average_half(&half);
        assert!((i32::from(avg[0]) - 2048).abs() <= 1, "{f} Hz: {avg:?}");
    }
}
