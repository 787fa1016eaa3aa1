//! `recovery`'s unit tests (host).

use super::*;

/// Records the calls, fails the wait of `fail` if set.
#[derive(Default)]
struct Trace {
    steps: Vec<RecoveryStep>,
    fail: Option<RecoveryStep>,
}

impl Trace {
    fn wait(&mut self, step: RecoveryStep) -> Result<(), StepTimeout> {
        self.steps.push(step);
        poll_until(step, 10, || self.fail != Some(step))
    }
}

impl Acquisition for Trace {
    fn faults(&mut self) -> Faults {
        Faults {
            adc_overrun: true,
            dma_error: false,
        }
    }
    fn stop_trigger(&mut self) {
        self.steps.push(RecoveryStep::StopTrigger);
    }
    fn stop_adc(&mut self) -> Result<(), StepTimeout> {
        self.wait(RecoveryStep::StopAdc)
    }
    fn pause_dma(&mut self) -> Result<(), StepTimeout> {
        self.wait(RecoveryStep::PauseDma)
    }
    fn clear_flags(&mut self) {
        self.steps.push(RecoveryStep::ClearFlags);
    }
    fn rearm_dma(&mut self) {
        self.steps.push(RecoveryStep::RearmDma);
    }
    fn start_adc(&mut self) {
        self.steps.push(RecoveryStep::StartAdc);
    }
    fn start_trigger(&mut self) {
        self.steps.push(RecoveryStep::StartTrigger);
    }
}

#[test]
fn the_sequence_runs_in_the_reference_manuals_order() {
    let mut t = Trace::default();
    assert_eq!(
        recover(&mut t),
        Ok(Faults {
            adc_overrun: true,
            dma_error: false
        })
    );
    assert_eq!(t.steps, RecoveryStep::ORDER);
}

#[test]
fn a_wait_that_runs_out_stops_the_sequence_and_is_counted() {
    let mut t = Trace {
        fail: Some(RecoveryStep::StopAdc),
        ..Trace::default()
    };
    let r = recover(&mut t);
    assert_eq!(r, Err(StepTimeout(RecoveryStep::StopAdc)));
    assert_eq!(t.steps, [RecoveryStep::StopTrigger, RecoveryStep::StopAdc]);
    let mut n = RecoveryCounts::default();
    n.count(r);
    n.count(Ok(Faults {
        adc_overrun: false,
        dma_error: true,
    }));
    assert_eq!(
        n,
        RecoveryCounts {
            recoveries: 2,
            adc_overruns: 0,
            dma_errors: 1,
            timeouts: 1
        }
    );
    let mut polls = 0;
    assert_eq!(
        poll_until(RecoveryStep::PauseDma, 7, || {
            polls += 1;
            false
        }),
        Err(StepTimeout(RecoveryStep::PauseDma))
    );
    assert_eq!(polls, 7);
}

/// Registers whose accesses keep RM0440's preconditions in mind: `ADSTP` only while
/// `ADSTART = 1`, a channel's `CNDTR` only with its `EN = 0` (a breach is recorded);
/// the encoder latch's channel can be made to keep `EN = 1` after its disable.
#[derive(Default)]
struct Bench {
    adstart: [bool; 2],
    dma_en: [bool; 2],
    latch_en: bool,
    latch_stuck: bool,
    breaches: Vec<&'static str>,
}

impl Bench {
    fn running() -> Self {
        Bench {
            adstart: [true; 2],
            dma_en: [true; 2],
            latch_en: true,
            ..Bench::default()
        }
    }
}

impl AcqRegisters for Bench {
    fn adc_flags(&mut self, _: usize) -> AdcFlags {
        AdcFlags::default()
    }
    fn adc_clear(&mut self, _: usize, _: AdcFlags) {}
    fn adc_cr(&mut self, i: usize) -> u32 {
        adc_rules::ADEN | if self.adstart[i] { ADSTART } else { 0 }
    }
    fn adc_cr_write(&mut self, i: usize, value: u32) {
        if value & ADSTP != 0 {
            if !self.adstart[i] {
                self.breaches.push("ADSTP with ADSTART = 0");
            }
            self.adstart[i] = false;
        }
        if value & ADSTART != 0 {
            self.adstart[i] = true;
        }
    }
    fn adc_dma_circular(&mut self, _: usize) {}
    fn adc_dma_off(&mut self, _: usize) {}
    fn dma_error(&mut self, _: usize) -> bool {
        false
    }
    fn dma_clear(&mut self, _: usize) {}
    fn dma_enabled(&mut self, i: usize) -> bool {
        self.dma_en[i]
    }
    fn dma_disable(&mut self, i: usize) {
        self.dma_en[i] = false;
    }
    fn dma_reload(&mut self, i: usize, _: u16) {
        if self.dma_en[i] {
            self.breaches.push("an ADC channel's CNDTR with EN = 1");
        }
    }
    fn dma_enable(&mut self, i: usize) {
        self.dma_en[i] = true;
    }
    fn latch_request(&mut self, _: bool) {}
    fn latch_disable(&mut self) {
        self.latch_en = self.latch_stuck;
    }
    fn latch_enabled(&mut self) -> bool {
        self.latch_en
    }
    fn latch_clear(&mut self) {}
    fn latch_reload(&mut self, _: u16) {
        if self.latch_en {
            self.breaches.push("the latch channel's CNDTR with EN = 1");
        }
    }
    fn latch_enable(&mut self) {
        self.latch_en = true;
    }
    fn trigger_stop(&mut self) {}
    fn trigger_start(&mut self) {}
}

/// The pause waits for the encoder latch's channel as for the ADCs' (RM0440: `CNDTR` is
/// writable only with the channel's `EN = 0`): a latch channel that keeps running stops
/// the sequence at `PauseDma`, its `CNDTR` untouched; one that stops lets it resume.
#[test]
fn the_pause_waits_for_the_latch_channel_too() {
    let mut acq = RegisterAcquisition {
        regs: Bench {
            latch_stuck: true,
            ..Bench::running()
        },
        ring_len: 48,
    };
    assert_eq!(recover(&mut acq), Err(StepTimeout(RecoveryStep::PauseDma)));
    assert!(acq.regs.breaches.is_empty(), "{:?}", acq.regs.breaches);
    let mut acq = RegisterAcquisition {
        regs: Bench::running(),
        ring_len: 48,
    };
    assert_eq!(recover(&mut acq), Ok(Faults::default()));
    assert!(acq.regs.breaches.is_empty(), "{:?}", acq.regs.breaches);
    assert!(acq.running());
}

/// The log names a timed-out step by [`RecoveryStep::name`]: each step's own name, the
/// module docs' step in kebab case, so that two steps never read alike in the log.
#[test]
fn each_step_has_its_own_name_in_the_log() {
    for (k, step) in RecoveryStep::ORDER.iter().enumerate() {
        let debug = format!("{step:?}");
        let mut kebab = String::new();
        for (j, c) in debug.chars().enumerate() {
            if c.is_ascii_uppercase() && j > 0 {
                kebab.push('-');
            }
            kebab.push(c.to_ascii_lowercase());
        }
        assert_eq!(step.name(), kebab);
        for other in &RecoveryStep::ORDER[k + 1..] {
            assert_ne!(step.name(), other.name());
        }
    }
}
