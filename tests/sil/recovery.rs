//! The acquisition's recovery on a register-level model of the STM32G474's ADC + DMA
//! (RM0440) with the firmware's own geometry (`drive_monitor::acquisition`: the ring's
//! length, the channels per ADC, the oversampling, the conversion time at the ADC clock).
//! Each ADC keeps its data register and `EOC` as the hardware does (a result sits in
//! `ADC_DR` with `EOC = 1` until the DMA reads it; a conversion that ends while `EOC` is 1
//! sets `OVR` and, with `OVRMOD = 0`, keeps the old data; while `OVR` is set the ADC issues
//! no DMA requests), and its DMA request: raised at each result while `DMAEN = 1`, held by
//! the DMA while the channel is off, served (one word moved) when the channel is enabled,
//! withdrawn when `DMAEN` is cleared. Conversions take their time (a sequence of three,
//! 870 ns each, at every trigger, [`OVERSAMPLING`] triggers per sample); `ADSTP` takes
//! effect when the conversion in flight ends, and every poll of a register costs the
//! model's clock time, so the recovery's waits can run out (a stuck ADC never clears
//! `ADSTART`). Each DMA channel keeps its `EN`, `CNDTR`, `TEIF` and the ring's words (which
//! channel each holds: a half with a word out of place is counted). Every register access
//! checks its precondition (`ADSTP` only while converting, `DMAEN`/`DMACFG` only with
//! `ADSTART = 0`, `CNDTR` only with the channel off). The firmware's own sequence,
//! `drive_monitor::recovery::RegisterAcquisition` (the code `src/firmware/acquisition.rs`
//! runs over the real registers), drives it; an overrun, a DMA error and a lapped ring are
//! injected and the monitor resumes with its state intact. The same sequence with only
//! `OVR` cleared (before the `EOC` clear) re-overruns at the first conversion and never
//! resumes, as does the firmware's former restart; without the `DMAEN` clear a DMA error
//! leaves every later sample's channels shifted by one word.

mod model;

use super::*;
use drive_monitor::acquisition::{conversion_ns, CHANNELS};
use drive_monitor::recovery::{
    self, AcqRegisters, Acquisition, AdcFlags, Faults, RecoveryStep, RegisterAcquisition,
    StepTimeout, POLL_LIMIT,
};
use model::POLL_NS;
pub(super) use model::{AdcDmaModel, ModelAcq, RING_LEN};

/// What a weakened sequence leaves out.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Without {
    /// The `EOC`/`EOS` clear: only `OVR` cleared in `ADC_ISR` (the sequence before the
    /// `EOC` clear).
    EocClear,
    /// The `DMAEN` clear (the sequence before it).
    DmaenClear,
    /// The wait for `JADSTART = 0` before the `DMAEN` clear.
    JadstartWait,
    /// Writing one set-only bit of `ADC_CR` alone (a read-modify-write instead).
    SetOnlyMask,
    /// The encoder latch's reload with the ADCs' rings.
    LatchReload,
    /// The capture request's toggle (`CC3DE` off in the pause, on after the re-arm).
    Cc3deToggle,
}

/// The firmware's sequence with one access left out ([`Without`]): every other register
/// access as the model's.
struct Weakened<'a>(&'a mut AdcDmaModel, Without);

