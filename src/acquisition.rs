//! The acquisition's geometry, written once for the firmware and the host's model of the
//! ADC and DMA (`tests/sil/recovery.rs`): channels per ADC, oversampling, the DMA ring's
//! length, the sampling time and the conversion time it gives; and the averaging of the
//! oversampled sequences into one sample ([`average_half`]).
//!
//! **Oversampling against the inverter's PWM.** An inverter switches at 2-16 kHz; its
//! line-to-neutral voltage is a pulse train whose switching components (around multiples
//! of the carrier, `m f_c +- n f_1`) are hundreds of volts. Sampled at the monitor's
//! 10 kHz behind the front end's single-pole 16 kHz RC, a component at `f` folds to
//! `|f - k f_s|`: 4 kHz switching puts its fifth group (20 kHz +- 50 Hz) onto the
//! fundamental, 8 kHz its fifth (40 kHz), 16 kHz its fifth (80 kHz), attenuated by the RC
//! only to 0.62, 0.37 and 0.20. So TIM1 triggers both ADCs [`OVERSAMPLING`] times per
//! sample (80 kHz) and the sample is the mean of the [`OVERSAMPLING`] sequences spread
//! evenly over the sample period: a moving average over one whole period, whose gain is
//! zero at every multiple of the sample rate, where the folding to the fundamental comes
//! from (`|sin(pi f N / f_t) / (N sin(pi f / f_t))|`, `f_t` the trigger rate). What
//! still folds is what lies near multiples of the trigger rate (80 kHz: the RC's 0.20
//! times the PWM's small high-order groups there); docs/firmware.md gives the front end's
//! anti-alias requirement and the figures.

use crate::clock;

/// Channels per ADC: ADC1 va, vb, vc; ADC2 ia, ib, ic.
pub const CHANNELS: usize = 3;
/// Sequences (triggers) averaged into one sample (module docs).
pub const OVERSAMPLING: usize = 8;
/// Samples per DMA half buffer: 1, so every sample wakes the sample task as it arrives
/// and the encoder is read within microseconds of the conversions.
pub const SAMPLES_PER_HALF: usize = 1;
/// 16-bit words in one DMA half buffer (one sample's sequences).
pub const HALF_LEN: usize = SAMPLES_PER_HALF * OVERSAMPLING * CHANNELS;
/// The DMA ring's length per ADC in 16-bit words (two halves), which is also the
/// channel's `CNDTR` at the start of a turn.
pub const RING_LEN: usize = 2 * HALF_LEN;

/// The regular channels' sampling time in ADC clock cycles, times 2 (`SMPx` = 24.5
/// cycles; halves are how RM0440 counts them): the front end drives each pin through
/// 1 kohm and 10 nF, far below the datasheet's source-resistance bound for 24.5 cycles
/// (about 11 kohm).
pub const SAMPLE_TIME_HALF_CYCLES: u32 = 49;
/// A 12-bit conversion's successive approximation in ADC cycles, times 2 (12.5 cycles).
pub const CONVERSION_HALF_CYCLES: u32 = 25;
/// One conversion [ADC clock cycles x 2]: sampling plus approximation (37 cycles).
pub const CONVERSION_TOTAL_HALF_CYCLES: u32 = SAMPLE_TIME_HALF_CYCLES + CONVERSION_HALF_CYCLES;

/// One conversion [ns] at [`clock::ADC_CLOCK_HZ`] (870 ns).
pub const fn conversion_ns() -> u32 {
    (CONVERSION_TOTAL_HALF_CYCLES as u64 * 1_000_000_000 / (2 * clock::ADC_CLOCK_HZ as u64)) as u32
}

/// One sequence of [`CHANNELS`] conversions [ns] (2.6 us).
pub const fn sequence_ns() -> u32 {
    conversion_ns() * CHANNELS as u32
}

/// The trigger rate [Hz] for `sample_rate_hz`: [`OVERSAMPLING`] sequences per sample.
pub const fn trigger_rate_hz(sample_rate_hz: u32) -> u32 {
    sample_rate_hz.saturating_mul(OVERSAMPLING as u32)
}

/// The longest the injected VREFINT conversion holds a regular sequence up [ns]: 247.5 +
/// 12.5 cycles (`supply::REFERENCE_SAMPLE_CYCLES`), once a second.
pub const fn reference_conversion_ns() -> u32 {
    (260 * 1_000_000_000_u64 / clock::ADC_CLOCK_HZ as u64) as u32
}

// A sequence, even one held up by the reference's injected conversion, ends before the
// next trigger at the default 10 kHz (12.5 us between triggers): no overrun by design.
const _: () = assert!(
    sequence_ns() + reference_conversion_ns()
        < 1_000_000_000 / trigger_rate_hz(crate::board::DEFAULT_SAMPLE_RATE_HZ)
);
const _: () =
    assert!(clock::timer_divider(trigger_rate_hz(crate::board::DEFAULT_SAMPLE_RATE_HZ)).is_some());

/// The mean of each channel over the [`OVERSAMPLING`] sequences of one half buffer
/// `half` (`[a, b, c, a, b, c, ...]`, [`HALF_LEN`] words), rounded to the nearest code.
/// A shorter `half` averages the whole sequences it holds; an empty one gives zeros.
#[inline]
pub fn average_half(half: &[u16]) -> [u16; CHANNELS] {
    let mut sum = [0u32; CHANNELS];
    let mut n = 0u32;
    for seq in half.chunks_exact(CHANNELS) {
        for (s, &code) in sum.iter_mut().zip(seq) {
            *s += u32::from(code);
        }
        n += 1;
    }
    let n = n.max(1);
    sum.map(|s| ((s + n / 2) / n) as u16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_geometry_fits_the_period() {
        assert_eq!(RING_LEN, 48);
        assert_eq!(conversion_ns(), 870);
        assert!(sequence_ns() < 12_500);
        assert_eq!(trigger_rate_hz(10_000), 80_000);
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
}
