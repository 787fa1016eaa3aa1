//! The checks of one sample's conversions and latched counts (`crate::acquisition`): the
//! per-conversion clip check against each channel's linear range ([`sum_clipped`],
//! held through the filter's memory by [`ClipHold`]) and the encoder count's step check
//! against the maximum speed ([`EncoderCheck`]).

use super::limits::ClipLimits;
use super::{CHANNELS, HALF_LEN, OVERSAMPLING};

/// Bit 15 of both halves: the clip bits of [`sum_clipped`]'s test words.
const CLIP_BITS: u32 = 0x8000_8000;

/// One sample's conversions of one ADC (`[a, b, c, a, b, c, ...]`, [`HALF_LEN`] 12-bit
/// codes, as the DMA writes them) -> each channel's sum over its [`OVERSAMPLING`]
/// conversions, and whether **any** conversion was clipped (at or beyond its channel's
/// linear range, `limits` from [`ClipLimits::new`]). Per conversion, not on the mean: eight
/// conversions of which two sat on the limit average below it (an inrush peak clipped for
/// 25 us of the 100 us), and the mean alone passes as valid; the result is that of comparing
/// each channel's minimum and maximum conversion with its range
/// ([`LinearRange::clips`](super::LinearRange::clips) of each conversion).
///
/// Two conversions at a time, no branch, no bounds check, no division: per 32-bit word of
/// two codes one add into the sums' halves (a sum of four 12-bit codes fits a half) and the
/// range test, an add and a subtraction whose bit 15 in either half says whether that code
/// clipped ([`ClipLimits`]), both ORed into the flags: six instructions a word, 72 an ADC.
/// On the Cortex-M4 a Thumb-2 kernel does exactly [`sum_clipped_portable`]'s arithmetic
/// (`acquisition/thumb.rs`: built for size, the compiler keeps an ADC's twelve words live
/// across the sums and spills them, about 55 instructions more a sample; `cargo qemu-core`
/// checks that the two agree); the host runs [`sum_clipped_portable`]. Codes wider than 12 bits (never from the ADC) give
/// sums and flags of no meaning, and no panic.
#[inline(always)]
pub fn sum_clipped(conversions: &[u16; HALF_LEN], limits: &ClipLimits) -> ([u32; CHANNELS], bool) {
    #[cfg(target_arch = "arm")]
    let (s_ab, s_ca, s_bc, flags) = super::thumb::sum_clipped_words(conversions, limits);
    #[cfg(not(target_arch = "arm"))]
    let (s_ab, s_ca, s_bc, flags) = sum_clipped_words(conversions, limits);
    let sums = [
        (s_ab & 0xFFFF) + (s_ca >> 16),
        (s_ab >> 16) + (s_bc & 0xFFFF),
        (s_ca & 0xFFFF) + (s_bc >> 16),
    ];
    (sums, flags & CLIP_BITS != 0)
}

/// [`sum_clipped`] in Rust alone, on every target: what the board's kernel computes, and
/// what `cargo qemu-core` checks it against.
#[inline(always)]
pub fn sum_clipped_portable(
    conversions: &[u16; HALF_LEN],
    limits: &ClipLimits,
) -> ([u32; CHANNELS], bool) {
    let (s_ab, s_ca, s_bc, flags) = sum_clipped_words(conversions, limits);
    let sums = [
        (s_ab & 0xFFFF) + (s_ca >> 16),
        (s_ab >> 16) + (s_bc & 0xFFFF),
        (s_ca & 0xFFFF) + (s_bc >> 16),
    ];
    (sums, flags & CLIP_BITS != 0)
}

