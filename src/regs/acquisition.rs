//! The acquisition's registers: ADC1/ADC2 (`ADC_ISR`, `ADC_CR`, `ADC_CFGR`), their common
//! prescaler, and DMA1's channels of the two rings and of the encoder latch
//! (`crate::recovery::AcqRegisters`, `crate::adc_rules::AdcPairSetup`; the sequences over
//! them are the library's). The ADC index `i` is 0 for ADC1 (the voltages), else ADC2 (the
//! currents); its ring's DMA channel is [`RING_CHANNELS`]`[i]`.

use super::{pac, Bus, Registers};
use crate::recovery::AdcFlags;
use pac::adc::vals::{Dmacfg, Dmaen, SampleTime};

/// The DMA1 channels of the ADCs' rings, as register indices (0: channel 1): ADC1's on
/// channel 1, ADC2's on channel 2.
pub const RING_CHANNELS: [usize; 2] = [0, 1];
/// The DMA1 channel of the encoder latch's ring, as a register index: channel 3.
pub const LATCH_CHANNEL: usize = 2;

/// The regular conversions' sampling time: 24.5 ADC cycles
/// (`crate::acquisition::SAMPLE_TIME_HALF_CYCLES`, 49 half cycles: 870 ns a conversion
/// with the 12.5 cycles of approximation at 42.5 MHz).
pub const SAMPLE_TIME: SampleTime = SampleTime::CYCLES24_5;

/// ADC `i`'s ring channel (0: ADC1's, else ADC2's).
const fn ring(i: usize) -> usize {
    if i == 0 {
        RING_CHANNELS[0]
    } else {
        RING_CHANNELS[1]
    }
}

impl<B: Bus> Registers<B> {
    /// `ADC_ISR`'s `OVR`, `EOC` and `EOS` of ADC `i`.
    pub fn adc_flags(self, i: usize) -> AdcFlags {
        let isr = self.adc(i).isr().read();
        AdcFlags {
            ovr: isr.ovr(),
            eoc: isr.eoc(),
            eos: isr.eos(),
        }
    }

    /// Clears the flags `f` of ADC `i` (write 1 to clear; the others are left as they are).
    pub fn adc_clear(self, i: usize, f: AdcFlags) {
        self.adc(i).isr().write(|w| {
            w.set_ovr(f.ovr);
            w.set_eoc(f.eoc);
            w.set_eos(f.eos);
        });
    }

    /// ADC `i`'s `ADC_CR`.
    pub fn adc_cr(self, i: usize) -> u32 {
        self.adc(i).cr().read().0
    }

    /// ADC `i`'s `ADC_CR` written whole, as the sequence computed it
    /// (`adc_rules::cr_setting`: one set-only bit, the ordinary bits as read), not a
    /// read-modify-write.
    pub fn adc_cr_write(self, i: usize, value: u32) {
        self.adc(i).cr().write_value(pac::adc::regs::Cr(value));
    }

    /// `ADC_CFGR.DMAEN` set and `DMACFG` circular on ADC `i`.
    pub fn adc_dma_circular(self, i: usize) {
        self.adc(i).cfgr().modify(|w| {
            w.set_dmaen(Dmaen::ENABLE);
            w.set_dmacfg(Dmacfg::CIRCULAR);
        });
    }

    /// `ADC_CFGR.DMAEN` cleared on ADC `i` (the ADC withdraws its DMA request).
    pub fn adc_dma_off(self, i: usize) {
        self.adc(i).cfgr().modify(|w| w.set_dmaen(Dmaen::DISABLE));
    }

    /// `ADC12_CCR.PRESC` (the common prescaler's field).
    pub fn adc_prescaler(self) -> u32 {
        u32::from(self.adc12().ccr().read().presc().to_bits())
    }

    /// `TEIE` cleared on the rings' and the latch's DMA channels: a transfer error stops
    /// the channel without the HAL's interrupt (which panics on one). Only with the
    /// channels disabled (before the first start).
    pub fn dma_errors_masked(self) {
        for n in RING_CHANNELS.into_iter().chain([LATCH_CHANNEL]) {
            self.dma1().ch(n).cr().modify(|w| w.set_teie(false));
        }
    }

    /// `DMA_ISR.TEIF` of ADC `i`'s ring channel.
    pub fn dma_error(self, i: usize) -> bool {
        self.dma1().isr().read().teif(ring(i))
    }

    /// `DMA_IFCR`: every flag of DMA register channel `n` cleared (`TEIF`, `HTIF`, `TCIF`,
    /// `GIF`).
    fn dma_clear_channel(self, n: usize) {
        self.dma1().ifcr().write(|w| {
            w.set_teif(n, true);
            w.set_htif(n, true);
            w.set_tcif(n, true);
            w.set_gif(n, true);
        });
    }

    /// Every flag of ADC `i`'s ring channel cleared.
    pub fn dma_clear(self, i: usize) {
        self.dma_clear_channel(ring(i));
    }

    /// `DMA_CCR.EN` of ADC `i`'s ring channel.
    pub fn dma_enabled(self, i: usize) -> bool {
        self.dma1().ch(ring(i)).cr().read().en()
    }

    /// `DMA_CNDTR` of ADC `i`'s ring channel: `transfers` (the channel is off).
    pub fn dma_reload(self, i: usize, transfers: u16) {
        self.dma1()
            .ch(ring(i))
            .ndtr()
            .write(|w| w.set_ndt(transfers));
    }

    /// `DMA_CCR.EN` set on ADC `i`'s ring channel.
    pub fn dma_enable(self, i: usize) {
        self.dma1().ch(ring(i)).cr().modify(|w| w.set_en(true));
    }

    /// `TIM4_DIER.CC3DE`: the latch's capture raises its DMA request (withdrawn when
    /// cleared).
    pub fn latch_request(self, on: bool) {
        self.tim4().dier().modify(|w| w.set_ccde(2, on));
    }

    /// `DMA_CCR.EN` of the latch's channel.
    pub fn latch_enabled(self) -> bool {
        self.dma1().ch(LATCH_CHANNEL).cr().read().en()
    }

    /// Every flag of the latch's channel cleared.
    pub fn latch_clear(self) {
        self.dma_clear_channel(LATCH_CHANNEL);
    }

    /// `DMA_CNDTR` of the latch's channel: `transfers` (the channel is off).
    pub fn latch_reload(self, transfers: u16) {
        self.dma1()
            .ch(LATCH_CHANNEL)
            .ndtr()
            .write(|w| w.set_ndt(transfers));
    }

    /// `DMA_CCR.EN` set on the latch's channel.
    pub fn latch_enable(self) {
        self.dma1()
            .ch(LATCH_CHANNEL)
            .cr()
            .modify(|w| w.set_en(true));
    }

    /// `DMA_ISR.TEIF` of DMA register channel `n` (the DMA interrupt's first look).
    pub fn dma_channel_error(self, n: usize) -> bool {
        self.dma1().isr().read().teif(n)
    }

    /// `HTIF` and `TCIF` of DMA register channel `n` acknowledged, `TEIF` left for the
    /// recovery.
    pub fn dma_acknowledge_transfers(self, n: usize) {
        self.dma1().ifcr().write(|w| {
            w.set_htif(n, true);
            w.set_tcif(n, true);
        });
    }
}
