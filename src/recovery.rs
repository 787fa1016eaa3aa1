//! Recovery of the acquisition after an ADC overrun or a DMA transfer error.
//!
//! The acquisition is TIM1's trigger (TRGO), two ADCs converting three channels each per
//! trigger, and one DMA channel per ADC moving the results into a ring. Two hardware faults
//! stop it for good unless they are cleared:
//! - **ADC overrun** (`OVR` in `ADC_ISR`): a conversion finished before the DMA took the
//!   previous result. With DMA on, the ADC then stops issuing DMA requests until software
//!   clears `OVR` (STM32G4 reference manual RM0440, "Managing conversions using the DMA"
//!   and "Overrun management"); restarting the DMA or the trigger alone never brings the
//!   data back.
//! - **DMA transfer error** (`TEIF` in `DMA_ISR`): the DMA hardware clears the channel's
//!   `EN` bit; nothing moves until the flag is cleared and the channel is re-armed (RM0440,
//!   "DMA transfer error management"). The HAL's DMA interrupt panics on it, so the
//!   firmware masks the channel's transfer-error interrupt (`TEIE`) and recovers here.
//!
//! Both show up in the sample task as a wait for ADC data that times out (or a ring the DMA
//! lapped). [`recover`] then runs one sequence, the same for every cause, in the order the
//! reference manual asks for:
//!
//! | step | what | why this order |
//! |---|---|---|
//! | [`RecoveryStep::StopTrigger`] | TIM1 counter off | no new conversion starts |
//! | [`RecoveryStep::StopAdc`] | `ADSTP` (written alone: `adc_rules::cr_setting`), then wait for `ADSTART = 0` and `JADSTART = 0` (bounded) | a conversion in flight ends before the DMA stops (else it would set `OVR` itself); `DMAEN` may change only with no regular and no injected conversion ongoing |
//! | [`RecoveryStep::PauseDma`] | `DMAEN = 0` in `ADC_CFGR`, then the channels' `EN = 0`, `CC3DE = 0` and the encoder latch's `EN = 0`, and a wait for them (bounded) | the ADC withdraws its DMA request (a request latched while the channel was off, after a transfer error, would otherwise move one stale word at the re-arm and shift the channels in the ring for good); `CNDTR` may only be written with the channel off |
//! | [`RecoveryStep::ClearFlags`] | `OVR`, `EOC`, `EOS` (write 1), `TEIF`/`HTIF`/`TCIF` (`DMA_IFCR`) | a latched `OVR` blocks the DMA requests; an `EOC` left set (the data register unread since the overrun) sets `OVR` again at the next conversion |
//! | [`RecoveryStep::RearmDma`] | `CNDTR` = ring length, ring indices reset (the encoder latch's ring too, its `EN = 1`, then `CC3DE = 1`), `DMAEN`/`DMACFG` circular, `EN = 1` | the DMA is ready before the ADC (and the timer) asks |
//! | [`RecoveryStep::StartAdc`] | `ADSTART = 1`, written alone (waits for the next trigger) | both ADCs armed before the trigger |
//! | [`RecoveryStep::StartTrigger`] | TIM1 counter on, timestamps continue from now | ADC1 and ADC2 start on the same trigger |
//!
//! The sequence is written once, over the [`Acquisition`] trait, and its register accesses
//! once, in [`RegisterAcquisition`] over the [`AcqRegisters`] trait: the firmware implements
//! that with the STM32G474's registers (`src/firmware/acquisition.rs`), the host tests with
//! a register-level model of ADC + DMA that keeps `ADC_DR` and `EOC` as the hardware does
//! and checks every access's precondition (`tests/sil/recovery.rs`), into which they inject
//! an overrun, a DMA error and a lapped ring. The monitor itself (its thresholds, the commissioning state, the
//! counters) is not touched by a recovery: only the acquisition restarts.

use crate::adc_rules::{self, cr_setting, ADDIS, ADSTART, ADSTP, JADSTART};