/// The word sums of the three word positions `(a, b)`, `(c, a)`, `(b, c)` over a sample's
/// four pairs of sequences, and the test words ORed ([`sum_clipped`]).
#[inline(always)]
fn sum_clipped_words(conversions: &[u16; HALF_LEN], limits: &ClipLimits) -> (u32, u32, u32, u32) {
    const { assert!(CHANNELS == 3 && OVERSAMPLING == 8) };
    // Written out: the firmware is built for size, which unrolls no loop.
    let [a0, b0, c0, a1, b1, c1, a2, b2, c2, a3, b3, c3, a4, b4, c4, a5, b5, c5, a6, b6, c6, a7, b7, c7] =
        *conversions;
    let [l_ab, l_ca, l_bc] = limits.words;
    let (s_ab, f_ab) = column(
        [word(a0, b0), word(a2, b2), word(a4, b4), word(a6, b6)],
        l_ab,
    );
    let (s_ca, f_ca) = column(
        [word(c0, a1), word(c2, a3), word(c4, a5), word(c6, a7)],
        l_ca,
    );
    let (s_bc, f_bc) = column(
        [word(b1, c1), word(b3, c3), word(b5, c5), word(b7, c7)],
        l_bc,
    );
    (s_ab, s_ca, s_bc, f_ab | f_ca | f_bc)
}

/// Two codes as one 32-bit word, `low` in the low half.
#[inline(always)]
fn word(low: u16, high: u16) -> u32 {
    u32::from(low) | (u32::from(high) << 16)
}

/// One word position of [`sum_clipped`] over a sample's four pairs of sequences: the
/// halves' sums, and the test words ORed (bit 15 of a half set: a code of that half
/// clipped).
#[inline(always)]
fn column([w0, w1, w2, w3]: [u32; 4], [above, below]: [u32; 2]) -> (u32, u32) {
    let test = |w: u32| w.wrapping_add(above) | below.wrapping_sub(w);
    let sum = w0.wrapping_add(w1).wrapping_add(w2).wrapping_add(w3);
    (sum, test(w0) | test(w1) | test(w2) | test(w3))
}

/// Samples a clip stays flagged after the clipped one: [`PwmFilter`]'s memory (its first
/// stage keeps `(1 - 1/4)^n` of a sample's value after `n` samples: 1 % after 16), so the
/// clipped conversions' share in the filtered readings after it is held out too.
pub const CLIP_HOLD_SAMPLES: u8 = 16;

/// The clip flags of the voltages and the currents held for [`CLIP_HOLD_SAMPLES`] after a
/// clipped sample (the filter's memory of it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClipHold {
    /// The clip flags of the latest samples, the newest in bit 0: voltages, currents.
    history: [u32; 2],
}

/// The bits of [`ClipHold`]'s history that flag a sample: its own and the
/// [`CLIP_HOLD_SAMPLES`] before it.
const HOLD_MASK: u32 = (1 << (CLIP_HOLD_SAMPLES as u32 + 1)) - 1;

impl ClipHold {
    /// One sample's clip flags `[voltage, current]` (from [`sum_clipped`]) -> the
    /// flags of the filtered sample: set while a clip is within [`CLIP_HOLD_SAMPLES`].
    #[inline(always)]
    pub fn step(&mut self, clipped: [bool; 2]) -> [bool; 2] {
        let [hv, hi] = &mut self.history;
        let [cv, ci] = clipped;
        *hv = (*hv << 1) | u32::from(cv);
        *hi = (*hi << 1) | u32::from(ci);
        [*hv & HOLD_MASK != 0, *hi & HOLD_MASK != 0]
    }
}

/// The encoder latch's counts checked against the largest step the maximum speed allows
/// between two triggers (a count that jumps further is a glitch on the encoder's lines, not
/// motion): such a step is **rejected**, and every later count is shifted back by it, so
/// the counts handed on stay continuous and the core takes no glitch for speed. The check
/// starts afresh after a gap in the triggers ([`EncoderCheck::restart`]: a recovery or a
/// paused acquisition, over which the shaft may have moved any distance).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncoderCheck {
    /// The last count latched (uncorrected).
    last: u16,
    /// The rejected steps' excess so far, summed (wrapping): subtracted from every count.
    offset: u16,
    /// The last step taken as motion [counts]: a rejected step is replaced by it.
    last_step: i16,
    /// The largest believable step between two triggers [counts].
    max_step: u16,
    /// The fast path's window ([`EncoderCheck::sample`]): `2^b` steps from `-m` to
    /// `max_step` (`2^b` the largest power of two within `2 max_step + 1`, `m = 2^b - 1 -
    /// max_step`), within the steps believed; `m` in both halves of a word.
    window_bias: u32,
    /// The bits that stay clear in both halves when every step `+ m` lies within the window
    /// (`0..2^b`).
    window_mask: u32,
    /// The fast path of [`EncoderCheck::sample`] is exact: `max_step` is at most
    /// [`FAST_MAX_STEP`].
    fast: bool,
    started: bool,
    /// `started && fast`: the next sample may take the fast path.
    ready: bool,
}

