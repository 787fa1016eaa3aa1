//! The commissioning record kept in flash: encode, decode, version and checksum.
//!
//! The record stores the healthy-residual statistics learned during commissioning
//! (per residual r1..r4: mean and spread, in the core's normalized units). Anything
//! that is not a complete, current-version record with a matching CRC and sane values
//! is rejected with a [`RecordError`], and the firmware then runs "not commissioned".
//!
//! **Two pages, in turn.** The record is kept in two flash pages ([`RecordPage`]:
//! [`crate::board::RECORD_FLASH_OFFSET`] and [`crate::board::RECORD_B_FLASH_OFFSET`]), each
//! copy with a sequence number. The boot reads both and puts the newer valid one into force
//! ([`load`]); a store erases and writes the *other* page, with the next number ([`store`]).
//! A power cut at any step of a store (during the erase, during the write) leaves the
//! page in force untouched: the next boot finds the old record or the new one, never none
//! (the erase and the write of one page took about 25 ms, and a cut there lost the only
//! copy).
//!
//! Since version 2 it also stores the fault isolation's healthy baseline
//! ([`monitor_core::isolation::Baseline`]: the mean and spread of its three parity
//! residuals), learned in the same commissioning run, so that after a reset the isolation
//! is judged against the machine's own baseline, not the nameplate parameters.
//!
//! Since version 3 it also stores the operating point that baseline was learned at
//! ([`Baseline::at`]), so that away from it the isolation allows for the nameplate's error.
//!
//! Since version 4 it also stores VDDA, the ADC's reference, measured while the run learned,
//! so that later readings are corrected by the reference's drift since (`supply`).
//!
//! # RecordLayout (little endian, [`RECORD_LEN`] = 104 bytes, a multiple of the G4's
//! 8-byte flash write unit)
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `b"DMCR"` |
//! | 4..6 | format version, `u16` ([`RECORD_VERSION`]) |
//! | 6..8 | payload length in bytes, `u16` (= 92) |
//! | 8..24 | `mean[0..4]`, `f32` each |
//! | 24..40 | `spread[0..4]`, `f32` each |
//! | 40..52 | isolation baseline `mean[0..3]`, `f32` each (zero when absent) |
//! | 52..64 | isolation baseline `spread[0..3]`, `f32` each (zero when absent) |
//! | 64..88 | the learned point: `i_d, i_q` [A], `v_d, v_q` [V], `we, wr` [rad/s], `f32` each (zero when absent) |
//! | 88..92 | flags, `u32`: bit 0 set when the isolation baseline is present, bit 1 when VDDA is |
//! | 92..96 | VDDA at commissioning [V], `f32` (zero when absent) |
//! | 96..100 | the copy's sequence number, `u32` ([`store`]: the newer of the two pages has the higher; 0 in records written before the two pages) |
//! | 100..104 | CRC-32/ISO-HDLC of bytes 0..100 ([`monitor_core::record::crc32`]) |
//!
//! Header, CRC, reader and writer are the project's one record format
//! ([`monitor_core::record`], [`FORMAT`]; the length field holds the payload's bytes).
//!
//! Version 3 records (96 bytes: as above up to the flags, the CRC at 92..96) are still
//! read, without VDDA; version 2 records (72 bytes: without the learned point, flags at
//! 64..68, the CRC at 68..72) too, with a baseline that has no learned point; version 1
//! records (48 bytes: the lamps' statistics at 8..40, 4 reserved bytes, the CRC at
//! 44..48) without an isolation baseline.
//!
//! Erased flash reads as all `0xFF`; that is reported as [`RecordError::Erased`].

use monitor_core::isolation::{Baseline, ParityResiduals, SteadyPoint};
pub use monitor_core::record::{crc32, RecordError};
use monitor_core::record::{RecordFormat, RecordLayout, RecordReader, CRC_LEN, HEADER_LEN};

/// Current record format version. Bump it whenever the layout or the meaning of the
/// stored numbers changes (for example a new normalization in the core): old records
/// are then rejected instead of misread.
pub const RECORD_VERSION: u16 = 4;
/// Encoded record length in bytes.
pub const RECORD_LEN: usize = 104;
/// Flag bit: the isolation baseline is present.
const FLAG_ISOLATION: u32 = 1;
/// Flag bit: the ADC reference's VDDA at commissioning is present.
const FLAG_VDDA: u32 = 2;

