//! The start's hardware: `drive_monitor::startup::StartupHw` on the STM32G474, each register
//! access one method of the register layer (`drive_monitor::regs`, held to RM0440 by
//! `tests/firmware/registers.rs`), the RAM that survives a reset, the stack's paint and embassy's
//! `init`. The sequence over them (the freeze, the watchdog, the previous run, the clock's
//! bounded waits, the safe mode, the self-check) is `drive_monitor::startup::start`, the
//! code the host tests run on a register model.

use drive_monitor::boot_block::BOOT_BLOCK_LEN;
use drive_monitor::clock::{self, ClockSource};
use drive_monitor::debug_halt::FreezeRegisters;
use drive_monitor::regs::MCU;
use drive_monitor::reset_record::RESET_RECORD_LEN;
use drive_monitor::startup::StartupHw;
use drive_monitor::watchdog::IwdgSetting;

use super::reset_ram;
use super::stack;

/// The registers before `init` (and the peripherals it hands back).
pub(super) struct StartRegisters;

/// embassy-stm32's configuration for the PLL from `source` at 170 MHz: 24 MHz HSE / 6 (or
/// 16 MHz HSI / 4) x 85 / 2, boost mode, the ADC12 clock from SYSCLK (the settings of
/// `drive_monitor::clock`, from which every rate and cycle count is derived; the
/// registers' encodings, `clock::pll_fields`); `None`: the reset configuration
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
    let f = clock::pll_fields(source);
    config.rcc.pll = Some(Pll {
        source: pll_source,
        prediv: PllPreDiv::from_bits(f.m),
        mul: PllMul::from_bits(f.n),
        divp: None,
        divq: None,
        divr: Some(PllRDiv::from_bits(f.r)),
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
        MCU.read_freeze()
    }

    fn write_freeze(&mut self, regs: FreezeRegisters) {
        MCU.write_freeze(regs);
    }

    fn iwdg_key(&mut self, key: u16) {
        MCU.iwdg_key(key);
    }

    fn iwdg_setting(&mut self, setting: IwdgSetting) {
        MCU.iwdg_setting(setting);
    }

    fn iwdg_updating(&mut self) -> bool {
        MCU.iwdg_updating()
    }

    fn reset_flags(&mut self) -> u32 {
        MCU.reset_flags()
    }

    fn clear_reset_flags(&mut self) {
        MCU.clear_reset_flags();
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
        MCU.hse_on(on);
    }

    fn hse_ready(&mut self) -> bool {
        MCU.hse_ready()
    }

    fn pll_configure(&mut self, pllcfgr: u32) {
        MCU.pll_configure(pllcfgr);
    }

    fn pll_on(&mut self, on: bool) {
        MCU.pll_on(on);
    }

    fn pll_ready(&mut self) -> bool {
        MCU.pll_ready()
    }

    fn delay_us(&mut self, us: u32) {
        cortex_m::asm::delay(us.saturating_mul(clock::HSI_HZ / 1_000_000));
    }

    fn init(&mut self, clock: Option<ClockSource>) -> embassy_stm32::Peripherals {
        embassy_stm32::init(clock_config(clock))
    }

    fn set_css(&mut self, on: bool) {
        MCU.set_css(on);
    }

    fn read_word(&mut self, address: u32) -> u32 {
        MCU.read_word(address)
    }
}
