//! The boot's self-check: what the firmware wrote, read back.
//!
//! Every remedy of the earlier reviews that lives in a register (the debug freeze, the clock
//! security system, the encoder's mode, filter and latch, the ADCs' common register) or in
//! the option bytes a user programs once (`CCMSRAM_RST`, `SRAM_PE`, nBOOT0 and nSWBOOT0, `IWDG_SW`,
//! `BFB2`, `DBANK`, the brown-out level) is read back at its address after it was written
//! ([`registers`]: the table `cargo fw bring-up` reads over the probe too), and each register
//! that does not hold the expected bits sets its bit in the run's [`Findings`]. The clock's
//! fallbacks are findings too ([`CRYSTAL_DID_NOT_START`], [`PLL_DID_NOT_LOCK`]).
//!
//! The findings go into every reset record the run writes (`ResetRecord::with_findings`),
//! so the next boot and the reset log in flash say which remedy did not take; the boot's log
//! and the virtual COM port's boot report list them at once.

use crate::clock::{ClockSource, ADC_PRESC};
use crate::supply::BOR_GOAL;

pub mod registers;
pub use registers::{CheckId, Expectation, RegisterCheck};

/// A finding's bit: the crystal did not start within `clock::HSE_STARTUP_TIMEOUT_MS` (the
/// HSI clocks the PLL instead).
pub const CRYSTAL_DID_NOT_START: u32 = 1 << 16;
/// A finding's bit: the PLL did not lock from the crystal within its bound
/// (`crate::startup::PLL_LOCK_POLLS`; the HSI clocks it instead).
pub const PLL_DID_NOT_LOCK: u32 = 1 << 17;

/// The run's self-check findings: a bit for each [`CheckId`] whose register did not hold
/// what the firmware wrote, and the clock's fallbacks ([`CRYSTAL_DID_NOT_START`],
/// [`PLL_DID_NOT_LOCK`]). 0: everything took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Findings(pub u32);

impl Findings {
    /// Nothing found.
    pub const NONE: Findings = Findings(0);

    /// Whether nothing was found.
    pub const fn is_clean(self) -> bool {
        self.0 == 0
    }

    /// The checks whose register did not hold the expected bits.
    pub fn mismatched(self) -> impl Iterator<Item = CheckId> {
        CheckId::ALL
            .into_iter()
            .filter(move |id| self.0 & id.bit() != 0)
    }

    /// Whether the crystal did not start.
    pub const fn crystal_did_not_start(self) -> bool {
        self.0 & CRYSTAL_DID_NOT_START != 0
    }

    /// Whether the PLL did not lock from the crystal.
    pub const fn pll_did_not_lock(self) -> bool {
        self.0 & PLL_DID_NOT_LOCK != 0
    }

    /// These findings and `other`'s.
    #[must_use]
    pub const fn with(self, other: u32) -> Findings {
        Findings(self.0 | other)
    }
}

/// The encoder timer's set-up the self-check expects (`motor_source::EncoderSetup`'s input
/// filter and direction).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncoderExpected {
    /// `ICxF` of both inputs (0..=15).
    pub filter: u8,
    /// Input A's polarity inverted (`CC1P`).
    pub invert_a: bool,
}

/// What this run's registers must hold: the clock `source` (the clock security system on
/// with the crystal only, `clock::css_on`), the encoder's set-up (`None` before it is
/// known: those bits are left out), the ADC clock's prescaler [`ADC_PRESC`] and the
/// brown-out level [`BOR_GOAL`].
pub fn expectation(source: ClockSource, encoder: Option<EncoderExpected>) -> Expectation {
    Expectation {
        crystal: crate::clock::css_on(source),
        encoder_filter: encoder.map(|e| e.filter),
        invert_a: encoder.map(|e| e.invert_a),
        adc_presc: ADC_PRESC,
        bor_level: u32::from(BOR_GOAL.number()),
    }
}