/// The commissioning record's format: magic `DMCR`, version [`RECORD_VERSION`] of
/// [`RECORD_LEN`] bytes; versions 3 (96 bytes), 2 (72 bytes) and 1 (48 bytes) still read.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMCR",
    current: RecordLayout {
        version: RECORD_VERSION,
        stored_len: RECORD_LEN,
        length: (RECORD_LEN - HEADER_LEN - CRC_LEN) as u16,
    },
    older: &[
        RecordLayout {
            version: 3,
            stored_len: 96,
            length: 84,
        },
        RecordLayout {
            version: 2,
            stored_len: 72,
            length: 60,
        },
        // Version 1's length left out its 4 reserved bytes before the CRC.
        RecordLayout {
            version: 1,
            stored_len: 48,
            length: 32,
        },
    ],
};

/// Learned healthy statistics of the four residuals, as stored in flash.
///
/// `mean[k]` and `spread[k]` are in the core's normalized residual units; `spread` must
/// be finite and >= 0, `mean` finite (the core checks its tighter ranges when the record
/// is applied with `Monitor::set_calibration`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationRecord {
    /// Mean of each residual r1..r4 over the commissioning run.
    pub mean: [f32; 4],
    /// Spread (standard deviation) of each residual r1..r4 over the commissioning run, >= 0.
    pub spread: [f32; 4],
    /// The fault isolation's baseline learned in the same run (`None`: not learned, or a
    /// version 1 record); its spreads > 0.
    pub isolation: Option<Baseline>,
    /// VDDA, the ADC's reference, when the run learned [V] (`None`: not measured, or a
    /// record before version 4): every later reading is corrected by VDDA now over it
    /// (`supply::ReferenceGain`); finite and > 0 (a run stores only a measurement in the
    /// reference's band, 3.2..3.4 V).
    pub vdda_v: Option<f32>,
}

fn values_ok(rec: &CalibrationRecord) -> bool {
    rec.mean.iter().all(|m| m.is_finite())
        && rec.spread.iter().all(|s| s.is_finite() && *s >= 0.0)
        && rec.isolation.is_none_or(|b| {
            b.mean.is_finite()
                && b.spread
                    .to_array()
                    .iter()
                    .all(|s| s.is_finite() && *s > 0.0)
                && point_fields(&b.at).iter().all(|x| x.is_finite())
        })
        && rec.vdda_v.is_none_or(|v| v.is_finite() && v > 0.0)
}

impl From<monitor_core::Calibration> for CalibrationRecord {
    fn from(c: monitor_core::Calibration) -> Self {
        Self {
            mean: c.mean,
            spread: c.spread,
            isolation: None,
            vdda_v: None,
        }
    }
}

impl From<CalibrationRecord> for monitor_core::Calibration {
    fn from(r: CalibrationRecord) -> Self {
        Self {
            mean: r.mean,
            spread: r.spread,
        }
    }
}

impl CalibrationRecord {
    /// Encode into the flash layout described in the module docs, sequence number 0.
    ///
    /// # Errors
    /// [`RecordError::Invalid`] if a value is non-finite or a spread is negative (such a
    /// record would be rejected at the next boot anyway).
    pub fn encode(&self) -> Result<[u8; RECORD_LEN], RecordError> {
        self.encode_copy(0)
    }

    /// Encode as the copy numbered `seq` (the module docs' two pages).
    ///
    /// # Errors
    /// As [`CalibrationRecord::encode`].
    pub fn encode_copy(&self, seq: u32) -> Result<[u8; RECORD_LEN], RecordError> {
        if !values_ok(self) {
            return Err(RecordError::Invalid);
        }
        let mut w = FORMAT.writer::<RECORD_LEN>();
        w.f32s(&self.mean);
        w.f32s(&self.spread);
        let iso = self.isolation.unwrap_or(Baseline {
            mean: ParityResiduals::default(),
            spread: ParityResiduals::default(),
            at: SteadyPoint::default(),
        });
        w.f32s(&iso.mean.to_array());
        w.f32s(&iso.spread.to_array());
        w.f32s(&point_fields(&iso.at));
        let flag = |present: bool, bit: u32| if present { bit } else { 0 };
        w.u32(
            flag(self.isolation.is_some(), FLAG_ISOLATION) | flag(self.vdda_v.is_some(), FLAG_VDDA),
        );
        w.f32(self.vdda_v.unwrap_or(0.0));
        w.u32(seq);
        Ok(w.finish())
    }

    /// Decode and validate a record read from flash. Only the record's own bytes are
    /// looked at; extra bytes (the rest of the page) are ignored.
    ///
    /// # Errors
    /// The record module's checks ([`RecordFormat::open`]: truncated, erased, magic, version,
    /// length, checksum), then [`RecordError::Invalid`] for unusable values.
    pub fn decode(bytes: &[u8]) -> Result<Self, RecordError> {
        Self::decode_copy(bytes).map(|(rec, _)| rec)
    }

