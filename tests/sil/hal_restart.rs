//! The first-week recovery's gaps (issue 74): a capture request pending at the latch's
//! re-arm, and a ring the HAL's `read` would restart by itself.

use super::recovery::{recover_weakened, AdcDmaModel, Without};
use drive_monitor::recovery;
use drive_monitor::ring_read::{read_half, Half, HalfBuffers};
use std::future::Future;
use std::pin::pin;
use std::task::{Context, Poll, Waker};

/// Runs a future the model completes at once (no executor needed).
fn now<F: Future>(f: F) -> F::Output {
    let mut f = pin!(f);
    match f.as_mut().poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(out) => out,
        Poll::Pending => panic!("the model's reads complete at once"),
    }
}

/// A DMA transfer error on the encoder latch's channel leaves TIM4's capture request
/// pending (the timer keeps requesting while the channel is off). The firmware's recovery
/// clears `CC3DE` before it stops the channel and sets it after the re-arm, which withdraws
/// the request: every sample's counts stay paired with its conversions. Without the toggle
/// the re-armed channel serves the stale request first, one count at the ring's start, and
/// every later count is one trigger late.
#[test]
fn a_pending_capture_request_shifts_the_latch_only_without_the_cc3de_toggle() {
    let run = |without: Option<Without>| {
        let mut acq = AdcDmaModel::running();
        // The samples taken while the latch's channel was off have no counts (the sample
        // task's latch read waits for them and is cut short): not counted.
        let mut during_fault = 0;
        for k in 0..1_500 {
            if k == 500 {
                acq.regs.inject_latch_dma_error();
            }
            // The sample task's next read finds the latch's channel off (its read guard,
            // or the wait's timeout): the recovery.
            if k == 510 {
                during_fault = acq.regs.unpaired_samples;
                match without {
                    None => recovery::recover(&mut acq).unwrap(),
                    Some(w) => recover_weakened(&mut acq, w).unwrap(),
                };
            }
            acq.regs.sample();
        }
        assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
        assert_eq!(during_fault, 2 * 10);
        (
            acq.regs.paired_samples,
            acq.regs.unpaired_samples - during_fault,
        )
    };
    let (checked, unpaired) = run(None);
    assert!(checked > 2_900, "{checked}");
    assert_eq!(unpaired, 0);
    let (_, unpaired) = run(Some(Without::Cc3deToggle));
    assert!(unpaired > 1_900, "{unpaired}");
}

/// A DMA transfer error between two reads of the sample task: embassy's
/// `RingBufferedAdc::read` finds the ring's channel off and restarts it with its own
/// `start()` (the channel enabled with `TEIF` set and `CNDTR` as it was, `ADC_CR` written
/// by read-modify-write: `ADEN` written back with `ADSTART`). The firmware's read guard
/// (`recovery::before_read`) runs the recovery first, so the HAL finds the ring running:
/// no rule broken, every half in place. Without the guard the HAL's restart breaks the
/// register rules.
#[test]
fn a_dma_error_between_two_reads_is_recovered_before_the_hals_read_restarts_the_ring() {
    for guarded in [true, false] {
        let mut acq = AdcDmaModel::running();
        for _ in 0..10 {
            assert!(acq.regs.sample());
        }
        acq.regs.inject_dma_error();
        if guarded {
            let faults = recovery::before_read(&mut acq)
                .expect("a channel off")
                .unwrap();
            assert!(faults.dma_error);
            assert_eq!(recovery::before_read(&mut acq), None, "running again");
        }
        for i in 0..2 {
            acq.regs.hal_read(i);
        }
        let delivered = (0..100).filter(|_| acq.regs.sample()).count();
        if guarded {
            assert!(acq.regs.violations.is_empty(), "{:?}", acq.regs.violations);
            assert_eq!(acq.regs.misaligned_halves, 0);
            assert!(delivered >= 99, "{delivered}");
        } else {
            assert!(
                acq.regs
                    .violations
                    .iter()
                    .any(|v| v.contains("read-modify-write")),
                "{:?}",
                acq.regs.violations
            );
        }
    }
}

/// The sample task's read of a half (`ring_read::read_half`, what `src/firmware/
/// sample_task.rs` awaits): a DMA transfer error on ADC2's channel (or ADC1's, or both)
/// while the task awaits ADC1's half is recovered before ADC2's read, so the HAL's read
/// never restarts a ring itself; an error between two halves is recovered before the first
/// read. Every later half reads, no register rule broken.
#[test]
fn a_dma_error_during_the_wait_for_adc1_is_recovered_before_adc2s_read() {
    for error in [None, Some((0, 1)), Some((0, 0))] {
        let mut acq = AdcDmaModel::running();
        let mut bufs = HalfBuffers::default();
        for _ in 0..10 {
            assert!(acq.regs.sample());
        }
        match error {
            Some(e) => acq.regs.error_on_read = Some(e),
            // Between two halves: the error is there before the first read.
            None => acq.regs.inject_dma_error(),
        }
        let half = now(read_half(&mut acq, &mut bufs));
        assert!(
            matches!(half, Half::Recovered(Ok(f)) if f.dma_error),
            "{error:?}: {half:?}"
        );
        assert_eq!(
            acq.regs.reads[1], 0,
            "{error:?}: ADC2's ring read while off"
        );
        for _ in 0..5 {
            acq.regs.sample();
            assert_eq!(
                now(read_half(&mut acq, &mut bufs)),
                Half::Read { lapped: [false; 2] }
            );
        }
        assert!(
            acq.regs.violations.is_empty(),
            "{error:?}: {:?}",
            acq.regs.violations
        );
        let delivered = (0..100).filter(|_| acq.regs.sample()).count();
        assert!(delivered >= 99, "{delivered}");
        assert_eq!(acq.regs.misaligned_halves, 0);
    }
}

/// A lap (the DMA a half ahead of the reader: samples lost) is reported for the ring it hit
/// (`Half::Read`'s `lapped`: ADC1's, then ADC2's or the latch's), so the recovery follows
/// for a lapped latch as for a lapped ADC: the latch's counts are the samples' encoder
/// positions, and one lap shifts them against the conversions.
#[test]
fn a_lap_on_any_ring_is_reported_a_lap_on_the_latch_too() {
    for (ring, lapped) in [(0, [true, false]), (1, [false, true]), (2, [false, true])] {
        let mut acq = AdcDmaModel::running();
        let mut bufs = HalfBuffers::default();
        for _ in 0..10 {
            assert!(acq.regs.sample());
        }
        acq.regs.lap_on_read[ring] = true;
        assert_eq!(
            now(read_half(&mut acq, &mut bufs)),
            Half::Read { lapped },
            "ring {ring}"
        );
        acq.regs.sample();
        assert_eq!(
            now(read_half(&mut acq, &mut bufs)),
            Half::Read { lapped: [false; 2] },
            "ring {ring}, the next half"
        );
    }
}
