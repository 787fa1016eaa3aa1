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
    /// window's bias whose halves are the steps within the window, ORed and tested once; no
    /// branch, no division (a borrow between the halves comes with a carry that cancels it
    /// whenever the low half is within the window, and fails the test otherwise). Any other
    /// sample goes count by count ([`EncoderCheck::check_sample`]).
    #[inline(always)]
    pub fn sample(&mut self, latched: &[u16; OVERSAMPLING]) -> (u16, u8) {
        const { assert!(OVERSAMPLING == 8) };
        if !self.ready {
            return self.sample_slow(latched);
        }
        let [c0, c1, c2, c3, c4, c5, c6, c7] = *latched;
        let [w0, w1, w2, w3] = [word(c0, c1), word(c2, c3), word(c4, c5), word(c6, c7)];
        // Each word's counts one trigger earlier: (c_{2j-1}, c_{2j}).
        let before = [
            u32::from(self.last) | (w0 << 16),
            (w0 >> 16) | (w1 << 16),
            (w1 >> 16) | (w2 << 16),
            (w2 >> 16) | (w3 << 16),
        ];
        let bias = self.window_bias;
        let steps = |w: u32, b: u32| w.wrapping_sub(b).wrapping_add(bias);
        let [b0, b1, b2, b3] = before;
        let out = steps(w0, b0) | steps(w1, b1) | steps(w2, b2) | steps(w3, b3);
        if out & self.window_mask != 0 {
            return self.sample_slow(latched);
        }
        let (first, last, before_last) = (
            (w0 & 0xFFFF) as u16,
            (w3 >> 16) as u16,
            (w3 & 0xFFFF) as u16,
        );
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady motion at any speed within the window takes the fast path, sample after
    /// sample, forwards and backwards, across the counter's wrap; a sample whose steps are
    /// beyond the maximum speed, all of them or four in a row, takes the count by count one
    /// (which rejects them) and gives its counts (away from the wrap: see the window's test).
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
                    // Away from the counter's wrap (see the window's test).
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

    /// The fast path's bound and window as [`EncoderCheck`]'s docs give them: `b` the largest with
    /// `2^b <= 2 max_step + 1` (spans 1, 3, 9, 19, 201, 2 341, 65 535, 131 071), at most 15; two
    /// steps in a word pass its test exactly when both lie within `-m..=max_step`, `m = 2^b - 1 -
    /// max_step`, away from the counter's wrap. (A narrower window is no error, the count by count
    /// path gives the same counts, but every sample beyond it pays for that path: the sample task's
    /// budget counts on the fast one.) At the wrap a step into it borrows from or carries into the
    /// next half, which then passes one count off: not tested here (docs/firmware.md, the
    /// survivors of `checks.rs`).
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
            for first in [5_000u16, 30_000, 65_000 - 8 * max_step] {
                for s1 in steps {
                    for s2 in steps {
                        let c1 = first.wrapping_add(s1 as u16);
                        let c2 = c1.wrapping_add(s2 as u16);
                        let (now, before) = (word(c1, c2), word(first, c1));
                        let out = now.wrapping_sub(before).wrapping_add(check.window_bias);
                        let passes = out & check.window_mask == 0;
                        let want = within(s1) && within(s2);
                        assert_eq!(passes, want, "max {max_step}: {first} {s1} {s2}");
                    }
                }
            }
        }
    }
}
