//! The acquisition's recovery on a register-level model of the STM32G474's ADC + DMA
//! (RM0440): each ADC keeps its data register and `EOC` as the hardware does (a result sits
//! in `ADC_DR` with `EOC = 1` until the DMA reads it; a conversion that ends while `EOC` is
//! 1 sets `OVR` and, with `OVRMOD = 0`, keeps the old data; while `OVR` is set the ADC
//! issues no DMA requests), each DMA channel its `EN`, `CNDTR` and `TEIF`, and every
//! register access checks its precondition (`ADSTP` only while converting, `DMAEN`/`DMACFG`
//! only with `ADSTART = 0`, `CNDTR` only with the channel off). The firmware's own sequence,
//! `drive_monitor::recovery::RegisterAcquisition` (the code `src/firmware/acquisition.rs`
//! runs over the real registers), drives it; an overrun, a DMA error and a lapped ring are
//! injected and the monitor resumes with its state intact. The same sequence with only
//! `OVR` cleared (the firmware's sequence before the `EOC` clear) re-overruns at the first
//! conversion and never resumes, as does the firmware's former restart.

use super::*;
use drive_monitor::recovery::{
    self, AcqRegisters, Acquisition, AdcFlags, Faults, RecoveryStep, RegisterAcquisition,
    StepTimeout,
};

/// The ring's length in DMA transfers (the firmware's `RING_LEN`, two halves of samples).
pub(super) const RING_LEN: u16 = 12;

/// One ADC as the recovery sees it.
#[derive(Clone, Copy, Debug, Default)]
struct AdcModel {
    adstart: bool,
    ovr: bool,
    eoc: bool,
    eos: bool,
    /// `ADC_DR`: the number of the conversion whose result it holds.
    dr: u32,
    /// `DMAEN` with `DMACFG` circular.
    dma_circular: bool,
}

/// One DMA channel.
#[derive(Clone, Copy, Debug, Default)]
struct DmaModel {
    en: bool,
    teif: bool,
    cndtr: u16,
    /// The results the channel moved, in order (the last few).
    moved: u32,
}

/// The two ADCs, their DMA channels and the trigger, at register level (module docs).
#[derive(Clone, Debug)]
pub(super) struct AdcDmaModel {
    trigger_on: bool,
    adc: [AdcModel; 2],
    dma: [DmaModel; 2],
    conversions: u32,
    /// Overruns the hardware latched (each conversion that ended with `EOC` still set).
    pub(super) overruns: u32,
    /// Register accesses made against their precondition (RM0440), in words.
    pub(super) violations: Vec<String>,
}

/// The acquisition the rig runs: the firmware's sequence over the model.
pub(super) type ModelAcq = RegisterAcquisition<AdcDmaModel>;

impl AdcDmaModel {
    pub(super) fn running() -> ModelAcq {
        let adc = AdcModel {
            adstart: true,
            dma_circular: true,
            ..AdcModel::default()
        };
        let dma = DmaModel {
            en: true,
            cndtr: RING_LEN,
            ..DmaModel::default()
        };
        RegisterAcquisition {
            regs: AdcDmaModel {
                trigger_on: true,
                adc: [adc; 2],
                dma: [dma; 2],
                conversions: 0,
                overruns: 0,
                violations: Vec::new(),
            },
            ring_len: RING_LEN,
        }
    }

    /// One trigger period: each converting ADC ends a conversion (an overrun if `EOC` is
    /// still set), then its DMA channel takes the result if it can. Whether both results
    /// reached the rings.
    pub(super) fn trigger(&mut self) -> bool {
        if !self.trigger_on {
            return false;
        }
        self.conversions += 1;
        let mut delivered = [false; 2];
        for ((a, d), got) in self.adc.iter_mut().zip(&mut self.dma).zip(&mut delivered) {
            if !a.adstart {
                continue;
            }
            if a.eoc {
                // OVRMOD = 0: the old result stays in ADC_DR.
                if !a.ovr {
                    self.overruns += 1;
                }
                a.ovr = true;
            } else {
                a.dr = self.conversions;
                a.eoc = true;
                a.eos = true;
            }
            // The DMA request: none while OVR is set.
            if a.eoc && !a.ovr && a.dma_circular && d.en {
                a.eoc = false;
                d.moved = a.dr;
                d.cndtr = if d.cndtr <= 1 { RING_LEN } else { d.cndtr - 1 };
                *got = true;
            }
        }
        delivered == [true; 2]
    }

