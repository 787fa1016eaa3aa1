//! The in-band part of an inverter's ripple taken out of the six channels ([`PwmFilter`];
//! `crate::acquisition`'s module docs, "The in-band ripple"): two one-pole low-passes in
//! integer arithmetic on each sample's oversampled sums, the fundamental's gain restored, the
//! encoder count held back by the filters' delay. On the Cortex-M4 each ADC's three
//! channels run as a Thumb-2 kernel (`thumb::filter3`); the host runs their Rust.

#[cfg(target_arch = "arm")]
use super::thumb;
use super::{CHANNELS, OVERSAMPLING};

/// Fractional bits of [`PwmFilter`]'s states (codes x 2^16: a sum of [`OVERSAMPLING`]
/// 12-bit codes times the input's scale stays below 2^30).
const FILTER_FRAC_BITS: u32 = 16;
/// The first stage's coefficient `a = 2^-2` (a one-pole low-pass `y += a (x - y)` at 10 kHz:
/// -3 dB at 458 Hz).
const STAGE1_SHIFT: u32 = 2;
/// The second stage's coefficient `a = 2^-1` (-3 dB at 1.1 kHz at 10 kHz).
const STAGE2_SHIFT: u32 = 1;
/// Samples the encoder count is held back, the filters' delay at the fundamental
/// (`(1 - a) / a`: 3 and 1 samples) so that the shaft angle goes with the readings.
pub const ENCODER_DELAY_SAMPLES: usize = 4;
/// Mid-scale in the filter's states (code 2048 x 2^16): the fundamental's gain is restored
/// about it (the swing, not the offset).
const FILTER_MID: i32 = 2048 << FILTER_FRAC_BITS;

/// The in-band part of an inverter's ripple taken out of the six channels (module docs):
/// two one-pole low-passes in integer arithmetic on the oversampled sums ([`sum_clipped`](super::sum_clipped),
/// [`sum_half`](super::sum_half): [`OVERSAMPLING`] sequences), `a = 1/4` then `a = 1/2` at the sample rate
/// (at 10 kHz: -3 dB at 458 Hz and 1.1 kHz; gain 0.052 at 4 kHz, 0.12 at 2 kHz, where an
/// 8 kHz carrier's second group lands), and the fundamental's gain restored (from
/// [`PwmFilter::new`]'s supply frequency: at 50 Hz the two stages pass 0.993), folded into
/// the input's scale about mid-scale so that a sample costs one multiply-add a channel and
/// no division. All six channels are filtered alike, so the machine's equations between the
/// voltages and currents hold through it (a linear filter commutes with a linear machine's
/// equations in steady state); the encoder count is held back [`ENCODER_DELAY_SAMPLES`]
/// samples to go with them. No allocation, no panics.
#[derive(Clone, Copy, Debug)]
pub struct PwmFilter {
    /// Each channel's two stages (voltages a, b, c, then currents), in codes x 2^16 plus
    /// half a code (the output's rounding, carried through the stages).
    stages: [[[i32; 2]; CHANNELS]; 2],
    /// The encoder counts of the last samples, oldest first.
    counts: [u16; ENCODER_DELAY_SAMPLES],
    /// A sum of [`OVERSAMPLING`] codes -> the stages' input: `sum x scale + bias`, the
    /// mean in codes x 2^16 with the gain restored about mid-scale, plus half a code.
    scale: i32,
    /// See `scale`.
    bias: i32,
    primed: bool,
}