    /// Decode a copy: the record and its sequence number (0 before version 4).
    ///
    /// # Errors
    /// As [`CalibrationRecord::decode`].
    pub fn decode_copy(bytes: &[u8]) -> Result<(Self, u32), RecordError> {
        let mut r = FORMAT.open(bytes)?;
        let out = Self::fields(&mut r)?;
        if !values_ok(&out.0) {
            return Err(RecordError::Invalid);
        }
        Ok(out)
    }

    /// The payload's fields as the record's version lays them out (module docs), and the
    /// copy's sequence number.
    fn fields(r: &mut RecordReader<'_>) -> Result<(Self, u32), RecordError> {
        let version = r.version();
        let mean = r.f32s::<4>()?;
        let spread = r.f32s::<4>()?;
        if version < 2 {
            // Version 1: 4 reserved bytes, no isolation baseline.
            r.take::<4>()?;
            let rec = Self {
                mean,
                spread,
                isolation: None,
                vdda_v: None,
            };
            return Ok((rec, 0));
        }
        let mut b = Baseline {
            mean: ParityResiduals::from_array(r.f32s::<3>()?),
            spread: ParityResiduals::from_array(r.f32s::<3>()?),
            at: SteadyPoint::default(),
        };
        if version >= 3 {
            let [id, iq, vd, vq, we, wr] = r.f32s::<6>()?;
            b.at = SteadyPoint {
                i: monitor_core::Dq { d: id, q: iq },
                v: monitor_core::Dq { d: vd, q: vq },
                we_rad_s: we,
                wr_rad_s: wr,
            };
        }
        let flags = r.u32()?;
        let mut vdda_v = None;
        let mut seq = 0;
        if version >= 4 {
            let v = r.f32()?;
            seq = r.u32()?;
            vdda_v = (flags & FLAG_VDDA != 0).then_some(v);
        }
        let rec = Self {
            mean,
            spread,
            isolation: (flags & FLAG_ISOLATION != 0).then_some(b),
            vdda_v,
        };
        Ok((rec, seq))
    }
}

/// The learned point's six numbers in the record's order.
fn point_fields(p: &SteadyPoint) -> [f32; 6] {
    [p.i.d, p.i.q, p.v.d, p.v.q, p.we_rad_s, p.wr_rad_s]
}

/// One of the record's two pages (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordPage {
    /// The first page ([`crate::board::RECORD_FLASH_OFFSET`]).
    A,
    /// The second page ([`crate::board::RECORD_B_FLASH_OFFSET`]).
    B,
}

impl RecordPage {
    /// Both pages.
    pub const BOTH: [RecordPage; 2] = [RecordPage::A, RecordPage::B];

    /// The other page.
    pub const fn other(self) -> RecordPage {
        match self {
            RecordPage::A => RecordPage::B,
            RecordPage::B => RecordPage::A,
        }
    }
}

/// Where the record is kept: the two flash pages on the board, byte arrays in the host
/// tests (the software-in-the-loop rig). Erase, write and read of one page.
pub trait RecordStore {
    /// What a failed flash operation reports.
    type Error;
    /// Reads the first [`RECORD_LEN`] bytes of `page`.
    ///
    /// # Errors
    /// When the page cannot be read.
    fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), Self::Error>;
    /// Erases `page` (every byte `0xFF`).
    ///
    /// # Errors
    /// When the erase fails.
    fn erase(&mut self, page: RecordPage) -> Result<(), Self::Error>;
    /// Writes `bytes` at the start of the (erased) `page`.
    ///
    /// # Errors
    /// When the write fails.
    fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), Self::Error>;
}

/// Why no record could be loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadError<E> {
    /// Neither page could be read (the first page's error).
    Read(E),
    /// No page holds a valid record (the first page's reason, or the second's when the
    /// first is erased or unreadable).
    Record(RecordError),
}

