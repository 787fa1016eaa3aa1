//! The acquisition's hardware: [`AcqRegisters`] on the STM32G474's ADC1/ADC2 and DMA1
//! channels 1/2/3, each register access one method of the register layer
//! (`drive_monitor::regs`, held to RM0440 by `tests/firmware/registers.rs`), beside embassy's ring
//! drivers. The recovery's sequence over them is `drive_monitor::recovery`'s
//! [`RegisterAcquisition`] (the same code the host tests run on a register-level model).
//!
//! The ring-buffered ADCs of embassy-stm32 own the DMA channels; what they do not offer
//! (stopping a conversion, clearing `DMAEN` and setting it again, clearing `OVR`/`EOC`/`EOS`
//! and `TEIF`, reloading `CNDTR`) is done on the registers.

use core::marker::PhantomData;

use drive_monitor::acquisition::{DMA_HALF_LEN, LATCH_HALF_LEN};
use drive_monitor::adc_rules::AdcPairSetup;
use drive_monitor::recovery::{AcqRegisters, Acquisition, AdcFlags, RegisterAcquisition};
use drive_monitor::regs::MCU;
use drive_monitor::ring_read::{RingRead, RingReads};
use embassy_stm32::adc::RingBufferedAdc;
use embassy_stm32::adc::{Adc, AdcConfig};
use embassy_stm32::dma::{self, ReadableRingBuffer};
use embassy_stm32::interrupt::typelevel::Handler;
use embassy_stm32::timer::low_level::Timer as HwTimer;
use embassy_stm32::{peripherals, Peri};
use embassy_time::{with_deadline, Duration, Instant};

/// The acquisition: trigger timer and the two ring-buffered ADCs, as the recovery drives
/// them ([`RegisterAcquisition`] over [`HwRegisters`]).
pub(super) type HwAcquisition = RegisterAcquisition<HwRegisters>;

/// The acquisition's hardware: trigger timer and the two ring-buffered ADCs.
pub(super) struct HwRegisters {
    pub(super) trigger: HwTimer<'static, peripherals::TIM1>,
    pub(super) adc1: RingBufferedAdc<'static, peripherals::ADC1>,
    pub(super) adc2: RingBufferedAdc<'static, peripherals::ADC2>,
    /// The encoder latch: TIM4's count captured at every trigger, one per sequence.
    pub(super) latch: ReadableRingBuffer<'static, u16>,
    /// When the trigger was last started, us (the timestamps continue from there).
    pub(super) started_us: u32,
    /// The wait for one half at most (`liveness::AdcWait::timeout_us`).
    pub(super) timeout: Duration,
    /// The current half's deadline ([`RingReads::start_wait`]).
    pub(super) deadline: Instant,
}

fn now_us() -> u32 {
    Instant::now().as_micros() as u32
}

/// Wraps the rings (not started yet) and masks the DMA channels' transfer-error interrupt:
/// the HAL's DMA interrupt panics on a transfer error; with the interrupt masked the error
/// stops the channel, the sample task's wait times out and the recovery clears and re-arms
/// it. `TEIE` may only be written with the channel disabled, as it is before the first
/// start.
pub(super) fn new_acquisition(
    trigger: HwTimer<'static, peripherals::TIM1>,
    adc1: RingBufferedAdc<'static, peripherals::ADC1>,
    adc2: RingBufferedAdc<'static, peripherals::ADC2>,
    latch: ReadableRingBuffer<'static, u16>,
    (ring_len, timeout): (u16, Duration),
) -> HwAcquisition {
    MCU.dma_errors_masked();
    RegisterAcquisition {
        regs: HwRegisters {
            trigger,
            adc1,
            adc2,
            latch,
            started_us: 0,
            timeout,
            deadline: Instant::now(),
        },
        ring_len,
    }
}

/// The ADC pair's set-up (`adc_rules::create_pair`) on embassy's `Adc::new` and the
/// registers: the peripherals go in, the two drivers come out.
pub(super) struct HwPair {
    pub(super) p1: Option<Peri<'static, peripherals::ADC1>>,
    pub(super) p2: Option<Peri<'static, peripherals::ADC2>>,
    pub(super) adc1: Option<Adc<'static, peripherals::ADC1>>,
    pub(super) adc2: Option<Adc<'static, peripherals::ADC2>>,
}

impl AdcPairSetup for HwPair {
    fn create(&mut self, i: usize) {
        if i == 0 {
            if let Some(p) = self.p1.take() {
                self.adc1 = Some(Adc::new(p, AdcConfig::default()));
            }
        } else if let Some(p) = self.p2.take() {
            self.adc2 = Some(Adc::new(p, AdcConfig::default()));
        }
    }

    fn cr(&mut self, i: usize) -> u32 {
        MCU.adc_cr(i)
    }

    fn write_cr(&mut self, i: usize, value: u32) {
        MCU.adc_cr_write(i, value);
    }

    fn prescaler(&mut self) -> u32 {
        MCU.adc_prescaler()
    }
}

