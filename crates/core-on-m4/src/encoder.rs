//! The encoder check's Thumb-2 kernel and fast path against the Rust and the count by
//! count path (`main`'s `check_kernels`, module docs 4).

use qemu_semihosting::println;

/// `check_kernels`' encoder part: `steps_ored` (the Thumb-2 kernel of the encoder check's
/// fast path) against `steps_ored_portable`, and `EncoderCheck::sample` (its fast path with
/// the kernel, or its count by count one) against the count by count check and the mean
/// (`EncoderCheck::check_sample`, `sample_count`), with the built-in largest step (4), on
/// the replay's latched counts and on 20 000 samples of a random walk about the counter's
/// wrap (steps of -5 to 5 counts a trigger, beyond the largest step either way). Prints the
/// samples checked, the walk's steps forwards through the wrap (65 535 -> 0) and the
/// mismatches; returns the mismatches and whether any step went through the wrap.
pub(crate) fn check_encoder_kernel(n: usize, seed: &mut u32) -> (u32, bool) {
    use crate::acquisition::{
        sample_count, steps_ored, steps_ored_portable, EncoderCheck, OVERSAMPLING,
    };
    let mut buf = (
        [0u16; crate::acquisition::HALF_LEN],
        [0u16; crate::acquisition::HALF_LEN],
        [0u16; OVERSAMPLING],
    );
    let (mut check, mut reference) = (EncoderCheck::new(4), EncoderCheck::new(4));
    let (mut last, mut count) = (0u16, 0u16);
    let (mut checked, mut through_wrap, mut mismatches) = (0u32, 0u32, 0u32);
    for k in 0..n + 20_000 {
        if k < n {
            crate::fill(k, &mut buf);
        } else {
            for c in buf.2.iter_mut() {
                *seed ^= *seed << 13;
                *seed ^= *seed >> 17;
                *seed ^= *seed << 5;
                let step = (*seed >> 8) % 11;
                let at = count.wrapping_add(step as u16).wrapping_sub(5);
                through_wrap += u32::from((at < 100) && (count > 65_435));
                count = at;
                *c = at;
            }
        }
        let latched = buf.2;
        // The window's bias of every largest step from 1 to 1 170 has halves below 2^11.
        let bias = (*seed >> 21) * 0x0001_0001;
        let (got, want) = (
            steps_ored(&latched, last, bias),
            steps_ored_portable(&latched, last, bias),
        );
        let mut corrected = latched;
        let rejects = reference.check_sample(&mut corrected);
        let (got_sample, want_sample) =
            (check.sample(&latched), (sample_count(&corrected), rejects));
        checked += 1;
        if got != want || got_sample != want_sample {
            mismatches += 1;
            if mismatches <= 5 {
                println!(
                    "mismatch kernel=steps_ored sample={} latched={:?} last={} got={:?} want={:?}",
                    k,
                    latched,
                    last,
                    (got, got_sample),
                    (want, want_sample)
                );
            }
        }
        last = latched[OVERSAMPLING - 1];
    }
    println!(
        "encoder_checks={} encoder_checks_through_wrap={} encoder_mismatches={}",
        checked, through_wrap, mismatches
    );
    (mismatches, through_wrap > 0)
}
