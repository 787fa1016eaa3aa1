//! The clock tree, written once: the PLL's settings that the firmware's clock
//! configuration (`clock_config` in `src/firmware/startup_hw.rs`) hands embassy-stm32, and
//! every rate and cycle count derived from them (the fault path's wait, the set-up deadline's SysTick
//! reload, the encoder timer's clock, the sample trigger's and the ADC's rates).
//!
//! The source is the NUCLEO-G474RE's 24 MHz crystal (HSE, [`ClockSource::Hse`]): 24 MHz /
//! [`HSE_PREDIV`] x [`PLL_MUL`] / [`PLL_RDIV`] = 170 MHz. When the crystal does not start
//! within [`HSE_STARTUP_TIMEOUT_MS`] the firmware falls back to the internal 16 MHz
//! oscillator ([`ClockSource::Hsi`]): 16 MHz HSI / [`PLL_PREDIV`] x [`PLL_MUL`] /
//! [`PLL_RDIV`], the same 170 MHz SYSCLK (the G474's
//! maximum, with the regulator's boost mode), AHB and APB1/APB2 undivided, so HCLK and the
//! timers' kernel clocks are SYSCLK too (RM0440, "Clock tree"; a timer on an undivided APB
//! runs at the APB clock). The ADC12 kernel clock is SYSCLK ([`ADC_CLOCK_DIV`]: the common
//! prescaler of `ADC12_CCR`, 4, which embassy-stm32 0.6 picks to stay below the ADC's
//! 60 MHz): 42.5 MHz.

/// The longest the firmware waits for the crystal (HSE) to start before it falls back to
/// the HSI [ms].
pub const HSE_STARTUP_TIMEOUT_MS: u32 = 100;

/// The board's crystal (HSE, NUCLEO-G474RE's X3) [Hz].
pub const HSE_HZ: u32 = 24_000_000;
/// The PLL's input divider `PLLM` (1..=16) with the crystal: 4 MHz into the PLL.
pub const HSE_PREDIV: u32 = 6;
/// The time base's error with the crystal [ppm]: an assumption for a 24 MHz crystal of
/// the board's kind (initial tolerance, temperature and ageing together); check the part
/// fitted (the board's bill of materials).
pub const HSE_ERROR_PPM: u32 = 50;
/// The HSI oscillator [Hz] (the fallback source).
pub const HSI_HZ: u32 = 16_000_000;
/// The PLL's input divider `PLLM` (1..=16) with the HSI: 4 MHz into the PLL.
pub const PLL_PREDIV: u32 = 4;
/// The time base's error with the HSI [ppm]: +-1 % over temperature (datasheet).
pub const HSI_ERROR_PPM: u32 = 10_000;

/// The PLL's source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClockSource {
    /// The 24 MHz crystal ([`HSE_HZ`]).
    Hse,
    /// The internal 16 MHz oscillator ([`HSI_HZ`]): the crystal did not start.
    Hsi,
    /// The internal 16 MHz oscillator: the crystal failed while running in the previous
    /// run (the clock security system's record), so it is not tried again
    /// ([`boot_source`]).
    HsiAfterFailure,
}

/// The clock source at boot: the HSI straight away when the previous run ended in a
/// clock failure (`crystal_failed`: the clock security system saw the crystal stop; an
/// intermittent crystal would start again and fail again), else the crystal's bounded
/// start (`start_crystal`: [`ClockSource::Hse`] or, when it does not start, the HSI).
pub fn boot_source(
    crystal_failed: bool,
    start_crystal: impl FnOnce() -> ClockSource,
) -> ClockSource {
    if crystal_failed {
        ClockSource::HsiAfterFailure
    } else {
        start_crystal()
    }
}

/// Whether the clock security system is switched on for `source` (`RCC_CR.CSSON`, after
/// the clock set-up): with the crystal clocking the PLL, so that its failure is seen (an
/// NMI, the hardware's switch to the HSI) instead of stopping the clock or passing
/// silently; embassy-stm32 0.6 leaves it off.
pub const fn css_on(source: ClockSource) -> bool {
    matches!(source, ClockSource::Hse)
}

impl ClockSource {
    /// The PLL's input divider `PLLM` for this source (4 MHz into the PLL).
    pub const fn prediv(self) -> u32 {
        match self {
            ClockSource::Hse => HSE_PREDIV,
            ClockSource::Hsi | ClockSource::HsiAfterFailure => PLL_PREDIV,
        }
    }

    /// The source's frequency [Hz].
    pub const fn hz(self) -> u32 {
        match self {
            ClockSource::Hse => HSE_HZ,
            ClockSource::Hsi | ClockSource::HsiAfterFailure => HSI_HZ,
        }
    }