    /// A conversion ended before the DMA took the previous result: `OVR` set, the data
    /// register holding the unread result (`EOC = 1`).
    pub(super) fn inject_overrun(&mut self) {
        for a in &mut self.adc {
            a.ovr = true;
            a.eoc = true;
        }
        self.overruns += 1;
    }

    /// A DMA transfer error: the hardware sets `TEIF` and clears `EN`.
    pub(super) fn inject_dma_error(&mut self) {
        for d in &mut self.dma {
            d.teif = true;
            d.en = false;
        }
    }

    fn violation(&mut self, what: String) {
        self.violations.push(what);
    }
}

impl AcqRegisters for AdcDmaModel {
    fn adc_flags(&mut self, i: usize) -> AdcFlags {
        let a = self.adc[i];
        AdcFlags {
            ovr: a.ovr,
            eoc: a.eoc,
            eos: a.eos,
        }
    }
    fn adc_clear(&mut self, i: usize, f: AdcFlags) {
        let a = &mut self.adc[i];
        a.ovr &= !f.ovr;
        a.eoc &= !f.eoc;
        a.eos &= !f.eos;
    }
    fn adc_started(&mut self, i: usize) -> bool {
        self.adc[i].adstart
    }
    fn adc_disabling(&mut self, _i: usize) -> bool {
        false
    }
    fn adc_stop(&mut self, i: usize) {
        if !self.adc[i].adstart {
            self.violation(format!("ADSTP on ADC{} while ADSTART = 0", i + 1));
        }
        // The conversion in flight ends (no result: the model's conversions are instant).
        self.adc[i].adstart = false;
    }
    fn adc_start(&mut self, i: usize) {
        self.adc[i].adstart = true;
    }
    fn adc_dma_circular(&mut self, i: usize) {
        if self.adc[i].adstart {
            self.violation(format!(
                "DMAEN/DMACFG of ADC{} written while ADSTART = 1",
                i + 1
            ));
        }
        self.adc[i].dma_circular = true;
    }
    fn dma_error(&mut self, i: usize) -> bool {
        self.dma[i].teif
    }
    fn dma_clear(&mut self, i: usize) {
        self.dma[i].teif = false;
    }
    fn dma_enabled(&mut self, i: usize) -> bool {
        self.dma[i].en
    }
    fn dma_disable(&mut self, i: usize) {
        self.dma[i].en = false;
    }
    fn dma_reload(&mut self, i: usize, transfers: u16) {
        if self.dma[i].en {
            self.violation(format!(
                "CNDTR of DMA channel {} written while EN = 1",
                i + 1
            ));
        }
        self.dma[i].cndtr = transfers;
    }
    fn dma_enable(&mut self, i: usize) {
        self.dma[i].en = true;
    }
    fn trigger_stop(&mut self) {
        self.trigger_on = false;
    }
    fn trigger_start(&mut self) {
        self.trigger_on = true;
    }
}

/// The firmware's sequence with only `OVR` cleared in `ADC_ISR` (before the `EOC` clear):
/// every register access as the model's, `EOC` and `EOS` left set.
struct OnlyOvr<'a>(&'a mut AdcDmaModel);