/// The newer valid copy of the two pages: its page, the record and its sequence number.
///
/// # Errors
/// [`LoadError`]: no page read, or no valid record in either.
pub fn newest<S: RecordStore>(
    store: &mut S,
) -> Result<(RecordPage, CalibrationRecord, u32), LoadError<S::Error>> {
    let mut best: Option<(RecordPage, CalibrationRecord, u32)> = None;
    let mut why: Option<LoadError<S::Error>> = None;
    for page in RecordPage::BOTH {
        let mut buf = [0u8; RECORD_LEN];
        match store.read(page, &mut buf) {
            Err(e) => {
                why.get_or_insert(LoadError::Read(e));
            }
            Ok(()) => match CalibrationRecord::decode_copy(&buf) {
                Ok((rec, seq)) => {
                    // The newer copy; the sequence numbers wrap, so "newer" is the nearer
                    // one ahead.
                    if best.is_none_or(|(_, _, b)| seq.wrapping_sub(b) as i32 > 0) {
                        best = Some((page, rec, seq));
                    }
                }
                Err(e) => {
                    let replace = match why {
                        None | Some(LoadError::Read(_)) => true,
                        Some(LoadError::Record(old)) => old == RecordError::Erased,
                    };
                    if replace {
                        why = Some(LoadError::Record(e));
                    }
                }
            },
        }
    }
    match (best, why) {
        (Some(b), _) => Ok(b),
        (None, Some(w)) => Err(w),
        (None, None) => Err(LoadError::Record(RecordError::Erased)),
    }
}

/// Reads both pages and returns the newer valid record (module docs).
///
/// # Errors
/// [`LoadError`]: no page read, or no valid record in either.
pub fn load<S: RecordStore>(store: &mut S) -> Result<CalibrationRecord, LoadError<S::Error>> {
    newest(store).map(|(_, rec, _)| rec)
}

/// The result of [`store`]: what went wrong, if anything, and what the store holds now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stored<E> {
    /// The first failure of encode, erase or write (`Ok` when all three worked).
    pub written: Result<(), StoreError<E>>,
    /// The record read back after the attempt (the newer valid copy; `None`: no valid
    /// record): this, not what was meant to be written, is what the monitor must use. After
    /// a failed erase or write it is the copy that was in force before.
    pub read_back: Option<CalibrationRecord>,
}

/// Why a record could not be written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreError<E> {
    /// The record holds an unusable value and was not written.
    Encode(RecordError),
    /// The page erase failed.
    Erase(E),
    /// The write failed.
    Write(E),
}