/// `b` of [`EncoderCheck`]'s window: the largest with `2^b <= 2 max_step + 1`, at most 15.
const fn window_bits(max_step: u16) -> u32 {
    let span = 2 * max_step as u32 + 1;
    let mut b = 0;
    while b < 15 && (1u32 << (b + 1)) <= span {
        b += 1;
    }
    b
}

/// Bit 15 of both halves of a word: what keeps [`sub_halves`] and [`add_halves`] from
/// borrowing or carrying from one half into the other.
const HALF_TOPS: u32 = 0x8000_8000;

/// `a - b` half by half, each half modulo 2^16, nothing borrowed from the low half by the
/// high one: bit 15 set in `a`'s halves and clear in `b`'s, so bits 0 to 14 of a half
/// subtract without a borrow out of it, and bit 15 of each half is then put right (`a15 ^
/// b15 ^` the borrow into bit 15, which the subtraction leaves as `!` its bit 15).
#[inline(always)]
const fn sub_halves(a: u32, b: u32) -> u32 {
    ((a | HALF_TOPS).wrapping_sub(b & !HALF_TOPS)) ^ (!(a ^ b) & HALF_TOPS)
}

/// `a + b` half by half, each half modulo 2^16, nothing carried from the low half into
/// the high one: bits 0 to 14 of the halves added (at most 0xFFFE a half), bit 15 of each
/// half then `a15 ^ b15 ^` the carry into it.
#[inline(always)]
const fn add_halves(a: u32, b: u32) -> u32 {
    ((a & !HALF_TOPS).wrapping_add(b & !HALF_TOPS)) ^ ((a ^ b) & HALF_TOPS)
}

/// [`EncoderCheck::sample`]'s steps with the window's bias, `c_k - c_{k-1} + m` (`c_{-1}`
/// the `last` count), two to a word as [`steps_ored_portable`] computes them, the four
/// words ORed. On the Cortex-M4 a Thumb-2 kernel (`acquisition/thumb.rs`: `usub16` and
/// `uadd16`, the halves apart in the instruction itself; `cargo qemu-core` checks the
/// fast path against the count by count one there); the host runs the portable arithmetic.
#[inline(always)]
pub fn steps_ored(latched: &[u16; OVERSAMPLING], last: u16, bias: u32) -> u32 {
    #[cfg(target_arch = "arm")]
    let out = super::thumb::steps_ored(latched, last, bias);
    #[cfg(not(target_arch = "arm"))]
    let out = steps_ored_portable(latched, last, bias);
    out
}

/// [`steps_ored`] in Rust alone, on every target: the words `(c_{2j}, c_{2j+1})` and
/// `(c_{2j-1}, c_{2j})` one trigger earlier, `w - b + bias` half by half ([`sub_halves`],
/// [`add_halves`]: nothing borrowed or carried from one half into the other), ORed.
#[inline(always)]
pub fn steps_ored_portable(latched: &[u16; OVERSAMPLING], last: u16, bias: u32) -> u32 {
    let [c0, c1, c2, c3, c4, c5, c6, c7] = *latched;
    let [w0, w1, w2, w3] = [word(c0, c1), word(c2, c3), word(c4, c5), word(c6, c7)];
    // Each word's counts one trigger earlier: (c_{2j-1}, c_{2j}).
    let [b0, b1, b2, b3] = [
        u32::from(last) | (w0 << 16),
        (w0 >> 16) | (w1 << 16),
        (w1 >> 16) | (w2 << 16),
        (w2 >> 16) | (w3 << 16),
    ];
    let steps = |w: u32, b: u32| add_halves(sub_halves(w, b), bias);
    steps(w0, b0) | steps(w1, b1) | steps(w2, b2) | steps(w3, b3)
}