/// One step of the recovery sequence, in its order (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecoveryStep {
    /// Stop the sample trigger.
    StopTrigger,
    /// Stop both ADCs' conversions and wait until they stopped.
    StopAdc,
    /// Clear both ADCs' `DMAEN`, disable both DMA channels and wait until they are off.
    PauseDma,
    /// Clear the ADCs' overrun flags and the DMA channels' interrupt flags.
    ClearFlags,
    /// Reload both DMA channels with the ring length, reset the rings, enable the channels
    /// and the ADCs' DMA requests.
    RearmDma,
    /// Start both ADCs' regular conversions (they wait for the trigger).
    StartAdc,
    /// Start the sample trigger (and continue the timestamps from now).
    StartTrigger,
}

impl RecoveryStep {
    /// All steps, in the order [`recover`] runs them.
    pub const ORDER: [RecoveryStep; 7] = [
        RecoveryStep::StopTrigger,
        RecoveryStep::StopAdc,
        RecoveryStep::PauseDma,
        RecoveryStep::ClearFlags,
        RecoveryStep::RearmDma,
        RecoveryStep::StartAdc,
        RecoveryStep::StartTrigger,
    ];

    /// A short name for logs.
    pub const fn name(self) -> &'static str {
        match self {
            RecoveryStep::StopTrigger => "stop-trigger",
            RecoveryStep::StopAdc => "stop-adc",
            RecoveryStep::PauseDma => "pause-dma",
            RecoveryStep::ClearFlags => "clear-flags",
            RecoveryStep::RearmDma => "rearm-dma",
            RecoveryStep::StartAdc => "start-adc",
            RecoveryStep::StartTrigger => "start-trigger",
        }
    }
}

/// The hardware faults latched when a recovery started.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faults {
    /// An ADC's `OVR` flag was set.
    pub adc_overrun: bool,
    /// A DMA channel's `TEIF` flag was set.
    pub dma_error: bool,
}

/// A bounded wait of the sequence ran out (a register never reached its state): the
/// acquisition is left stopped; the sample task tries again at its next timeout, and the
/// watchdog resets the MCU if that never helps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepTimeout(pub RecoveryStep);

/// Polls of a register the sequence's waits allow ([`crate::adc_rules::POLL_LIMIT`], the
/// ADC set-up's bound too, kept there, below both).
pub use crate::adc_rules::POLL_LIMIT;

/// Polls `done` up to `limit` times; `Err(StepTimeout(step))` when it never returned true.
/// The firmware's bounded waits on a register (here and in the ADC set-up).
///
/// # Errors
/// [`StepTimeout`] naming `step`.
pub fn poll_until(
    step: RecoveryStep,
    limit: u32,
    mut done: impl FnMut() -> bool,
) -> Result<(), StepTimeout> {
    for _ in 0..limit {
        if done() {
            return Ok(());
        }
    }
    Err(StepTimeout(step))
}

/// The acquisition as [`recover`] drives it: both ADCs and their DMA channels, and the
/// trigger. Each method is one [`RecoveryStep`] (the waits bounded, [`poll_until`]).
pub trait Acquisition {
    /// The faults latched now (`OVR`, `TEIF`), read before anything is cleared.
    fn faults(&mut self) -> Faults;
    /// [`RecoveryStep::StopTrigger`].
    fn stop_trigger(&mut self);
    /// [`RecoveryStep::StopAdc`].
    ///
    /// # Errors
    /// [`StepTimeout`] when `ADSTART` never cleared.
    fn stop_adc(&mut self) -> Result<(), StepTimeout>;
    /// [`RecoveryStep::PauseDma`].
    ///
    /// # Errors
    /// [`StepTimeout`] when `EN` never cleared.
    fn pause_dma(&mut self) -> Result<(), StepTimeout>;
    /// [`RecoveryStep::ClearFlags`].
    fn clear_flags(&mut self);
    /// [`RecoveryStep::RearmDma`].
    fn rearm_dma(&mut self);
    /// [`RecoveryStep::StartAdc`].
    fn start_adc(&mut self);
    /// [`RecoveryStep::StartTrigger`].
    fn start_trigger(&mut self);
}

