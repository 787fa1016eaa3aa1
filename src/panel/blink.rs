//! The FAULT lamp's blink codes (`crate::panel`'s module docs give the table): the code of
//! each fault the isolation names, of "not named" and of the three phases of shorted turns,
//! following the core's fault list; the lamp's pattern for a code ([`blink_code_lamp`]) and
//! a recorded trace read back ([`read_blink_code`], for the tests and for users who log the
//! pin).

/// Blink code of a fault detected that the isolation did not name (the panel's module
/// docs): the one after the last fault's ([`blink_code`] of the core's fault list,
/// `monitor_core::FAULTS`), 10 with Table 1's nine faults, so a fault added to the list
/// cannot collide with it.
pub const NOT_NAMED_CODE: u8 = blink_code(FAULT_CODES);

/// Blink code of shorted turns in phase a; b and c follow (the panel's module docs):
/// after [`NOT_NAMED_CODE`] (11, 12, 13 with Table 1's nine faults).
pub const WINDING_CODE_A: u8 = NOT_NAMED_CODE + 1;

/// The number of faults with a blink code: the core's fault list's length (at most 240,
/// so the winding codes after them fit a `u8`).
const FAULT_CODES: u8 = {
    assert!(monitor_core::FAULT_COUNT <= 240, "blink codes are one byte");
    monitor_core::FAULT_COUNT as u8
};

/// Blink code of shorted turns in the phase of index `phase_index` (0, 1, 2 for a, b, c):
/// 11, 12, 13.
pub const fn winding_code(phase_index: u8) -> u8 {
    WINDING_CODE_A.saturating_add(phase_index)
}

/// Blink code of a candidate index (`monitor_core::Fault::index`): `index + 1` (1..=9 for
/// Table 1's nine faults).
pub const fn blink_code(candidate_index: u8) -> u8 {
    candidate_index.saturating_add(1)
}

/// A pulse of the code, ms.
const BLINK_ON_MS: u32 = 250;
/// One pulse's slot, ms.
const BLINK_SLOT_MS: u32 = 500;
/// The dark gap after a code's pulses, ms.
const BLINK_GAP_MS: u32 = 1500;

/// Fault lamp state at `t_ms` for blink code `n` (>= 1): `n` pulses of 250 ms in 500 ms
/// slots, then 1.5 s dark; period `n * 500 + 1500` ms.
pub fn blink_code_lamp(n: u8, t_ms: u32) -> bool {
    if n == 0 {
        return false;
    }
    let period = u32::from(n) * BLINK_SLOT_MS + BLINK_GAP_MS;
    let phase = t_ms % period;
    phase < u32::from(n) * BLINK_SLOT_MS && phase % BLINK_SLOT_MS < BLINK_ON_MS
}

/// Decode a blink code from a recorded fault-lamp trace sampled every `step_ms`
/// (counts the pulses of the first complete group). For tests and for users who log
/// the pin; returns `None` if no complete group is seen.
pub fn read_blink_code(trace: &[bool], step_ms: u32) -> Option<u8> {
    let gap_steps = (BLINK_GAP_MS / step_ms.max(1)) as usize;
    // find the end of a dark gap, then count rising edges until the next gap
    let mut dark = 0usize;
    let mut start = None;
    for (k, &on) in trace.iter().enumerate() {
        if on {
            if dark >= gap_steps.saturating_sub(1) {
                start = Some(k);
                break;
            }
            dark = 0;
        } else {
            dark += 1;
        }
    }
    let start = start?;
    let mut pulses = 0u8;
    let mut prev = false;
    let mut dark = 0usize;
    for &on in trace.get(start..)? {
        if on && !prev {
            pulses = pulses.saturating_add(1);
        }
        dark = if on { 0 } else { dark + 1 };
        if dark >= gap_steps.saturating_sub(1) {
            return Some(pulses);
        }
        prev = on;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A code of `n` is `n` pulses of 250 ms, each at the start of its 500 ms slot, then
    /// 1.5 s dark, over and over: lit 250 ms of each slot and `n x 250` ms a period, at
    /// the millisecond; code 0 never lit.
    #[test]
    fn a_codes_pulses_are_250_ms_at_the_start_of_each_500_ms_slot() {
        for n in [1u8, 2, 9, NOT_NAMED_CODE, winding_code(2)] {
            let period = u32::from(n) * 500 + 1_500;
            let lit = (0..period).filter(|t| blink_code_lamp(n, *t)).count();
            assert_eq!(lit, usize::from(n) * 250, "code {n}");
            for start in (0..u32::from(n)).map(|k| k * 500) {
                for t in [start, start + 249, period + start] {
                    assert!(blink_code_lamp(n, t), "code {n} at {t} ms");
                }
                for t in [start + 250, start + 499] {
                    assert!(!blink_code_lamp(n, t), "code {n} at {t} ms");
                }
            }
            for t in u32::from(n) * 500..period {
                assert!(!blink_code_lamp(n, t), "code {n} at {t} ms: the gap");
            }
        }
        assert!((0..10_000).all(|t| !blink_code_lamp(0, t)));
    }
}