/// The largest `max_step` for which [`EncoderCheck::sample`]'s fast path is exact: a
/// sample's counts then lie within `7 x max_step` of its first, and their differences
/// from it sum to at most `28 x max_step` (1 + 2 + ... + 7), within an `i16`.
pub const FAST_MAX_STEP: u16 = (i16::MAX / 28) as u16;

impl EncoderCheck {
    /// A check allowing `max_step` counts between two triggers
    /// ([`max_step_per_trigger`]).
    pub const fn new(max_step: u16) -> Self {
        Self {
            last: 0,
            offset: 0,
            last_step: 0,
            max_step,
            window_bias: {
                let m = ((1u32 << window_bits(max_step)) - 1).saturating_sub(max_step as u32);
                m | (m << 16)
            },
            window_mask: {
                let inside = (1u32 << window_bits(max_step)) - 1;
                !(inside | (inside << 16))
            },
            fast: max_step <= FAST_MAX_STEP,
            started: false,
            ready: false,
        }
    }

    /// Whether the next sample may take [`EncoderCheck::sample`]'s fast path (started, and
    /// `max_step` within [`FAST_MAX_STEP`]); for the tests.
    #[cfg(test)]
    pub(crate) fn fast_ready(&self) -> bool {
        self.ready
    }

    /// The next count is taken as it is (after a gap in the triggers).
    pub fn restart(&mut self) {
        self.started = false;
        self.ready = false;
        self.last_step = 0;
    }

    /// One latched `count` -> the count corrected by the rejected steps, and whether this
    /// step was rejected. A rejected step is replaced by the last step taken as motion (the
    /// speed held over the glitch): a one-count spike leaves the counts of constant motion
    /// exactly as they were, a lasting jump (edges gained or lost) is taken out of every
    /// later count.
    #[inline(always)]
    pub fn check(&mut self, count: u16) -> (u16, bool) {
        let step = count.wrapping_sub(self.last) as i16;
        self.last = count;
        let rejected = self.started && step.unsigned_abs() > self.max_step;
        if rejected {
            let excess = step.wrapping_sub(self.last_step);
            self.offset = self.offset.wrapping_add(excess as u16);
        } else if self.started {
            self.last_step = step;
        }
        self.started = true;
        (count.wrapping_sub(self.offset), rejected)
    }

    /// A sample's latched counts (oldest first) corrected in place ([`EncoderCheck::check`]
    /// on each); returns how many were rejected.
    #[inline]
    pub fn check_sample(&mut self, latched: &mut [u16]) -> u8 {
        // The state in registers for the sample's counts ([`EncoderCheck::check`] on each).
        let mut s = *self;
        let mut rejected = 0u8;
        for c in latched.iter_mut() {
            let (corrected, bad) = s.check(*c);
            *c = corrected;
            rejected = rejected.saturating_add(u8::from(bad));
        }
        s.ready = s.started && s.fast;
        *self = s;
        rejected
    }
}

