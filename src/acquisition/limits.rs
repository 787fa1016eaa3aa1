//! The channels' linear ranges ([`LinearRange`], [`LinearRanges`]) and one ADC's clip check
//! precomputed from them ([`ClipLimits`]): what the per-conversion clip check
//! (`checks::sum_clipped`) and its Thumb-2 kernel (`thumb::sum_clipped_words`) both read,
//! below either.

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

/// One ADC's clip check, precomputed from its three channels' [`LinearRange`]s for
/// [`sum_clipped`](super::sum_clipped), which takes a sample's conversions two at a time: the 16-bit codes of a
/// pair of sequences `a b c a b c` as the three 32-bit words `(a, b)`, `(c, a)`, `(b, c)`
/// (the first code in the low half). Per word position, in each half: `0x8000 - high`
/// (`above`: bit 15 of the half of `word + above` is set when its code is at or above
/// `high`) and `0x8000 + low` (`below`: bit 15 of the half of `below - word` is set when
/// its code is at or below `low`). For 12-bit codes neither half carries nor borrows into
/// the other: `0x8000 - high + 4095 < 0x1_0000` and `0x8000 + low - 4095 > 0`.
///
/// Laid out as the Thumb-2 kernel reads it, one `(above, below)` pair of words per word
/// position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct ClipLimits {
    /// The `(above, below)` pairs of the word positions `(a, b)`, `(c, a)`, `(b, c)`.
    pub(super) words: [[u32; 2]; CHANNELS],
}

impl ClipLimits {
    /// The limits of `ranges` (channels a, b, c of one ADC), computed once at
    /// configuration.
    pub const fn new(ranges: &[LinearRange; CHANNELS]) -> Self {
        let [a, b, c] = *ranges;
        // The word positions of a pair of sequences: (a, b), (c, a), (b, c).
        Self {
            words: [limits(a, b), limits(c, a), limits(b, c)],
        }
    }
}

/// The `(above, below)` pair of a word position whose halves are channels `lo` and `hi`.
const fn limits(lo: LinearRange, hi: LinearRange) -> [u32; 2] {
    [halves(above(lo), above(hi)), halves(below(lo), below(hi))]
}

/// `0x8000 - high` ([`ClipLimits`]; `high` beyond 0x8000 taken as 0x8000, which no 12-bit
/// code reaches either way).
const fn above(r: LinearRange) -> u32 {
    let high = if r.high > 0x8000 { 0x8000 } else { r.high };
    0x8000 - high as u32
}

/// `0x8000 + low` ([`ClipLimits`]; `low` beyond 0x7FFF taken as 0x7FFF, at or below
/// which every 12-bit code lies either way).
const fn below(r: LinearRange) -> u32 {
    let low = if r.low > 0x7FFF { 0x7FFF } else { r.low };
    0x8000 + low as u32
}

/// A 32-bit word of two 16-bit halves, `low` first.
const fn halves(low: u32, high: u32) -> u32 {
    low | (high << 16)
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