/// Writes `rec` as the next copy into the page not in force (erase, write; the copy in
/// force untouched), then reads both pages back. Whatever fails, the result says what the
/// store holds afterwards ([`Stored::read_back`]), so the caller can make the monitor use
/// exactly that.
pub fn store<S: RecordStore>(store: &mut S, rec: &CalibrationRecord) -> Stored<S::Error> {
    let (page, seq) = match newest(store) {
        Ok((page, _, seq)) => (page.other(), seq.wrapping_add(1)),
        Err(_) => (RecordPage::A, 1),
    };
    let written = match rec.encode_copy(seq) {
        Err(e) => Err(StoreError::Encode(e)),
        Ok(bytes) => match store.erase(page) {
            Err(e) => Err(StoreError::Erase(e)),
            Ok(()) => store.write(page, &bytes).map_err(StoreError::Write),
        },
    };
    Stored {
        written,
        read_back: load(store).ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> CalibrationRecord {
        CalibrationRecord {
            mean: [0.01, -0.02, 0.003, 0.0],
            spread: [0.05, 0.04, 0.06, 0.07],
            isolation: Some(Baseline {
                mean: ParityResiduals::from_array([1e-4, -2e-4, 3e-3]),
                spread: ParityResiduals::from_array([4e-4, 4e-4, 1e-3]),
                at: SteadyPoint {
                    i: monitor_core::Dq { d: 3.5, q: 4.25 },
                    v: monitor_core::Dq { d: -2.0, q: 325.0 },
                    we_rad_s: 314.0,
                    wr_rad_s: 303.5,
                },
            }),
            vdda_v: None,
        }
    }

    #[test]
    fn a_version_2_record_is_read_without_the_learned_point() {
        // The version 2 layout: the current one without bytes 64..88.
        let s = sample();
        let v3 = s.encode().unwrap();
        let mut v2 = [0u8; 72];
        v2[..64].copy_from_slice(&v3[..64]);
        v2[4..6].copy_from_slice(&2u16.to_le_bytes());
        v2[6..8].copy_from_slice(&60u16.to_le_bytes());
        v2[64..68].copy_from_slice(&v3[88..92]);
        let crc = crc32(&v2[..68]);
        v2[68..].copy_from_slice(&crc.to_le_bytes());
        let mut page = [0xFFu8; RECORD_LEN];
        page[..72].copy_from_slice(&v2);
        let mut want = s;
        if let Some(b) = want.isolation.as_mut() {
            b.at = SteadyPoint::default();
        }
        assert_eq!(CalibrationRecord::decode(&page), Ok(want));
        assert_ne!(want, s, "the learned point is what version 3 adds");
    }

    #[test]
    fn a_record_without_the_isolation_baseline_round_trips() {
        let r = CalibrationRecord {
            isolation: None,
            ..sample()
        };
        assert_eq!(CalibrationRecord::decode(&r.encode().unwrap()), Ok(r));
    }

    #[test]
    fn a_version_1_record_is_read_without_the_isolation_baseline() {
        // Built by hand to the version 1 layout (module docs).
        let mut v1 = [0u8; 48];
        v1[..4].copy_from_slice(b"DMCR");
        v1[4..6].copy_from_slice(&1u16.to_le_bytes());
        v1[6..8].copy_from_slice(&32u16.to_le_bytes());
        let s = sample();
        for (k, v) in s.mean.iter().chain(s.spread.iter()).enumerate() {
            v1[8 + 4 * k..12 + 4 * k].copy_from_slice(&v.to_le_bytes());
        }
        let crc = crc32(&v1[..44]);
        v1[44..].copy_from_slice(&crc.to_le_bytes());
        let mut page = [0xFFu8; RECORD_LEN];
        page[..48].copy_from_slice(&v1);
        let want = CalibrationRecord {
            isolation: None,
            ..s
        };
        assert_eq!(CalibrationRecord::decode(&page), Ok(want));
        // A flipped bit in its payload is caught by its own CRC.
        page[20] ^= 4;
        assert_eq!(CalibrationRecord::decode(&page), Err(RecordError::Crc));
    }

    #[test]
    fn a_zero_isolation_spread_is_rejected() {
        let mut r = sample();
        r.isolation = Some(Baseline {
            mean: ParityResiduals::default(),
            spread: ParityResiduals::from_array([0.0, 1e-3, 1e-3]),
            at: SteadyPoint::default(),
        });
        assert_eq!(r.encode(), Err(RecordError::Invalid));
    }

    /// `sample()` as the record's code before the record module wrote it (its own field
    /// writer and bit-by-bit CRC-32).
    const WRITTEN_BEFORE: &str = "444d4352030054000ad7233c0ad7a3bca69b443b00000000cdcc4c3d0ad7233d8fc2753d295c8f3d17b7d13817b751b9a69b443b17b7d13917b7d1396f12833a0000604000008840000000c00080a24300009d4300c0974301000000084965b8";

    #[test]
    fn a_record_written_by_the_former_code_reads_and_is_rewritten_with_the_same_payload() {
        let old: Vec<u8> = (0..WRITTEN_BEFORE.len() / 2)
            .map(|k| u8::from_str_radix(&WRITTEN_BEFORE[2 * k..2 * k + 2], 16).unwrap())
            .collect();
        // A version 3 record (96 bytes): read, without VDDA.
        assert_eq!(old.len(), 96);
        assert_eq!(CalibrationRecord::decode(&old), Ok(sample()));
        // Written again as version 4: the same header magic, the same bytes up to the
        // flags, then VDDA (absent: zero) and the reserved word before the CRC.
        let new = sample().encode().unwrap();
        assert_eq!(new[..4], old[..4]);
        assert_eq!(new[4..8], [4, 0, 92, 0]);
        assert_eq!(new[8..92], old[8..92]);
        assert_eq!(new[92..100], [0; 8]);
    }

    /// VDDA at commissioning round trips; one that is not finite and positive is refused.
    #[test]
    fn the_commissioned_vdda_round_trips_and_a_bad_one_is_refused() {
        let r = CalibrationRecord {
            vdda_v: Some(3.287),
            ..sample()
        };
        let bytes = r.encode().unwrap();
        assert_eq!(bytes[92..96], 3.287f32.to_le_bytes());
        assert_eq!(bytes[88] & 2, 2, "the VDDA flag");
        assert_eq!(CalibrationRecord::decode(&bytes), Ok(r));
        for bad in [0.0, -3.3, f32::NAN, f32::INFINITY] {
            let out = CalibrationRecord {
                vdda_v: Some(bad),
                ..sample()
            };
            assert_eq!(out.encode(), Err(RecordError::Invalid), "{bad}");
        }
    }

    #[test]
    fn crc_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn round_trip() {
        let bytes = sample().encode().unwrap();
        assert_eq!(CalibrationRecord::decode(&bytes), Ok(sample()));
        let mut page = [0xFFu8; 2048];
        page[..RECORD_LEN].copy_from_slice(&bytes);
        assert_eq!(CalibrationRecord::decode(&page), Ok(sample()));
    }

    #[test]
    fn rejects_invalid_values_on_encode() {
        let mut r = sample();
        r.spread[2] = -1.0;
        assert_eq!(r.encode(), Err(RecordError::Invalid));
        r.spread[2] = f32::NAN;
        assert_eq!(r.encode(), Err(RecordError::Invalid));
    }
}
