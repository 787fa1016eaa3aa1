//! The ADCs' set-up under a deadline.
//!
//! embassy-stm32 0.6 sets the ADCs up with loops that wait on register flags without a
//! bound: `Adc::new` polls `ADCAL` after each of the two calibrations and `ADRDY` after
//! `ADEN` (after an `ADDIS` poll), and `into_ring_buffered` polls `ADSTART` when it stops a
//! conversion and `ADRDY` again when it re-enables the ADC (RM0440, "ADC on-off control",
//! "Calibration"). The firmware cannot change those loops; it bounds them in time instead:
//! before the set-up it arms a deadline of [`SETUP_DEADLINE_MS`] on the Cortex-M SysTick
//! timer, marks each [`SetupStep`] as it begins, and disarms the deadline when the
//! acquisition runs. SysTick's exception has priority 0 (its reset value, which nothing
//! changes), above the sample executor's interrupt (P1) the set-up runs in, so it fires
//! while a loop spins; it then writes the reset record [`on_deadline`] makes (the step and
//! the deadline, [`crate::reset_record::ResetCause::SetupDeadline`]) and resets the MCU by
//! software. The next boot logs `... the adc set-up step <step> did not finish within
//! 20 ms`. The firmware's own waits on ADC flags are bounded by counts (the reference's
//! conversion, [`crate::supply::measure_now`]; the recovery's, [`crate::recovery::poll_until`]).
//!
//! The set-up record written before the set-up ([`crate::reset_record::ResetRecord::setup`])
//! and the watchdog stay as the backstop for what SysTick cannot interrupt: a loop with
//! interrupts masked (none of the set-up's loops is).

use crate::reset_record::ResetRecord;

/// The set-up's deadline [ms]: the whole ADC set-up takes well under 1 ms (two
/// calibrations of about 116 ADC cycles, three 20 us regulator and calibration delays per
/// ADC, the enables and the reference's 6 us conversion), so 20 ms is a hang, and it
/// leaves the watchdog's 500 ms as a backstop.
pub const SETUP_DEADLINE_MS: u32 = 20;

/// SysTick's clock on the STM32G4 with `CLKSOURCE = 0`: HCLK / 8 (RM0440, "Clocks": the
/// RCC feeds the Cortex system timer's external clock with the AHB clock divided by 8;
/// PM0214, "SysTick timer"). At 170 MHz, 21.25 MHz.
pub const fn systick_hz(hclk_hz: u32) -> u32 {
    hclk_hz / 8
}

/// SysTick's reload value for a deadline of `deadline_ms` at `hclk_hz` (the counter counts
/// `reload + 1` ticks of HCLK / 8); `None` when it does not fit SysTick's 24 bits (more
/// than 789 ms at 170 MHz) or is zero.
pub fn systick_reload(hclk_hz: u32, deadline_ms: u32) -> Option<u32> {
    let ticks = u64::from(systick_hz(hclk_hz)) * u64::from(deadline_ms) / 1000;
    let reload = ticks.checked_sub(1)?;
    u32::try_from(reload)
        .ok()
        .filter(|r| *r > 0 && *r < (1 << 24))
}

/// One step of the ADC set-up, in its order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetupStep {
    /// ADC1 (voltages): clock, regulator, calibrations, enable (`Adc::new`).
    Adc1,
    /// ADC1's regular sequence, trigger and DMA ring (`into_ring_buffered`).
    Ring1,
    /// VREFINT on ADC1's injected channel: configured and measured once.
    Reference,
    /// ADC2 (currents): as ADC1.
    Adc2,
    /// ADC2's sequence, trigger and ring.
    Ring2,
    /// Both rings and ADCs started, then the trigger.
    Start,
}

impl SetupStep {
    /// All steps, in their order.
    pub const ALL: [SetupStep; 6] = [
        SetupStep::Adc1,
        SetupStep::Ring1,
        SetupStep::Reference,
        SetupStep::Adc2,
        SetupStep::Ring2,
        SetupStep::Start,
    ];