impl AcqRegisters for Weakened<'_> {
    fn adc_flags(&mut self, i: usize) -> AdcFlags {
        self.0.adc_flags(i)
    }
    fn adc_clear(&mut self, i: usize, f: AdcFlags) {
        let f = match self.1 {
            Without::EocClear => AdcFlags {
                ovr: f.ovr,
                ..AdcFlags::default()
            },
            _ => f,
        };
        self.0.adc_clear(i, f);
    }
    fn adc_cr(&mut self, i: usize) -> u32 {
        let cr = self.0.adc_cr(i);
        match self.1 {
            // The former wait looked at ADSTART only.
            Without::JadstartWait => cr & !model::CR_JADSTART,
            _ => cr,
        }
    }
    fn adc_cr_write(&mut self, i: usize, value: u32) {
        let value = match self.1 {
            // A read-modify-write: the set-only bits as read written back.
            Without::SetOnlyMask => value | (self.0.adc_cr(i) & model::CR_SET_ONLY),
            _ => value,
        };
        self.0.adc_cr_write(i, value);
    }
    fn adc_dma_circular(&mut self, i: usize) {
        self.0.adc_dma_circular(i);
    }
    fn adc_dma_off(&mut self, i: usize) {
        if self.1 != Without::DmaenClear {
            self.0.adc_dma_off(i);
        }
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
    fn latch_disable(&mut self) {
        self.0.latch_disable();
    }
    fn latch_enabled(&mut self) -> bool {
        self.0.latch_enabled()
    }
    fn latch_clear(&mut self) {
        self.0.latch_clear();
    }
    fn latch_reload(&mut self, transfers: u16) {
        if self.1 != Without::LatchReload {
            self.0.latch_reload(transfers);
        }
    }
    fn latch_enable(&mut self) {
        self.0.latch_enable();
    }
    fn latch_request(&mut self, on: bool) {
        if self.1 != Without::Cc3deToggle {
            self.0.latch_request(on);
        }
    }
    fn trigger_stop(&mut self) {
        self.0.trigger_stop();
    }
    fn trigger_start(&mut self) {
        self.0.trigger_start();
    }
}

/// The recovery without `without` ([`Weakened`]).
pub(super) fn recover_weakened(
    acq: &mut ModelAcq,
    without: Without,
) -> Result<Faults, StepTimeout> {
    let mut weak = RegisterAcquisition {
        regs: Weakened(&mut acq.regs, without),
        ring_len: acq.ring_len,
    };
    recovery::recover(&mut weak)
}

/// The recovery with only `OVR` cleared.
fn recover_only_ovr(acq: &mut ModelAcq) -> Result<Faults, StepTimeout> {
    recover_weakened(acq, Without::EocClear)
}

/// The recovery without the `DMAEN` clear.
fn recover_keeping_dmaen(acq: &mut ModelAcq) -> Result<Faults, StepTimeout> {
    recover_weakened(acq, Without::DmaenClear)
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
    // Every sample after the two recoveries had its channels in place.
    assert_eq!(rig.acq.regs.misaligned_halves, 0);
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
    assert!(!acq.regs.sample() && !acq.regs.sample());
    assert!(acq.regs.adc_flags(0).ovr && acq.regs.adc_flags(0).eoc);
    assert_eq!(
        recovery::recover(&mut acq),
        Ok(Faults {
            adc_overrun: true,
            dma_error: true
        })
    );
    assert!(acq.regs.sample());
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert!(acq.regs.sample());
    assert_eq!(
        RecoveryStep::ORDER.first(),
        Some(&RecoveryStep::StopTrigger)
    );
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    assert_eq!(acq.regs.misaligned_halves, 0);
}

/// A DMA transfer error leaves a DMA request raised while the channel was off. The
/// firmware's sequence clears `DMAEN` with the ADC stopped, which withdraws it: after the
/// recovery every half holds va, vb, vc (ia, ib, ic) in their places. Without the `DMAEN`
/// clear the re-armed channel serves the stale request first, one word from the data
/// register, and every later half is shifted by one word: vc read as va, for good.
#[test]
fn after_a_dma_error_the_channels_stay_in_place_only_with_the_dmaen_clear() {
    for (name, restart) in [
        (
            "firmware",
            recovery::recover::<ModelAcq> as fn(&mut ModelAcq) -> Result<Faults, StepTimeout>,
        ),
        ("without the DMAEN clear", recover_keeping_dmaen),
    ] {
        let mut acq = AdcDmaModel::running();
        for _ in 0..10 {
            assert!(acq.regs.sample());
        }
        acq.regs.inject_dma_error();
        assert!(!acq.regs.sample());
        let faults = restart(&mut acq).unwrap();
        assert!(faults.dma_error, "{name}");
        let delivered = (0..100).filter(|_| acq.regs.sample()).count();
        assert!(delivered >= 99, "{name}: {delivered}");
        let shifted = acq.regs.misaligned_halves;
        if name == "firmware" {
            assert_eq!(shifted, 0, "{name}");
            assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
        } else {
            assert!(shifted >= 2 * 99, "{name}: {shifted} halves shifted");
        }
    }
}

