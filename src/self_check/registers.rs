//! The registers the boot's self-check reads back, with their addresses, masks and
//! expected values (RM0440, the STM32G474's reference manual; the addresses are the
//! peripherals' base plus the register's offset, the bit positions its field tables').
//!
//! One table for two readers: the firmware reads each address after it wrote the
//! register (`crate::self_check`, the boot's self-check) and `cargo fw bring-up`
//! (`tools/fwtool`, which includes this file as it is) reads the same addresses over the
//! probe and prints each against its expected value. So this file names no other module and
//! no crate: plain constants and functions, `no_std` and `std` alike.

/// One check: the register at `address`, its bits in `mask` against `expected`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegisterCheck {
    /// What is checked (its bit in the mismatch mask: [`CheckId::bit`]).
    pub id: CheckId,
    /// The register's address.
    pub address: u32,
    /// The bits compared.
    pub mask: u32,
    /// Their expected value (`value & mask == expected`).
    pub expected: u32,
}

impl RegisterCheck {
    /// Whether a read `value` of the register holds the expected bits.
    pub const fn holds(&self, value: u32) -> bool {
        value & self.mask == self.expected
    }
}

/// What the self-check reads back, each the remedy of an earlier review.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CheckId {
    /// `DBGMCU_APB1FZR1.DBG_IWDG_STOP` (bit 12): a halt stops the watchdog.
    FreezeWatchdog = 0,
    /// `DBGMCU_APB2FZR.DBG_TIM1_STOP` (bit 11) and `DBG_TIM15_STOP` (bit 16): a halt stops
    /// the sample trigger and embassy-time's clock.
    FreezeTimers = 1,
    /// `RCC_CR.CSSON` (bit 19): the clock security system, on with the crystal only.
    ClockSecurity = 2,
    /// `FLASH_OPTR.CCMSRAM_RST` (bit 25) = 1: CCM SRAM kept across a system reset (0 erases
    /// it, and with flip-link the reset record lies there).
    CcmSramKept = 3,
    /// `FLASH_OPTR.SRAM_PE` (bit 24) = 1: SRAM parity off (on, a read of RAM not written
    /// since power-on, the reset record's, may raise a parity NMI).
    SramParityOff = 4,
    /// `FLASH_OPTR.nBOOT0` (bit 27) = 1: boot from the main flash when the option bit
    /// decides.
    BootFromFlash = 5,
    /// `FLASH_OPTR.IWDG_SW` (bit 16) = 1: the watchdog started by software, with the
    /// boot's timeout.
    WatchdogBySoftware = 6,
    /// `FLASH_OPTR.BFB2` (bit 20) = 0: boot from bank 1, where the code is linked.
    BootBank1 = 7,
    /// `FLASH_OPTR.DBANK` (bit 22) = 1: dual-bank flash, which the record pages need.
    DualBank = 8,
    /// `FLASH_OPTR.BOR_LEV` (bits 10:8) = 4: the brown-out reset at about 2.8 V.
    BrownOutLevel = 9,
    /// `TIM4_SMCR.SMS` = 0011 (encoder mode 3, x4) and `TS` = ITR0 (TIM1's TRGO).
    EncoderMode = 10,
    /// `TIM4_CCMR1`: `CC1S` = `CC2S` = 01 (TI1, TI2) and the record's input filter in
    /// `IC1F` and `IC2F`.
    EncoderInputs = 11,
    /// `TIM4_CCMR2.CC3S` = 11: channel 3 captures on TRC, the count latched at the
    /// trigger.
    EncoderLatch = 12,
    /// `TIM4_CCER`: `CC1E`, `CC2E`, `CC3E` on, `CC1P` the record's direction, `CC2P` and
    /// `CC3P` off.
    EncoderEnables = 13,
    /// `TIM4_DIER.CC3DE` (bit 11): each latch raises the DMA request.
    LatchDma = 14,
    /// `ADC12_CCR`: `PRESC` = 0010 (/4, 42.5 MHz), `CKMODE` = 00, `DUAL` = 00000
    /// (independent), `VREFEN` on.
    AdcCommon = 15,
    /// `FLASH_OPTR.nSWBOOT0` (bit 26) = 0: the option bit `nBOOT0` chooses the boot memory,
    /// not the BOOT0 pin (PB8). At the factory's 1 the pin decides and `nBOOT0` has no
    /// effect: a pin high at a reset starts ST's bootloader instead of the firmware. (Bit 18
    /// of the findings: 16 and 17 are the clock's.)
    BootPinIgnored = 18,
}

