//! The checks of one sample's conversions and latched counts (`crate::acquisition`): the
//! per-conversion clip check against each channel's linear range ([`sum_half_clipped`],
//! held through the filter's memory by [`ClipHold`]) and the encoder count's step check
//! against the maximum speed ([`EncoderCheck`]).

use super::CHANNELS;

/// One channel's linear range in ADC codes: a conversion at or below `low`, or at or
/// above `high`, is **clipped** (the front end's output was at or beyond its linear limit,
/// so the conversion's value is not the input's). The board's ranges come from the motor
/// record (`motor_source::linear_ranges`: the record's full scale about its offset, narrowed
/// by the amplifier's output headroom, within the rails).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinearRange {
    /// The lowest code still clipped from below (0: only the rail).
    pub low: u16,
    /// The lowest code clipped from above (4095: only the rail).
    pub high: u16,
}

impl LinearRange {
    /// The ADC's rails alone: 0 and 4095 clipped, 1..=4094 inside.
    pub const RAILS: LinearRange = LinearRange { low: 0, high: 4095 };

    /// The codes strictly inside, `low + 1 ..= high - 1`, counted (0 for an empty range:
    /// every conversion clipped).
    #[inline(always)]
    const fn inside(self) -> u16 {
        self.high.saturating_sub(self.low).saturating_sub(1)
    }

    /// Whether `code` is clipped: `code <= low || code >= high`, as one unsigned compare.
    #[inline(always)]
    pub const fn clips(self, code: u16) -> bool {
        code.wrapping_sub(self.low.wrapping_add(1)) >= self.inside()
    }
}

/// [`super::sum_half`] and the clip check of every conversion in `half` against its channel's
/// linear range in `ranges` (a, b, c): `true` when any conversion of the sample is
/// clipped. Per conversion, not on the mean: eight conversions of which two sat on the
/// limit average below it (an inrush peak clipped for 25 us of the 100 us), and the mean
/// alone passes as valid. Equivalent to comparing each channel's minimum and maximum
/// conversion with its range; one unsigned compare a conversion.
#[inline]
pub fn sum_half_clipped(
    half: &[u16],
    ranges: &[LinearRange; CHANNELS],
) -> ([u32; CHANNELS], u32, bool) {
    let (sequences, _) = half.as_chunks::<CHANNELS>();
    // Branch-free: with `d = (code - (low + 1)) mod 2^16` (the code's place in the range,
    // wrapped below it), the code clips when `d >= inside`, that is when
    // `d + (2^16 - inside)` carries into bit 16: ORed over the conversions, bit 16 says
    // whether any clipped (an add, a zero-extending add and an OR a conversion).
    let [ka, kb, kc] = ranges.map(|r| 0x1_0000 - u32::from(r.low.wrapping_add(1)));
    let [ia, ib, ic] = ranges.map(|r| 0x1_0000 - u32::from(r.inside()));
    let [mut a, mut b, mut c] = [0u32; CHANNELS];
    let mut carry = 0u32;
    for &[x, y, z] in sequences {
        let (x, y, z) = (u32::from(x), u32::from(y), u32::from(z));
        a += x;
        b += y;
        c += z;
        carry |=
            (((x + ka) & 0xFFFF) + ia) | (((y + kb) & 0xFFFF) + ib) | (((z + kc) & 0xFFFF) + ic);
    }
    ([a, b, c], sequences.len() as u32, carry & 0x1_0000 != 0)
}

/// The six channels' linear ranges: voltages a, b, c (ADC1) and currents a, b, c (ADC2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinearRanges {
    /// The voltage channels'.
    pub voltage: [LinearRange; CHANNELS],
    /// The current channels'.
    pub current: [LinearRange; CHANNELS],
}

impl LinearRanges {
    /// Only the rails clip, on every channel.
    pub const RAILS: LinearRanges = LinearRanges {
        voltage: [LinearRange::RAILS; CHANNELS],
        current: [LinearRange::RAILS; CHANNELS],
    };
}

/// Samples a clip stays flagged after the clipped one: [`PwmFilter`]'s memory (its first
/// stage keeps `(1 - 1/4)^n` of a sample's value after `n` samples: 1 % after 16), so the
/// clipped conversions' share in the filtered readings after it is held out too.
pub const CLIP_HOLD_SAMPLES: u8 = 16;

/// The clip flags of the voltages and the currents held for [`CLIP_HOLD_SAMPLES`] after a
/// clipped sample (the filter's memory of it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClipHold {
    left: [u8; 2],
}

impl ClipHold {
    /// One sample's clip flags `[voltage, current]` (from [`sum_half_clipped`]) -> the
    /// flags of the filtered sample: set while a clip is within [`CLIP_HOLD_SAMPLES`].
    #[inline]
    pub fn step(&mut self, clipped: [bool; 2]) -> [bool; 2] {
        let [lv, li] = &mut self.left;
        let [cv, ci] = clipped;
        [hold(lv, cv), hold(li, ci)]
    }
}

/// One flag of [`ClipHold::step`].
#[inline(always)]
fn hold(left: &mut u8, clipped: bool) -> bool {
    if clipped {
        *left = CLIP_HOLD_SAMPLES;
        true
    } else if *left > 0 {
        *left -= 1;
        true
    } else {
        false
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
    started: bool,
}

impl EncoderCheck {
    /// A check allowing `max_step` counts between two triggers
    /// ([`max_step_per_trigger`]).
    pub const fn new(max_step: u16) -> Self {
        Self {
            last: 0,
            offset: 0,
            last_step: 0,
            max_step,
            started: false,
        }
    }

    /// The next count is taken as it is (after a gap in the triggers).
    pub fn restart(&mut self) {
        self.started = false;
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
        *self = s;
        rejected
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