/// The waits are bounded: an ADC whose `ADSTART` never clears stops the sequence at
/// `StopAdc` after [`POLL_LIMIT`] polls (about 3 ms of the model's clock), nothing
/// re-armed; a working one stops within one conversion time.
#[test]
fn a_stuck_adc_times_the_stop_out_and_a_working_one_stops_within_a_conversion() {
    let mut acq = AdcDmaModel::running();
    assert!(acq.regs.sample());
    let t0 = acq.regs.now_ns;
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    let took = acq.regs.now_ns - t0;
    assert!(
        took <= u64::from(conversion_ns()) + 10 * POLL_NS,
        "{took} ns"
    );

    let mut acq = AdcDmaModel::running();
    acq.regs.adc[1].stuck = true;
    let t0 = acq.regs.now_ns;
    assert_eq!(
        recovery::recover(&mut acq),
        Err(StepTimeout(RecoveryStep::StopAdc))
    );
    let took_ms = (acq.regs.now_ns - t0) as f64 / 1e6;
    assert!(
        took_ms >= POLL_LIMIT as f64 * POLL_NS as f64 / 1e6,
        "{took_ms} ms"
    );
    assert!(!acq.regs.trigger_on && acq.regs.dma.iter().all(|d| d.en));
    assert!(!acq.regs.sample());
}

/// The recovery after one that timed out at `StopAdc`: ADC1 stopped then (`ADSTART = 0`),
/// ADC2's conversion has ended since. RM0440 allows `ADSTP` only with `ADSTART = 1` and
/// `ADDIS = 0`: the sequence sets it on neither stopped ADC (the model counts an `ADSTP`
/// on a stopped ADC as a violation), and the acquisition resumes.
#[test]
fn a_recovery_after_a_timed_out_one_sets_no_adstp_on_a_stopped_adc() {
    let mut acq = AdcDmaModel::running();
    acq.regs.adc[1].stuck = true;
    assert_eq!(
        recovery::recover(&mut acq),
        Err(StepTimeout(RecoveryStep::StopAdc))
    );
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    acq.regs.adc[1].stuck = false;
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    assert!(acq.regs.sample() && acq.regs.sample());
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
    // 3 turns and 5 triggers: the ring's position is not at its start.
    for _ in 0..(3 * RING_LEN as usize / CHANNELS + 5) {
        acq.regs.trigger();
    }
    assert_ne!(acq.regs.dma[0].cndtr, RING_LEN);
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert_eq!(acq.regs.dma.map(|d| d.cndtr), [RING_LEN; 2]);
    assert!(acq.regs.sample());
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    assert_eq!(
        acq.regs.dma[0].moved,
        acq.regs.conversions * CHANNELS as u32
    );
    assert_eq!(acq.regs.misaligned_halves, 0);
}

/// The ADC's register rules in the recovery (`drive_monitor::adc_rules`), against the
/// model's checks: a recovery that starts while thread mode's VREFINT conversion runs on
/// ADC1's injected channel waits for `JADSTART = 0` before clearing `DMAEN`, and every
/// `ADC_CR` write sets one set-only bit alone. Without the wait (the former one looked at
/// `ADSTART` only) `DMAEN` is cleared during the injected conversion; with a
/// read-modify-write of `ADC_CR` the set-only bits read as 1 are written back.
#[test]
fn the_recovery_keeps_the_adc_register_rules_during_an_injected_conversion() {
    let run = |without: Option<Without>| {
        let mut acq = AdcDmaModel::running();
        for _ in 0..10 {
            assert!(acq.regs.sample());
        }
        acq.regs.start_injected();
        let r = match without {
            None => recovery::recover(&mut acq),
            Some(w) => recover_weakened(&mut acq, w),
        };
        for _ in 0..10 {
            acq.regs.sample();
        }
        (r, acq.regs.violations)
    };
    let (r, violations) = run(None);
    assert!(r.is_ok(), "{r:?}");
    assert!(violations.is_empty(), "{violations:?}");
    let (_, violations) = run(Some(Without::JadstartWait));
    assert!(
        violations
            .iter()
            .any(|v| v.contains("DMAEN of ADC1 cleared while JADSTART = 1")),
        "{violations:?}"
    );
    let (_, violations) = run(Some(Without::SetOnlyMask));
    assert!(
        violations.iter().any(|v| v.contains("read-modify-write")),
        "{violations:?}"
    );
}

