//! The acquisition's recovery: a model of the ADC/DMA hardware (the rules of the reference
//! manual RM0440 that `drive_monitor::recovery` relies on) into which an ADC overrun and a
//! DMA transfer error are injected; the monitor resumes with its state intact. The
//! firmware's former restart (no `OVR` cleared) is run on the same model and never
//! resumes.

use super::*;
use drive_monitor::recovery::{self, Acquisition, Faults, Step, StepTimeout};

/// The ADCs, their DMA channels and the trigger, as far as the recovery is concerned.
#[derive(Clone, Copy, Debug)]
pub(super) struct FakeAcq {
    trigger_on: bool,
    /// `ADSTART`: the ADCs convert on each trigger.
    adstart: bool,
    /// `OVR`: latched by a conversion whose previous result nobody took; while set, the
    /// ADC issues no DMA requests (RM0440, with `DMAEN = 1`).
    ovr: bool,
    /// The data register holds a result the DMA has not taken.
    dr_full: bool,
    /// The ADCs' `DMAEN`.
    dmaen: bool,
    /// The DMA channels' `EN` (cleared by the hardware on a transfer error).
    dma_en: bool,
    /// `TEIF`.
    teif: bool,
}

impl FakeAcq {
    pub(super) fn running() -> Self {
        Self {
            trigger_on: true,
            adstart: true,
            ovr: false,
            dr_full: false,
            dmaen: true,
            dma_en: true,
            teif: false,
        }
    }

    /// One trigger period: whether a conversion's results reach the ring.
    pub(super) fn trigger(&mut self) -> bool {
        if !(self.trigger_on && self.adstart) {
            return false;
        }
        if self.ovr {
            return false;
        }
        if self.dmaen && self.dma_en {
            self.dr_full = false;
            return true;
        }
        // Nobody takes the result: the next conversion overruns.
        if self.dr_full {
            self.ovr = true;
        }
        self.dr_full = true;
        false
    }

    /// A conversion finished before the DMA took the previous one.
    fn inject_overrun(&mut self) {
        self.ovr = true;
    }

    /// A DMA transfer error: the hardware sets `TEIF` and clears `EN`.
    fn inject_dma_error(&mut self) {
        self.teif = true;
        self.dma_en = false;
    }
}

impl Acquisition for FakeAcq {
    fn faults(&mut self) -> Faults {
        Faults {
            adc_overrun: self.ovr,
            dma_error: self.teif,
        }
    }
    fn stop_trigger(&mut self) {
        self.trigger_on = false;
    }
    fn stop_adc(&mut self) -> Result<(), StepTimeout> {
        self.adstart = false;
        Ok(())
    }
    fn pause_dma(&mut self) -> Result<(), StepTimeout> {
        self.dma_en = false;
        Ok(())
    }
    fn clear_flags(&mut self) {
        self.ovr = false;
        self.teif = false;
    }
    fn rearm_dma(&mut self) {
        self.dr_full = false;
        self.dmaen = true;
        self.dma_en = true;
    }
    fn start_adc(&mut self) {
        self.adstart = true;
    }
    fn start_trigger(&mut self) {
        self.trigger_on = true;
    }
}

/// The firmware's restart before the recovery: the trigger stopped, the DMA paused and
/// resumed with the rings cleared, `ADSTART` set, the trigger started, and `OVR` never
/// cleared.
fn former_restart(acq: &mut FakeAcq) -> Result<Faults, StepTimeout> {
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
        rig.acq.inject_overrun();
    }
    if k == DMA_ERROR_AT {
        rig.acq.inject_dma_error();
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
    let mut acq = FakeAcq::running();
    acq.inject_dma_error();
    // The ADC goes on converting into a full data register: overrun.
    assert!(!acq.trigger() && !acq.trigger());
    assert!(acq.ovr);
    assert_eq!(
        recovery::recover(&mut acq),
        Ok(Faults {
            adc_overrun: true,
            dma_error: true
        })
    );
    assert!(acq.trigger());
    assert_eq!(recovery::recover(&mut acq), Ok(Faults::default()));
    assert!(acq.trigger());
    assert_eq!(Step::ORDER.first(), Some(&Step::StopTrigger));
}