    /// The step's name in logs and records.
    pub const fn name(self) -> &'static str {
        match self {
            SetupStep::Adc1 => "adc1",
            SetupStep::Ring1 => "adc1-ring",
            SetupStep::Reference => "vrefint",
            SetupStep::Adc2 => "adc2",
            SetupStep::Ring2 => "adc2-ring",
            SetupStep::Start => "start",
        }
    }

    /// The step's number for the firmware's static: 1.. in order (0 means "no set-up
    /// running").
    pub const fn number(self) -> u8 {
        self as u8 + 1
    }

    /// The step of a number (`None` for 0, "no set-up running", and out of range).
    pub fn from_number(n: u8) -> Option<SetupStep> {
        SetupStep::ALL.get(usize::from(n.checked_sub(1)?)).copied()
    }
}

/// What the deadline's exception does with the step number `running` (0: no set-up is
/// running, the deadline came after the guard was disarmed): the record to write before
/// the reset, or `None` to do nothing.
pub fn on_deadline(running: u8) -> Option<ResetRecord> {
    SetupStep::from_number(running)
        .map(|s| ResetRecord::setup_deadline(s.name(), SETUP_DEADLINE_MS))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reset_record::{PreviousRun, ResetCause, ResetSource};

    #[test]
    fn steps_number_from_one_and_zero_is_none() {
        for step in SetupStep::ALL {
            assert_eq!(SetupStep::from_number(step.number()), Some(step));
        }
        assert_eq!(SetupStep::from_number(0), None);
        assert_eq!(SetupStep::from_number(7), None);
    }

    #[test]
    fn the_deadline_fits_systick() {
        // 20 ms at HCLK/8 = 21.25 MHz: 425 000 ticks.
        assert_eq!(
            systick_reload(170_000_000, SETUP_DEADLINE_MS),
            Some(424_999)
        );
        assert_eq!(systick_reload(170_000_000, 800), None, "over 24 bits");
        assert_eq!(systick_reload(170_000_000, 0), None);
    }

    /// PM0214, "SysTick reload value register": `RELOAD` is 24 bits, 0x00_0001 to
    /// 0xFF_FFFF; a reload of 0 never fires (the exception comes as the counter goes from 1
    /// to 0).
    #[test]
    fn the_reload_stays_within_systicks_24_bits_and_above_zero() {
        // HCLK / 8 = 2^24 Hz for 1 s: 2^24 ticks, the reload 0xFF_FFFF, the largest.
        assert_eq!(systick_reload(134_217_728, 1_000), Some(0x00FF_FFFF));
        // 1 Hz more at SysTick (8 Hz of HCLK): a reload of 2^24, beyond 24 bits.
        assert_eq!(systick_reload(134_217_736, 1_000), None);
        // HCLK / 8 = 1 kHz: 1 ms is one tick, a reload of 0; 2 ms a reload of 1.
        assert_eq!(systick_reload(8_000, 1), None);
        assert_eq!(systick_reload(8_000, 2), Some(1));
    }

    #[test]
    fn a_step_that_overruns_the_deadline_is_reported_at_the_next_boot() {
        assert_eq!(on_deadline(0), None, "disarmed: nothing happens");
        let rec = on_deadline(SetupStep::Ring2.number()).unwrap();
        // The handler's software reset: reported whatever reset came (unlike the
        // watchdog's set-up record).
        for source in [ResetSource::Software, ResetSource::IndependentWatchdog] {
            let PreviousRun::Recorded(back) = PreviousRun::at_boot(&rec.encode(), source) else {
                panic!("not reported after a {source:?} reset");
            };
            assert_eq!(
                (back.cause(), back.message(), back.line_or_ms()),
                (ResetCause::SetupDeadline, "adc2-ring", SETUP_DEADLINE_MS)
            );
        }
    }
}
