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
/// 639 + 213 + 785 + 100 = 1 737 instructions, 3 647.7, 3 648 cycles at 2.1; the frame
/// 9 440 x 268 / 201 = 12 586.7, 12 587 instructions, 26 432.7, 26 433 cycles; with 30 +
/// 400 + 1 500 + 2 000 a half's samples are processed at worst 34 011, 37 659 and 41 307
/// cycles after its request with 1, 2, 3 samples per half (the processing latency). The
/// depth follows from the lap case, the copy at 2.6 cycles an instruction.
#[test]
fn the_ring_depth_follows_from_the_latency_budget() {
    assert_eq!(sample_period_cycles(10_000), 17_000);
    assert_eq!(LOG_FRAME_INSTRUCTIONS, 12_587);
    assert_eq!(LOG_FRAME_CYCLES, 26_433);
    assert_eq!(worst_latency_cycles(1), 34_011);
    assert_eq!(worst_latency_cycles(2), 37_659);
    assert_eq!(worst_latency_cycles(3), 41_307);
    // The lap case (2.6 cycles an instruction): the frame 12 587 x 2.6 = 32 726.2, 32 727;
    // a sample's copy 100 x 2.6 = 260; with 3 930 of wake-up the copy is done 36 917,
    // 37 177 and 37 437 cycles after the request with 1, 2, 3 samples per half. The DMA
    // writes a half's first word again 9, 17, 25 triggers of 2 125 cycles after its start,
    // less two conversions of 147: 18 831, 35 831, 52 831 cycles after its completion.
    assert_eq!(LAP_FRAME_CYCLES, 32_727);
    assert_eq!(lap_latency_cycles(1), 36_917);
    assert_eq!(lap_latency_cycles(2), 37_177);
    assert_eq!(lap_latency_cycles(3), 37_437);
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
    // with one sample per half against 36 917); a faster one a deeper one.
    assert_eq!(samples_per_half_for(5_000), 1);
    assert!(samples_per_half_for(20_000) > 3);
}

/// The latch's ring keeps step with the ADCs' rings: TIM1's trigger latches one count per
/// sequence, so a half of the latch's ring holds the triggers of a DMA half, three samples
/// of eight (24), and the ring two such halves (48); a half of any other length hands the
/// sample task counts of other triggers than its conversions'.
#[test]
fn the_latch_ring_holds_one_count_per_trigger_of_a_dma_half() {
    assert_eq!(LATCH_HALF_LEN, 3 * 8);
    assert_eq!(LATCH_LEN, 2 * 3 * 8);
    assert_eq!(LATCH_HALF_LEN, DMA_HALF_LEN / CHANNELS);
    assert_eq!(LATCH_HALF_LEN, SAMPLES_PER_HALF * OVERSAMPLING);
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
    let rails = ClipLimits::new(&[LinearRange::RAILS; CHANNELS]);
    let (sums, clipped) = sum_clipped(&half, &rails);
    assert!(clipped);
    assert_eq!((sums, OVERSAMPLING as u32), sum_half(&half));
    // An amplifier that clips 62 codes before the rails: a conversion at 4040 is beyond
    // its linear range though no rail code.
    let amp = LinearRange {
        low: 62,
        high: 4033,
    };
    let mut near = [2048u16; HALF_LEN];
    near[7] = 4040;
    assert!(!sum_clipped(&near, &rails).1);
    assert!(sum_clipped(&near, &ClipLimits::new(&[amp; CHANNELS])).1);
}