impl EncoderCheck {
    /// One sample's latched counts (oldest first) -> the sample's count (the mean of the
    /// counts corrected by the rejected steps, [`super::sample_count`]) and how many were
    /// rejected: the same as [`EncoderCheck::check_sample`] and [`super::sample_count`] on
    /// the corrected counts. Steps within the fast path's window (motion up to the maximum
    /// speed forwards, a little less backwards: every sample but a glitch's, the one after a
    /// restart, and with a `max_step` beyond [`FAST_MAX_STEP`] every one) take the fast
    /// path: two steps a 32-bit word, `(c1, c2) - (c0, c1)`, a subtraction and an add of the
    /// window's bias half by half, whose halves are the steps within the window, ORed and
    /// tested once ([`steps_ored`]); no branch, no division. Nothing is borrowed or carried
    /// from one half into the other: a plain 32-bit subtraction borrowed from the high half
    /// when the low half's step went forwards through the counter's wrap (65 535 -> 0), and
    /// a step of `max_step + 1` in the high half then passed as motion. Any other sample
    /// goes count by count ([`EncoderCheck::check_sample`]).
    #[inline(always)]
    pub fn sample(&mut self, latched: &[u16; OVERSAMPLING]) -> (u16, u8) {
        const { assert!(OVERSAMPLING == 8) };
        if !self.ready {
            return self.sample_slow(latched);
        }
        let out = steps_ored(latched, self.last, self.window_bias);
        if out & self.window_mask != 0 {
            return self.sample_slow(latched);
        }
        let [c0, c1, c2, c3, c4, c5, c6, c7] = *latched;
        let [w0, w1, w2, w3] = [word(c0, c1), word(c2, c3), word(c4, c5), word(c6, c7)];
        let (first, last, before_last) = (c0, c7, c6);
        // Every step within `max_step`: the differences from the first count sum to
        // `sum - 8 first` within an i16 ([`FAST_MAX_STEP`]); their mean rounded as
        // `sample_count` rounds it, `floor((d + 4) / 8)`.
        // (Written out: the firmware's size-optimised build turns an array's `map` or a
        // fold into a loop.)
        let halves = |w: u32| (w & 0xFFFF) + (w >> 16);
        let sum = halves(w0) + halves(w1) + halves(w2) + halves(w3);
        let d = sum.wrapping_sub(8 * u32::from(first)) as u16 as i16;
        let mean = (i32::from(d) + 4) >> 3;
        self.last_step = last.wrapping_sub(before_last) as i16;
        self.last = last;
        (first.wrapping_sub(self.offset).wrapping_add(mean as u16), 0)
    }

    /// [`EncoderCheck::sample`] count by count: [`EncoderCheck::check_sample`] and
    /// [`super::sample_count`] (after a restart, a glitch, or with a `max_step` beyond
    /// [`FAST_MAX_STEP`]).
    #[cold]
    #[inline(never)]
    fn sample_slow(&mut self, latched: &[u16; OVERSAMPLING]) -> (u16, u8) {
        #[cfg(test)]
        SLOW_SAMPLES.with(|n| n.set(n.get() + 1));
        let mut counts = *latched;
        let rejected = self.check_sample(&mut counts);
        (super::sample_count(&counts), rejected)
    }
}

/// The largest believable step of the encoder count between two triggers [counts]:
/// `ceil(counts_per_rev x max_rev_per_s / trigger_hz) + 1` (the `+ 1`: a step that meets
/// an edge just after one trigger and just before the next). 4 for 4 096 counts at 50 rev/s
/// (twice a four-pole machine's synchronous speed at 50 Hz) and 80 kHz; at least 1, at most
/// `u16::MAX / 2`; 1 for invalid inputs.
pub fn max_step_per_trigger(counts_per_rev: u32, max_rev_per_s: f32, trigger_hz: u32) -> u16 {
    let per_trigger = counts_per_rev as f32 * max_rev_per_s / trigger_hz as f32;
    if !(per_trigger.is_finite() && per_trigger >= 0.0) || trigger_hz == 0 {
        return 1;
    }
    let whole = per_trigger as u32;
    let ceil = if (whole as f32) < per_trigger {
        whole + 1
    } else {
        whole
    };
    ceil.saturating_add(1).clamp(1, u32::from(u16::MAX / 2)) as u16
}

// The samples [`EncoderCheck::sample_slow`] took on this thread: the tests' view of which
// path a sample took.
#[cfg(test)]
std::thread_local! {
    static SLOW_SAMPLES: core::cell::Cell<u32> = const { core::cell::Cell::new(0) };
}

// The checks' own tests, which reach the fast path and its parts: a file of their own.
#[cfg(test)]
#[path = "checks_tests.rs"]
mod tests;
