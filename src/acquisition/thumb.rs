//! The sample path's three kernels in Thumb-2 assembly, for the Cortex-M4 (the board and
//! the QEMU program): [`sum_clipped_words`] (the oversampled sums and the per-conversion clip
//! check, `acquisition::sum_clipped`), [`filter3`] (three channels of
//! `acquisition::PwmFilter`) and [`steps_ored`] (the encoder check's fast path,
//! `acquisition::EncoderCheck::sample`). Each does exactly the arithmetic of its Rust
//! counterpart, `sum_clipped_portable`, `filter3_portable` and `steps_ored_portable`, which
//! the host runs; `cargo qemu-core` runs them on the replay and on clipped, edge and
//! wrapping cases and fails unless they agree.
//!
//! Why assembly: the firmware is built for size, and the compiler, given the sums and the
//! range tests of an ADC's twelve words, computes the sums first and keeps the words live
//! for the tests, spilling them to the stack (about 100 instructions an ADC where these
//! take 72); its filter reloads the sums it spilled. The encoder's steps take the
//! Cortex-M4's halfword instructions, `usub16` and `uadd16`, which the compiler does not
//! choose: in portable Rust the halves kept apart cost 46 instructions a sample more
//! (`cargo qemu-core`: `sampling_path=364`, 317 with the kernel). No loop, no branch, no
//! stack. These three functions are the library's only `unsafe` (`asm!`; the workspace
//! denies `unsafe_code`, allowed here item by item as in the firmware's register files),
//! built for ARM only.

use super::limits::ClipLimits;
use super::{CHANNELS, HALF_LEN, OVERSAMPLING};

/// The template of one word of [`sum_clipped_words`] after its position's first: the word
/// at byte offset `$offset` loaded into `{w}`, added into the position's sum `{$sum}`, and
/// `word + above` and `below - word` ORed into the flags `{f}` (six instructions).
macro_rules! clip_word {
    ($sum:literal, $offset:literal) => {
        concat!(
            "ldr {w}, [{p}, #",
            $offset,
            "]\n",
            "add {",
            $sum,
            "}, {",
            $sum,
            "}, {w}\n",
            "add {t}, {w}, {a}\n",
            "orr {f}, {f}, {t}\n",
            "sub {t}, {b}, {w}\n",
            "orr {f}, {f}, {t}",
        )
    };
}

/// The template of one word position of [`sum_clipped_words`] after the first: its
/// `(above, below)` pair loaded from byte offset `$pair` of the limits into `{a}`, `{b}`;
/// its first word (byte offset `$first`) loaded as the sum `{$sum}`, its tests ORed into the
/// flags `{f}`; then the other three words ([`clip_word`], byte offsets `$rest`).
macro_rules! clip_position {
    ($sum:literal, $pair:literal, $first:literal, $($rest:literal),+) => {
        concat!(
            "ldrd {a}, {b}, [{lim}, #", $pair, "]\n",
            "ldr {", $sum, "}, [{p}, #", $first, "]\n",
            "add {t}, {", $sum, "}, {a}\n",
            "orr {f}, {f}, {t}\n",
            "sub {t}, {b}, {", $sum, "}\n",
            "orr {f}, {f}, {t}",
            $("\n", clip_word!($sum, $rest)),+
        )
    };
}

/// The word sums of the word positions `(a, b)`, `(c, a)`, `(b, c)` of one ADC's sample and
/// the test words ORed: `checks::sum_clipped_words`' arithmetic, word by word in the same
/// order. Per word position its `(above, below)` pair is loaded once (`ClipLimits` is
/// `repr(C)`: three such pairs), then per word a load, an add into the sum, `word + above`
/// and `below - word` ORed into the flags: six instructions a word. One block of assembly,
/// its template written a word position at a time ([`clip_position`], [`clip_word`]).
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn sum_clipped_words(
    conversions: &[u16; HALF_LEN],
    limits: &ClipLimits,
) -> (u32, u32, u32, u32) {
    let (ab, ca, bc, flags): (u32, u32, u32, u32);
    // SAFETY: the loads read the 48 bytes of `conversions` (words at byte offsets 0 to
    // 44; the Cortex-M4 loads a word at a halfword boundary, `CCR.UNALIGN_TRP` is never
    // set) and the 24 bytes of `limits` (`repr(C)`, word-aligned: `ldrd`), both through
    // live shared references; the block writes only its own output and scratch
    // registers, touches no other memory and no stack, and sets no condition flags.
    unsafe {
        core::arch::asm!(
            // (a, b): words 0, 3, 6, 9 (byte offsets 0, 12, 24, 36); its first word starts
            // the flags.
            "ldrd {a}, {b}, [{lim}]",
            "ldr {ab}, [{p}]",
            "add {t}, {ab}, {a}",
            "sub {f}, {b}, {ab}",
            "orr {f}, {f}, {t}",
            clip_word!("ab", 12),
            clip_word!("ab", 24),
            clip_word!("ab", 36),
            // (c, a): words 1, 4, 7, 10.
            clip_position!("ca", 8, 4, 16, 28, 40),
            // (b, c): words 2, 5, 8, 11.
            clip_position!("bc", 16, 8, 20, 32, 44),
            p = in(reg) conversions.as_ptr(),
            lim = in(reg) limits as *const ClipLimits,
            ab = out(reg) ab,
            ca = out(reg) ca,
            bc = out(reg) bc,
            f = out(reg) flags,
            a = out(reg) _,
            b = out(reg) _,
            t = out(reg) _,
            w = out(reg) _,
            options(pure, readonly, nostack, preserves_flags),
        );
    }
    (ab, ca, bc, flags)
}