/// Runs the recovery sequence on `acq` (module docs) and returns the faults that were
/// latched when it started.
///
/// # Errors
/// [`StepTimeout`] when a bounded wait ran out (the sequence stops there).
pub fn recover<A: Acquisition>(acq: &mut A) -> Result<Faults, StepTimeout> {
    let faults = pause(acq)?;
    resume(acq);
    Ok(faults)
}

/// The recovery's first half: the faults latched now, then the trigger, the ADCs and the
/// DMA stopped ([`RecoveryStep::StopTrigger`], [`RecoveryStep::StopAdc`],
/// [`RecoveryStep::PauseDma`]). Also what the sample task does before a flash erase
/// (`app::carry_out`'s store): nothing converts, nothing moves, so nothing can lap while
/// the flash is busy; [`resume`] starts it again.
///
/// # Errors
/// [`StepTimeout`] when a bounded wait ran out (the sequence stops there).
pub fn pause<A: Acquisition>(acq: &mut A) -> Result<Faults, StepTimeout> {
    let faults = acq.faults();
    acq.stop_trigger();
    acq.stop_adc()?;
    acq.pause_dma()?;
    Ok(faults)
}

/// The recovery's second half, after [`pause`]: the flags cleared, the DMA re-armed from
/// the rings' starts, the ADCs and the trigger started ([`RecoveryStep::ClearFlags`] ..
/// [`RecoveryStep::StartTrigger`]).
pub fn resume<A: Acquisition>(acq: &mut A) {
    acq.clear_flags();
    acq.rearm_dma();
    acq.start_adc();
    acq.start_trigger();
}

/// Before the sample task reads the rings: when a channel of the acquisition is off (a DMA
/// transfer error cleared its `EN` since the last read), the recovery runs now and its
/// result is returned. Embassy-stm32 0.6's `RingBufferedAdc::read` would otherwise restart
/// a ring it finds off with its own `start()`: the DMA channel enabled again without the
/// flags cleared or `CNDTR` reloaded, and `ADC_CR` written by read-modify-write (`ADEN`
/// written back with `ADSTART`, against [`crate::adc_rules`]). `None`: every channel runs.
pub fn before_read<R: AcqRegisters>(
    acq: &mut RegisterAcquisition<R>,
) -> Option<Result<Faults, StepTimeout>> {
    if acq.running() {
        None
    } else {
        Some(recover(acq))
    }
}

/// An ADC's status flags of `ADC_ISR` that the recovery reads and clears (RM0440): `OVR`,
/// `EOC` (a result waits in `ADC_DR`) and `EOS` (a sequence ended).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdcFlags {
    /// `OVR`: a conversion ended while `EOC` was still set.
    pub ovr: bool,
    /// `EOC`: the data register holds a result nobody read.
    pub eoc: bool,
    /// `EOS`: the regular sequence ended.
    pub eos: bool,
}

impl AdcFlags {
    /// What [`RecoveryStep::ClearFlags`] writes to `ADC_ISR` (write 1 to clear): `OVR`, `EOC` and
    /// `EOS` together, as ST's HAL does. After an overrun with `OVRMOD = 0` the data
    /// register was never read and `EOC` stays 1; RM0440 sets `OVR` again as soon as a
    /// conversion ends while `EOC` is 1, so clearing `OVR` alone re-overruns at the first
    /// conversion after the restart.
    pub const RECOVERY_CLEAR: AdcFlags = AdcFlags {
        ovr: true,
        eoc: true,
        eos: true,
    };
}

