//! The firmware's log lines for events, each spelled from a typed value of the library:
//! what the start found (`drive_monitor::startup::BootNote`: the clock, why the previous
//! run ended, the stack, the self-check's findings, the brown-out level, the safe mode),
//! what the boot put into force, and what thread mode's period did
//! (`drive_monitor::app::PeriodOutput`: the offset trim, the reference, liveness changes,
//! the commissioning's ends and store, the range state). The status line is `log_status`
//! in `src/firmware.rs`.

use core::sync::atomic::Ordering;

use defmt::{error, info, warn};
use drive_monitor::app::PeriodOutput;
use drive_monitor::board::{ReferenceCheck, VDDA_BAND_V};
use drive_monitor::boot::{Booted, CalibrationMissing};
use drive_monitor::clip_watch::RangeChange;
use drive_monitor::clock::ClockSource;
use drive_monitor::commissioning::RunEnd;
use drive_monitor::flash_record::{self, StoreError};
use drive_monitor::liveness::LivenessChange;
use drive_monitor::offset_trim::{
    ChannelTrim, TrimKind, TrimResult, MAX_OFFSET_CODES, RETRIM_STEP_CODES,
};
use drive_monitor::reset_record::{log, PreviousRun, ResetCause, ResetRecord, ResetSource};
use drive_monitor::self_check::CheckId;
use drive_monitor::startup::{BootFacts, BootNote, SafeModeReason};
use drive_monitor::supply::{BorCheck, ReferenceChange, BOR_GOAL};

use super::flash::FlashError;
use super::RESTARTS;

/// The boot's brown-out check: the level in force, and below [`BOR_GOAL`] how to raise it
/// (docs/firmware.md, "Brown-out level"); the firmware does not write the option bytes.
fn log_bor(check: BorCheck) {
    match check {
        BorCheck::AtGoal(l) => info!(
            "brown-out reset level {=u8} (about {=f32} V)",
            l.number(),
            l.falling_v()
        ),
        BorCheck::BelowGoal(l) => warn!(
            "brown-out reset level {=u8} (about {=f32} V) is below level {=u8} ({=f32} V): the MCU runs on at a supply far below 3.3 V, and flash records are refused (a sag during an erase or a write would tear them); program it once for this board: cargo fw bor (docs/firmware.md, bring-up)",
            l.number(),
            l.falling_v(),
            BOR_GOAL.number(),
            BOR_GOAL.falling_v()
        ),
        BorCheck::Reserved(v) => warn!(
            "brown-out reset level: FLASH_OPTR.BOR_LEV holds the reserved value {=u8}; flash records are refused",
            v
        ),
    }
}

/// What the start found (`BootFacts::notes`), in order.
pub(super) fn log_facts(facts: &BootFacts) {
    for note in facts.notes() {
        match note {
            BootNote::Clock(Some(source)) => log_clock(source),
            BootNote::Clock(None) => {
                warn!("clock: the 16 MHz reset clock (HSI, no PLL): safe mode")
            }
            BootNote::PreviousRun(source, previous) => log_previous_run(previous, source),
            BootNote::StackOverflowed => log_stack(),
            BootNote::FailedBoots(n) => warn!(
                "{=u8} boots in a row failed before the monitor was up (the safe mode after {=u8})",
                n,
                drive_monitor::boot_block::SAFE_MODE_AFTER
            ),
            BootNote::Mismatch(id) => log_mismatch(id),
            BootNote::BrownOut(check) => log_bor(check),
            BootNote::SafeMode(reason) => log_safe_mode(reason),
        }
    }
    if facts.findings.crystal_did_not_start() {
        warn!("self-check: the crystal did not start within its bound");
    }
    if facts.findings.pll_did_not_lock() {
        error!("self-check: the PLL did not lock from the crystal: running on the HSI");
    }
}