impl PwmFilter {
    /// A filter at `sample_rate_hz` whose gain at `supply_hz` is restored to 1 (invalid
    /// rates: no restoring).
    pub fn new(sample_rate_hz: u32, supply_hz: f32) -> Self {
        let w = core::f32::consts::TAU * supply_hz / sample_rate_hz as f32;
        // |a / (1 - b e^{-jw})|^2 of each stage.
        let gain2 = |shift: u32| {
            let a = 1.0 / (1u32 << shift) as f32;
            let b = 1.0 - a;
            let (re, im) = (1.0 - b * micro_cos(w), b * micro_sin(w));
            a * a / (re * re + im * im)
        };
        let g2 = gain2(STAGE1_SHIFT) * gain2(STAGE2_SHIFT);
        let gain = if g2.is_finite() && g2 > 0.25 && g2 <= 1.0 {
            sqrt_near_one(1.0 / g2)
        } else {
            1.0
        };
        // The mean of OVERSAMPLING codes x 2^16 x gain, rounded (gain < 2: below 2^14);
        // mid-scale kept where it is, exactly.
        let one = (1i32 << FILTER_FRAC_BITS) / OVERSAMPLING as i32;
        let scale = (gain * one as f32 + 0.5) as i32;
        let mid_sum = 2048 * OVERSAMPLING as i32;
        let bias = FILTER_MID - mid_sum * scale + (1 << (FILTER_FRAC_BITS - 1));
        Self {
            stages: [[[0; 2]; CHANNELS]; 2],
            counts: [0; ENCODER_DELAY_SAMPLES],
            scale,
            bias,
            primed: false,
        }
    }

    /// One sample: the voltages' and currents' sums over [`OVERSAMPLING`] sequences (from
    /// [`sum_clipped`] or [`sum_half`]) and the encoder count read with them; the filtered
    /// codes (rounded, within 0..=4095) and the encoder count of
    /// [`ENCODER_DELAY_SAMPLES`] samples ago. The first sample starts the stages at its own
    /// value (no run-up from zero).
    #[inline(always)]
    pub fn step(
        &mut self,
        v: [u32; CHANNELS],
        i: [u32; CHANNELS],
        count: u16,
    ) -> ([u16; CHANNELS], [u16; CHANNELS], u16) {
        self.step_with(v, i, count, filter3)
    }

    /// [`PwmFilter::step`] in Rust alone on every target (on the Cortex-M4 `step` runs a
    /// Thumb-2 kernel; `cargo qemu-core` checks the two against each other).
    pub fn step_portable(
        &mut self,
        v: [u32; CHANNELS],
        i: [u32; CHANNELS],
        count: u16,
    ) -> ([u16; CHANNELS], [u16; CHANNELS], u16) {
        self.step_with(v, i, count, filter3_portable)
    }

    /// [`PwmFilter::step`] with `filter` for each ADC's three channels.
    #[inline(always)]
    fn step_with(
        &mut self,
        v: [u32; CHANNELS],
        i: [u32; CHANNELS],
        count: u16,
        filter: Filter3,
    ) -> ([u16; CHANNELS], [u16; CHANNELS], u16) {
        if !self.primed {
            self.prime(v, i, count);
        }
        let (scale, bias) = (self.scale, self.bias);
        let [voltages, currents] = &mut self.stages;
        let v = filter(voltages, v, scale, bias);
        let i = filter(currents, i, scale, bias);
        const { assert!(ENCODER_DELAY_SAMPLES == 4) };
        let [delayed, c1, c2, c3] = self.counts;
        self.counts = [c1, c2, c3, count];
        (v, i, delayed)
    }

    /// The first sample: every stage at its own input, the delayed counts at its count.
    #[cold]
    #[inline(never)]
    fn prime(&mut self, v: [u32; CHANNELS], i: [u32; CHANNELS], count: u16) {
        let (scale, bias) = (self.scale, self.bias);
        for (st, sum) in self.stages.iter_mut().flatten().zip(v.into_iter().chain(i)) {
            let x = input(sum, scale, bias);
            *st = [x, x];
        }
        self.counts = [count; ENCODER_DELAY_SAMPLES];
        self.primed = true;
    }
}

/// Three channels of [`PwmFilter`]: their stages, their sums, the input's scale and bias
/// -> their codes ([`filter3`], [`filter3_portable`]).
type Filter3 = fn(&mut [[i32; 2]; CHANNELS], [u32; CHANNELS], i32, i32) -> [u16; CHANNELS];

