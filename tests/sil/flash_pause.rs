//! A commissioning's flash store does not lap the DMA ring: `app::carry_out` pauses the
//! acquisition around the erase and the write (`app::AcquisitionPause`, on the board the
//! sample task's `recovery::pause` and `recovery::resume`).
//!
//! The erase is modelled at its worst: 22 ms (a G4 page erase) with interrupts masked, as
//! embassy-stm32's region API erases (`erase_sector_with_critical_section`), so the sample
//! task reads nothing while the trigger, the ADCs and the DMA go on. The firmware's own
//! erase (`Flash::blocking_erase`, bank 2 while the code runs from bank 1) keeps interrupts
//! enabled; the pause makes the ring safe whichever way the erase runs.

use std::cell::RefCell;
use std::rc::Rc;

use super::recovery::{AdcDmaModel, ModelAcq};
use super::{old_record, FakeFlash, FlashError};
use drive_monitor::acquisition::trigger_rate_hz;
use drive_monitor::app::{carry_out, AcquisitionPause, NoPause};
use drive_monitor::commissioning::Action;
use drive_monitor::flash_record::{RecordPage, RecordStore, RECORD_LEN};

/// A G4 page erase [ms] (datasheet `t_ERASE`, about 22 ms).
const ERASE_MS: u64 = 22;

/// The record page whose erase takes [`ERASE_MS`] with the sample task held off: the
/// acquisition's hardware runs on (its triggers), nothing is read.
struct ErasingFlash {
    page: FakeFlash,
    acq: Rc<RefCell<ModelAcq>>,
    /// The samples (blocks of one sample's conversions) the DMA completed while the erase
    /// held the reader off.
    halves_during_erase: u32,
}

impl RecordStore for ErasingFlash {
    type Error = FlashError;
    fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), FlashError> {
        self.page.read(page, buf)
    }
    fn erase(&mut self, page: RecordPage) -> Result<(), FlashError> {
        let mut acq = self.acq.borrow_mut();
        let triggers = ERASE_MS * u64::from(trigger_rate_hz(super::FS)) / 1_000;
        for _ in 0..triggers {
            acq.regs.trigger();
        }
        self.halves_during_erase = acq.regs.dma[0].halves;
        self.page.erase(page)
    }
    fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), FlashError> {
        self.page.write(page, bytes)
    }
}

/// The sample task's pause on the model.
struct Pause(Rc<RefCell<ModelAcq>>);

impl AcquisitionPause for Pause {
    fn pause(&mut self) -> bool {
        drive_monitor::recovery::pause(&mut *self.0.borrow_mut()).is_ok()
    }
    fn resume(&mut self) {
        drive_monitor::recovery::resume(&mut *self.0.borrow_mut());
    }
}

/// Stores a record through `carry_out` with `pause`; the halves the DMA completed while the
/// erase held the reader off, and the acquisition after it.
fn store(pause: &mut impl AcquisitionPause, acq: &Rc<RefCell<ModelAcq>>) -> u32 {
    for _ in 0..10 {
        assert!(acq.borrow_mut().regs.sample());
    }
    let mut flash = ErasingFlash {
        page: FakeFlash::erased(),
        acq: acq.clone(),
        halves_during_erase: 0,
    };
    let action = Action::Store {
        run: 1,
        record: old_record(),
    };
    let (_, stored) = carry_out(action, &mut flash, pause);
    assert!(stored.is_some_and(|s| s.read_back == Some(old_record())));
    flash.halves_during_erase
}

#[test]
fn the_flash_store_pauses_the_acquisition_so_the_erase_laps_nothing() {
    let acq = Rc::new(RefCell::new(AdcDmaModel::running()));
    let halves = store(&mut Pause(acq.clone()), &acq);
    let after = &mut *acq.borrow_mut();
    // Paused: no conversion, no transfer while the flash was busy.
    assert_eq!(halves, 0);
    assert!(
        after.regs.violations.is_empty(),
        "{:?}",
        after.regs.violations
    );
    // Resumed from the rings' starts: every sample in place.
    let delivered = (0..100).filter(|_| after.regs.sample()).count();
    assert!(delivered >= 99, "{delivered}");
    assert_eq!(after.regs.misaligned_halves, 0);
    assert_eq!(after.regs.unpaired_samples, 0);
}

/// The control: the same store without the pause. 22 ms are 1 760 triggers, 220 samples
/// against a ring of six (two halves of three): lapped 36 times over.
#[test]
fn without_the_pause_the_erase_laps_the_ring() {
    let acq = Rc::new(RefCell::new(AdcDmaModel::running()));
    let samples = store(&mut NoPause, &acq);
    let ring = 2 * drive_monitor::acquisition::SAMPLES_PER_HALF as u32;
    assert!(samples > ring, "{samples} samples: no lap");
    assert_eq!(samples, 220);
}
