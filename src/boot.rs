//! The firmware's boot composition, hardware-free: the motor record → the machine in force
//! → its sample path, isolator and encoder set-up; the commissioning record → the
//! thresholds and the isolation baseline; the supervisor thread mode runs.
//!
//! The firmware (`src/firmware.rs`) reads the two flash pages and hands the motor page's
//! bytes and the commissioning store to [`boot`], then logs what [`Booted`] says
//! (`firmware/logs.rs`) and starts the sample task with [`Booted::path`] and the encoder
//! with [`BootMachine::encoder`]. The host's software-in-the-loop rig (`tests/sil/`) boots
//! through the same function, so every SIL test runs this composition.
//!
//! Every failure has one defined fallback, and [`Booted`] says which was taken:
//!
//! | what failed | fallback | said by |
//! |---|---|---|
//! | the motor record: erased page, bad CRC, truncated, another version, values the core rejects | the built-in default machine ([`motor_source::default_record`]) | [`BootMachine::source`] ([`MachineSource::describe`]); the panel's default-motor mark |
//! | a valid record's machine at the firmware's sample rate ([`SamplePath::new`]) | the built-in default machine | [`MachineSource::Default`] with [`RecordError::Invalid`] |
//! | the isolation of the record's machine ([`Isolator::new`]) | the record's machine monitored by the lamps, nothing isolated (the blink code is the lamps' top candidate, the status line says `iso=not-judged`) | [`BootMachine::isolation`] |
//! | the commissioning record: unreadable, invalid, refused by the core | not commissioned (the default thresholds) | [`Booted::calibration`] |
//! | the built-in default at the firmware's sample rate | none: [`boot`] returns the error (the settings are constants a host test checks, so this cannot happen) | `Err` |

use crate::app::{AppError, Command, CommandError, SamplePath, Settings, Supervisor};
use crate::flash_record::{self, CalibrationRecord, LoadError, RecordStore};
use crate::motor_source::{self, EncoderSetup, MachineSource};
use crate::reset_record::PreviousRun;
use monitor_core::motor_record::{MotorRecord, RecordError};
use monitor_core::{ConfigError, Isolator};

/// The machine in force after boot and how its hardware is set up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BootMachine {
    /// The motor record in force: the flash page's, or [`motor_source::default_record`].
    pub record: MotorRecord,
    /// Where it came from (the boot log's line, the panel's default-motor mark).
    pub source: MachineSource,
    /// The encoder timer's set-up from [`BootMachine::record`] (counts, direction, filter,
    /// pull-ups: [`motor_source::encoder_setup`]).
    pub encoder: EncoderSetup,
    /// The six channels' linear ranges for the per-conversion clip check
    /// ([`motor_source::linear_ranges`]).
    pub ranges: crate::acquisition::LinearRanges,
    /// `Ok`: the fault isolation judges against this machine; `Err`: the core's isolation
    /// rejects it ([`Isolator::new`]'s check): the lamps still monitor it, nothing is
    /// isolated.
    pub isolation: Result<(), ConfigError>,
}

/// Why the commissioning record was not put into force at boot: "not commissioned", the
/// default thresholds monitor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CalibrationMissing<E> {
    /// The store could not be read.
    Read(E),
    /// The bytes are no valid record ([`RecordError::Erased`]: never commissioned).
    Record(RecordError),
    /// A valid record whose values the core refused ([`CommandError::Calibration`]).
    Refused(CommandError),
}

/// Everything [`boot`] built, and what it had to fall back to.
#[derive(Clone, Debug)]
pub struct Booted<E> {
    /// The machine in force and its hardware set-up.
    pub machine: BootMachine,
    /// The sample path for the sample task, the stored calibration in force when
    /// [`Booted::calibration`] is `Ok`.
    pub path: SamplePath,
    /// Thread mode's supervisor: the default-motor mark, the machine's isolator, the
    /// stored isolation baseline.
    pub supervisor: Supervisor,
    /// The commissioning record in force, or why there is none.
    pub calibration: Result<CalibrationRecord, CalibrationMissing<E>>,
    /// The record's isolation baseline was put into force (commissioned with a record that
    /// holds one, version 2 or later, and an isolator).
    pub baseline_restored: bool,
}

/// The machine of the motor record in `page` (the bytes read from its flash page; an
/// unreadable page is passed as erased, all `0xFF`) and its sample path at
/// `sample_rate_hz`, each failure replaced by its fallback (module docs); with the isolator
/// for the machine when the core accepts it.
///
/// # Errors
/// [`AppError`] only if the built-in default is rejected at `sample_rate_hz` (nothing can
/// be monitored then).
pub fn machine(
    page: &[u8],
    sample_rate_hz: u32,
) -> Result<(BootMachine, SamplePath, Option<Isolator>), AppError> {
    let (mut record, mut source) = motor_source::select(page);
    let path = match motor_source::sample_path(&record, sample_rate_hz) {
        Ok(path) => path,
        Err(_) => {
            // A record the core accepted as values but not at this sample rate.
            record = motor_source::default_record();
            source = MachineSource::Default(RecordError::Invalid);
            motor_source::sample_path(&record, sample_rate_hz)?
        }
    };
    let isolator = motor_source::isolator(&record);
    let machine = BootMachine {
        record,
        source,
        encoder: motor_source::encoder_setup(&record, sample_rate_hz),
        ranges: motor_source::linear_ranges(&record),
        isolation: isolator.map(|_| ()),
    };
    Ok((machine, path, isolator.ok()))
}

/// Puts the commissioning record in `store` into force in `path` (the core's
/// [`Command::SetCalibration`]).
///
/// # Errors
/// [`CalibrationMissing`]: the store unreadable, the record invalid or refused; `path`
/// keeps the default thresholds.
pub fn install_calibration<S: RecordStore>(
    store: &mut S,
    path: &mut SamplePath,
) -> Result<CalibrationRecord, CalibrationMissing<S::Error>> {
    let record = flash_record::load(store).map_err(|e| match e {
        LoadError::Read(e) => CalibrationMissing::Read(e),
        LoadError::Record(e) => CalibrationMissing::Record(e),
    })?;
    path.command(Command::SetCalibration(record))
        .map_err(CalibrationMissing::Refused)?;
    Ok(record)
}

/// The boot: the machine of the motor record in `motor_page` ([`machine`]), the
/// commissioning record in `store` put into force ([`install_calibration`]), and the
/// supervisor for `settings` at `now_ms` after `previous`, with the default-motor mark,
/// the machine's isolator and the record's isolation baseline. The firmware calls it once,
/// before the sample task starts.
///
/// # Errors
/// As [`machine`].
pub fn boot<S: RecordStore>(
    motor_page: &[u8],
    store: &mut S,
    settings: &Settings,
    previous: PreviousRun,
    now_ms: u32,
) -> Result<Booted<S::Error>, AppError> {
    let (machine, mut path, isolator) = self::machine(motor_page, settings.sample_rate_hz)?;
    let calibration = install_calibration(store, &mut path);
    let mut supervisor = Supervisor::new(settings, previous, now_ms, path.status());
    supervisor.set_default_motor(machine.source.is_default());
    supervisor.set_isolator(isolator);
    let baseline_restored = calibration
        .as_ref()
        .is_ok_and(|rec| supervisor.restore_isolation(rec));
    if let Ok(rec) = &calibration {
        supervisor.restore_reference(rec);
    }
    Ok(Booted {
        machine,
        path,
        supervisor,
        calibration,
        baseline_restored,
    })
}