/// A channel's sum of [`OVERSAMPLING`] codes as [`PwmFilter`]'s input ([`PwmFilter`]'s
/// `scale` and `bias`).
#[inline(always)]
fn input(sum: u32, scale: i32, bias: i32) -> i32 {
    (sum as i32).wrapping_mul(scale).wrapping_add(bias)
}

/// Three channels of [`PwmFilter::step`]: [`filter3_portable`], on the Cortex-M4 as a
/// Thumb-2 kernel (`acquisition/thumb.rs`, eight instructions a channel; `cargo qemu-core`
/// checks that the two agree).
#[inline(always)]
fn filter3(
    st: &mut [[i32; 2]; CHANNELS],
    sums: [u32; CHANNELS],
    scale: i32,
    bias: i32,
) -> [u16; CHANNELS] {
    #[cfg(target_arch = "arm")]
    let codes = thumb::filter3(st, sums, scale, bias);
    #[cfg(not(target_arch = "arm"))]
    let codes = filter3_portable(st, sums, scale, bias);
    codes
}

/// Three channels of [`PwmFilter::step`] in Rust alone ([`filter_channel`] each), on every
/// target.
#[inline(always)]
fn filter3_portable(
    st: &mut [[i32; 2]; CHANNELS],
    sums: [u32; CHANNELS],
    scale: i32,
    bias: i32,
) -> [u16; CHANNELS] {
    let [s0, s1, s2] = st;
    let [x0, x1, x2] = sums;
    [
        filter_channel(s0, x0, scale, bias),
        filter_channel(s1, x1, scale, bias),
        filter_channel(s2, x2, scale, bias),
    ]
}

/// One channel of [`PwmFilter::step`]: `sum` as the input, through the two stages `st`,
/// rounded to a code within 0..=4095 (the half code for the rounding is in the states).
#[inline(always)]
fn filter_channel(st: &mut [i32; 2], sum: u32, scale: i32, bias: i32) -> u16 {
    let x = input(sum, scale, bias);
    let [a, b] = st;
    *a = a.wrapping_add(x.wrapping_sub(*a) >> STAGE1_SHIFT);
    *b = b.wrapping_add(a.wrapping_sub(*b) >> STAGE2_SHIFT);
    (*b >> FILTER_FRAC_BITS).clamp(0, 4095) as u16
}

/// `sqrt(x)` for `x` in 1..=4 (the inverse gain squared) by Newton's iteration from `x`:
/// six steps reach f32's precision there (no `std` on the board).
fn sqrt_near_one(x: f32) -> f32 {
    let mut y = x;
    for _ in 0..6 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// cos for the filter's set-up (host and board alike: `micromath`-free Taylor series,
/// accurate to 1e-6 for |x| < 0.5, the supply's angle per sample).
fn micro_cos(x: f32) -> f32 {
    let x2 = x * x;
    1.0 - x2 / 2.0 + x2 * x2 / 24.0 - x2 * x2 * x2 / 720.0
}

/// sin, as [`micro_cos`].
fn micro_sin(x: f32) -> f32 {
    let x2 = x * x;
    x * (1.0 - x2 / 6.0 + x2 * x2 / 120.0 - x2 * x2 * x2 / 5040.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The set-up's cosine and sine within 1e-6 of the true ones for |x| < 0.5 (their
    /// docs), against `f64`'s, and the square root within f32's precision for 1..=4.
    #[test]
    fn the_set_ups_cos_sin_and_sqrt_are_accurate_where_used() {
        for k in -500..=500 {
            let x = k as f32 / 1_000.0;
            let c = f64::from(x).cos();
            let s = f64::from(x).sin();
            assert!((f64::from(micro_cos(x)) - c).abs() < 1e-6, "cos {x}");
            assert!((f64::from(micro_sin(x)) - s).abs() < 1e-6, "sin {x}");
        }
        for k in 0..=300 {
            let x = 1.0 + k as f32 / 100.0;
            let r = f64::from(x).sqrt();
            let y = f64::from(sqrt_near_one(x));
            assert!((y - r).abs() < 1e-6 * r, "sqrt {x}: {y}");
        }
    }
}
