//! The sample task's read of one DMA half, written once over [`RingReads`] (the firmware's
//! ring-buffered ADCs and latch ring, `src/firmware/acquisition.rs`; the host tests' register
//! model): the rings' channels checked before **each** read, the reads bounded by the
//! half's deadline.
//!
//! Why before each read: embassy-stm32 0.6's `RingBufferedAdc::read` restarts a ring whose
//! DMA channel it finds off with its own `start()` (the channel enabled with `TEIF` set and
//! `CNDTR` as it was, `ADC_CR` written by read-modify-write, `ADEN` written back with
//! `ADSTART`: against `crate::adc_rules`). The sample task reads ADC1's ring, then ADC2's,
//! then the latch's: a DMA transfer error on ADC2's channel while the task awaits ADC1's
//! half would reach the HAL's restart at ADC2's read if only the first read were guarded.
//! So [`read_half`] runs `recovery::before_read` before the first read and again before
//! each later one; a channel found off ends the half with the recovery
//! ([`Half::Recovered`]), and the HAL's `read` only ever sees running rings. What is left:
//! a transfer error in the few instructions between the check and the HAL's own look at
//! the channel (no await between them).

use crate::acquisition::{DMA_HALF_LEN, LATCH_HALF_LEN};
use crate::recovery::{self, AcqRegisters, Faults, RegisterAcquisition, StepTimeout};

/// One ring read's outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RingRead {
    /// The half was read.
    Data,
    /// The DMA lapped the reader: samples were lost.
    Lapped,
    /// No half within the deadline.
    TimedOut,
}

/// The rings' reads (module docs): the registers of the recovery and the HAL's reads.
// The sample task runs on one executor and its futures are never sent across threads: the
// trait's async methods need no `Send` bound.
#[allow(async_fn_in_trait)]
pub trait RingReads: AcqRegisters {
    /// Starts the half's deadline: the reads below time out at the wait's timeout from now
    /// (`liveness::AdcWait::timeout_us`).
    fn start_wait(&mut self);
    /// ADC `i`'s half (0: ADC1, the voltages; 1: ADC2, the currents) into `buf`: the HAL's
    /// read, which restarts a ring it finds off (module docs), bounded by the deadline.
    async fn read_adc(&mut self, i: usize, buf: &mut [u16; DMA_HALF_LEN]) -> RingRead;
    /// The encoder latch's half into `buf`, bounded by the deadline.
    async fn read_latch(&mut self, buf: &mut [u16; LATCH_HALF_LEN]) -> RingRead;
}

/// One half's buffers: ADC1's, ADC2's and the latch's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HalfBuffers {
    /// ADC1's half: the voltages.
    pub v: [u16; DMA_HALF_LEN],
    /// ADC2's half: the currents.
    pub i: [u16; DMA_HALF_LEN],
    /// The latched encoder counts.
    pub latched: [u16; LATCH_HALF_LEN],
}

impl Default for HalfBuffers {
    fn default() -> Self {
        Self {
            v: [0; DMA_HALF_LEN],
            i: [0; DMA_HALF_LEN],
            latched: [0; LATCH_HALF_LEN],
        }
    }
}

/// What one half's read came to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Half {
    /// A ring's channel was off before a read (a DMA transfer error since the last one):
    /// the recovery ran, its result; the half is dropped.
    Recovered(Result<Faults, StepTimeout>),
    /// The half was read; `lapped`: the DMA lapped the reader on ADC1's ring, on ADC2's or
    /// the latch's (samples lost: the recovery follows).
    Read {
        /// ADC1's ring, then ADC2's or the latch's.
        lapped: [bool; 2],
    },
    /// No data within the deadline (an ADC overrun, a stopped trigger): the recovery
    /// follows.
    TimedOut,
}

/// Reads one half into `bufs` (module docs).
pub async fn read_half<R: RingReads>(
    acq: &mut RegisterAcquisition<R>,
    bufs: &mut HalfBuffers,
) -> Half {
    if let Some(r) = recovery::before_read(acq) {
        return Half::Recovered(r);
    }
    acq.regs.start_wait();
    let v = acq.regs.read_adc(0, &mut bufs.v).await;
    // ADC2's ring (or the latch's) may have stopped while ADC1's was awaited.
    if let Some(r) = recovery::before_read(acq) {
        return Half::Recovered(r);
    }
    let i = acq.regs.read_adc(1, &mut bufs.i).await;
    if let Some(r) = recovery::before_read(acq) {
        return Half::Recovered(r);
    }
    let latch = acq.regs.read_latch(&mut bufs.latched).await;
    if [v, i, latch].contains(&RingRead::TimedOut) {
        return Half::TimedOut;
    }
    Half::Read {
        lapped: [
            v == RingRead::Lapped,
            i == RingRead::Lapped || latch == RingRead::Lapped,
        ],
    }
}
