//! The record pages' ECC errors: a torn flash write must not loop the boot.
//!
//! The STM32G474's flash keeps an ECC over every 64-bit double word (RM0440, "Error code
//! correction (ECC)"). A write that a reset or a power loss cut short can leave a double
//! word whose ECC does not match: reading it is a **double error**, `ECCD` in
//! `FLASH_ECCR` with the failing address, and an NMI. Without a handler of its own the NMI
//! went to the default handler, which records and resets, and the next boot read the page
//! again: a boot loop.
//!
//! The firmware's NMI handler asks [`nmi_action`]: a double error in one of the record
//! pages (the motor record, the commissioning record) is latched ([`EccLatch`]),
//! `ECCD` is cleared and the handler returns, so the read completes (with wrong data);
//! a clock failure seen by the clock security system (`RCC_CIFR.CSSF`) is recorded and
//! resets onto the internal oscillator ([`nmi_cause`]); any other NMI (a double error in
//! the code) goes to the fault path. Every read of a record page goes through [`CheckedFlash`]: it clears the
//! latch before the read and looks at it after; a double error makes the read fail
//! ([`ReadError::Ecc`]) and **marks the page bad** for the rest of the run, so it is not
//! read again; an erase (the next commissioning's store) clears the mark. The boot then
//! falls back: the built-in motor for the motor record's page, "not commissioned" for the
//! commissioning record's, and runs.

use core::sync::atomic::{AtomicU32, Ordering};

use crate::board::{RECORD_FLASH_OFFSET, RECORD_PAGE_SIZE, RESET_LOG_FLASH_OFFSET};

/// `FLASH_ECCR.ECCD`: an ECC double error (write 1 to clear).
pub const ECCR_ECCD: u32 = 1 << 31;
/// `FLASH_ECCR.BK_ECC`: the error is in bank 2.
pub const ECCR_BK_ECC: u32 = 1 << 21;
/// `FLASH_ECCR.SYSF_ECC`: the error is in the system flash.
pub const ECCR_SYSF_ECC: u32 = 1 << 22;
/// `FLASH_ECCR.ADDR_ECC`: the failing address within its bank.
pub const ECCR_ADDR_MASK: u32 = 0x0007_FFFF;
/// A bank's size in dual-bank mode (512 KiB device): bank 2 starts at this offset.
pub const BANK_SIZE: u32 = 256 * 1024;

/// The first flash offset of the record pages (the reset log's first page, below the
/// commissioning record's second page and the motor record's).
pub const RECORD_PAGES_START: u32 = RESET_LOG_FLASH_OFFSET;
/// One past the last flash offset of the record pages.
pub const RECORD_PAGES_END: u32 = RECORD_FLASH_OFFSET + RECORD_PAGE_SIZE;

/// A double ECC error: the failing flash offset from 0x0800_0000.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EccError {
    /// The failing byte offset in the user flash (bank 2 offsets from [`BANK_SIZE`]).
    pub offset: u32,
}

/// The double error a value of `FLASH_ECCR` reports (`None`: no `ECCD`, or one in the
/// system flash, which the firmware does not read).
pub fn double_error(eccr: u32) -> Option<EccError> {
    if eccr & ECCR_ECCD == 0 || eccr & ECCR_SYSF_ECC != 0 {
        return None;
    }
    let bank = if eccr & ECCR_BK_ECC != 0 {
        BANK_SIZE
    } else {
        0
    };
    Some(EccError {
        offset: bank + (eccr & ECCR_ADDR_MASK),
    })
}

/// What the NMI handler does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NmiAction {
    /// A double error in a record page: latch it, clear `ECCD`, return (the read
    /// completes; [`CheckedFlash`] rejects it).
    RecordPageEcc(EccError),
    /// Anything else: the fault path (record, reset).
    Fault,
    /// The clock security system saw the crystal fail (`RCC_CIFR.CSSF`): the hardware has
    /// switched SYSCLK to the 16 MHz HSI and stopped the PLL. Clear `CSSF`, record a clock
    /// failure (`reset_record::ResetCause::ClockFailure`) and reset: the next boot runs
    /// the PLL from the HSI at 170 MHz and the RUN lamp marks it (`clock::boot_source`).
    ClockFailure,
}

/// `RCC_CIFR.CSSF`: the clock security system's flag (RM0440, "Clock interrupt flag
/// register", bit 8).
pub const CIFR_CSSF: u32 = 1 << 8;

/// The NMI handler's decision on `RCC_CIFR` (`cifr`) and `FLASH_ECCR` (`eccr`): a clock
/// failure first (the NMI's other source), else [`nmi_action`].
pub fn nmi_cause(cifr: u32, eccr: u32) -> NmiAction {
    if cifr & CIFR_CSSF != 0 {
        NmiAction::ClockFailure
    } else {
        nmi_action(eccr)
    }
}

/// The NMI handler's decision on `FLASH_ECCR`'s value `eccr` (module docs).
pub fn nmi_action(eccr: u32) -> NmiAction {
    match double_error(eccr) {
        Some(e) if (RECORD_PAGES_START..RECORD_PAGES_END).contains(&e.offset) => {
            NmiAction::RecordPageEcc(e)
        }
        _ => NmiAction::Fault,
    }
}

