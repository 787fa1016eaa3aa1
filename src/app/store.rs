//! Thread mode's commissioning actions carried out: the record stored in flash, with the
//! acquisition paused around the erase and the write, and the command for the sample task.

use super::Command;
use crate::commissioning::Action;
use crate::flash_record::{self, RecordStore, Stored};

/// The acquisition stopped and started again around a flash erase and write (on the board
/// a command to the sample task, which runs `recovery::pause` and, when told,
/// `recovery::resume`; in the host tests the register model's).
///
/// Why: a page erase keeps the flash busy for about 22 ms. Embassy-stm32 0.6's
/// `Flash::blocking_erase` waits for it with interrupts enabled and the code runs from bank
/// 1 while the records are in bank 2 (read-while-write), so the sample task goes on; but
/// the HAL's region API erases inside a critical section (`erase_sector_with_critical_
/// section`: 22 ms with interrupts masked, 130 sample periods against a ring of six), and
/// code placed in bank 2, or single-bank option bytes, would stall every fetch for the
/// erase. With the acquisition paused nothing converts and nothing moves, so however the
/// erase runs, nothing laps: the monitor sees a gap of the erase's length in its samples
/// (bridged by the core up to 100 ms).
pub trait AcquisitionPause {
    /// Stops the acquisition; `false` when it did not stop (the erase goes on: with the
    /// HAL's blocking erase and the code in bank 1 the sample task still runs).
    fn pause(&mut self) -> bool;
    /// Starts it again.
    fn resume(&mut self);
}

/// No acquisition to pause (a store before sampling starts, a test without one).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoPause;

impl AcquisitionPause for NoPause {
    fn pause(&mut self) -> bool {
        true
    }
    fn resume(&mut self) {}
}

/// Carries out a commissioning [`Action`]: the command for the sample task, after storing
/// the calibration in `store` for [`Action::Store`] (erase, write, read back: the command
/// reports what the store holds, whatever failed), with the acquisition paused by `pause`
/// from before the erase to after the read-back ([`AcquisitionPause`]). Also returns the
/// storage result.
pub fn carry_out<S: RecordStore>(
    action: Action,
    store: &mut S,
    pause: &mut impl AcquisitionPause,
) -> (Option<Command>, Option<Stored<S::Error>>) {
    match action {
        Action::None => (None, None),
        Action::Start { duration_s } => (Some(Command::StartCommissioning { duration_s }), None),
        Action::Cancel { run } => (Some(Command::CancelCommissioning { run }), None),
        Action::Store { run, record } => {
            pause.pause();
            let stored = flash_record::store(store, &record);
            pause.resume();
            (
                Some(Command::CalibrationStored {
                    run,
                    stored: stored.read_back,
                }),
                Some(stored),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With no acquisition nothing runs that a flash erase could stall: the pause holds
    /// (`true`: the trait's "stopped"), and resuming is a no-op.
    #[test]
    fn with_no_acquisition_the_pause_always_holds() {
        let mut none = NoPause;
        assert!(none.pause());
        none.resume();
        assert!(none.pause());
    }
}
