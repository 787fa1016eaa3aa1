//! The stack: painted at boot, its high-water mark measured while the firmware runs, and an
//! overflow in the previous run detected at the next boot.
//!
//! **Layout.** The firmware links with flip-link (`.cargo/config.toml`): the stack sits at
//! the bottom of RAM, below `.data`, `.bss` and `.uninit`, and grows down towards
//! 0x2000_0000. A stack that overflows runs off the start of RAM into no memory at all
//! and faults (a bus fault on the stacking, escalated, or a lock-up that the watchdog ends)
//! instead of silently overwriting the DMA rings and the monitor's state above it, as it
//! did with cortex-m-rt's default layout (the stack at the top of RAM, growing down onto
//! the statics). [`region_bottom`] finds the stack's lowest address for either layout.
//!
//! **Paint.** At boot the firmware fills the stack below its own frame with [`PAINT`].
//! [`high_water_words`] counts from the bottom up the words still holding it: the stack
//! never reached below them. The status line's `stack=` is the rest, in bytes
//! ([`high_water_bytes`]).
//!
//! **Overflow at the next boot.** A stack that reached the bottom of RAM overwrote the
//! lowest [`GUARD_WORDS`]; the run then ended in a fault or a lock-up and a reset (RAM
//! keeps its content across a reset). The boot looks at the guard before painting again
//! ([`overflowed`]): only when the previous run painted it (a marker in `.uninit`,
//! [`PAINTED`]), so power-on garbage is no overflow.

/// The start of RAM (`memory.x`'s `RAM` origin, SRAM1 at 0x2000_0000 in RM0440's memory
/// map): the stack's bottom with flip-link.
pub const RAM_START: u32 = 0x2000_0000;

/// The word the stack is painted with.
pub const PAINT: u32 = 0x57AC_C0DE;
/// The marker the firmware keeps in `.uninit` RAM once the stack is painted, so the next
/// boot knows the guard words were painted ([`overflowed`]).
pub const PAINTED: u32 = 0x5041_494E;
/// The lowest words of the stack region that only an overflow reaches (64 bytes: more than
/// the deepest frame the sample path's interrupt stacks above a nearly full stack).
pub const GUARD_WORDS: usize = 16;
/// The bytes below the current stack pointer left unpainted at boot (the painting code's
/// own frame and a margin).
pub const PAINT_MARGIN_BYTES: u32 = 256;

/// The stack region's lowest address: the start of RAM `ram_start` when the stack lies below
/// the statics (flip-link: the initial stack pointer `initial_sp` is at or below the first
/// static's address `first_static`), else cortex-m-rt's `_stack_end` (`stack_end`: the end
/// of the statics; the default layout, the stack above them).
pub const fn region_bottom(
    initial_sp: u32,
    first_static: u32,
    ram_start: u32,
    stack_end: u32,
) -> u32 {
    if initial_sp <= first_static {
        ram_start
    } else {
        stack_end
    }
}

/// The words of a stack region of `len` words still holding [`PAINT`] from its bottom up
/// (`word(i)`: the region's `i`-th word from the bottom, read volatile on the board): the
/// stack never reached below the first other word.
pub fn high_water_words(len: usize, word: impl Fn(usize) -> u32) -> usize {
    (0..len).find(|&i| word(i) != PAINT).unwrap_or(len)
}

/// The stack's high-water mark [bytes] in a region of `len` words whose lowest
/// `untouched` words still hold [`PAINT`] ([`high_water_words`]).
pub const fn high_water_bytes(len: usize, untouched: usize) -> u32 {
    (len.saturating_sub(untouched) * 4) as u32
}

/// Whether the previous run's stack reached the bottom of its region: it had painted the
/// region (`painted_marker == PAINTED`) and a word of the lowest [`GUARD_WORDS`]
/// (`guard`) no longer holds [`PAINT`].
pub fn overflowed(painted_marker: u32, guard: &[u32]) -> bool {
    painted_marker == PAINTED && guard.iter().take(GUARD_WORDS).any(|&w| w != PAINT)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_high_water_mark_counts_the_words_the_stack_reached() {
        // A region of 100 words, the top 30 used at some point, one word below left
        // painted by chance (a frame's unwritten slot) does not hide the depth.
        let mut ram = vec![PAINT; 100];
        for w in &mut ram[70..] {
            *w = 0;
        }
        ram[85] = PAINT;
        let untouched = high_water_words(ram.len(), |i| ram[i]);
        assert_eq!(untouched, 70);
        assert_eq!(high_water_bytes(ram.len(), untouched), 120);
        assert_eq!(high_water_words(0, |_| 0), 0);
        assert_eq!(high_water_bytes(100, 100), 0);
    }

    #[test]
    fn an_overflow_is_the_guard_overwritten_after_a_painted_run() {
        let mut guard = [PAINT; GUARD_WORDS];
        assert!(!overflowed(PAINTED, &guard));
        guard[GUARD_WORDS - 1] = 0x2000_1234;
        assert!(overflowed(PAINTED, &guard));
        // Power-on RAM (no marker): no verdict from garbage.
        assert!(!overflowed(0xFFFF_FFFF, &guard));
    }

    #[test]
    fn the_region_starts_at_ram_with_flip_link_and_after_the_statics_without() {
        // flip-link: the stack's top at 0x2001_D000, the statics above it.
        assert_eq!(
            region_bottom(0x2001_D000, 0x2001_D000, 0x2000_0000, 0x2002_0000),
            0x2000_0000
        );
        // cortex-m-rt's own layout: statics at the bottom, the stack from the top of RAM
        // down to their end.
        assert_eq!(
            region_bottom(0x2002_0000, 0x2000_0000, 0x2000_0000, 0x2000_2300),
            0x2000_2300
        );
    }
}