impl AcqRegisters for OnlyOvr<'_> {
    fn adc_flags(&mut self, i: usize) -> AdcFlags {
        self.0.adc_flags(i)
    }
    fn adc_clear(&mut self, i: usize, f: AdcFlags) {
        self.0.adc_clear(
            i,
            AdcFlags {
                ovr: f.ovr,
                ..AdcFlags::default()
            },
        );
    }
    fn adc_started(&mut self, i: usize) -> bool {
        self.0.adc_started(i)
    }
    fn adc_disabling(&mut self, i: usize) -> bool {
        self.0.adc_disabling(i)
    }
    fn adc_stop(&mut self, i: usize) {
        self.0.adc_stop(i);
    }
    fn adc_start(&mut self, i: usize) {
        self.0.adc_start(i);
    }
    fn adc_dma_circular(&mut self, i: usize) {
        self.0.adc_dma_circular(i);
    }
    fn dma_error(&mut self, i: usize) -> bool {
        self.0.dma_error(i)
    }
    fn dma_clear(&mut self, i: usize) {
        self.0.dma_clear(i);
    }
    fn dma_enabled(&mut self, i: usize) -> bool {
        self.0.dma_enabled(i)
    }
    fn dma_disable(&mut self, i: usize) {
        self.0.dma_disable(i);
    }
    fn dma_reload(&mut self, i: usize, transfers: u16) {
        self.0.dma_reload(i, transfers);
    }
    fn dma_enable(&mut self, i: usize) {
        self.0.dma_enable(i);
    }
    fn trigger_stop(&mut self) {
        self.0.trigger_stop();
    }
    fn trigger_start(&mut self) {
        self.0.trigger_start();
    }
}

/// The recovery with only `OVR` cleared ([`OnlyOvr`]).
fn recover_only_ovr(acq: &mut ModelAcq) -> Result<Faults, StepTimeout> {
    let mut weak = RegisterAcquisition {
        regs: OnlyOvr(&mut acq.regs),
        ring_len: acq.ring_len,
    };
    recovery::recover(&mut weak)
}

/// The firmware's restart before the recovery: the trigger stopped, the DMA paused and
/// resumed with the rings cleared, `ADSTART` set, the trigger started, and `OVR` never
/// cleared.
fn former_restart(acq: &mut ModelAcq) -> Result<Faults, StepTimeout> {
    let faults = acq.faults();
    acq.stop_trigger();
    acq.pause_dma()?;
    acq.rearm_dma();
    acq.start_adc();
    acq.start_trigger();
    Ok(faults)
}

const OVERRUN_AT: usize = 20_000;
const DMA_ERROR_AT: usize = 25_000;

fn inject(rig: &mut Rig, k: usize) {
    if k == OVERRUN_AT {
        rig.acq.regs.inject_overrun();
    }
    if k == DMA_ERROR_AT {
        rig.acq.regs.inject_dma_error();
    }
}

#[test]
fn the_monitor_resumes_after_an_adc_overrun_and_a_dma_error_with_its_state_intact() {
    let frames = steady_frames(3.5);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    let calibration = rig.path.monitor().calibration();
    assert!(calibration.is_some());
    rig.run(&frames, inject).unwrap();
    // One recovery each, at the first timeout (2 ms after the last sample).
    let timeout_periods = rig.adc.timeout_us() as usize * FS as usize / 1_000_000;
    assert_eq!(timeout_periods, 20);
    assert_eq!(
        rig.recoveries,
        [
            Ok(Faults {
                adc_overrun: true,
                dma_error: false
            }),
            // The ADCs kept converting with the DMA off: an overrun followed the error.
            Ok(Faults {
                adc_overrun: true,
                dma_error: true
            }),
        ]
    );
    assert_eq!(
        rig.restarts_at_ms,
        [
            ((OVERRUN_AT + timeout_periods - 1) / 10) as u32,
            ((DMA_ERROR_AT + timeout_periods - 1) / 10) as u32
        ]
    );
    assert_eq!(rig.adc.restarts(), 2);
    // The monitor's state is intact: the same thresholds, the sample counter went on (only
    // the samples of the two gaps are missing), the watchdog petted throughout, the panel
    // commissioned after the run-up (a 2 ms gap is no stall) and no reset record.
    assert_eq!(rig.path.monitor().calibration(), calibration);
    assert_eq!(
        rig.path.samples() as usize,
        frames.len() - 2 * timeout_periods
    );
    assert!(rig.seen.iter().all(|s| s.tick.pet_watchdog));
    assert!(rig
        .seen
        .iter()
        .filter(|s| s.t_ms >= 1_000)
        .all(|s| s.tick.mode == Mode::Commissioned && s.tick.liveness.is_none()));
    assert_eq!(ResetRecord::decode(&rig.survivors.reset_ram), None);
    // After the two gaps (the timestamps continued from each restart) the monitor still
    // judges the machine steady and healthy.
    let last = rig.path.monitor().output();
    assert!(last.quasi_steady && !last.fault_detected, "{last:?}");
}

