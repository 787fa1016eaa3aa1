//! One period of thread mode, written once: the firmware's `Thread` (`src/firmware.rs`)
//! and the host's software-in-the-loop rig (`tests/sil/`) both run [`period`] over their
//! [`ThreadHw`]: the offset trim's result and the reference's checks taken, the
//! supervisor's tick, the watchdog petted while samples flow, the run marked up, the reset
//! record written or cleared for a stall, the commissioning's action carried out (the
//! record stored with the acquisition paused around the erase and the write), the
//! reference's correction, the lamps. What is left for the caller: logging
//! [`PeriodOutput`]'s events and sending its commands to the sample task, in order.

use super::{carry_out, AcquisitionPause, Command, MonitorStatus, Supervisor, Tick};
use crate::board::ReferenceCheck;
use crate::flash_record::{RecordStore, Stored};
use crate::liveness::{LivenessChange, LONG_UP_AFTER_MS, UP_AFTER_MS};
use crate::offset_trim::TrimResult;
use crate::panel::PanelLamps;
use crate::reset_record::ResetRecord;
use crate::supply::{ReferenceAdc, ReferenceChange};

/// Thread mode's hardware (module docs): the firmware's on the board, the rig's models in
/// the host tests.
pub trait ThreadHw {
    /// The commissioning record's store (the flash pages behind the brown-out gate).
    type Store: RecordStore;
    /// The acquisition's pause around a store.
    type Pause: AcquisitionPause;
    /// VREFINT on ADC1's injected channel.
    type Reference: ReferenceAdc;
    /// Pets the watchdog.
    fn pet_watchdog(&mut self);
    /// The store and the pause, together (the store is carried out with the pause).
    fn store_and_pause(&mut self) -> (&mut Self::Store, &mut Self::Pause);
    /// The reference's ADC (`None`: none to poll).
    fn reference(&mut self) -> Option<&mut Self::Reference>;
    /// Shows `lamps` on the panel.
    fn show(&mut self, lamps: &PanelLamps);
    /// Writes the reset record (`None`: clears it).
    fn write_record(&mut self, record: Option<ResetRecord>);
    /// Marks the run up in the boot block (`long`: long up; `crate::boot_block`).
    fn mark_up(&mut self, long: bool);
}

/// What the sample task handed over since the last period, and the period's time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PeriodInput {
    /// The period's time since boot [ms].
    pub now_ms: u32,
    /// The sample task's latest status, if a new one came.
    pub status: Option<MonitorStatus>,
    /// The button was pressed since the last period.
    pub pressed: bool,
    /// The offset trim's result, if one came.
    pub trim: Option<TrimResult>,
    /// The start-up check of the reference, if it came.
    pub reference: Option<ReferenceCheck>,
}

/// What one period did, for the caller to log and to send (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeriodOutput<E> {
    /// The supervisor's tick (the lamps shown, the liveness change, the run that ended, the
    /// range state's change).
    pub tick: Tick,
    /// The commands for the sample task, in the order they are to be sent.
    pub commands: [Option<Command>; 2],
    /// The commissioning record's store, when the tick's action was one.
    pub stored: Option<Stored<E>>,
    /// The offset trim's result taken (to log).
    pub trim: Option<TrimResult>,
    /// The reference's verdict changes (the start-up check's, then the periodic one's).
    pub reference_changes: [Option<ReferenceChange>; 2],
    /// The run was marked up (`Some(false)`) or long up (`Some(true)`) in this period.
    pub marked_up: Option<bool>,
    /// The status line is due (every second period: 100 ms).
    pub status_line: bool,
}

/// Thread mode's state across periods (beside the supervisor).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ThreadState {
    log_div: u32,
    /// Since when samples have flowed with the watchdog petted [ms].
    flowing_since_ms: Option<u32>,
    /// 0: not up yet; 1: marked up; 2: marked long up.
    marked: u8,
}

/// One period (module docs) at `input.now_ms`.
pub fn period<H: ThreadHw>(
    supervisor: &mut Supervisor,
    state: &mut ThreadState,
    input: PeriodInput,
    hw: &mut H,
) -> PeriodOutput<<H::Store as RecordStore>::Error> {
    let now_ms = input.now_ms;
    if let Some(trim) = &input.trim {
        supervisor.set_offset_fault(trim);
    }
    let start_up = input
        .reference
        .and_then(|check| supervisor.observe_reference(check, now_ms));
    let polled = hw
        .reference()
        .and_then(|adc| supervisor.poll_reference(now_ms, adc));
    let tick = supervisor.tick(now_ms, input.status, input.pressed);
    let marked_up = watch_up(state, &tick, now_ms, hw);
    match tick.liveness {
        Some(LivenessChange::RecordStall { for_ms }) => {
            hw.write_record(Some(ResetRecord::sample_stall(for_ms)));
        }
        Some(LivenessChange::Recovered { .. }) => hw.write_record(None),
        _ => {}
    }
    let (store, pause) = hw.store_and_pause();
    let (command, stored) = carry_out(tick.action, store, pause);
    let gain = tick.reference_gain.map(Command::ReferenceGain);
    hw.show(&tick.lamps);
    state.log_div += 1;
    let status_line = state.log_div >= 2;
    if status_line {
        state.log_div = 0;
    }
    PeriodOutput {
        tick,
        commands: [command, gain],
        stored,
        trim: input.trim,
        reference_changes: [start_up, polled],
        marked_up,
        status_line,
    }
}

/// The watchdog petted while samples flow (the tick says), and the run marked up after
/// [`UP_AFTER_MS`] and long up after [`LONG_UP_AFTER_MS`] of it; returns a mark made now.
fn watch_up<H: ThreadHw>(
    state: &mut ThreadState,
    tick: &Tick,
    now_ms: u32,
    hw: &mut H,
) -> Option<bool> {
    if !tick.pet_watchdog {
        state.flowing_since_ms = None;
        return None;
    }
    hw.pet_watchdog();
    let since = *state.flowing_since_ms.get_or_insert(now_ms);
    let flowing = now_ms.wrapping_sub(since);
    let due = if flowing >= LONG_UP_AFTER_MS {
        2
    } else if flowing >= UP_AFTER_MS {
        1
    } else {
        0
    };
    if due > state.marked {
        state.marked = due;
        let long = due == 2;
        hw.mark_up(long);
        return Some(long);
    }
    None
}