/// The double error the NMI handler latched for the read in progress (one at a time;
/// the firmware has one static).
#[derive(Debug)]
pub struct EccLatch(AtomicU32);

/// The latch's "set" bit (offsets are below 2^19).
const LATCHED: u32 = 1 << 31;

impl EccLatch {
    /// An empty latch.
    pub const fn new() -> Self {
        Self(AtomicU32::new(0))
    }

    /// Latches `e` (the NMI handler).
    pub fn latch(&self, e: EccError) {
        self.0.store(LATCHED | e.offset, Ordering::SeqCst);
    }

    /// The latched error, and empties the latch.
    pub fn take(&self) -> Option<EccError> {
        let v = self.0.swap(0, Ordering::SeqCst);
        (v & LATCHED != 0).then_some(EccError {
            offset: v & !LATCHED,
        })
    }
}

impl Default for EccLatch {
    fn default() -> Self {
        Self::new()
    }
}

/// The flash driver's plain accesses.
pub trait RawFlash {
    /// The driver's error.
    type Error;
    /// Reads `buf.len()` bytes at `offset` (from 0x0800_0000).
    ///
    /// # Errors
    /// The driver's.
    fn read_raw(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), Self::Error>;
}

/// Why a checked read failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadError<E> {
    /// The driver's error.
    Driver(E),
    /// A double ECC error during this read (the page is marked bad from now on).
    Ecc(EccError),
    /// The page was marked bad earlier in this run: not read again.
    MarkedBad,
}

/// The record pages' reads with their ECC errors handled (module docs): `raw` and the
/// pages marked bad in this run (a bit for each 2 KiB page from [`RECORD_PAGES_START`]).
#[derive(Debug)]
pub struct CheckedFlash<F> {
    /// The driver.
    pub raw: F,
    bad: u32,
}

/// The bit of the record page `offset` is in (each 2 KiB page from [`RECORD_PAGES_START`]
/// its own: a torn double word in a reset log page marks that page, not the motor
/// record's beside it).
fn page_bit(offset: u32) -> Option<u32> {
    if (RECORD_PAGES_START..RECORD_PAGES_END).contains(&offset) {
        Some(1 << ((offset - RECORD_PAGES_START) / RECORD_PAGE_SIZE))
    } else {
        None
    }
}
const _: () = assert!((RECORD_PAGES_END - RECORD_PAGES_START) / RECORD_PAGE_SIZE <= 32);

impl<F: RawFlash> CheckedFlash<F> {
    /// `raw` with no page marked bad.
    pub fn new(raw: F) -> Self {
        Self { raw, bad: 0 }
    }

    /// Whether the record page holding `offset` is marked bad.
    pub fn is_bad(&self, offset: u32) -> bool {
        page_bit(offset).is_some_and(|b| self.bad & b != 0)
    }

    fn set_bad(&mut self, offset: u32, bad: bool) {
        if let Some(b) = page_bit(offset) {
            if bad {
                self.bad |= b;
            } else {
                self.bad &= !b;
            }
        }
    }