impl CheckId {
    /// Every check, in the order of their bits.
    pub const ALL: [CheckId; 17] = [
        CheckId::FreezeWatchdog,
        CheckId::FreezeTimers,
        CheckId::ClockSecurity,
        CheckId::CcmSramKept,
        CheckId::SramParityOff,
        CheckId::BootFromFlash,
        CheckId::WatchdogBySoftware,
        CheckId::BootBank1,
        CheckId::DualBank,
        CheckId::BrownOutLevel,
        CheckId::EncoderMode,
        CheckId::EncoderInputs,
        CheckId::EncoderLatch,
        CheckId::EncoderEnables,
        CheckId::LatchDma,
        CheckId::AdcCommon,
        CheckId::BootPinIgnored,
    ];
    /// The checks read right after the clock set-up (the freeze, the clock security
    /// system, the option bytes).
    pub const BOOT: [CheckId; 11] = [
        CheckId::FreezeWatchdog,
        CheckId::FreezeTimers,
        CheckId::ClockSecurity,
        CheckId::CcmSramKept,
        CheckId::SramParityOff,
        CheckId::BootFromFlash,
        CheckId::WatchdogBySoftware,
        CheckId::BootBank1,
        CheckId::DualBank,
        CheckId::BrownOutLevel,
        CheckId::BootPinIgnored,
    ];
    /// The checks read once the acquisition runs (the encoder's timer, the ADCs' common
    /// register).
    pub const ACQUISITION: [CheckId; 6] = [
        CheckId::EncoderMode,
        CheckId::EncoderInputs,
        CheckId::EncoderLatch,
        CheckId::EncoderEnables,
        CheckId::LatchDma,
        CheckId::AdcCommon,
    ];

    /// The check's bit in a mismatch mask.
    pub const fn bit(self) -> u32 {
        1 << (self as u32)
    }

    /// The register and field, as RM0440 names them.
    pub const fn name(self) -> &'static str {
        match self {
            CheckId::FreezeWatchdog => "DBGMCU_APB1FZR1.DBG_IWDG_STOP",
            CheckId::FreezeTimers => "DBGMCU_APB2FZR.DBG_TIM1_STOP/DBG_TIM15_STOP",
            CheckId::ClockSecurity => "RCC_CR.CSSON",
            CheckId::CcmSramKept => "FLASH_OPTR.CCMSRAM_RST",
            CheckId::SramParityOff => "FLASH_OPTR.SRAM_PE",
            CheckId::BootFromFlash => "FLASH_OPTR.nBOOT0",
            CheckId::WatchdogBySoftware => "FLASH_OPTR.IWDG_SW",
            CheckId::BootBank1 => "FLASH_OPTR.BFB2",
            CheckId::DualBank => "FLASH_OPTR.DBANK",
            CheckId::BrownOutLevel => "FLASH_OPTR.BOR_LEV",
            CheckId::EncoderMode => "TIM4_SMCR.SMS/TS",
            CheckId::EncoderInputs => "TIM4_CCMR1.CC1S/CC2S/IC1F/IC2F",
            CheckId::EncoderLatch => "TIM4_CCMR2.CC3S",
            CheckId::EncoderEnables => "TIM4_CCER.CC1E/CC1P/CC2E/CC2P/CC3E/CC3P",
            CheckId::LatchDma => "TIM4_DIER.CC3DE",
            CheckId::AdcCommon => "ADC12_CCR.PRESC/CKMODE/DUAL/VREFEN",
            CheckId::BootPinIgnored => "FLASH_OPTR.nSWBOOT0",
        }
    }
}

/// `DBGMCU_APB1FZR1` (DBGMCU at 0xE004_2000, offset 0x08).
pub const DBGMCU_APB1FZR1: u32 = 0xE004_2008;
/// `DBGMCU_APB2FZR` (offset 0x10).
pub const DBGMCU_APB2FZR: u32 = 0xE004_2010;
/// `RCC_CR` (RCC at 0x4002_1000, offset 0x00).
pub const RCC_CR: u32 = 0x4002_1000;
/// `FLASH_OPTR` (the flash interface at 0x4002_2000, offset 0x20).
pub const FLASH_OPTR: u32 = 0x4002_2020;
/// TIM4's base.
const TIM4: u32 = 0x4000_0800;
/// `TIM4_SMCR` (offset 0x08).
pub const TIM4_SMCR: u32 = TIM4 + 0x08;
/// `TIM4_DIER` (offset 0x0C).
pub const TIM4_DIER: u32 = TIM4 + 0x0C;
/// `TIM4_CCMR1` (offset 0x18).
pub const TIM4_CCMR1: u32 = TIM4 + 0x18;
/// `TIM4_CCMR2` (offset 0x1C).
pub const TIM4_CCMR2: u32 = TIM4 + 0x1C;
/// `TIM4_CCER` (offset 0x20).
pub const TIM4_CCER: u32 = TIM4 + 0x20;
/// `ADC12_CCR` (the ADC1/ADC2 common registers at 0x5000_0300, offset 0x08).
pub const ADC12_CCR: u32 = 0x5000_0308;

/// `RCC_CR.CSSON`.
pub const CSSON: u32 = 1 << 19;
/// `FLASH_OPTR.BOR_LEV`'s field.
pub const OPTR_BOR_LEV: u32 = 0b111 << 8;
/// `FLASH_OPTR.IWDG_SW`.
pub const OPTR_IWDG_SW: u32 = 1 << 16;
/// `FLASH_OPTR.BFB2`.
pub const OPTR_BFB2: u32 = 1 << 20;
/// `FLASH_OPTR.DBANK`.
pub const OPTR_DBANK: u32 = 1 << 22;
/// `FLASH_OPTR.SRAM_PE`.
pub const OPTR_SRAM_PE: u32 = 1 << 24;
/// `FLASH_OPTR.CCMSRAM_RST`.
pub const OPTR_CCMSRAM_RST: u32 = 1 << 25;
/// `FLASH_OPTR.nBOOT0`.
pub const OPTR_NBOOT0: u32 = 1 << 27;
/// `FLASH_OPTR.nSWBOOT0`.
pub const OPTR_NSWBOOT0: u32 = 1 << 26;

