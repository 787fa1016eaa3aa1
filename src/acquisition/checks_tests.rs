//! The tests of `acquisition/checks.rs` that reach its private parts: the encoder check's
//! fast path against its count by count one, at the counter's wrap too, the fast path's
//! window and the half-by-half arithmetic.

use super::*;

/// Steady motion at any speed within the window takes the fast path, sample after
/// sample, forwards and backwards, across the counter's wrap; a sample whose steps are
/// beyond the maximum speed, all of them or four in a row, takes the count by count one
/// (which rejects them) and gives its counts; at the wrap the tests below.
#[test]
fn motion_within_the_window_takes_the_fast_path_and_beyond_it_the_slow_one() {
    let slow = || SLOW_SAMPLES.with(core::cell::Cell::get);
    for max_step in [1u16, 4, 9, 100, FAST_MAX_STEP] {
        let max = i32::from(max_step);
        let m = (1 << window_bits(max_step)) - 1 - max;
        let speeds = [-m, -1, 0, 1, max / 2, max];
        for speed in speeds.into_iter().filter(|s| (-m..=max).contains(s)) {
            let mut check = EncoderCheck::new(max_step);
            let mut count = 65_000u16;
            let next = |count: &mut u16| -> [u16; OVERSAMPLING] {
                std::array::from_fn(|_| {
                    *count = count.wrapping_add(speed as u16);
                    *count
                })
            };
            check.sample(&next(&mut count));
            for k in 0..40 {
                let latched = next(&mut count);
                let mut reference = check;
                let want = reference.sample_slow(&latched);
                let went_slow = slow();
                assert_eq!(check.sample(&latched), want, "max {max_step} speed {speed}");
                assert_eq!(
                    slow(),
                    went_slow,
                    "max {max_step} speed {speed}: sample {k}"
                );
            }
            // Beyond the maximum speed: every step, then four of a sample's steps, the
            // first, the middle or the last (its words' steps two by two).
            for beyond in [0..8, 0..4, 2..6, 4..8] {
                // Mid-range (at the wrap: the tests below).
                check.restart();
                count = 30_000;
                check.sample(&next(&mut count));
                let mut latched = [0u16; OVERSAMPLING];
                let mut at = check.last;
                for (j, c) in latched.iter_mut().enumerate() {
                    let step = if beyond.contains(&j) { max + 1 } else { speed };
                    at = at.wrapping_add(step as u16);
                    *c = at;
                }
                let mut reference = check;
                let want = reference.sample_slow(&latched);
                assert_eq!(want.1, beyond.len() as u8, "max {max_step}: {latched:?}");
                let went_slow = slow();
                assert_eq!(check.sample(&latched), want, "max {max_step}: {latched:?}");
                assert_eq!(slow(), went_slow + 1, "max {max_step}: {latched:?}");
            }
        }
    }
}

/// At the counter's wrap the fast path is the count by count one: a step forwards
/// through 65 535 -> 0 in a word's low half (1 count, or `max_step`), then a step of
/// exactly `max_step + 1` in its high half, is rejected either way, once, for every
/// `max_step` the fast path takes and in each of a sample's four words. (A borrow from
/// the low half into the high one let that step through as motion.)
#[test]
fn a_step_beyond_the_maximum_after_a_forward_wrap_is_rejected_on_the_fast_path() {
    for max_step in 1..=FAST_MAX_STEP {
        for j in 0..4usize {
            for into in [1, max_step] {
                // The counts from the primed sample's first on: 1 count a trigger up to
                // 65 535, the low half's `into` through the wrap at count `8 + 2j`,
                // then `max_step + 1`, then 1 count a trigger again.
                let wrap_at = 8 + 2 * j;
                let mut counts = [0u16; 2 * OVERSAMPLING];
                for (k, c) in counts.iter_mut().enumerate() {
                    *c = match k {
                        k if k < wrap_at => u16::MAX - (wrap_at - 1 - k) as u16,
                        k if k == wrap_at => into - 1,
                        k => into + max_step + (k - wrap_at - 1) as u16,
                    };
                }
                let (primed, latched) = counts.split_at(OVERSAMPLING);
                let latched: [u16; OVERSAMPLING] = latched.try_into().unwrap();
                let mut check = EncoderCheck::new(max_step);
                check.sample(primed.try_into().unwrap());
                assert!(check.fast_ready());
                let mut reference = check;
                let want = reference.sample_slow(&latched);
                assert_eq!(want.1, 1, "max {max_step}: {latched:?}");
                let got = check.sample(&latched);
                assert_eq!(got, want, "max {max_step}, word {j}: {latched:?}");
                assert_eq!(check, reference, "max {max_step}, word {j}");
            }
        }
    }
}