/// A register that did not hold what the firmware wrote (the self-check).
pub(super) fn log_mismatch(id: CheckId) {
    error!(
        "self-check: {=str} does not hold what the firmware wrote or expects (docs/firmware.md, \"The self-check\")",
        id.name()
    );
}

/// The safe mode's reason.
fn log_safe_mode(reason: SafeModeReason) {
    match reason {
        SafeModeReason::BootLoop { failed_boots } => error!(
            "SAFE MODE: {=u8} boots in a row failed before the monitor was up; not monitoring. The FAULT lamp blinks code {=u8}; press the reset button to try again",
            failed_boots,
            reason.code()
        ),
        SafeModeReason::PllDidNotLock => error!(
            "SAFE MODE: the PLL locked neither from the crystal nor from the HSI; not monitoring. The FAULT lamp blinks code {=u8}",
            reason.code()
        ),
    }
}

/// The clock's source (`drive_monitor::clock::ClockSource`) and the time base's error it
/// implies.
fn log_clock(source: ClockSource) {
    match source {
        ClockSource::Hse => info!(
            "clock: {=str}, time base within +-{=u32} ppm",
            source.name(),
            source.error_ppm()
        ),
        ClockSource::Hsi | ClockSource::HsiAfterFailure => warn!(
            "clock: {=str}; frequencies, speeds and time constants are known to +-{=u32} ppm only (the RUN lamp's steady 2 s from 5 s of every 10 s)",
            source.name(),
            source.error_ppm()
        ),
    }
}

/// A change of the reference's verdict (`Supervisor::observe_reference`,
/// `Supervisor::poll_reference`): why the sensors are flagged, or that they are not any more.
fn log_reference(change: ReferenceChange) {
    match change {
        ReferenceChange::Flagged(ReferenceCheck::OutOfBand(v)) => error!(
            "reference: VDDA {=f32} V outside {=f32}..{=f32} V: every reading is off by that ratio; the sensors are flagged until it returns",
            v,
            VDDA_BAND_V.0,
            VDDA_BAND_V.1
        ),
        ReferenceChange::Flagged(_) => {
            error!("reference: VREFINT unreadable; the sensors are flagged until a reading is in band")
        }
        ReferenceChange::Cleared(v) => warn!(
            "reference: VDDA {=f32} V back in band: the sensor flags it set are cleared",
            v
        ),
    }
}

/// The previous run's end (`drive_monitor::startup`) in the log.
fn log_previous_run(previous: PreviousRun, source: ResetSource) {
    info!("reset by {=str}", source.name());
    match previous {
        PreviousRun::Clean => {}
        PreviousRun::WatchdogReset { phase: None } => {
            error!("previous run ended in a watchdog reset with no reason recorded: the firmware hung")
        }
        PreviousRun::WatchdogReset { phase: Some(p) } => error!(
            "previous run ended in a watchdog reset with no reason recorded: the firmware hung in its {=str} phase",
            p.name()
        ),
        PreviousRun::ResetDuring { record, source } => warn!(
            "previous run: {=str} recorded ({=u32}), then a {=str} reset came before the watchdog's",
            record.message(),
            record.line_or_ms(),
            source.name()
        ),
        PreviousRun::Recorded(rec) => log_record(&rec),
    }
}