/// What the expected values depend on: the run's clock source, the motor record's encoder
/// set-up (`None`: not known, as for `cargo fw bring-up`, which then leaves those bits out
/// of the comparison) and the ADC clock's prescaler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expectation {
    /// The crystal clocks the PLL: the clock security system is on.
    pub crystal: bool,
    /// The encoder inputs' filter `ICxF` (0..=15).
    pub encoder_filter: Option<u8>,
    /// Input A's polarity inverted (`CC1P`): the record's direction.
    pub invert_a: Option<bool>,
    /// `ADC12_CCR.PRESC`'s expected field value (0b0010: /4 at 170 MHz).
    pub adc_presc: u32,
    /// The brown-out level wanted (`BOR_LEV`, 4).
    pub bor_level: u32,
}

impl Expectation {
    /// A board running from its crystal, the encoder's set-up not known: what
    /// `cargo fw bring-up` compares with.
    pub const BRING_UP: Expectation = Expectation {
        crystal: true,
        encoder_filter: None,
        invert_a: None,
        adc_presc: 0b0010,
        bor_level: 4,
    };

    /// The check `id` against this expectation.
    pub const fn check(&self, id: CheckId) -> RegisterCheck {
        let (address, mask, expected) = match id {
            CheckId::FreezeWatchdog => (DBGMCU_APB1FZR1, 1 << 12, 1 << 12),
            CheckId::FreezeTimers => (DBGMCU_APB2FZR, (1 << 11) | (1 << 16), (1 << 11) | (1 << 16)),
            CheckId::ClockSecurity => (RCC_CR, CSSON, if self.crystal { CSSON } else { 0 }),
            CheckId::CcmSramKept => (FLASH_OPTR, OPTR_CCMSRAM_RST, OPTR_CCMSRAM_RST),
            CheckId::SramParityOff => (FLASH_OPTR, OPTR_SRAM_PE, OPTR_SRAM_PE),
            CheckId::BootFromFlash => (FLASH_OPTR, OPTR_NBOOT0, OPTR_NBOOT0),
            CheckId::BootPinIgnored => (FLASH_OPTR, OPTR_NSWBOOT0, 0),
            CheckId::WatchdogBySoftware => (FLASH_OPTR, OPTR_IWDG_SW, OPTR_IWDG_SW),
            CheckId::BootBank1 => (FLASH_OPTR, OPTR_BFB2, 0),
            CheckId::DualBank => (FLASH_OPTR, OPTR_DBANK, OPTR_DBANK),
            CheckId::BrownOutLevel => (FLASH_OPTR, OPTR_BOR_LEV, (self.bor_level & 0b111) << 8),
            // SMS in bits 2:0 and 16, TS in bits 6:4 and 21:20.
            CheckId::EncoderMode => (TIM4_SMCR, 0x0031_0077, 0b0011),
            CheckId::EncoderInputs => match self.encoder_filter {
                Some(f) => {
                    let f = (f & 0xF) as u32;
                    (TIM4_CCMR1, 0xF3F3, 0x0101 | (f << 4) | (f << 12))
                }
                None => (TIM4_CCMR1, 0x0303, 0x0101),
            },
            CheckId::EncoderLatch => (TIM4_CCMR2, 0b11, 0b11),
            // CC1E bit 0, CC1P 1, CC2E 4, CC2P 5, CC3E 8, CC3P 9.
            CheckId::EncoderEnables => match self.invert_a {
                Some(inv) => (TIM4_CCER, 0x333, 0x111 | if inv { 0b10 } else { 0 }),
                None => (TIM4_CCER, 0x331, 0x111),
            },
            CheckId::LatchDma => (TIM4_DIER, 1 << 11, 1 << 11),
            // DUAL bits 4:0, CKMODE 17:16, PRESC 21:18, VREFEN 22.
            CheckId::AdcCommon => (
                ADC12_CCR,
                0x1F | (0b11 << 16) | (0xF << 18) | (1 << 22),
                ((self.adc_presc & 0xF) << 18) | (1 << 22),
            ),
        };
        RegisterCheck {
            id,
            address,
            mask,
            expected,
        }
    }

    /// The mismatch mask of the checks `ids` ([`CheckId::bit`] set for each check whose
    /// register, read by `read` at its address, does not hold the expected bits).
    pub fn mismatches(&self, ids: &[CheckId], mut read: impl FnMut(u32) -> u32) -> u32 {
        ids.iter()
            .map(|&id| self.check(id))
            .filter(|c| !c.holds(read(c.address)))
            .fold(0, |mask, c| mask | c.id.bit())
    }
}
