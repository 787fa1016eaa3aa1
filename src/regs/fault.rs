//! The fault path's registers: the lamps without the HAL's drivers (which may be in any
//! state), the Cortex-M4's fault status registers, and the NMI's two sources (the clock
//! security system's `RCC_CIFR.CSSF`, the flash's `FLASH_ECCR.ECCD`).

use super::{pac, Bus, Registers};
use crate::board::{Lamp, Port};
use pac::gpio::vals::Moder;

/// The Cortex-M4's fault status registers (Armv7-M ARM, "System Control Block").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultStatus {
    /// `CFSR` (0xE000_ED28): the configurable fault status (MemManage, BusFault,
    /// UsageFault).
    pub cfsr: u32,
    /// `HFSR` (0xE000_ED2C): the HardFault status.
    pub hfsr: u32,
    /// `BFAR` (0xE000_ED38): the bus fault's address.
    pub bfar: u32,
}

impl<B: Bus> Registers<B> {
    fn gpio(self, port: Port) -> pac::gpio::Gpio {
        match port {
            Port::A => super::block!(self, pac::gpio::Gpio, pac::GPIOA),
            Port::B => super::block!(self, pac::gpio::Gpio, pac::GPIOB),
            Port::C => super::block!(self, pac::gpio::Gpio, pac::GPIOC),
            Port::D => super::block!(self, pac::gpio::Gpio, pac::GPIOD),
            Port::E => super::block!(self, pac::gpio::Gpio, pac::GPIOE),
            Port::F => super::block!(self, pac::gpio::Gpio, pac::GPIOF),
            Port::G => super::block!(self, pac::gpio::Gpio, pac::GPIOG),
        }
    }

    /// Every lamp's pin an output (`GPIOx_MODER` = 01), lit where `on` says, dark
    /// elsewhere: one `GPIOx_BSRR` write a port (set bits low, reset bits high), so a
    /// port's lamps change together. The GPIO clocks are on (`embassy_stm32::init`
    /// enables every port's).
    pub fn show_lamps(self, on: impl Fn(Lamp) -> bool) {
        for port in [
            Port::A,
            Port::B,
            Port::C,
            Port::D,
            Port::E,
            Port::F,
            Port::G,
        ] {
            let mut bsrr = 0u32;
            for lamp in Lamp::ALL.into_iter().filter(|l| l.pin().port == port) {
                let n = usize::from(lamp.pin().number);
                self.gpio(port)
                    .moder()
                    .modify(|w| w.set_moder(n, Moder::OUTPUT));
                bsrr |= if on(lamp) { 1 << n } else { 1 << (n + 16) };
            }
            if bsrr != 0 {
                self.gpio(port)
                    .bsrr()
                    .write_value(pac::gpio::regs::Bsrr(bsrr));
            }
        }
    }

    /// The fault status registers ([`FaultStatus`]).
    pub fn fault_status(self) -> FaultStatus {
        let at = self.bus.at(cortex_m::peripheral::SCB::PTR as usize);
        // SAFETY: the bus hands back memory for the System Control Block's registers
        // (`Bus`'s contract); they are only read.
        #[allow(unsafe_code)]
        let scb = unsafe { &*at.cast::<cortex_m::peripheral::scb::RegisterBlock>() };
        FaultStatus {
            cfsr: scb.cfsr.read(),
            hfsr: scb.hfsr.read(),
            bfar: scb.bfar.read(),
        }
    }

    /// `RCC_CIFR` and `FLASH_ECCR`, the NMI's sources (`crate::flash_ecc::nmi_cause`).
    pub fn nmi_sources(self) -> (u32, u32) {
        (self.rcc().cifr().read().0, self.flash().eccr().read().0)
    }

    /// `RCC_CICR.CSSC`: the clock security system's flag cleared (its NMI would pend
    /// again).
    pub fn clear_clock_failure(self) {
        self.rcc().cicr().write(|w| w.set_cssc(true));
    }

    /// `FLASH_ECCR.ECCD` and `ECCC` cleared (write 1; the other bits are read-only or
    /// enables, written back as read).
    pub fn clear_ecc(self) {
        self.flash().eccr().modify(|w| {
            w.set_eccd(true);
            w.set_eccc(true);
        });
    }
}