    /// SYSCLK from this source [Hz].
    pub const fn sysclk_hz(self) -> u32 {
        self.hz() / self.prediv() * PLL_MUL / PLL_RDIV
    }

    /// The time base's error [ppm]: every rate the monitor measures (supply frequency,
    /// speed, slip, time constants) is off by up to this much.
    pub const fn error_ppm(self) -> u32 {
        match self {
            ClockSource::Hse => HSE_ERROR_PPM,
            ClockSource::Hsi | ClockSource::HsiAfterFailure => HSI_ERROR_PPM,
        }
    }

    /// A short name for the boot report.
    pub const fn name(self) -> &'static str {
        match self {
            ClockSource::Hse => "24 MHz crystal (HSE)",
            ClockSource::Hsi => "internal oscillator (HSI, +-1 %): the crystal did not start",
            ClockSource::HsiAfterFailure => {
                "internal oscillator (HSI, +-1 %): the crystal failed in the previous run (clock security system)"
            }
        }
    }
}
/// `RCC_PLLCFGR` for the PLL from `source` (RM0440, "PLL configuration register"), as
/// embassy-stm32's `init` writes it from the firmware's clock configuration: `PLLSRC`
/// (bits 1:0; 2 the HSI16, 3 the HSE) and the source's [`pll_fields`] ([`PllFields::cfgr`]).
/// The boot writes it for the PLL's bounded lock before `init`
/// (`crate::startup::pll_locks`).
pub const fn pll_cfgr(source: ClockSource) -> u32 {
    let src = match source {
        ClockSource::Hse => 3,
        ClockSource::Hsi | ClockSource::HsiAfterFailure => 2,
    };
    pll_fields(source).cfgr(src)
}

/// The PLL's dividers and multiplier as `RCC_PLLCFGR`'s fields encode them (RM0440):
/// what embassy-stm32's `rcc::Pll` is given (`PllPreDiv`, `PllMul`, `PllRDiv` from these
/// bits, `src/firmware/startup_hw.rs`) and what [`pll_cfgr`] writes for the bounded lock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PllFields {
    /// `PLLM`: the input divider less one (0..=15: /1../16).
    pub m: u8,
    /// `PLLN`: the multiplier (8..=127).
    pub n: u8,
    /// `PLLR`: the R output's divider, `R / 2 - 1` (0: /2, 1: /4, 2: /6, 3: /8).
    pub r: u8,
}

impl PllFields {
    /// `RCC_PLLCFGR` with these fields and the source selection `pllsrc` (bits 1:0), as
    /// RM0440 lays the register out: `PLLM` (bits 7:4), `PLLN` (bits 14:8), `PLLREN` (bit
    /// 24: the R output, SYSCLK's, on) and `PLLR` (bits 26:25); the P and Q outputs off.
    pub const fn cfgr(self, pllsrc: u32) -> u32 {
        pllsrc
            | ((self.m as u32) << 4)
            | ((self.n as u32) << 8)
            | (1 << 24)
            | ((self.r as u32) << 25)
    }
}

/// The PLL's fields from `source` ([`PllFields`]).
pub const fn pll_fields(source: ClockSource) -> PllFields {
    PllFields {
        m: (source.prediv() - 1) as u8,
        n: PLL_MUL as u8,
        r: (PLL_RDIV / 2 - 1) as u8,
    }
}

/// The PLL's multiplier `PLLN` (8..=127).
pub const PLL_MUL: u32 = 85;
/// The PLL's `R` output divider (2, 4, 6 or 8): SYSCLK.
pub const PLL_RDIV: u32 = 2;

/// SYSCLK [Hz]: `HSE / PLLM x PLLN / PLLR` = 170 MHz (the same from the HSI, checked
/// below).
pub const SYSCLK_HZ: u32 = ClockSource::Hse.sysclk_hz();
/// HCLK [Hz] (AHB undivided): the CPU's clock, the DWT cycle counter's and SysTick's
/// (`/ 8` for its external reference).
pub const HCLK_HZ: u32 = SYSCLK_HZ;
/// The timers' kernel clock [Hz] (APB1 and APB2 undivided): TIM1 (the sample trigger) and
/// TIM4 (the encoder).
pub const TIMER_HZ: u32 = SYSCLK_HZ;
/// The ADC kernel clock's divider (`ADC12_CCR.PRESC`, with `ADC12SEL` = SYSCLK): the
/// smallest that keeps the ADC clock within [`ADC_CLOCK_MAX_HZ`], which is embassy's
/// choice too; read back at the set-up ([`ADC_PRESC`]).
pub const ADC_CLOCK_DIV: u32 = adc_clock_divider(SYSCLK_HZ);