#[test]
fn the_former_restart_never_clears_the_overrun_and_ends_in_a_watchdog_reset() {
    let frames = steady_frames(3.5);
    for at in [OVERRUN_AT, DMA_ERROR_AT] {
        let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
        rig.restart = former_restart;
        let reset = rig.run(&frames, |rig, k| {
            if k == at {
                inject(rig, k);
            }
        });
        assert_eq!(reset, Err(Reset::Watchdog), "fault at {at}");
        assert!(rig.recoveries.len() >= 240, "{}", rig.recoveries.len());
        let PreviousRun::Recorded(rec) = Rig::boot(rig.survivors.clone()).previous else {
            panic!("no record");
        };
        assert_eq!(rec.cause(), ResetCause::SampleStall);
    }
}

#[test]
fn the_sequence_on_the_model_clears_what_blocks_the_dma() {
    let mut acq = AdcDmaModel::running();
    acq.regs.inject_dma_error();
    // The ADC goes on converting into a full data register: overrun.
    assert!(!acq.regs.trigger() && !acq.regs.trigger());
    assert!(acq.regs.adc_flags(0).ovr && acq.regs.adc_flags(0).eoc);
    assert_eq!(
        recovery::recover(&mut acq),
        Ok(Faults {
            adc_overrun: true,
            dma_error: true
        })
    );
    assert!(acq.regs.trigger());
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert!(acq.regs.trigger());
    assert_eq!(
        RecoveryStep::ORDER.first(),
        Some(&RecoveryStep::StopTrigger)
    );
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
}

/// The done-when of the overrun recovery: with the model's `EOC` behaviour, a forced
/// overrun resumes within 2 ms (the sample task's timeout: 20 periods at 10 kHz) with no
/// second overrun, every register access within its precondition; the same sequence
/// without the `EOC` clear re-overruns at the first conversion after every restart and
/// never resumes.
#[test]
fn a_forced_overrun_resumes_within_2_ms_and_without_the_eoc_clear_it_never_does() {
    let frames = steady_frames(3.5);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    let overruns_before = rig.acq.regs.overruns;
    rig.run(&frames, |rig, k| {
        if k == OVERRUN_AT {
            rig.acq.regs.inject_overrun();
        }
    })
    .unwrap();
    assert_eq!(
        rig.acq.regs.overruns - overruns_before,
        1,
        "a second overrun"
    );
    assert_eq!(
        rig.recoveries,
        [Ok(Faults {
            adc_overrun: true,
            dma_error: false
        })]
    );
    let resumed_ms = rig.restarts_at_ms[0] as f64 - OVERRUN_AT as f64 / 10.0;
    assert!(
        resumed_ms <= 2.0,
        "resumed {resumed_ms} ms after the overrun"
    );
    assert!(
        rig.acq.regs.violations.is_empty(),
        "{:?}",
        rig.acq.regs.violations
    );

    // Without the EOC clear: OVR again at the first conversion after each restart.
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    rig.restart = recover_only_ovr;
    let reset = rig.run(&frames, |rig, k| {
        if k == OVERRUN_AT {
            rig.acq.regs.inject_overrun();
        }
    });
    assert_eq!(reset, Err(Reset::Watchdog));
    assert!(rig.acq.regs.overruns > 100, "{}", rig.acq.regs.overruns);
    assert!(rig.recoveries.iter().skip(1).all(|r| *r
        == Ok(Faults {
            adc_overrun: true,
            dma_error: false
        })));
}

/// A lapped ring (the reader fell a turn behind the DMA, the sample task's read fails):
/// the same sequence reloads `CNDTR` with the whole ring from its start, within its
/// preconditions, and the next trigger delivers.
#[test]
fn a_lapped_ring_is_reloaded_from_its_start() {
    let mut acq = AdcDmaModel::running();
    for _ in 0..(3 * RING_LEN as usize + 5) {
        assert!(acq.regs.trigger());
    }
    assert_ne!(acq.regs.dma[0].cndtr, RING_LEN);
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert_eq!(acq.regs.dma.map(|d| d.cndtr), [RING_LEN; 2]);
    assert!(acq.regs.trigger());
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    assert_eq!(acq.regs.dma[0].moved, acq.regs.conversions);
}