fn log_record(rec: &ResetRecord) {
    match rec.cause() {
        ResetCause::Panic => error!(
            "previous run ended in a panic: {=str} at {=str}:{=u32}",
            rec.message(),
            rec.file(),
            rec.line_or_ms()
        ),
        ResetCause::DefmtPanic => error!(
            "previous run ended in a defmt panic during {=str}, called from {=u32:#010x} (addr2line -e the ELF; the message is in that run's log)",
            rec.message(),
            rec.line_or_ms()
        ),
        ResetCause::SetupTimeout => error!(
            "previous run ended in a watchdog reset: the {=str} set-up did not finish",
            rec.message()
        ),
        ResetCause::HardFault => error!(
            "previous run ended in a {=str} at pc {=u32:#010x}: {=str} (addr2line -e the ELF)",
            rec.file(),
            rec.line_or_ms(),
            rec.message()
        ),
        ResetCause::SetupDeadline => error!(
            "previous run ended in a software reset: the adc set-up step {=str} did not finish within {=u32} ms",
            rec.message(),
            rec.line_or_ms()
        ),
        ResetCause::SampleStall => error!(
            "previous run ended in a watchdog reset: the sample path had stalled (no samples for {=u32} ms when recorded; recoveries did not help)",
            rec.line_or_ms()
        ),
        ResetCause::ClockFailure => error!(
            "previous run ended in a clock failure: the crystal stopped and the clock security system switched to the HSI; running on the HSI (+-1 %), the crystal not tried again until the next reset"
        ),
    }
}

/// What the boot composition (`drive_monitor::boot::boot`) put into force and each fallback
/// it took: the machine's source, the isolation, the commissioning record.
pub(super) fn log_boot<E: defmt::Format>(booted: &Booted<E>) {
    info!("{=str}", booted.machine.source.describe());
    if booted.machine.isolation.is_err() {
        warn!("the fault isolation rejects this machine: isolation off, the lamps monitor it (blink code: their top candidate)");
    }
    match &booted.calibration {
        Ok(_) => info!("commissioned: record loaded"),
        Err(CalibrationMissing::Read(e)) => warn!("flash read failed: {}: not commissioned", e),
        Err(CalibrationMissing::Record(e)) => {
            warn!("no valid commissioning record: {=str}", e.describe())
        }
        Err(CalibrationMissing::Refused(_)) => {
            warn!("stored calibration out of the core's range: not commissioned")
        }
    }
    if booted.baseline_restored {
        info!("isolation baseline restored from the record");
    }
}

/// What one thread-mode period did (`drive_monitor::app::period`), in the log.
pub(super) fn log_period(out: &PeriodOutput<FlashError>) {
    if let Some(trim) = &out.trim {
        log_trim(trim);
    }
    for change in out.reference_changes.into_iter().flatten() {
        log_reference(change);
    }
    if let Some(change) = out.tick.liveness {
        on_liveness(change);
    }
    if let Some(end) = out.tick.run_ended {
        log_run_end(end);
    }
    if let Some(change) = out.tick.clip_range {
        log_clip_range(change);
    }
    if let Some(stored) = &out.stored {
        log_stored(stored);
    }
    if let Some(gain) = out.tick.reference_gain {
        log_reference_gain(gain);
    }
    match out.marked_up {
        Some(false) => info!(
            "up: samples flowed for {=u32} s: the failed boots in a row end",
            drive_monitor::boot_block::UP_AFTER_MS / 1_000
        ),
        Some(true) => info!("up for 10 minutes: the reset log's entries are given back"),
        None => {}
    }
}

fn on_liveness(change: LivenessChange) {
    match change {
        LivenessChange::Stalled { for_ms } => error!(
            "SAMPLE PATH STALLED: no samples for {=u32} ms (restarts so far {=u32}); watchdog not petted",
            for_ms,
            RESTARTS.load(Ordering::Relaxed)
        ),
        LivenessChange::RecordStall { .. } => {}
        LivenessChange::Recovered { after_ms } => {
            warn!("sample path recovered after {=u32} ms", after_ms);
        }
    }
}