/// The smallest divider of `ADC12_CCR.PRESC` that brings `kernel_hz` within
/// [`ADC_CLOCK_MAX_HZ`] (256 when none does; the quotient rounded up, so that a kernel clock
/// a few hertz above a multiple of the limit is not taken as within it).
pub const fn adc_clock_divider(kernel_hz: u32) -> u32 {
    const DIVIDERS: [u32; 12] = [1, 2, 4, 6, 8, 10, 12, 16, 32, 64, 128, 256];
    let mut rest: &[u32] = &DIVIDERS;
    while let [div, tail @ ..] = rest {
        if kernel_hz.div_ceil(*div) <= ADC_CLOCK_MAX_HZ {
            return *div;
        }
        rest = tail;
    }
    256
}
/// `ADC12_CCR.PRESC`'s encoding of [`ADC_CLOCK_DIV`] ([`adc_presc`]): embassy-stm32 0.6
/// picks the divider itself in `Adc::new`; the firmware reads the field back after the
/// set-up (`adc_rules::create_pair`) and reports a difference.
pub const ADC_PRESC: u32 = match adc_presc(ADC_CLOCK_DIV) {
    Some(presc) => presc,
    None => panic!("the ADC clock's divider has no encoding in ADC12_CCR.PRESC"),
};

/// `ADC12_CCR.PRESC`'s encoding of the divider `div` (RM0440: 0 /1, 1 /2, 2 /4, 3 /6, 4 /8,
/// 5 /10, 6 /12, 7 /16, 8 /32, 9 /64, 10 /128, 11 /256); `None` for a divider it has not.
pub const fn adc_presc(div: u32) -> Option<u32> {
    match div {
        1 => Some(0),
        2 => Some(1),
        4 => Some(2),
        6 => Some(3),
        8 => Some(4),
        10 => Some(5),
        12 => Some(6),
        16 => Some(7),
        32 => Some(8),
        64 => Some(9),
        128 => Some(10),
        256 => Some(11),
        _ => None,
    }
}
/// The ADC clock [Hz]: 42.5 MHz.
pub const ADC_CLOCK_HZ: u32 = SYSCLK_HZ / ADC_CLOCK_DIV;

/// CPU cycles per millisecond at [`HCLK_HZ`] (170 000).
pub const CYCLES_PER_MS: u32 = HCLK_HZ / 1_000;

/// The G474's largest SYSCLK [Hz] (boost mode).
pub const SYSCLK_MAX_HZ: u32 = 170_000_000;
/// The ADC's largest clock [Hz] (datasheet, single ADC).
pub const ADC_CLOCK_MAX_HZ: u32 = 60_000_000;

const _: () = assert!(
    SYSCLK_HZ <= SYSCLK_MAX_HZ,
    "SYSCLK above the G474's maximum"
);
const _: () = assert!(ADC_CLOCK_HZ <= ADC_CLOCK_MAX_HZ, "ADC clock too fast");
const _: () = assert!(
    HSI_HZ / PLL_PREDIV >= 2_660_000 && HSI_HZ / PLL_PREDIV <= 16_000_000,
    "PLL input out of range"
);
const _: () = assert!(
    HSE_HZ / HSE_PREDIV >= 2_660_000 && HSE_HZ / HSE_PREDIV <= 16_000_000,
    "PLL input out of range"
);
const _: () = assert!(
    ClockSource::Hsi.sysclk_hz() == SYSCLK_HZ && HSE_HZ.is_multiple_of(HSE_PREDIV),
    "the fallback gives another SYSCLK"
);

