//! The acquisition's registers: the recovery sequence of `drive_monitor::recovery` (ADC
//! overrun, DMA transfer error) on the STM32G474's ADC1/ADC2 and DMA1 channels 1/2, in the
//! order of the reference manual RM0440 (the table in `drive_monitor::recovery`).
//!
//! The ring-buffered ADCs of embassy-stm32 own the DMA channels; what they do not offer
//! (stopping a conversion without clearing `DMAEN`, clearing `OVR` and `TEIF`, reloading
//! `CNDTR`) is done here on the registers, with every wait bounded
//! ([`recovery::poll_until`]).

use drive_monitor::recovery::{self, Acquisition, Faults, Step, StepTimeout, POLL_LIMIT};
use embassy_stm32::adc::RingBufferedAdc;
use embassy_stm32::pac;
use embassy_stm32::pac::adc::vals::{Adstp, Dmacfg, Dmaen};
use embassy_stm32::peripherals;
use embassy_stm32::timer::low_level::Timer as HwTimer;
use embassy_time::Instant;

/// The two ADCs' registers, ADC1 (voltages) then ADC2 (currents).
const ADCS: [pac::adc::Adc; 2] = [pac::ADC1, pac::ADC2];
/// The DMA1 channels of the two rings (register index: channel 1 is index 0).
const DMA_CHANNELS: [usize; 2] = [0, 1];

/// The acquisition: trigger timer and the two ring-buffered ADCs.
pub(super) struct HwAcquisition {
    pub(super) trigger: HwTimer<'static, peripherals::TIM1>,
    pub(super) adc1: RingBufferedAdc<'static, peripherals::ADC1>,
    pub(super) adc2: RingBufferedAdc<'static, peripherals::ADC2>,
    /// DMA transfers per ring turn (the ring's length in 16-bit words).
    ring_len: u16,
    /// When the trigger was last started, us (the timestamps continue from there).
    pub(super) started_us: u32,
}

fn now_us() -> u32 {
    Instant::now().as_micros() as u32
}

impl HwAcquisition {
    /// Wraps the rings (not started yet) and masks the DMA channels' transfer-error
    /// interrupt: the HAL's DMA interrupt panics on a transfer error; with the interrupt
    /// masked the error stops the channel, the sample task's wait times out and
    /// [`recovery::recover`] clears and re-arms it. `TEIE` may only be written with the
    /// channel disabled, as it is before the first start.
    pub(super) fn new(
        trigger: HwTimer<'static, peripherals::TIM1>,
        adc1: RingBufferedAdc<'static, peripherals::ADC1>,
        adc2: RingBufferedAdc<'static, peripherals::ADC2>,
        ring_len: u16,
    ) -> Self {
        for n in DMA_CHANNELS {
            pac::DMA1.ch(n).cr().modify(|w| w.set_teie(false));
        }
        Self {
            trigger,
            adc1,
            adc2,
            ring_len,
            started_us: 0,
        }
    }

    /// The first start: both rings and ADCs, then the trigger.
    pub(super) fn start(&mut self) {
        self.adc1.start();
        self.adc2.start();
        self.start_trigger();
    }
}

impl Acquisition for HwAcquisition {
    fn faults(&mut self) -> Faults {
        let isr = pac::DMA1.isr().read();
        Faults {
            adc_overrun: ADCS.iter().any(|a| a.isr().read().ovr()),
            dma_error: DMA_CHANNELS.iter().any(|&n| isr.teif(n)),
        }
    }

    fn stop_trigger(&mut self) {
        self.trigger.stop();
    }

    fn stop_adc(&mut self) -> Result<(), StepTimeout> {
        for a in ADCS {
            let cr = a.cr().read();
            if cr.adstart() && !cr.addis() {
                a.cr().modify(|w| w.set_adstp(Adstp::STOP));
            }
        }
        recovery::poll_until(Step::StopAdc, POLL_LIMIT, || {
            ADCS.iter().all(|a| !a.cr().read().adstart())
        })
    }

    fn pause_dma(&mut self) -> Result<(), StepTimeout> {
        self.adc1.stop();
        self.adc2.stop();
        recovery::poll_until(Step::PauseDma, POLL_LIMIT, || {
            DMA_CHANNELS
                .iter()
                .all(|&n| !pac::DMA1.ch(n).cr().read().en())
        })
    }

    fn clear_flags(&mut self) {
        for a in ADCS {
            // Write 1 to clear; the other flags are left as they are.
            a.isr().write(|w| w.set_ovr(true));
        }
        pac::DMA1.ifcr().write(|w| {
            for n in DMA_CHANNELS {
                w.set_teif(n, true);
                w.set_htif(n, true);
                w.set_tcif(n, true);
                w.set_gif(n, true);
            }
        });
    }

    fn rearm_dma(&mut self) {
        for n in DMA_CHANNELS {
            // The whole ring again, from its start (the channel is off: CNDTR is writable).
            pac::DMA1.ch(n).ndtr().write(|w| w.set_ndt(self.ring_len));
        }
        // The rings' read and write positions from the reloaded counters.
        self.adc1.clear();
        self.adc2.clear();
        for a in ADCS {
            // ADSTART = 0 here, so DMAEN/DMACFG are writable.
            a.cfgr().modify(|w| {
                w.set_dmaen(Dmaen::ENABLE);
                w.set_dmacfg(Dmacfg::CIRCULAR);
            });
        }
        for n in DMA_CHANNELS {
            pac::DMA1.ch(n).cr().modify(|w| w.set_en(true));
        }
    }

    fn start_adc(&mut self) {
        for a in ADCS {
            a.cr().modify(|w| w.set_adstart(true));
        }
    }

    fn start_trigger(&mut self) {
        self.started_us = now_us();
        self.trigger.start();
    }
}