/// The check two conversions at a time is [`LinearRange::clips`] of each conversion: every
/// code 0..=4095 at every one of a sample's 24 places, against channels of three different
/// ranges (each place's channel its own), the other codes inside; the sums those of the
/// codes; with `sum_clipped` and with `sum_clipped_portable`.
#[test]
fn the_check_two_at_a_time_is_the_range_test_of_each_conversion() {
    let ranges = [
        LinearRange {
            low: 115,
            high: 4033,
        },
        LinearRange::RAILS,
        LinearRange { low: 62, high: 63 },
    ];
    let limits = ClipLimits::new(&ranges);
    let inside = [2000u16, 2000, 62];
    for place in 0..HALF_LEN {
        let channel = place % CHANNELS;
        for code in 0..=4095u16 {
            let mut half = [0u16; HALF_LEN];
            for (k, c) in half.iter_mut().enumerate() {
                *c = inside[k % CHANNELS];
            }
            // Channel c's range 62..63 has no code inside: every conversion of it clips.
            let others_clip = channel != 2;
            half[place] = code;
            let (sums, clipped) = sum_clipped(&half, &limits);
            let want = others_clip || ranges[channel].clips(code);
            assert_eq!(clipped, want, "place {place} code {code}");
            assert_eq!(sums, sum_half(&half).0, "place {place} code {code}");
            // The Rust alone (what `cargo qemu-core` checks the board's kernel against).
            let portable = sum_clipped_portable(&half, &limits);
            assert_eq!(
                portable,
                (sum_half(&half).0, want),
                "place {place} code {code}"
            );
        }
    }
    // And with channel c inside a range of its own, only the code tested clips.
    let ranges = [ranges[0], ranges[1], LinearRange::RAILS];
    let limits = ClipLimits::new(&ranges);
    for place in 0..HALF_LEN {
        for code in [0u16, 1, 114, 115, 116, 4032, 4033, 4094, 4095] {
            let mut half = [2000u16; HALF_LEN];
            half[place] = code;
            let want = ranges[place % CHANNELS].clips(code);
            assert_eq!(
                sum_clipped(&half, &limits).1,
                want,
                "place {place} code {code}"
            );
            let portable = sum_clipped_portable(&half, &limits);
            assert_eq!(
                portable,
                (sum_half(&half).0, want),
                "place {place} code {code}"
            );
        }
    }
    // Limits beyond 12 bits: taken as the codes they let through.
    let wide = ClipLimits::new(
        &[LinearRange {
            low: 0,
            high: u16::MAX,
        }; CHANNELS],
    );
    assert!(!sum_clipped(&[4095; HALF_LEN], &wide).1);
    assert!(sum_clipped(&[0; HALF_LEN], &wide).1);
    // A low beyond 12 bits: every code is at or below it, so every conversion of its
    // channel clips, mid-scale too, in both of the channel's word positions.
    for low in [0x8000, 0x9000, u16::MAX] {
        let high = u16::MAX;
        for channel in 0..CHANNELS {
            let mut ranges = [LinearRange::RAILS; CHANNELS];
            ranges[channel] = LinearRange { low, high };
            let limits = ClipLimits::new(&ranges);
            for code in [0u16, 1, 2048, 4094, 4095] {
                assert!(ranges[channel].clips(code), "low {low:#x} code {code}");
                let mut half = [2048u16; HALF_LEN];
                for c in half.iter_mut().skip(channel).step_by(CHANNELS) {
                    *c = code;
                }
                let clipped = sum_clipped(&half, &limits).1;
                assert!(clipped, "low {low:#x} channel {channel} code {code}");
            }
        }
    }
}