/// Three channels of `PwmFilter` (`filter3_portable`'s arithmetic): per channel its two
/// stages loaded, the input `sum x scale + bias` (`mla`), the stages `a += (x - a) >> 2`,
/// `b += (a - b) >> 1` (arithmetic shifts, wrapping), the stages stored, the code `b >> 16`
/// saturated to 0..=4095 (`usat`): eight instructions a channel.
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn filter3(
    st: &mut [[i32; 2]; CHANNELS],
    sums: [u32; CHANNELS],
    scale: i32,
    bias: i32,
) -> [u16; CHANNELS] {
    let [mut x0, mut x1, mut x2] = sums;
    // SAFETY: `ldrd`/`strd` read and write the 24 bytes of `st` (word-aligned `i32`s)
    // through the live exclusive reference; nothing else is touched, no stack.
    unsafe {
        core::arch::asm!(
            "ldrd {a}, {b}, [{st}]",
            "mla {x0}, {x0}, {scale}, {bias}",
            "sub {t}, {x0}, {a}",
            "add {a}, {a}, {t}, asr #2",
            "sub {t}, {a}, {b}",
            "add {b}, {b}, {t}, asr #1",
            "strd {a}, {b}, [{st}]",
            "usat {x0}, #12, {b}, asr #16",
            "ldrd {a}, {b}, [{st}, #8]",
            "mla {x1}, {x1}, {scale}, {bias}",
            "sub {t}, {x1}, {a}",
            "add {a}, {a}, {t}, asr #2",
            "sub {t}, {a}, {b}",
            "add {b}, {b}, {t}, asr #1",
            "strd {a}, {b}, [{st}, #8]",
            "usat {x1}, #12, {b}, asr #16",
            "ldrd {a}, {b}, [{st}, #16]",
            "mla {x2}, {x2}, {scale}, {bias}",
            "sub {t}, {x2}, {a}",
            "add {a}, {a}, {t}, asr #2",
            "sub {t}, {a}, {b}",
            "add {b}, {b}, {t}, asr #1",
            "strd {a}, {b}, [{st}, #16]",
            "usat {x2}, #12, {b}, asr #16",
            st = in(reg) st.as_mut_ptr(),
            scale = in(reg) scale,
            bias = in(reg) bias,
            x0 = inout(reg) x0,
            x1 = inout(reg) x1,
            x2 = inout(reg) x2,
            a = out(reg) _,
            b = out(reg) _,
            t = out(reg) _,
            // `usat` sets the sticky Q flag when it saturates.
            options(nostack),
        );
    }
    [x0 as u16, x1 as u16, x2 as u16]
}

/// `EncoderCheck::sample`'s steps with the window's bias, ORed (`checks::steps_ored_portable`'s
/// arithmetic): per word of two counts `(c_{2j}, c_{2j+1})` (byte offset `4j`) and the word
/// one trigger earlier, `(c_{2j-1}, c_{2j})` (byte offset `4j - 2`; for the first, `last`
/// and `c_0` packed, `pkhbt`), `usub16` and `uadd16`: each half subtracted and added alone,
/// nothing borrowed or carried between them. Nineteen instructions, no stack.
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn steps_ored(latched: &[u16; OVERSAMPLING], last: u16, bias: u32) -> u32 {
    let out: u32;
    // SAFETY: the loads read the 16 bytes of `latched` (words at byte offsets 0 to 12 and
    // 2 to 10; the Cortex-M4 loads a word at a halfword boundary, `CCR.UNALIGN_TRP` is
    // never set) through a live shared reference; the block writes only its own output
    // and scratch registers, touches no other memory and no stack. `usub16` and `uadd16`
    // set the GE flags, which the block does not claim to preserve.
    unsafe {
        core::arch::asm!(
            "ldr {w}, [{p}]",
            "pkhbt {b}, {last}, {w}, lsl #16",
            "usub16 {o}, {w}, {b}",
            "uadd16 {o}, {o}, {bias}",
            "ldr {w}, [{p}, #4]",
            "ldr {b}, [{p}, #2]",
            "usub16 {t}, {w}, {b}",
            "uadd16 {t}, {t}, {bias}",
            "orr {o}, {o}, {t}",
            "ldr {w}, [{p}, #8]",
            "ldr {b}, [{p}, #6]",
            "usub16 {t}, {w}, {b}",
            "uadd16 {t}, {t}, {bias}",
            "orr {o}, {o}, {t}",
            "ldr {w}, [{p}, #12]",
            "ldr {b}, [{p}, #10]",
            "usub16 {t}, {w}, {b}",
            "uadd16 {t}, {t}, {bias}",
            "orr {o}, {o}, {t}",
            p = in(reg) latched.as_ptr(),
            last = in(reg) u32::from(last),
            bias = in(reg) bias,
            o = out(reg) out,
            w = out(reg) _,
            b = out(reg) _,
            t = out(reg) _,
            options(pure, readonly, nostack),
        );
    }
    out
}