/// The register accesses of the acquisition's recovery, one per hardware action: ADC `i`
/// (0: ADC1, the voltages; 1: ADC2, the currents), its DMA channel `i`, the trigger. The
/// firmware implements it on the STM32G474's registers (`src/firmware/acquisition.rs`);
/// the host tests on a register-level model of ADC + DMA that keeps `ADC_DR` and `EOC` as
/// the hardware does and checks each access's precondition (`tests/sil/recovery.rs`).
/// [`RegisterAcquisition`] is the sequence over them, the same code on both.
pub trait AcqRegisters {
    /// `ADC_ISR`'s `OVR`, `EOC`, `EOS` of ADC `i`.
    fn adc_flags(&mut self, i: usize) -> AdcFlags;
    /// Writes 1 to the flags set in `f` of ADC `i`'s `ADC_ISR` (clears them).
    fn adc_clear(&mut self, i: usize, f: AdcFlags);
    /// `ADC_CR` of ADC `i` (the bits of [`crate::adc_rules`]).
    fn adc_cr(&mut self, i: usize) -> u32;
    /// Writes `value` to ADC `i`'s `ADC_CR`: the sequence writes one set-only bit at a time
    /// ([`crate::adc_rules::cr_setting`]); `ADSTP` only with `ADSTART = 1` and `ADDIS = 0`.
    fn adc_cr_write(&mut self, i: usize, value: u32);
    /// `DMAEN = 1`, `DMACFG` circular in ADC `i`'s `ADC_CFGR` (allowed only with
    /// `ADSTART = 0`).
    fn adc_dma_circular(&mut self, i: usize);
    /// `DMAEN = 0` in ADC `i`'s `ADC_CFGR` (allowed only with `ADSTART = 0` and
    /// `JADSTART = 0`): the ADC issues no DMA request, and withdraws one it raised.
    fn adc_dma_off(&mut self, i: usize);
    /// `TEIF` of DMA channel `i`.
    fn dma_error(&mut self, i: usize) -> bool;
    /// Clears `TEIF`, `HTIF`, `TCIF` and `GIF` of DMA channel `i` (`DMA_IFCR`).
    fn dma_clear(&mut self, i: usize);
    /// `EN` of DMA channel `i`.
    fn dma_enabled(&mut self, i: usize) -> bool;
    /// Disables DMA channel `i` (`EN = 0`; on the board through the HAL's ring).
    fn dma_disable(&mut self, i: usize);
    /// Writes `CNDTR` of DMA channel `i` (allowed only with `EN = 0`) and resets the
    /// ring's read position to match.
    fn dma_reload(&mut self, i: usize, transfers: u16);
    /// Enables DMA channel `i` (`EN = 1`).
    fn dma_enable(&mut self, i: usize);
    /// The encoder timer's capture DMA request (`TIM4_DIER.CC3DE`): off, the timer raises
    /// no request and withdraws one it raised (a capture made while the latch's channel
    /// was off, which the re-armed channel would otherwise serve first: one stale count at
    /// the ring's start, every later count one trigger late); on, each capture raises one.
    fn latch_request(&mut self, on: bool);
    /// Disables the encoder latch's DMA channel (`EN = 0`): the channel that copies the
    /// encoder timer's captured count at every trigger into its ring
    /// (`acquisition::LATCH_LEN`).
    fn latch_disable(&mut self);
    /// `EN` of the encoder latch's DMA channel.
    fn latch_enabled(&mut self) -> bool;
    /// Clears the latch channel's `TEIF`, `HTIF`, `TCIF`, `GIF`.
    fn latch_clear(&mut self);
    /// Writes the latch channel's `CNDTR` (allowed only with `EN = 0`) and resets its
    /// ring's read position to match.
    fn latch_reload(&mut self, transfers: u16);
    /// Enables the latch channel (`EN = 1`).
    fn latch_enable(&mut self);
    /// Stops the sample trigger (TIM1's counter).
    fn trigger_stop(&mut self);
    /// Starts the sample trigger.
    fn trigger_start(&mut self);
}

/// The two ADCs and their DMA channels.
const CHANNELS: [usize; 2] = [0, 1];

/// The acquisition over its registers: [`Acquisition`] (the recovery's steps) written once
/// over [`AcqRegisters`], for the board's registers and the host's model alike.
#[derive(Debug)]
pub struct RegisterAcquisition<R> {
    /// The registers.
    pub regs: R,
    /// DMA transfers per ring turn (the ring's length in 16-bit words).
    pub ring_len: u16,
}

impl<R: AcqRegisters> Acquisition for RegisterAcquisition<R> {
    fn faults(&mut self) -> Faults {
        Faults {
            adc_overrun: CHANNELS.iter().any(|&i| self.regs.adc_flags(i).ovr),
            dma_error: CHANNELS.iter().any(|&i| self.regs.dma_error(i)),
        }
    }

    fn stop_trigger(&mut self) {
        self.regs.trigger_stop();
    }