/// The fast path against the count by count one on random samples at the counter's wrap:
/// each a primed check, then samples whose steps are drawn one by one (mostly within the
/// window, some just beyond either bound or anywhere), the same counts, rejects and state
/// after each, for largest steps from 1 to [`FAST_MAX_STEP`]. Counts the samples that
/// held a step beyond the maximum right after a step through the wrap in the word's low
/// half, so a run that drew none of them fails.
#[test]
fn the_fast_path_is_the_count_by_count_check_on_random_samples_at_the_wrap() {
    let mut seed = 0x2545_F491u32;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    let mut wrapped_then_beyond = 0u32;
    for max_step in [1u16, 2, 3, 4, 5, 7, 9, 16, 100, 700, FAST_MAX_STEP] {
        let max = i32::from(max_step);
        let m = (1 << window_bits(max_step)) - 1 - max;
        for case in 0..4_000u32 {
            let mut check = EncoderCheck::new(max_step);
            // The primed sample ends within four largest steps of the wrap, either side.
            let mut count = (random() % (8 * u32::from(max_step) + 1)) as u16;
            count = count.wrapping_sub(4 * max_step).wrapping_sub(8);
            check.sample(&std::array::from_fn(|_| {
                count = count.wrapping_add(1);
                count
            }));
            for k in 0..3 {
                let mut steps = [0i32; OVERSAMPLING];
                for s in steps.iter_mut() {
                    let r = random();
                    *s = match r % 16 {
                        0 => max + 1,
                        1 => -max - 1,
                        2 => -m - 1,
                        3 => max + 1 + (r >> 8) as i32 % 3,
                        4 => (r >> 16) as i32,
                        _ => (r >> 8) as i32 % (max + m + 1) - m,
                    };
                }
                let mut latched = [0u16; OVERSAMPLING];
                let mut before = count;
                for (j, (c, s)) in latched.iter_mut().zip(steps).enumerate() {
                    let at = before.wrapping_add(s as u16);
                    let through_wrap = at < before && (0..=max).contains(&s);
                    if j % 2 == 0 && through_wrap && steps[j + 1] > max {
                        wrapped_then_beyond += 1;
                    }
                    *c = at;
                    before = at;
                }
                count = before;
                let was = check;
                let mut reference = check;
                let want = reference.sample_slow(&latched);
                let got = check.sample(&latched);
                assert_eq!(
                    got, want,
                    "max {max_step}, case {case}, sample {k}: {latched:?} after {was:?}"
                );
                assert_eq!(check, reference, "max {max_step}, case {case}, sample {k}");
            }
        }
    }
    assert!(wrapped_then_beyond > 1_000, "{wrapped_then_beyond}");
}

/// The fast path's bound and window as [`EncoderCheck`]'s docs give them: `b` the largest with
/// `2^b <= 2 max_step + 1` (spans 1, 3, 9, 19, 201, 2 341, 65 535, 131 071), at most 15; two
/// steps in a word pass its test ([`steps_ored_portable`]) exactly when both lie within `-m..=max_step`, `m = 2^b - 1 -
/// max_step`, away from the counter's wrap and across it, either way (65 535 -> 0, and 32 767
/// -> 32 768, where bit 15 turns). (A narrower window is no error, the count by count path
/// gives the same counts, but every sample beyond it pays for that path: the sample task's
/// budget counts on the fast one.)
#[test]
fn the_fast_paths_window_is_the_documented_one() {
    // The fast path's largest step: 28 x 1 170 = 32 760 fits an i16, 28 x 1 171 not.
    assert_eq!(FAST_MAX_STEP, 1_170);
    let bits = [
        (0, 0),
        (1, 1),
        (4, 3),
        (9, 4),
        (100, 7),
        (FAST_MAX_STEP, 11),
    ];
    for (max_step, b) in bits.into_iter().chain([(u16::MAX / 2, 15), (u16::MAX, 15)]) {
        assert_eq!(window_bits(max_step), b, "max {max_step}");
    }
    for (max_step, b) in bits.into_iter().skip(1) {
        let check = EncoderCheck::new(max_step);
        let max = i32::from(max_step);
        let m = (1 << b) - 1 - max;
        // Motion backwards is believed a little less far, never further.
        assert!((0..=max).contains(&m), "max {max_step}: m {m}");
        let steps = [
            -m - 2,
            -m - 1,
            -m,
            -m + 1,
            -1,
            0,
            1,
            max - 1,
            max,
            max + 1,
            max + 2,
        ];
        let within = |s: i32| (-m..=max).contains(&s);
        let wraps = [u16::MAX - 1, u16::MAX, 0, 1, 32_767, 32_768];
        for first in [5_000u16, 30_000, 65_000 - 8 * max_step]
            .into_iter()
            .chain(wraps)
        {
            for s1 in steps {
                for s2 in steps {
                    let c1 = first.wrapping_add(s1 as u16);
                    let c2 = c1.wrapping_add(s2 as u16);
                    // The two steps in the first word, then none.
                    let latched = [c1, c2, c2, c2, c2, c2, c2, c2];
                    let out = steps_ored_portable(&latched, first, check.window_bias);
                    let passes = out & check.window_mask == 0;
                    let want = within(s1) && within(s2);
                    assert_eq!(passes, want, "max {max_step}: {first} {s1} {s2}");
                }
            }
        }
    }
}

/// [`sub_halves`] and [`add_halves`] are each half's own arithmetic modulo 2^16,
/// nothing borrowed or carried between the halves: every pair of the values at bit 15's
/// and the counter's edges in either half, and random words.
#[test]
fn the_halves_are_subtracted_and_added_apart() {
    let lanes = |x: u32| [x as u16, (x >> 16) as u16];
    let check = |a: u32, b: u32| {
        let ([a0, a1], [b0, b1]) = (lanes(a), lanes(b));
        let sub = word(a0.wrapping_sub(b0), a1.wrapping_sub(b1));
        let add = word(a0.wrapping_add(b0), a1.wrapping_add(b1));
        assert_eq!(sub_halves(a, b), sub, "{a:#010x} - {b:#010x}");
        assert_eq!(add_halves(a, b), add, "{a:#010x} + {b:#010x}");
    };
    let edges = [0u16, 1, 2, 0x7FFE, 0x7FFF, 0x8000, 0x8001, 0xFFFE, 0xFFFF];
    for a0 in edges {
        for a1 in edges {
            for b0 in edges {
                for b1 in edges {
                    check(word(a0, a1), word(b0, b1));
                }
            }
        }
    }
    let mut seed = 0x1234_5678u32;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    for _ in 0..100_000 {
        check(random(), random());
    }
}
