//! The supply's registers: the option bytes (the brown-out level, the flash's banks) and
//! VREFINT on ADC1's injected channel (`crate::supply::ReferenceAdc`).

use super::{pac, Bus, Registers};
use crate::adc_rules;
use pac::adc::vals::{Exten, SampleTime};

/// ADC1's VREFINT channel (RM0440, "ADC1 connectivity": ADC1_IN18).
pub const VREFINT_CHANNEL: u8 = 18;

/// VREFINT's sampling time: 247.5 ADC cycles, 5.8 us at 42.5 MHz (the datasheet's
/// `t_S_vrefint` asks for at least 4 us).
pub const VREFINT_SAMPLE_TIME: SampleTime = SampleTime::CYCLES247_5;

impl<B: Bus> Registers<B> {
    /// `FLASH_OPTR` (the option bytes in force).
    pub fn optr(self) -> u32 {
        self.flash().optr().read().0
    }

    /// `FLASH_OPTR.DBANK`: the option bytes select dual-bank flash.
    pub fn dual_bank(self) -> bool {
        self.flash().optr().read().dbank()
    }

    /// ADC1's injected sequence: one conversion of VREFINT ([`VREFINT_CHANNEL`]),
    /// software-triggered, with [`VREFINT_SAMPLE_TIME`] (channel 18's field of `SMPR2`; the
    /// regular sequence's sample times are `SMPR1` and channels 10..17 of `SMPR2`). Call
    /// with ADC1 enabled and `ADSTART = JADSTART = 0`: `SMPR2` and `JSQR` are writable
    /// only then.
    pub fn configure_reference(self) {
        let adc = self.adc(0);
        adc.smpr2()
            .modify(|w| w.set_smp(usize::from(VREFINT_CHANNEL - 10), VREFINT_SAMPLE_TIME));
        adc.jsqr().write(|w| {
            w.set_jl(0);
            w.set_jexten(Exten::DISABLED);
            w.set_jsq(0, VREFINT_CHANNEL);
        });
    }

    /// The factory's VREFINT calibration word (`VREFINT_CAL`, system memory).
    pub fn vrefint_calibration(self) -> u16 {
        self.vrefintcal().data().read()
    }

    /// `ADC12_CCR.VREFEN` set: the VREFINT buffer on.
    pub fn vrefint_enable(self) {
        self.adc12().ccr().modify(|w| w.set_vrefen(true));
    }

    /// `ADC1_CR.JADSTART` written alone (`adc_rules::cr_setting`: no other set-only bit
    /// written back). The caller keeps the read and the write in one critical section (the
    /// sample task's recovery writes `ADC1_CR` too).
    pub fn start_injected(self) {
        let cr = self.adc(0).cr();
        let value = adc_rules::cr_setting(cr.read().0, adc_rules::JADSTART);
        cr.write_value(pac::adc::regs::Cr(value));
    }

    /// The injected conversion's result (`ADC1_JDR1`) once `ADC1_ISR.JEOS` says it ended,
    /// `JEOS` and `JEOC` then cleared (write 1; the regular group's flags stay).
    pub fn injected_result(self) -> Option<u16> {
        let adc = self.adc(0);
        if !adc.isr().read().jeos() {
            return None;
        }
        let code = adc.jdr(0).read().jdata();
        adc.isr().write(|w| {
            w.set_jeos(true);
            w.set_jeoc(true);
        });
        Some(code)
    }
}