/// The findings of the checks `ids` against `expected`, each register read by `read` at
/// its address (on the board a volatile read of the address; in the host tests the
/// register model's).
pub fn run(ids: &[CheckId], expected: &Expectation, read: impl FnMut(u32) -> u32) -> Findings {
    Findings(expected.mismatches(ids, read))
}

#[cfg(test)]
mod tests {
    use super::registers::*;
    use super::*;
    use crate::debug_halt::{self, FreezeRegisters, FROZEN};
    use crate::supply::{BorCheck, BorLevel};

    /// The table's bits are the ones the rest of the firmware writes and reads: the
    /// freeze the boot computes, the brown-out level `supply` decodes, the clock's
    /// prescaler.
    #[test]
    fn the_table_agrees_with_the_firmwares_own_constants() {
        let e = expectation(ClockSource::Hse, None);
        let after = FROZEN.registers_after(FreezeRegisters {
            apb1fzr1: 0,
            apb2fzr: 0,
        });
        assert!(e.check(CheckId::FreezeWatchdog).holds(after.apb1fzr1));
        assert!(e.check(CheckId::FreezeTimers).holds(after.apb2fzr));
        assert_eq!(
            e.check(CheckId::FreezeTimers).mask,
            debug_halt::DBG_TIM1_STOP | debug_halt::DBG_TIM15_STOP
        );
        assert_eq!(
            e.check(CheckId::FreezeWatchdog).mask,
            debug_halt::DBG_IWDG_STOP
        );
        // The brown-out check holds exactly where `supply` says the level is at its goal.
        for n in 0..8u32 {
            let optr = 0xFFEF_F0AA | (n << 8);
            let at_goal = matches!(BorCheck::of_optr(optr), BorCheck::AtGoal(_));
            assert_eq!(e.check(CheckId::BrownOutLevel).holds(optr), at_goal, "{n}");
        }
        assert_eq!(
            BorLevel::from_optr(e.check(CheckId::BrownOutLevel).expected),
            Some(BOR_GOAL)
        );
        assert_eq!(e.check(CheckId::AdcCommon).expected >> 18 & 0xF, ADC_PRESC);
        // The clock security system: on with the crystal only.
        assert_eq!(e.check(CheckId::ClockSecurity).expected, CSSON);
        let hsi = expectation(ClockSource::Hsi, None);
        assert_eq!(hsi.check(CheckId::ClockSecurity).expected, 0);
        // Every check has its own bit; the two groups make the whole list.
        let bits = CheckId::ALL.iter().fold(0u32, |m, id| m | id.bit());
        assert_eq!(bits.count_ones() as usize, CheckId::ALL.len());
        assert_eq!(bits & (CRYSTAL_DID_NOT_START | PLL_DID_NOT_LOCK), 0);
        assert_eq!(
            CheckId::BOOT.len() + CheckId::ACQUISITION.len(),
            CheckId::ALL.len()
        );
        // Each check names its register and field, as the log and `cargo fw bring-up` print
        // them; no two alike.
        let names: Vec<&str> = CheckId::ALL.iter().map(|c| c.name()).collect();
        for (id, name) in CheckId::ALL.iter().zip(&names) {
            let register = match e.check(*id).address {
                0xE004_2008 => "DBGMCU_APB1FZR1.",
                0xE004_2010 => "DBGMCU_APB2FZR.",
                0x4002_1000 => "RCC_CR.",
                0x4002_2020 => "FLASH_OPTR.",
                0x4000_0808 => "TIM4_SMCR.",
                0x4000_0818 => "TIM4_CCMR1.",
                0x4000_081C => "TIM4_CCMR2.",
                0x4000_0820 => "TIM4_CCER.",
                0x4000_080C => "TIM4_DIER.",
                0x5000_0308 => "ADC12_CCR.",
                other => panic!("{id:?} at {other:#x}, an address not in RM0440's list"),
            };
            assert!(name.starts_with(register), "{id:?}: {name}");
        }
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), names.len());
    }

    /// Every check's register, mask and expected bits, RM0440's fields written out as
    /// numbers (the board's run: the crystal, the encoder's filter 6 with input A inverted).
    #[test]
    fn every_check_reads_the_bits_rm0440_gives() {
        let setup = EncoderExpected {
            filter: 6,
            invert_a: true,
        };
        let e = expectation(ClockSource::Hse, Some(setup));
        let table = [
            (
                CheckId::FreezeWatchdog,
                0xE004_2008,
                0x0000_1000,
                0x0000_1000,
            ),
            (CheckId::FreezeTimers, 0xE004_2010, 0x0001_0800, 0x0001_0800),
            (
                CheckId::ClockSecurity,
                0x4002_1000,
                0x0008_0000,
                0x0008_0000,
            ),
            (CheckId::CcmSramKept, 0x4002_2020, 0x0200_0000, 0x0200_0000),
            (
                CheckId::SramParityOff,
                0x4002_2020,
                0x0100_0000,
                0x0100_0000,
            ),
            (
                CheckId::BootFromFlash,
                0x4002_2020,
                0x0800_0000,
                0x0800_0000,
            ),
            (
                CheckId::WatchdogBySoftware,
                0x4002_2020,
                0x0001_0000,
                0x0001_0000,
            ),
            (CheckId::BootBank1, 0x4002_2020, 0x0010_0000, 0),
            (CheckId::DualBank, 0x4002_2020, 0x0040_0000, 0x0040_0000),
            (
                CheckId::BrownOutLevel,
                0x4002_2020,
                0x0000_0700,
                0x0000_0400,
            ),
            (CheckId::EncoderMode, 0x4000_0808, 0x0031_0077, 0x0000_0003),
            (
                CheckId::EncoderInputs,
                0x4000_0818,
                0x0000_F3F3,
                0x0000_6161,
            ),
            (CheckId::EncoderLatch, 0x4000_081C, 0x0000_0003, 0x0000_0003),
            (
                CheckId::EncoderEnables,
                0x4000_0820,
                0x0000_0333,
                0x0000_0113,
            ),
            (CheckId::LatchDma, 0x4000_080C, 0x0000_0800, 0x0000_0800),
            (CheckId::AdcCommon, 0x5000_0308, 0x007F_001F, 0x0048_0000),
        ];
        for (id, address, mask, expected) in table {
            assert_eq!(
                e.check(id),
                RegisterCheck {
                    id,
                    address,
                    mask,
                    expected
                },
                "{id:?}"
            );
        }
        // Not knowing the record: the filter's and the direction's bits left out.
        let b = Expectation::BRING_UP;
        assert_eq!(b.check(CheckId::EncoderInputs).mask, 0x0303);
        assert_eq!(b.check(CheckId::EncoderEnables).mask, 0x0331);
    }

    /// The findings: clean only without a bit; a finding found twice stays found.
    #[test]
    fn findings_add_up_and_a_check_listed_twice_is_found_once() {
        assert!(Findings::NONE.is_clean());
        let f = Findings(CheckId::DualBank.bit());
        assert!(!f.is_clean());
        assert_eq!(f.with(CheckId::DualBank.bit()), f);
        assert_eq!(
            f.with(PLL_DID_NOT_LOCK).0,
            CheckId::DualBank.bit() | PLL_DID_NOT_LOCK
        );
        assert!(f.with(PLL_DID_NOT_LOCK).pll_did_not_lock());
        let e = expectation(ClockSource::Hse, None);
        let twice = [CheckId::DualBank, CheckId::DualBank];
        assert_eq!(run(&twice, &e, |_| 0), f);
    }

    /// The G474's factory option bytes (0xFFEF_F8AA, RM0440) hold everything the firmware
    /// wants but the brown-out level (0 at the factory) and `nSWBOOT0` (1 at the factory:
    /// the BOOT0 pin decides, `nBOOT0` has no effect): the self-check finds those two, and
    /// `cargo fw bor` sets both.
    #[test]
    fn the_factory_option_bytes_miss_the_brown_out_level_and_the_boot_pin() {
        let e = expectation(ClockSource::Hse, None);
        let option_checks = [
            CheckId::CcmSramKept,
            CheckId::SramParityOff,
            CheckId::BootFromFlash,
            CheckId::WatchdogBySoftware,
            CheckId::BootBank1,
            CheckId::DualBank,
            CheckId::BrownOutLevel,
            CheckId::BootPinIgnored,
        ];
        let found = run(&option_checks, &e, |a| {
            assert_eq!(a, FLASH_OPTR);
            0xFFEF_F8AA
        });
        assert_eq!(
            found.mismatched().collect::<Vec<_>>(),
            [CheckId::BrownOutLevel, CheckId::BootPinIgnored]
        );
        // After `cargo fw bor` (BOR_LEV = 4, nSWBOOT0 = 0, bit 26): nothing found; one bit
        // off each time: each check sees its own.
        let wanted = (0xFFEF_F8AA | (4 << 8)) & !(1 << 26);
        assert!(run(&option_checks, &e, |_| wanted).is_clean());
        for (id, bit) in [
            (CheckId::CcmSramKept, OPTR_CCMSRAM_RST),
            (CheckId::SramParityOff, OPTR_SRAM_PE),
            (CheckId::BootFromFlash, OPTR_NBOOT0),
            (CheckId::WatchdogBySoftware, OPTR_IWDG_SW),
            (CheckId::BootBank1, OPTR_BFB2),
            (CheckId::DualBank, OPTR_DBANK),
            (CheckId::BootPinIgnored, OPTR_NSWBOOT0),
        ] {
            let optr = wanted ^ bit;
            let found = run(&option_checks, &e, |_| optr);
            assert_eq!(found.mismatched().collect::<Vec<_>>(), [id], "{id:?}");
        }
        assert_eq!(OPTR_NSWBOOT0, 1 << 26);
    }

    /// The encoder's registers as embassy's `Qei::new` and the firmware's latch set them
    /// (RM0440's fields written out here): encoder mode 3, TI1/TI2, the record's filter and
    /// direction, channel 3 on TRC with its DMA request.
    #[test]
    fn the_encoder_checks_read_the_fields_the_set_up_writes() {
        let setup = EncoderExpected {
            filter: 6,
            invert_a: true,
        };
        let e = expectation(ClockSource::Hse, Some(setup));
        let regs = |a: u32| match a {
            TIM4_SMCR => 0b0011,                               // SMS = 3, TS = ITR0
            TIM4_CCMR1 => 0b01 | 6 << 4 | 0b01 << 8 | 6 << 12, // CC1S, IC1F, CC2S, IC2F
            TIM4_CCMR2 => 0b11,                                // CC3S = TRC
            TIM4_CCER => 1 | 1 << 1 | 1 << 4 | 1 << 8,         // CC1E, CC1P, CC2E, CC3E
            TIM4_DIER => 1 << 11,                              // CC3DE
            ADC12_CCR => 0b0010 << 18 | 1 << 22,               // PRESC /4, VREFEN
            _ => panic!("{a:#x}"),
        };
        assert!(run(&CheckId::ACQUISITION, &e, regs).is_clean());
        // Another filter, the direction not inverted, the latch's request off.
        let wrong = |a: u32| match a {
            TIM4_CCMR1 => regs(a) & !(0xF << 4),
            TIM4_CCER => regs(a) & !(1 << 1),
            TIM4_DIER => 0,
            _ => regs(a),
        };
        let found = run(&CheckId::ACQUISITION, &e, wrong);
        assert_eq!(
            found.mismatched().collect::<Vec<_>>(),
            [
                CheckId::EncoderInputs,
                CheckId::EncoderEnables,
                CheckId::LatchDma
            ]
        );
        // `cargo fw bring-up` does not know the record: the filter and direction are left
        // out, the rest is compared.
        assert!(
            run(&CheckId::ACQUISITION, &Expectation::BRING_UP, |a| match a {
                TIM4_CCMR1 => regs(a) & !(0xF << 4),
                TIM4_CCER => regs(a) & !(1 << 1),
                _ => regs(a),
            })
            .is_clean()
        );
    }
}