    /// Reads `buf.len()` bytes at `offset` with the NMI handler's `latch` looked at after
    /// the read, without marking the page: the reset log's reads, which treat a page as
    /// full from a double error on and read it again in the same boot.
    ///
    /// # Errors
    /// [`ReadError::Driver`]; [`ReadError::Ecc`] when the read raised a double error.
    pub fn read_unmarked(
        &mut self,
        latch: &EccLatch,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<(), ReadError<F::Error>> {
        let _stale = latch.take();
        self.raw.read_raw(offset, buf).map_err(ReadError::Driver)?;
        match latch.take() {
            Some(e) => Err(ReadError::Ecc(e)),
            None => Ok(()),
        }
    }

    /// The page holding `offset` was erased: no longer bad.
    pub fn erased(&mut self, offset: u32) {
        self.set_bad(offset, false);
    }

    /// Reads `buf.len()` bytes at `offset`, with the NMI handler's `latch` looked at
    /// after the read.
    ///
    /// # Errors
    /// [`ReadError::MarkedBad`] without a read when the page is marked bad;
    /// [`ReadError::Driver`]; [`ReadError::Ecc`] when the read raised a double error (the
    /// page is then marked bad).
    pub fn read(
        &mut self,
        latch: &EccLatch,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<(), ReadError<F::Error>> {
        if self.is_bad(offset) {
            return Err(ReadError::MarkedBad);
        }
        let _stale = latch.take();
        self.raw.read_raw(offset, buf).map_err(ReadError::Driver)?;
        match latch.take() {
            Some(e) => {
                self.set_bad(e.offset, true);
                self.set_bad(offset, true);
                Err(ReadError::Ecc(e))
            }
            None => Ok(()),
        }
    }

    /// A record page of `N` bytes at `offset`, read as erased (all `0xFF`, which no record
    /// parses from) when the read failed: the boot then takes its fallback. The error, for
    /// the log.
    pub fn read_or_erased<const N: usize>(
        &mut self,
        latch: &EccLatch,
        offset: u32,
    ) -> ([u8; N], Result<(), ReadError<F::Error>>) {
        let mut page = [0xFF_u8; N];
        let result = self.read(latch, offset, &mut page);
        if result.is_err() {
            page = [0xFF; N];
        }
        (page, result)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eccr_decoding_follows_the_register_layout() {
        // RM0440 FLASH_ECCR: ECCD bit 31, SYSF_ECC bit 22, BK_ECC bit 21, ADDR_ECC 18:0.
        let eccr = 0x8000_0000 | 0x0020_0000 | 0x3_F010;
        assert_eq!(double_error(eccr), Some(EccError { offset: 0x7_F010 }));
        assert_eq!(
            nmi_action(eccr),
            NmiAction::RecordPageEcc(EccError { offset: 0x7_F010 })
        );
        // In the code (bank 1) or the system flash, or no ECCD: the fault path.
        assert_eq!(nmi_action(0x8000_1000), NmiAction::Fault);
        assert_eq!(nmi_action(eccr | ECCR_SYSF_ECC), NmiAction::Fault);
        assert_eq!(nmi_action(eccr & !ECCR_ECCD), NmiAction::Fault);
        // The same address in bank 1 (BK_ECC clear) is code, at offset 0x3_F010: a fault,
        // never taken for a record page's error (the handler would return into bad code).
        let bank1 = eccr & !ECCR_BK_ECC;
        assert_eq!(double_error(bank1), Some(EccError { offset: 0x3_F010 }));
        assert_eq!(nmi_action(bank1), NmiAction::Fault);
    }

    /// A flash whose reads of one double word raise the NMI's latch, as a torn write does.
    struct Torn<'a> {
        latch: &'a EccLatch,
        torn: u32,
    }

    impl RawFlash for Torn<'_> {
        type Error = ();
        fn read_raw(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), ()> {
            if (offset..offset + buf.len() as u32).contains(&self.torn) {
                self.latch.latch(EccError { offset: self.torn });
            }
            buf.fill(0xA5);
            Ok(())
        }
    }

    /// A double error in the motor record's page marks that page bad, not the records'
    /// pages beside it nor the reset log's; an erase clears the mark.
    #[test]
    fn a_double_error_marks_its_own_page_alone() {
        use crate::board::{MOTOR_RECORD_FLASH_OFFSET, RECORD_B_FLASH_OFFSET};
        let latch = EccLatch::new();
        let torn = MOTOR_RECORD_FLASH_OFFSET + 0x40;
        let mut flash = CheckedFlash::new(Torn {
            latch: &latch,
            torn,
        });
        let mut buf = [0u8; 8];
        assert_eq!(
            flash.read(&latch, MOTOR_RECORD_FLASH_OFFSET, &mut [0u8; 132]),
            Err(ReadError::Ecc(EccError { offset: torn }))
        );
        assert!(flash.is_bad(MOTOR_RECORD_FLASH_OFFSET));
        assert_eq!(
            flash.read(&latch, MOTOR_RECORD_FLASH_OFFSET, &mut buf),
            Err(ReadError::MarkedBad)
        );
        for other in [
            RECORD_FLASH_OFFSET,
            RECORD_B_FLASH_OFFSET,
            RESET_LOG_FLASH_OFFSET,
        ] {
            assert!(!flash.is_bad(other), "{other:#x}");
            assert_eq!(flash.read(&latch, other, &mut buf), Ok(()), "{other:#x}");
        }
        flash.erased(MOTOR_RECORD_FLASH_OFFSET);
        assert!(!flash.is_bad(MOTOR_RECORD_FLASH_OFFSET));
        // Outside the record pages nothing is marked.
        assert!(!flash.is_bad(0x100));
    }

    /// The reset log's reads (`read_unmarked`): a double error fails the read and marks
    /// nothing (the log reads the page again a double word at a time, in the same boot); a
    /// stale latch from an earlier read is no error of this one.
    #[test]
    fn the_logs_reads_report_a_double_error_and_mark_nothing() {
        let latch = EccLatch::new();
        let torn = RESET_LOG_FLASH_OFFSET + 0x48;
        let mut flash = CheckedFlash::new(Torn {
            latch: &latch,
            torn,
        });
        let mut page = [0u8; 2048];
        assert_eq!(
            flash.read_unmarked(&latch, RESET_LOG_FLASH_OFFSET, &mut page),
            Err(ReadError::Ecc(EccError { offset: torn }))
        );
        assert!(!flash.is_bad(RESET_LOG_FLASH_OFFSET));
        let mut dw = [0u8; 8];
        assert_eq!(
            flash.read_unmarked(&latch, RESET_LOG_FLASH_OFFSET, &mut dw),
            Ok(())
        );
        assert_eq!(dw, [0xA5; 8]);
        latch.latch(EccError { offset: 0 });
        assert_eq!(
            flash.read_unmarked(&latch, RESET_LOG_FLASH_OFFSET, &mut dw),
            Ok(())
        );
    }
}