/// The first start: the rings (the ADCs' and the encoder latch's) armed, both ADCs started,
/// then the trigger, with the recovery's own steps (`RegisterAcquisition`: `CNDTR`, the
/// rings' positions, `DMAEN` circular, `EN`, then `ADSTART` written alone), not the HAL's
/// `RingBufferedAdc::start`, whose read-modify-write of `ADC_CR` writes `ADEN` back with
/// `ADSTART` (`drive_monitor::adc_rules`). The rings' `EN` set here is what the HAL's
/// `read` looks at (`is_running`), so it does not start them again.
pub(super) fn start(acq: &mut HwAcquisition) {
    acq.rearm_dma();
    acq.start_adc();
    acq.start_trigger();
}

impl AcqRegisters for HwRegisters {
    fn adc_flags(&mut self, i: usize) -> AdcFlags {
        MCU.adc_flags(i)
    }

    fn adc_clear(&mut self, i: usize, f: AdcFlags) {
        MCU.adc_clear(i, f);
    }

    fn adc_cr(&mut self, i: usize) -> u32 {
        MCU.adc_cr(i)
    }

    fn adc_cr_write(&mut self, i: usize, value: u32) {
        MCU.adc_cr_write(i, value);
    }

    fn adc_dma_circular(&mut self, i: usize) {
        MCU.adc_dma_circular(i);
    }

    fn adc_dma_off(&mut self, i: usize) {
        MCU.adc_dma_off(i);
    }

    fn dma_error(&mut self, i: usize) -> bool {
        MCU.dma_error(i)
    }

    fn dma_clear(&mut self, i: usize) {
        MCU.dma_clear(i);
    }

    fn dma_enabled(&mut self, i: usize) -> bool {
        MCU.dma_enabled(i)
    }

    fn dma_disable(&mut self, i: usize) {
        if i == 0 {
            self.adc1.stop();
        } else {
            self.adc2.stop();
        }
    }

    fn dma_reload(&mut self, i: usize, transfers: u16) {
        // The whole ring again, from its start (the channel is off: CNDTR is writable);
        // the ring's read and write positions from the reloaded counter.
        MCU.dma_reload(i, transfers);
        if i == 0 {
            self.adc1.clear();
        } else {
            self.adc2.clear();
        }
    }

    fn dma_enable(&mut self, i: usize) {
        MCU.dma_enable(i);
    }

    fn latch_request(&mut self, on: bool) {
        MCU.latch_request(on);
    }

    fn latch_disable(&mut self) {
        self.latch.request_pause();
    }

    fn latch_enabled(&mut self) -> bool {
        MCU.latch_enabled()
    }

    fn latch_clear(&mut self) {
        MCU.latch_clear();
    }

    fn latch_reload(&mut self, transfers: u16) {
        MCU.latch_reload(transfers);
        self.latch.clear();
    }

    fn latch_enable(&mut self) {
        MCU.latch_enable();
    }

    fn trigger_stop(&mut self) {
        self.trigger.stop();
    }

    fn trigger_start(&mut self) {
        self.started_us = now_us();
        self.trigger.start();
    }
}

impl RingReads for HwRegisters {
    fn start_wait(&mut self) {
        self.deadline = Instant::now() + self.timeout;
    }

    async fn read_adc(&mut self, i: usize, buf: &mut [u16; DMA_HALF_LEN]) -> RingRead {
        let read = if i == 0 {
            with_deadline(self.deadline, self.adc1.read(buf)).await
        } else {
            with_deadline(self.deadline, self.adc2.read(buf)).await
        };
        match read {
            Err(_) => RingRead::TimedOut,
            Ok(Ok(_)) => RingRead::Data,
            Ok(Err(_)) => RingRead::Lapped,
        }
    }

    async fn read_latch(&mut self, buf: &mut [u16; LATCH_HALF_LEN]) -> RingRead {
        match with_deadline(self.deadline, self.latch.read_exact(buf)).await {
            Err(_) => RingRead::TimedOut,
            Ok(Ok(_)) => RingRead::Data,
            Ok(Err(_)) => RingRead::Lapped,
        }
    }
}

/// The ADC rings' DMA interrupt: embassy-stm32 0.6's handler panics whenever it runs with
/// `TEIF` set (it checks the flag before `HTIF`/`TCIF`, whatever `TEIE` says), so a transfer
/// error that coincides with a half- or full-transfer interrupt would end the run. This
/// handler looks first: with `TEIF` set (the hardware has cleared the channel's `EN`) it
/// acknowledges `HTIF`/`TCIF` and returns, leaving `TEIF` for the recovery
/// ([`RegisterAcquisition`]: the sample task's wait times out, the sequence clears and
/// re-arms the channel); otherwise it is embassy's handler. `N` is the channel's register
/// index (0: DMA1 channel 1).
pub(super) struct AdcDmaInterrupt<T: dma::ChannelInstance, const N: usize> {
    _channel: PhantomData<T>,
}

impl<T: dma::ChannelInstance, const N: usize> Handler<T::Interrupt> for AdcDmaInterrupt<T, N> {
    #[allow(unsafe_code)]
    unsafe fn on_interrupt() {
        if MCU.dma_channel_error(N) {
            MCU.dma_acknowledge_transfers(N);
            return;
        }
        // SAFETY: called from this channel's interrupt, as embassy's handler expects.
        unsafe { <dma::InterruptHandler<T> as Handler<T::Interrupt>>::on_interrupt() }
    }
}