/// Clips at several places at once are flagged as one alone is: any two of a sample's 24
/// conversions on a rail (of one word position, of one half of the words, of two), and
/// all 24; and a channel whose range is inverted (`low` above `high`: every code clips, one
/// between them beyond both limits at once), all its conversions there; with `sum_clipped`
/// and `sum_clipped_portable`.
#[test]
fn clips_at_several_places_at_once_are_flagged() {
    type Kernel = fn(&[u16; HALF_LEN], &ClipLimits) -> ([u32; CHANNELS], bool);
    let kernels: [Kernel; 2] = [sum_clipped, sum_clipped_portable];
    let rails = ClipLimits::new(&[LinearRange::RAILS; CHANNELS]);
    for kernel in kernels {
        for first in 0..HALF_LEN {
            for second in first + 1..HALF_LEN {
                for (x, y) in [(0, 0), (4095, 4095), (0, 4095), (4095, 0)] {
                    let mut half = [2048u16; HALF_LEN];
                    (half[first], half[second]) = (x, y);
                    assert!(kernel(&half, &rails).1, "{first} {second}: {x} {y}");
                }
            }
        }
        for rail in [0, 4095] {
            assert!(kernel(&[rail; HALF_LEN], &rails).1, "all at {rail}");
        }
        for channel in 0..CHANNELS {
            let mut ranges = [LinearRange::RAILS; CHANNELS];
            ranges[channel] = LinearRange {
                low: 3000,
                high: 1000,
            };
            let limits = ClipLimits::new(&ranges);
            for code in [500u16, 1000, 2000, 3000, 3500] {
                assert!(ranges[channel].clips(code), "{code}");
                // Every conversion of the channel at `code`, the others inside their rails.
                let half: [u16; HALF_LEN] =
                    std::array::from_fn(|k| if k % CHANNELS == channel { code } else { 2048 });
                let clipped = kernel(&half, &limits).1;
                assert!(clipped, "channel {channel} code {code}");
            }
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
    // The voltages' flag the same, on its own: a voltage clip, then one on both.
    assert_eq!(hold.step([true, false]), [true, false]);
    let flagged = (0..40).take_while(|_| hold.step([false, false])[0]).count();
    assert_eq!(flagged, usize::from(CLIP_HOLD_SAMPLES));
    assert_eq!(hold.step([true, true]), [true, true]);
    for k in 0..CLIP_HOLD_SAMPLES {
        assert_eq!(hold.step([false, false]), [true, true], "{k}");
    }
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
    // Invalid inputs, 1 as for no motion: an endless speed, a negative one, no trigger.
    assert_eq!(max_step_per_trigger(4_096, f32::INFINITY, 80_000), 1);
    assert_eq!(max_step_per_trigger(4_096, -50.0, 80_000), 1);
    assert_eq!(max_step_per_trigger(4_096, 50.0, 0), 1);
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

/// [`EncoderCheck::sample`] (its fast path and its count by count one) gives what the
/// count-by-count check and the mean of the corrected counts give, sample after sample:
/// motion at steady speeds forwards and backwards across the counter's wrap, single-count
/// spikes, lasting jumps, bursts of noise, restarts; for largest steps from 1 to beyond
/// [`FAST_MAX_STEP`].
#[test]
fn the_encoders_fast_path_is_the_count_by_count_check() {
    let mut seed = 0x9E37_79B9u32;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    for max_step in [1u16, 2, 4, 9, 100, FAST_MAX_STEP, FAST_MAX_STEP + 1, 5_000] {
        let mut fast = EncoderCheck::new(max_step);
        let mut reference = EncoderCheck::new(max_step);
        let mut count = random() as u16;
        let (mut fast_samples, mut rejected) = (0u32, 0u32);
        for k in 0..20_000u32 {
            // A speed for a stretch of samples: within the largest step, either way.
            let speed = (k / 500) as i32 % 7 - 3;
            let step = speed * i32::from(max_step.min(2_000)) / 3;
            let mut latched = [0u16; OVERSAMPLING];
            for c in latched.iter_mut() {
                count = count.wrapping_add(step as u16);
                *c = count;
            }
            match random() % 50 {
                0 => latched[(random() % 8) as usize] ^= 0x0100,
                1 => {
                    let at = (random() % 8) as usize;
                    let jump = (random() % 2_000) as u16;
                    for c in &mut latched[at..] {
                        *c = c.wrapping_add(jump);
                    }
                    count = count.wrapping_add(jump);
                }
                2 => latched = std::array::from_fn(|_| random() as u16),
                3 => {
                    fast.restart();
                    reference.restart();
                }
                _ => {}
            }
            let was = fast;
            let got = fast.sample(&latched);
            let mut corrected = latched;
            let rejects = reference.check_sample(&mut corrected);
            let want = (sample_count(&corrected), rejects);
            assert_eq!(
                got, want,
                "max {max_step}, sample {k}: {latched:?} after {was:?}"
            );
            assert_eq!(fast, reference, "max {max_step}, sample {k}");
            fast_samples += u32::from(was.fast_ready() && got.1 == 0);
            rejected += u32::from(got.1);
        }
        assert!(rejected > 0, "max {max_step}");
        if max_step <= FAST_MAX_STEP {
            assert!(fast_samples > 15_000, "max {max_step}: {fast_samples}");
        }
    }
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
        let (v, _, count) = f.step([sum; 3], [code(0.0); 3], k as u16);
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

/// The filter's first sample starts its stages at that sample's value, no run-up from zero
/// (mid-scale is kept exactly), and the held-back count at that sample's count; with
/// `step` and with `step_portable` (the Rust alone, which `cargo qemu-core` checks the
/// board's Thumb-2 kernel against).
#[test]
fn the_filter_starts_at_its_first_sample() {
    let mid = 2048 * OVERSAMPLING as u32;
    for portable in [false, true] {
        let mut f = PwmFilter::new(10_000, 50.0);
        for k in 0..2 * ENCODER_DELAY_SAMPLES as u16 {
            let (v, i, count) = if portable {
                f.step_portable([mid; CHANNELS], [mid; CHANNELS], 100 + k)
            } else {
                f.step([mid; CHANNELS], [mid; CHANNELS], 100 + k)
            };
            let codes = ([2048; CHANNELS], [2048; CHANNELS]);
            assert_eq!((v, i), codes, "sample {k}, portable {portable}");
            let held = k.saturating_sub(ENCODER_DELAY_SAMPLES as u16);
            assert_eq!(count, 100 + held, "sample {k}, portable {portable}");
        }
    }
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

/// The task must keep up as well as the ring hold. A ring deeper than the smallest that
/// holds holds too (10 kHz: 3 to 8 samples a half). A sample whose work takes its whole
/// period, or more, fits no depth: the work at the lap case is 1 737 instructions x 2.6 =
/// 4 516.2, 4 517 cycles; at 40 kHz a sample has 4 250 (the copy's latency is within the
/// slack from 10 samples a half on, 39 257 against 42 717 cycles, the work is not), at
/// 37 635 Hz exactly 4 517 (9 samples a half: 38 997 against 40 878).
#[test]
fn a_ring_fits_only_where_the_task_keeps_up() {
    for k in 3..=8 {
        assert!(ring_fits(10_000, k), "{k} samples a half at 10 kHz");
    }
    assert_eq!(lap_cycles(SAMPLE_WORK_INSTRUCTIONS), 4_517);
    assert_eq!(sample_period_cycles(40_000), 4_250);
    assert_eq!(lap_latency_cycles(10), 39_257);
    assert_eq!(lap_slack_cycles(40_000, 10), 42_717);
    for k in 1..=16 {
        assert!(!ring_fits(40_000, k), "{k} samples a half at 40 kHz");
    }
    assert_eq!(samples_per_half_for(40_000), 8);
    assert_eq!(sample_period_cycles(37_635), 4_517);
    assert_eq!(lap_latency_cycles(9), 38_997);
    assert_eq!(lap_slack_cycles(37_635, 9), 40_878);
    assert!(
        !ring_fits(37_635, 9),
        "a sample's work takes its whole period"
    );
}

/// The times that decide whether a sequence ends before the next trigger, from RM0440's
/// cycles at the ADC clock of 170 MHz / 4 = 42.5 MHz: a sequence is three conversions of
/// 24.5 + 12.5 = 37 cycles (3 x 870.6 ns, each rounded down: 2 610 ns); the injected
/// VREFINT conversion 247.5 + 12.5 = 260 cycles (6 117.6 ns); a rate whose sequence held up
/// by it ends after the next trigger does not fit.
#[test]
fn a_sequence_and_the_references_conversion_take_their_adc_cycles() {
    let cycle_ns: f64 = 1e9 / 42.5e6;
    let sequence = f64::from(sequence_ns());
    assert!(
        (sequence - 3.0 * (37.0 * cycle_ns).floor()).abs() < 0.5,
        "{sequence} ns"
    );
    let reference = f64::from(reference_conversion_ns());
    assert!((reference - 260.0 * cycle_ns).abs() < 1.0, "{reference} ns");
    // 17 kHz: triggers at 136 kHz, 7 353 ns apart, a rate the timers' clock divides
    // (1 250): longer than a sequence, shorter than one held up by VREFINT.
    assert_eq!(crate::clock::timer_divider(17_000 * 8), Some(1_250));
    assert!(!fits(17_000));
    // No trigger, no sample.
    assert!(!fits(0));
}

/// The builder's encoder check across a gap and a dropped sample, the shaft at 3 counts a
/// trigger, 4 at most: after a gap in the triggers (a recovery) the shaft has moved on,
/// 1 000 counts, and the builder restarted takes the first count after it as motion; a
/// dropped sample's counts still go through the check, so the next sample's first step is
/// one trigger's 3 counts, not the 27 of the dropped sample's triggers.
#[test]
fn a_gap_restarts_the_encoder_check_and_a_dropped_samples_counts_go_through_it() {
    let codes = [2_048u16; HALF_LEN];
    let run = |from: u16| -> [u16; OVERSAMPLING] {
        core::array::from_fn(|k| from.wrapping_add(3 * k as u16))
    };
    let mut builder = SampleBuilder::new(10_000, 50.0, &LinearRanges::RAILS, 4);
    assert_eq!(builder.build(&codes, &codes, &run(100)).encoder_rejects, 0);
    builder.restart();
    assert_eq!(
        builder.build(&codes, &codes, &run(1_100)).encoder_rejects,
        0
    );
    builder.skip(&run(1_124));
    assert_eq!(
        builder.build(&codes, &codes, &run(1_148)).encoder_rejects,
        0
    );
}