/// The divider of [`TIMER_HZ`] that gives `rate_hz`, when it is exact (`None` otherwise, or
/// for 0): the sample trigger's period in timer clocks.
pub const fn timer_divider(rate_hz: u32) -> Option<u32> {
    if rate_hz == 0 || !TIMER_HZ.is_multiple_of(rate_hz) {
        None
    } else {
        Some(TIMER_HZ / rate_hz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clock_tree_gives_170_mhz_and_the_rates_follow() {
        // An independent computation: 24 MHz / 6 (16 MHz / 4 from the HSI) = 4 MHz PLL
        // input, x 85 = 340 MHz VCO, / 2 = 170 MHz.
        assert_eq!(SYSCLK_HZ, 170_000_000);
        assert_eq!(ClockSource::Hse.sysclk_hz(), 170_000_000);
        assert_eq!(ClockSource::Hsi.sysclk_hz(), 170_000_000);
        assert_eq!(ClockSource::Hse.prediv(), 6);
        assert_eq!(CYCLES_PER_MS, 170_000);
        assert_eq!(ADC_CLOCK_HZ, 42_500_000);
        assert_eq!(ADC_PRESC, 0b0010);
        assert_eq!(timer_divider(10_000), Some(17_000));
        assert_eq!(timer_divider(80_000), Some(2_125));
        assert_eq!(timer_divider(30_000), None);
        assert_eq!(timer_divider(0), None);
        assert_eq!(ClockSource::HsiAfterFailure.sysclk_hz(), 170_000_000);
        // RM0440's fields written out: HSE (3), M = 6 (5), N = 85, R enabled, R = /2 (0).
        assert_eq!(pll_cfgr(ClockSource::Hse), 3 | 5 << 4 | 85 << 8 | 1 << 24);
        // HSI16 (2), M = 4 (3).
        assert_eq!(pll_cfgr(ClockSource::Hsi), 2 | 3 << 4 | 85 << 8 | 1 << 24);
        assert_eq!(
            pll_cfgr(ClockSource::HsiAfterFailure),
            pll_cfgr(ClockSource::Hsi)
        );
        // The fields embassy is handed: M - 1, N, R / 2 - 1 (RM0440's encodings).
        let hse = PllFields { m: 5, n: 85, r: 0 };
        assert_eq!(pll_fields(ClockSource::Hse), hse);
        assert_eq!(pll_fields(ClockSource::Hsi), PllFields { m: 3, ..hse });
    }

    /// `ADC12_CCR.PRESC`'s table in RM0440 ("ADC common control register"): each of the
    /// twelve dividers its code, nothing for a divider the field has not.
    #[test]
    fn every_adc_divider_has_rm0440s_presc_code() {
        let rm0440 = [
            (1, 0b0000),
            (2, 0b0001),
            (4, 0b0010),
            (6, 0b0011),
            (8, 0b0100),
            (10, 0b0101),
            (12, 0b0110),
            (16, 0b0111),
            (32, 0b1000),
            (64, 0b1001),
            (128, 0b1010),
            (256, 0b1011),
        ];
        for (div, code) in rm0440 {
            assert_eq!(adc_presc(div), Some(code), "/{div}");
        }
        for div in [0, 3, 5, 7, 9, 14, 24, 48, 100, 255, 512] {
            assert_eq!(adc_presc(div), None, "/{div}");
        }
    }

    /// The smallest divider that keeps the ADC clock at or below 60 MHz: a kernel clock at
    /// the limit undivided, one hertz above it halved, and so on along the field's
    /// dividers; above 15.36 GHz none would do (not reachable with a `u32`).
    #[test]
    fn the_adc_divider_is_the_smallest_within_60_mhz() {
        let cases = [
            (16_000_000, 1),
            (60_000_000, 1),
            (60_000_001, 2),
            (120_000_000, 2),
            (120_000_001, 4),
            (170_000_000, 4),
            (240_000_000, 4),
            (240_000_001, 6),
            (360_000_001, 8),
            (u32::MAX, 128),
        ];
        for (kernel_hz, div) in cases {
            assert_eq!(adc_clock_divider(kernel_hz), div, "{kernel_hz} Hz");
            assert!(adc_presc(div).is_some(), "/{div}");
        }
    }

    /// `RCC_PLLCFGR`'s fields where RM0440 puts them, each at its largest value: `PLLSRC`
    /// 1:0, `PLLM` 7:4, `PLLN` 14:8, `PLLREN` 24 and `PLLR` 26:25; `PLLR` = 1 (/4) alone at
    /// bit 25.
    #[test]
    fn the_pll_fields_are_where_rm0440_puts_them() {
        let widest = PllFields {
            m: 15,
            n: 127,
            r: 3,
        };
        assert_eq!(widest.cfgr(3), 0x0700_7FF3);
        let by_four = PllFields { m: 0, n: 0, r: 1 };
        assert_eq!(by_four.cfgr(0), 0x0300_0000);
        let by_two = PllFields { m: 0, n: 0, r: 0 };
        assert_eq!(by_two.cfgr(0), 0x0100_0000);
    }

    /// The time base's error by source: the crystal's 50 ppm (the assumption above), the
    /// HSI's +-1 % over temperature (the datasheet: 10 000 ppm), after a crystal failure too.
    #[test]
    fn the_time_bases_error_is_its_sources() {
        assert_eq!(ClockSource::Hse.error_ppm(), 50);
        assert_eq!(ClockSource::Hsi.error_ppm(), 10_000);
        assert_eq!(ClockSource::HsiAfterFailure.error_ppm(), 10_000);
    }

    /// The boot log's names tell the three sources apart and say why the HSI runs.
    #[test]
    fn each_source_is_named_with_why_it_runs() {
        assert!(ClockSource::Hse.name().contains("crystal (HSE)"));
        let hsi = ClockSource::Hsi.name();
        assert!(hsi.contains("(HSI, +-1 %)"), "{hsi}");
        assert!(hsi.contains("did not start"), "{hsi}");
        let after = ClockSource::HsiAfterFailure.name();
        assert!(after.contains("(HSI, +-1 %)"), "{after}");
        assert!(after.contains("failed in the previous run"), "{after}");
    }
}