/// The offset trim, channel by channel (`drive_monitor::offset_trim`): the start-up trim,
/// or a re-trim at standstill that moved a zero.
fn log_trim(trim: &TrimResult) {
    if trim.kind == TrimKind::Retrim {
        info!("offset re-trim: the shaft stands, the currents are zero");
    }
    let names = ["va", "vb", "vc", "ia", "ib", "ic"];
    let channels = trim.voltage.iter().chain(trim.current.iter());
    for (name, channel) in names.into_iter().zip(channels) {
        match *channel {
            ChannelTrim::Trimmed(code) => info!("offset trim {=str}: zero at {=f32} codes, in force", name, code),
            ChannelTrim::OutOfBound(code) => error!(
                "offset trim {=str}: zero at {=f32} codes, beyond +-{=f32} of the zero in force: sensor flagged, not used",
                name,
                code,
                MAX_OFFSET_CODES
            ),
            ChannelTrim::NotQuiet(spread) => info!(
                "offset trim {=str}: not quiet (spread {=f32} codes; motor running or supply on): not trimmed",
                name,
                spread
            ),
            ChannelTrim::TooFar(code) => warn!(
                "offset re-trim {=str}: zero at {=f32} codes, more than {=f32} from the zero in force: not used",
                name,
                code,
                RETRIM_STEP_CODES
            ),
        }
    }
}

fn log_run_end(end: RunEnd) {
    match end {
        RunEnd::Commissioned { run } => info!("commissioning run {=u16}: stored and in force", run),
        RunEnd::CancelledByUser { run } => info!("commissioning run {=u16}: cancelled", run),
        RunEnd::Failed { run, why } => error!(
            "commissioning run {}: FAILED ({=str}); the thresholds in force are unchanged or the flash's",
            run,
            why.name()
        ),
    }
}

fn log_stored<E: defmt::Format>(stored: &flash_record::Stored<E>) {
    match &stored.written {
        Ok(()) => info!(
            "commissioning record written, read back: {}",
            stored.read_back.is_some()
        ),
        Err(StoreError::Encode(e)) => {
            error!("commissioning record not written: {=str}", e.describe())
        }
        Err(StoreError::Erase(e)) => error!("flash erase failed: {}", e),
        Err(StoreError::Write(e)) => error!("flash write failed: {}", e),
    }
}

/// The stack: an overflow in the previous run (its guard words written; the previous run
/// then ended in a fault or a lock-up).
fn log_stack() {
    error!("previous run: the stack reached the bottom of RAM (a stack overflow; flip-link made it fault instead of overwriting the statics)");
}

/// What the boot wrote to the reset log (`log::record_boot`), or why not.
pub(super) fn log_reset_log(written: Result<log::Written, FlashError>) {
    match written {
        Ok(log::Written::Entry(seq)) => info!("reset log: entry #{=u32} written to flash", seq),
        Ok(log::Written::Counted { failed: true }) => warn!(
            "reset log: the failed run counted, not entered ({=u32} entries between two runs up for 10 minutes: the log's rate limit)",
            log::FULL_ENTRIES
        ),
        Ok(log::Written::Counted { failed: false }) => {}
        Ok(log::Written::Pending { failed }) => info!(
            "reset log: counted in RAM (failed run {=bool}), written with the next {=u32} or after a run that is up",
            failed,
            log::FLUSH_AFTER
        ),
        Err(e) => warn!("reset log: not written: {}", e),
    }
}

/// A new correction of the readings for the ADC's reference (VDDA now over VDDA at
/// commissioning, `drive_monitor::supply::ReferenceGain`).
fn log_reference_gain(gain: f32) {
    info!(
        "reference: readings corrected by {=f32} (VDDA now over VDDA at commissioning)",
        gain
    );
}

/// The range state changed (`drive_monitor::clip_watch`): clipping persists in steady
/// running (the front end's linear range too small for this motor: the verdict could not
/// judge, the panel's range mark), or no longer; the front ends that clipped in the window
/// that decided it and its share of clipped samples.
fn log_clip_range(change: RangeChange) {
    if change.too_small {
        warn!(
            "clip: {=u32} per mille of the samples clipped in steady running for 6 s (voltage {=bool}, current {=bool}): the front end's linear range is too small for this motor, not judged",
            change.permille,
            change.voltage,
            change.current
        );
    } else {
        info!("clip: steady running without clipping for 6 s: judged again");
    }
}
