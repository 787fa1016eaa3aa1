//! Thread mode's hardware on the rig: what `app::period` runs on in the host tests.

use super::{startup, FakeFlash, ModelPause};
use drive_monitor::app::ThreadHw;
use drive_monitor::reset_record::{ResetRecord, RESET_RECORD_LEN};

/// Thread mode's hardware on the rig (`app::ThreadHw`): the survivors' flash and reset
/// record, the acquisition's pause on the register model, the watchdog's last pet, the
/// reference when the test gives one.
pub(crate) struct RigThread<'a> {
    pub(crate) now_ms: u32,
    pub(crate) flash: &'a mut FakeFlash,
    pub(crate) reset_ram: &'a mut [u8; RESET_RECORD_LEN],
    pub(crate) pause: ModelPause<'a>,
    pub(crate) reference: Option<&'a mut startup::FakeReference>,
    pub(crate) last_pet_ms: &'a mut u32,
    pub(crate) marked_up: &'a mut Vec<bool>,
}

impl<'a> ThreadHw for RigThread<'a> {
    type Store = FakeFlash;
    type Pause = ModelPause<'a>;
    type Reference = startup::FakeReference;
    fn pet_watchdog(&mut self) {
        *self.last_pet_ms = self.now_ms;
    }
    fn store_and_pause(&mut self) -> (&mut FakeFlash, &mut ModelPause<'a>) {
        (&mut *self.flash, &mut self.pause)
    }
    fn reference(&mut self) -> Option<&mut startup::FakeReference> {
        self.reference.as_deref_mut()
    }
    fn show(&mut self, _lamps: &drive_monitor::panel::PanelLamps) {}
    fn write_record(&mut self, record: Option<ResetRecord>) {
        *self.reset_ram = record.map_or([0; RESET_RECORD_LEN], |r| r.encode());
    }
    fn mark_up(&mut self, long: bool) {
        self.marked_up.push(long);
    }
}