/// The G4's erratum: the model's first conversion after more than 1 ms without one is
/// wrong. A stopped trigger times the wait out after 2 ms; after the recovery the sample
/// path drops the first sample (`adc_rules::IdleDiscard`, as the sample task does with the
/// time since its last data), so no sample holding that conversion reaches it. After a
/// short idle (0.5 ms) nothing is wrong and nothing is dropped.
#[test]
fn the_first_sample_after_a_long_idle_is_dropped_and_none_after_a_short_one() {
    use drive_monitor::adc_rules::IdleDiscard;
    let run = |idle_samples: usize| {
        let mut acq = AdcDmaModel::running();
        let mut discard = IdleDiscard::default();
        let (mut delivered_bad, mut dropped) = (0, 0);
        let mut last_data_ns = 0;
        for k in 0..200 {
            if k == 50 {
                acq.regs.trigger_stop();
            }
            if k == 50 + idle_samples {
                recovery::recover(&mut acq).unwrap();
                let idle_us = (acq.regs.now_ns - last_data_ns) / 1_000;
                discard.on_start(idle_us as u32);
            }
            if acq.regs.sample() {
                last_data_ns = acq.regs.now_ns;
                let bad = acq.regs.last_block_bad.iter().any(|&b| b);
                if discard.drop_next() {
                    dropped += 1;
                } else if k > 50 {
                    delivered_bad += u32::from(bad);
                }
            }
        }
        (delivered_bad, dropped, acq.regs.violations)
    };
    let (bad, dropped, violations) = run(20);
    assert_eq!((bad, dropped), (0, 1));
    assert!(violations.is_empty(), "{violations:?}");
    let (bad, dropped, _) = run(5);
    assert_eq!((bad, dropped), (0, 0));
}

/// The encoder count latched in hardware at the trigger (TIM4's capture on TIM1's `TRGO`,
/// copied by a DMA channel into a ring beside the ADCs'): every sample's latched counts
/// come from the triggers of its own conversions, through a lapped ring, an overrun and a
/// DMA error and their recoveries. Without the latch's reload in the recovery the ADCs'
/// rings restart from their start and the latch's does not: the counts belong to other
/// triggers.
#[test]
fn the_latched_encoder_count_belongs_to_the_conversions_of_its_sample() {
    let run = |without: Option<Without>| {
        let mut acq = AdcDmaModel::running();
        for k in 0..2_000 {
            if k == 500 {
                acq.regs.inject_overrun();
            }
            if k == 1_000 {
                acq.regs.inject_dma_error();
            }
            if k == 1_500 || !acq.regs.sample() && k % 20 == 0 {
                match without {
                    None => recovery::recover(&mut acq).unwrap(),
                    Some(w) => recover_weakened(&mut acq, w).unwrap(),
                };
            }
        }
        (acq.regs.paired_samples, acq.regs.unpaired_samples)
    };
    let (checked, unpaired) = run(None);
    assert!(checked > 3_000, "{checked}");
    assert_eq!(unpaired, 0);
    let (_, unpaired) = run(Some(Without::LatchReload));
    assert!(unpaired > 100, "{unpaired}");
}

/// The first start (`src/firmware/acquisition.rs`, `start`) is the recovery's last three
/// steps on the acquisition the set-up left: the rings armed, `ADSTART` written alone, the
/// trigger; on the model no rule is broken, every sample arrives with its channels in place
/// and its latched counts paired.
#[test]
fn the_first_start_keeps_the_register_rules_and_pairs_the_counts() {
    let mut acq = AdcDmaModel::stopped();
    assert!(!acq.regs.sample());
    acq.rearm_dma();
    acq.start_adc();
    acq.start_trigger();
    let delivered = (0..300).filter(|_| acq.regs.sample()).count();
    assert!(delivered >= 298, "{delivered}");
    assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
    assert_eq!(acq.regs.misaligned_halves, 0);
    assert_eq!(acq.regs.unpaired_samples, 0);
    assert!(acq.regs.paired_samples >= 596);
}
