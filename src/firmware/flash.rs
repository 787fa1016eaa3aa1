//! The record pages in the board's flash: the embassy driver ([`Driver`], `None` with
//! single-bank option bytes) behind `drive_monitor::flash_ecc::CheckedFlash`, so that
//! every read of a record page is checked for an ECC double error (the NMI handler in
//! `failure.rs` latches it in `failure::ECC`) and a bad page falls back.

use defmt::warn;
use drive_monitor::board;
use drive_monitor::flash_ecc::{CheckedFlash, RawFlash, ReadError};
use drive_monitor::flash_record::{RecordPage, RecordStore, RECORD_LEN};
use drive_monitor::supply::{BorCheck, FromBorRefusal};
use embassy_stm32::flash::{Blocking, Flash};
use monitor_core::motor_record::STORED_LEN as MOTOR_RECORD_LEN;

use super::failure;

/// Why the board's flash could not be used.
#[derive(defmt::Format)]
pub(super) enum FlashError {
    /// The option bytes select single-bank flash (the records' pages need dual-bank).
    SingleBank,
    /// The flash driver's error.
    Driver(embassy_stm32::flash::Error),
    /// A double ECC error in the page (a torn write): the page is marked bad for this run.
    Ecc {
        /// The failing offset from 0x0800_0000.
        offset: u32,
    },
    /// The page was marked bad earlier in this run.
    MarkedBad,
    /// Erases and writes are refused: the brown-out level (`BOR_LEV`, 255: reserved) is
    /// below the goal (`drive_monitor::supply::BorGate`; `cargo fw bor`).
    BrownOutLevel(u8),
}

impl FromBorRefusal for FlashError {
    fn bor_refused(check: BorCheck) -> Self {
        FlashError::BrownOutLevel(check.status_number())
    }
}

/// The flash driver (`None`: the option bytes are single-bank).
pub(super) struct Driver(pub(super) Option<Flash<'static, Blocking>>);

impl Driver {
    fn get(&mut self) -> Result<&mut Flash<'static, Blocking>, FlashError> {
        self.0.as_mut().ok_or(FlashError::SingleBank)
    }
}

impl RawFlash for Driver {
    type Error = FlashError;
    fn read_raw(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.get()?
            .blocking_read(offset, buf)
            .map_err(FlashError::Driver)
    }
}

/// The record pages in the board's flash, every read checked for ECC double errors
/// (`drive_monitor::flash_ecc`: the NMI handler latches them in `failure::ECC`).
pub(super) struct BoardFlash(pub(super) CheckedFlash<Driver>);

/// A checked read's error as the firmware logs it.
fn flash_error(e: ReadError<FlashError>) -> FlashError {
    match e {
        ReadError::Driver(e) => e,
        ReadError::Ecc(e) => FlashError::Ecc { offset: e.offset },
        ReadError::MarkedBad => FlashError::MarkedBad,
    }
}

impl BoardFlash {
    fn read_at(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        self.0.read(&failure::ECC, offset, buf).map_err(flash_error)
    }
}

/// A commissioning record page's offset from the start of flash.
fn record_offset(page: RecordPage) -> u32 {
    match page {
        RecordPage::A => board::RECORD_FLASH_OFFSET,
        RecordPage::B => board::RECORD_B_FLASH_OFFSET,
    }
}

impl RecordStore for BoardFlash {
    type Error = FlashError;
    fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), Self::Error> {
        self.read_at(record_offset(page), buf)
    }
    fn erase(&mut self, page: RecordPage) -> Result<(), Self::Error> {
        let from = record_offset(page);
        self.0
            .raw
            .get()?
            .blocking_erase(from, from + board::RECORD_PAGE_SIZE)
            .map_err(FlashError::Driver)?;
        self.0.erased(from);
        Ok(())
    }
    fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), Self::Error> {
        self.0
            .raw
            .get()?
            .blocking_write(record_offset(page), bytes)
            .map_err(FlashError::Driver)
    }
}

/// The motor record's page (`board::MOTOR_RECORD_FLASH_OFFSET`), read as erased when the
/// flash cannot be read or the read raised an ECC double error (the page is then marked
/// bad; the reason is logged): `drive_monitor::boot` then runs the built-in default.
pub(super) fn read_motor_page(flash: &mut BoardFlash) -> [u8; MOTOR_RECORD_LEN] {
    let (page, read) = flash
        .0
        .read_or_erased::<MOTOR_RECORD_LEN>(&failure::ECC, board::MOTOR_RECORD_FLASH_OFFSET);
    if let Err(e) = read {
        warn!("motor record page unreadable: {}; running the built-in motor (write the record again: docs/firmware.md)", flash_error(e));
    }
    page
}

/// The reset log's pages (`drive_monitor::reset_record::log`) in bank 2 from
/// `board::RESET_LOG_FLASH_OFFSET`: reads checked for ECC double errors, erases and writes
/// refused below the brown-out goal (as the records'; the boot appends before sampling
/// starts, so nothing is running that an erase could hold up).
pub(super) struct LogPages<'a> {
    pub(super) flash: &'a mut BoardFlash,
    pub(super) bor: BorCheck,
}

impl LogPages<'_> {
    fn offset(page: usize, offset: usize) -> u32 {
        board::RESET_LOG_FLASH_OFFSET + page as u32 * board::RECORD_PAGE_SIZE + offset as u32
    }
}

impl drive_monitor::reset_record::log::LogFlash for LogPages<'_> {
    type Error = FlashError;
    fn read(&mut self, page: usize, offset: usize, buf: &mut [u8]) -> Result<(), FlashError> {
        self.flash
            .0
            .read_unmarked(&failure::ECC, Self::offset(page, offset), buf)
            .map_err(flash_error)
    }
    fn erase(&mut self, page: usize) -> Result<(), FlashError> {
        if !self.bor.allows_flash_writes() {
            return Err(FlashError::bor_refused(self.bor));
        }
        let from = Self::offset(page, 0);
        self.flash
            .0
            .raw
            .get()?
            .blocking_erase(from, from + board::RECORD_PAGE_SIZE)
            .map_err(FlashError::Driver)?;
        self.flash.0.erased(from);
        Ok(())
    }
    fn write(&mut self, page: usize, offset: usize, bytes: &[u8]) -> Result<(), FlashError> {
        if !self.bor.allows_flash_writes() {
            return Err(FlashError::bor_refused(self.bor));
        }
        self.flash
            .0
            .raw
            .get()?
            .blocking_write(Self::offset(page, offset), bytes)
            .map_err(FlashError::Driver)
    }
}