    fn stop_adc(&mut self) -> Result<(), StepTimeout> {
        for i in CHANNELS {
            let cr = self.regs.adc_cr(i);
            if cr & ADSTART != 0 && cr & ADDIS == 0 {
                self.regs.adc_cr_write(i, cr_setting(cr, ADSTP));
            }
        }
        // The regular conversions stopped and an injected one (the reference's, from thread
        // mode) ended: DMAEN may change only with neither ongoing.
        let regs = &mut self.regs;
        poll_until(RecoveryStep::StopAdc, POLL_LIMIT, || {
            CHANNELS
                .iter()
                .all(|&i| regs.adc_cr(i) & (ADSTART | JADSTART) == 0)
        })
    }

    fn pause_dma(&mut self) -> Result<(), StepTimeout> {
        for i in CHANNELS {
            // ADSTART = JADSTART = 0 here (the step before waited for both): DMAEN is
            // writable.
            self.regs.adc_dma_off(i);
        }
        for i in CHANNELS {
            self.regs.dma_disable(i);
        }
        // The capture's request withdrawn before its channel stops, as DMAEN for the ADCs.
        self.regs.latch_request(false);
        self.regs.latch_disable();
        let regs = &mut self.regs;
        poll_until(RecoveryStep::PauseDma, POLL_LIMIT, || {
            CHANNELS.iter().all(|&i| !regs.dma_enabled(i)) && !regs.latch_enabled()
        })
    }

    fn clear_flags(&mut self) {
        for i in CHANNELS {
            self.regs.adc_clear(i, AdcFlags::RECOVERY_CLEAR);
            self.regs.dma_clear(i);
        }
        self.regs.latch_clear();
    }

    fn rearm_dma(&mut self) {
        for i in CHANNELS {
            // The channel is off: CNDTR is writable.
            self.regs.dma_reload(i, self.ring_len);
        }
        // The encoder latch from its ring's start too, one count per sequence: the counts
        // stay at the places of the conversions of the same trigger.
        let channels = adc_rules::CHANNELS as u16;
        self.regs.latch_reload(self.ring_len / channels);
        self.regs.latch_enable();
        self.regs.latch_request(true);
        for i in CHANNELS {
            // ADSTART = 0 here, so DMAEN/DMACFG are writable.
            self.regs.adc_dma_circular(i);
        }
        for i in CHANNELS {
            self.regs.dma_enable(i);
        }
    }

    fn start_adc(&mut self) {
        for i in CHANNELS {
            let cr = self.regs.adc_cr(i);
            self.regs.adc_cr_write(i, cr_setting(cr, ADSTART));
        }
    }

    fn start_trigger(&mut self) {
        self.regs.trigger_start();
    }
}

impl<R: AcqRegisters> RegisterAcquisition<R> {
    /// Whether every channel of the acquisition runs: both ADC rings' DMA channels and the
    /// encoder latch's have `EN` set ([`before_read`]).
    pub fn running(&mut self) -> bool {
        CHANNELS.iter().all(|&i| self.regs.dma_enabled(i)) && self.regs.latch_enabled()
    }
}

/// Counts of the recoveries since boot, by cause (for the log; the status line's
/// `restarts` counts them all).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecoveryCounts {
    /// Recoveries run.
    pub recoveries: u32,
    /// Of those, with an ADC overrun latched.
    pub adc_overruns: u32,
    /// Of those, with a DMA transfer error latched.
    pub dma_errors: u32,
    /// Recoveries stopped by a bounded wait ([`StepTimeout`]).
    pub timeouts: u32,
}

impl RecoveryCounts {
    /// Counts one recovery's result.
    pub fn count(&mut self, result: Result<Faults, StepTimeout>) {
        self.recoveries = self.recoveries.saturating_add(1);
        match result {
            Ok(f) => {
                self.adc_overruns = self.adc_overruns.saturating_add(u32::from(f.adc_overrun));
                self.dma_errors = self.dma_errors.saturating_add(u32::from(f.dma_error));
            }
            Err(_) => self.timeouts = self.timeouts.saturating_add(1),
        }
    }
}

#[cfg(test)]
mod tests;
