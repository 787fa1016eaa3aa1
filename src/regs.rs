//! The register layer: every register the firmware reads or writes itself (beside the
//! HAL's drivers), one method an access, written against stm32-metapac's register blocks
//! (the PAC embassy-stm32 0.6 is built on, `stm32-metapac` 21 with `stm32g474re`).
//!
//! The blocks are not taken at their fixed addresses but through a [`Bus`]: on the board
//! [`McuBus`] hands back the MCU's own address (`MCU`, what `src/firmware/*` calls), in the
//! host tests (`tests/firmware/registers.rs`) a memory of the test's own stands behind every
//! peripheral, and the test reads back word by word, at RM0440's addresses and bits written
//! out there, what each method wrote, and answers each read. So a wrong register, bit or
//! value here fails `cargo test`; `src/firmware/*` names no register (`tests/firmware/registers.rs`
//! checks that too) and only calls these methods, around embassy-stm32's drivers.
//!
//! The methods, by what they serve:
//! - [`startup`]: the debug freeze, the watchdog's keys, the reset flags, the crystal, the
//!   PLL, the clock security system, the self-check's reads (`crate::startup::StartupHw`);
//! - [`acquisition`]: the ADCs' and their DMA channels' flags and controls, the encoder
//!   latch's channel, the DMA interrupt's acknowledgement (`crate::recovery::AcqRegisters`,
//!   `crate::adc_rules::AdcPairSetup`);
//! - [`encoder`]: TIM4's input filter, direction and latch on the trigger;
//! - [`supply`]: the option bytes, VREFINT on ADC1's injected channel
//!   (`crate::supply::ReferenceAdc`);
//! - [`fault`]: the fault path's lamps, the fault status registers, the NMI's sources.

use stm32_metapac as pac;

pub mod acquisition;
pub mod encoder;
pub mod fault;
pub mod startup;
pub mod supply;

/// Where the register blocks are (module docs).
///
/// # Safety
/// [`Bus::at`] must return, for a peripheral's base address, a pointer to memory that
/// holds the whole block's registers (on the board the peripheral itself; in a test 4 KiB
/// of memory around it), valid for volatile reads and writes for as long as the bus is
/// used.
#[allow(unsafe_code)]
pub unsafe trait Bus: Copy {
    /// The memory standing for the peripheral at `address`.
    fn at(self, address: usize) -> *mut ();
}

/// The MCU's own addresses: the bus on the board.
#[derive(Clone, Copy, Debug, Default)]
pub struct McuBus;

// SAFETY: on the STM32G474 the peripherals' base addresses are the peripherals (RM0440,
// "Memory map"); the layer only ever asks for those.
#[allow(unsafe_code)]
unsafe impl Bus for McuBus {
    #[inline(always)]
    fn at(self, address: usize) -> *mut () {
        address as *mut ()
    }
}

/// The register layer on `bus` (module docs).
#[derive(Clone, Copy, Debug)]
pub struct Registers<B: Bus> {
    bus: B,
}

/// The layer on the board's own registers.
pub const MCU: Registers<McuBus> = Registers::new(McuBus);

/// A peripheral block of type `$ty` on the bus, at the address of stm32-metapac's `$pac`.
macro_rules! block {
    ($self:ident, $ty:ty, $pac:expr) => {{
        let at = $self.bus.at($pac.as_ptr() as usize);
        // SAFETY: the bus hands back memory for the whole block (`Bus`'s contract).
        #[allow(unsafe_code)]
        let block = unsafe { <$ty>::from_ptr(at) };
        block
    }};
}
use block;

impl<B: Bus> Registers<B> {
    /// The layer on `bus`.
    pub const fn new(bus: B) -> Self {
        Self { bus }
    }

    fn rcc(self) -> pac::rcc::Rcc {
        block!(self, pac::rcc::Rcc, pac::RCC)
    }

    fn flash(self) -> pac::flash::Flash {
        block!(self, pac::flash::Flash, pac::FLASH)
    }

    fn dbgmcu(self) -> pac::dbgmcu::Dbgmcu {
        block!(self, pac::dbgmcu::Dbgmcu, pac::DBGMCU)
    }

    fn iwdg(self) -> pac::iwdg::Iwdg {
        block!(self, pac::iwdg::Iwdg, pac::IWDG)
    }

    /// ADC `i`'s registers: ADC1 (the voltages) for 0, else ADC2 (the currents).
    fn adc(self, i: usize) -> pac::adc::Adc {
        if i == 0 {
            block!(self, pac::adc::Adc, pac::ADC1)
        } else {
            block!(self, pac::adc::Adc, pac::ADC2)
        }
    }

    fn adc12(self) -> pac::adccommon::AdcCommon {
        block!(self, pac::adccommon::AdcCommon, pac::ADC12_COMMON)
    }

    fn dma1(self) -> pac::bdma::Dma {
        block!(self, pac::bdma::Dma, pac::DMA1)
    }

    fn tim4(self) -> pac::timer::TimGp16 {
        block!(self, pac::timer::TimGp16, pac::TIM4)
    }

    fn vrefintcal(self) -> pac::vrefintcal::Vrefintcal {
        block!(self, pac::vrefintcal::Vrefintcal, pac::VREFINTCAL)
    }

    /// The 32-bit word at `address` (the self-check's reads, `crate::self_check::registers`'s
    /// addresses).
    pub fn read_word(self, address: u32) -> u32 {
        let at = self.bus.at(address as usize).cast::<u32>();
        // SAFETY: the self-check's table names aligned 32-bit registers of peripherals
        // whose clocks run when it reads them (`Bus`'s contract for the memory).
        #[allow(unsafe_code)]
        let word = unsafe { at.read_volatile() };
        word
    }
}
