//! The start's registers: `drive_monitor::startup::StartupHw` on the STM32G474, one register
//! access a method. The sequence over them (the freeze, the watchdog, the previous run, the
//! clock's bounded waits, the safe mode, the self-check) is `drive_monitor::startup::start`,
//! the code the host tests run on a register model.

use drive_monitor::boot_block::BOOT_BLOCK_LEN;
use drive_monitor::clock::{self, ClockSource};
use drive_monitor::debug_halt::FreezeRegisters;
use drive_monitor::reset_record::RESET_RECORD_LEN;
use drive_monitor::startup::StartupHw;
use drive_monitor::watchdog::IwdgSetting;
use embassy_stm32::pac;

use super::reset_ram;
use super::stack;

/// The registers before `init` (and the peripherals it hands back).
pub(super) struct StartRegisters;

/// embassy-stm32's configuration for the PLL from `source` at 170 MHz: 24 MHz HSE / 6 (or
/// 16 MHz HSI / 4) x 85 / 2, boost mode, the ADC12 clock from SYSCLK (the settings of
/// `drive_monitor::clock`, from which every rate and cycle count is derived; the
/// registers' encodings: PLLM - 1, PLLN, PLLR / 2 - 1); `None`: the reset configuration
/// (the 16 MHz HSI, no PLL), the safe mode's.
fn clock_config(source: Option<ClockSource>) -> embassy_stm32::Config {
    use embassy_stm32::rcc::*;
    let mut config = embassy_stm32::Config::default();
    let Some(source) = source else {
        return config;
    };
    let pll_source = match source {
        ClockSource::Hse => {
            config.rcc.hse = Some(Hse {
                freq: embassy_stm32::time::Hertz(clock::HSE_HZ),
                mode: HseMode::Oscillator,
            });
            PllSource::HSE
        }
        ClockSource::Hsi | ClockSource::HsiAfterFailure => PllSource::HSI,
    };
    config.rcc.pll = Some(Pll {
        source: pll_source,
        prediv: PllPreDiv::from_bits((source.prediv() - 1) as u8),
        mul: PllMul::from_bits(clock::PLL_MUL as u8),
        divp: None,
        divq: None,
        divr: Some(PllRDiv::from_bits((clock::PLL_RDIV / 2 - 1) as u8)),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    // The ADC12 kernel clock mux defaults to "no clock" (Adc::new would panic).
    config.rcc.mux.adc12sel = mux::Adcsel::SYS;
    config
}

impl StartupHw for StartRegisters {
    type Peripherals = embassy_stm32::Peripherals;

    fn read_freeze(&mut self) -> FreezeRegisters {
        FreezeRegisters {
            apb1fzr1: pac::DBGMCU.apb1lfzr().read().0,
            apb2fzr: pac::DBGMCU.apb2fzr().read().0,
        }
    }

    fn write_freeze(&mut self, regs: FreezeRegisters) {
        pac::DBGMCU
            .apb1lfzr()
            .write_value(pac::dbgmcu::regs::Apb1lfzr(regs.apb1fzr1));
        pac::DBGMCU
            .apb2fzr()
            .write_value(pac::dbgmcu::regs::Apb2fzr(regs.apb2fzr));
    }

    fn iwdg_key(&mut self, key: u16) {
        pac::IWDG
            .kr()
            .write(|w| w.set_key(pac::iwdg::vals::Key::from_bits(key)));
    }

    fn iwdg_setting(&mut self, setting: IwdgSetting) {
        pac::IWDG
            .pr()
            .write(|w| w.set_pr(pac::iwdg::vals::Pr::from_bits(setting.pr)));
        pac::IWDG.rlr().write(|w| w.set_rl(setting.rlr));
    }

    fn iwdg_updating(&mut self) -> bool {
        let sr = pac::IWDG.sr().read();
        sr.pvu() || sr.rvu()
    }

    fn reset_flags(&mut self) -> u32 {
        pac::RCC.csr().read().0
    }

    fn clear_reset_flags(&mut self) {
        pac::RCC.csr().modify(|w| w.set_rmvf(true));
    }

    fn read_reset_record(&mut self) -> [u8; RESET_RECORD_LEN] {
        reset_ram::read_reset_record()
    }

    fn write_reset_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]) {
        reset_ram::write_reset_record(bytes);
    }

    fn read_boot_block(&mut self) -> [u8; BOOT_BLOCK_LEN] {
        reset_ram::read_boot_block()
    }

    fn write_boot_block(&mut self, bytes: &[u8; BOOT_BLOCK_LEN]) {
        reset_ram::write_boot_block(bytes);
    }

    fn check_and_paint_stack(&mut self) -> bool {
        stack::check_and_paint()
    }

    fn hse_on(&mut self, on: bool) {
        pac::RCC.cr().modify(|w| w.set_hseon(on));
    }

    fn hse_ready(&mut self) -> bool {
        pac::RCC.cr().read().hserdy()
    }

    fn pll_configure(&mut self, pllcfgr: u32) {
        pac::RCC
            .pllcfgr()
            .write_value(pac::rcc::regs::Pllcfgr(pllcfgr));
    }

    fn pll_on(&mut self, on: bool) {
        pac::RCC.cr().modify(|w| w.set_pllon(on));
    }

    fn pll_ready(&mut self) -> bool {
        pac::RCC.cr().read().pllrdy()
    }

    fn delay_us(&mut self, us: u32) {
        cortex_m::asm::delay(us.saturating_mul(clock::HSI_HZ / 1_000_000));
    }

    fn init(&mut self, clock: Option<ClockSource>) -> embassy_stm32::Peripherals {
        embassy_stm32::init(clock_config(clock))
    }

    fn set_css(&mut self, on: bool) {
        pac::RCC.cr().modify(|w| w.set_csson(on));
    }

    fn read_word(&mut self, address: u32) -> u32 {
        read_word(address)
    }
}

/// The register at `address`: the self-check's reads.
#[allow(unsafe_code)]
pub(super) fn read_word(address: u32) -> u32 {
    // SAFETY: the self-check table's addresses (`drive_monitor::self_check::registers`):
    // aligned 32-bit registers of peripherals whose clocks `init` enabled (the encoder's
    // timer and the ADCs' common register are read once the acquisition runs), of the
    // core's debug block, the flash interface and RCC, read only.
    unsafe { core::ptr::read_volatile(address as *const u32) }
}
