//! Thread mode's commands to the sample task: sent with a bounded wait, and the pause of the
//! acquisition around a flash store (`drive_monitor::app::AcquisitionPause`).

use defmt::{error, warn};
use drive_monitor::app::{AcquisitionPause, Command};
use embassy_time::{with_timeout, Duration, Instant};

use super::{COMMANDS, COMMAND_SEND_TIMEOUT_MS, PAUSED, PAUSE_WAIT_MS, RESUME};

/// Sends `cmd` to the sample task, waiting at most [`COMMAND_SEND_TIMEOUT_MS`] for a slot in
/// the queue (else the command is dropped and logged).
pub(super) async fn send(cmd: Command) {
    let sent = with_timeout(
        Duration::from_millis(COMMAND_SEND_TIMEOUT_MS),
        COMMANDS.send(cmd),
    )
    .await;
    if sent.is_err() {
        error!("command queue full: {=str} dropped", cmd.name());
    }
}

/// The sample task's pause around a flash erase and write (`app::AcquisitionPause`): the
/// command, then a bounded busy wait in thread mode for the sample task (which preempts
/// it) to say it paused; the resume by signal.
pub(super) struct SampleTaskPause;

impl AcquisitionPause for SampleTaskPause {
    fn pause(&mut self) -> bool {
        PAUSED.reset();
        // A resume left from a pause the sample task never took must not end this one.
        RESUME.reset();
        if COMMANDS.try_send(Command::PauseAcquisition).is_err() {
            error!("flash: command queue full, the acquisition not paused");
            return false;
        }
        let deadline = Instant::now() + Duration::from_millis(PAUSE_WAIT_MS);
        while Instant::now() < deadline {
            if let Some(paused) = PAUSED.try_take() {
                return paused;
            }
        }
        warn!(
            "flash: the sample task did not pause within {=u64} ms",
            PAUSE_WAIT_MS
        );
        false
    }

    fn resume(&mut self) {
        RESUME.signal(());
    }
}
