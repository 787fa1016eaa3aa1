//! The commissioning record kept in flash: encode, decode, version and checksum.
//!
//! The record stores the healthy-residual statistics learned during commissioning
//! (per residual r1..r4: mean and spread, in the core's normalized units). It is written
//! to the page at [`crate::board::RECORD_FLASH_OFFSET`] and read back at boot. Anything
//! that is not a complete, current-version record with a matching CRC and sane values
//! is rejected with a [`FlashRecordError`], and the firmware then runs "not commissioned".
//!
//! Since version 2 it also stores the fault isolation's healthy baseline
//! ([`monitor_core::isolation::Baseline`]: the mean and spread of its three parity
//! residuals), learned in the same commissioning run, so that after a reset the isolation
//! is judged against the machine's own baseline, not the nameplate parameters.
//!
//! Since version 3 it also stores the operating point that baseline was learned at
//! ([`Baseline::at`]), so that away from it the isolation allows for the nameplate's error.
//!
//! # Layout (little endian, [`RECORD_LEN`] = 96 bytes, a multiple of the G4's 8-byte
//! flash write unit)
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `b"DMCR"` |
//! | 4..6 | format version, `u16` ([`RECORD_VERSION`]) |
//! | 6..8 | payload length in bytes, `u16` (= 84) |
//! | 8..24 | `mean[0..4]`, `f32` each |
//! | 24..40 | `spread[0..4]`, `f32` each |
//! | 40..52 | isolation baseline `mean[0..3]`, `f32` each (zero when absent) |
//! | 52..64 | isolation baseline `spread[0..3]`, `f32` each (zero when absent) |
//! | 64..88 | the learned point: `i_d, i_q` [A], `v_d, v_q` [V], `we, wr` [rad/s], `f32` each (zero when absent) |
//! | 88..92 | flags, `u32`: bit 0 set when the isolation baseline is present |
//! | 92..96 | CRC-32 (IEEE 802.3, reflected, as zlib) of bytes 0..92 |
//!
//! Version 2 records (72 bytes: as above without the learned point, flags at 64..68, the
//! CRC at 68..72) are still read, with a baseline that has no learned point; version 1
//! records (48 bytes: the lamps' statistics at 8..40, 4 reserved bytes, the CRC at
//! 44..48) without an isolation baseline.
//!
//! Erased flash reads as all `0xFF`; that is reported as [`FlashRecordError::Erased`].

use monitor_core::isolation::{Baseline, ParityResiduals, SteadyPoint};

/// Magic bytes at the start of a record.
pub const RECORD_MAGIC: [u8; 4] = *b"DMCR";
/// Current record format version. Bump it whenever the layout or the meaning of the
/// stored numbers changes (for example a new normalization in the core): old records
/// are then rejected instead of misread.
pub const RECORD_VERSION: u16 = 3;
/// Encoded record length in bytes.
pub const RECORD_LEN: usize = 96;
const PAYLOAD_LEN: u16 = 84;
const CRC_OFFSET: usize = 92;
/// Version 2: length, payload length and CRC offset.
const V2_LEN: usize = 72;
const V2_PAYLOAD_LEN: u16 = 60;
const V2_CRC_OFFSET: usize = 68;
/// Version 1: length, payload length and CRC offset.
const V1_LEN: usize = 48;
const V1_PAYLOAD_LEN: u16 = 32;
const V1_CRC_OFFSET: usize = 44;
/// Flag bit: the isolation baseline is present.
const FLAG_ISOLATION: u32 = 1;

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
}

/// Why a stored record was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum FlashRecordError {
    /// Fewer than [`RECORD_LEN`] bytes were given.
    Truncated,
    /// The page is erased (all `0xFF`): never commissioned.
    Erased,
    /// The magic bytes do not match: not a record of this firmware.
    BadMagic,
    /// A record of another format version (the stored version is given).
    UnsupportedVersion(u16),
    /// The payload length field does not match this version's layout.
    BadLength,
    /// The CRC does not match: the record is corrupt (bit flip, torn write).
    BadChecksum,
    /// CRC is fine but a value is not usable (non-finite, or spread < 0).
    InvalidValue,
}

impl core::fmt::Display for FlashRecordError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Truncated => f.write_str("record truncated"),
            Self::Erased => f.write_str("no record (erased flash)"),
            Self::BadMagic => f.write_str("bad record magic"),
            Self::UnsupportedVersion(v) => write!(f, "unsupported record version {v}"),
            Self::BadLength => f.write_str("bad record payload length"),
            Self::BadChecksum => f.write_str("record checksum mismatch"),
            Self::InvalidValue => f.write_str("record holds an unusable value"),
        }
    }
}

#[cfg(target_os = "none")]
impl defmt::Format for FlashRecordError {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            Self::Truncated => defmt::write!(f, "Truncated"),
            Self::Erased => defmt::write!(f, "Erased"),
            Self::BadMagic => defmt::write!(f, "BadMagic"),
            Self::UnsupportedVersion(v) => defmt::write!(f, "UnsupportedVersion({=u16})", v),
            Self::BadLength => defmt::write!(f, "BadLength"),
            Self::BadChecksum => defmt::write!(f, "BadChecksum"),
            Self::InvalidValue => defmt::write!(f, "InvalidValue"),
        }
    }
}

/// CRC-32 (IEEE 802.3 polynomial, reflected, init and final XOR 0xFFFF_FFFF; zlib's
/// `crc32`): the core's one implementation, shared with the motor record. Check value:
/// `crc32(b"123456789") == 0xCBF4_3926`.
pub use monitor_core::motor_record::crc32;

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
}

impl From<monitor_core::Calibration> for CalibrationRecord {
    fn from(c: monitor_core::Calibration) -> Self {
        Self {
            mean: c.mean,
            spread: c.spread,
            isolation: None,
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
    /// Encode into the flash layout described in the module docs.
    ///
    /// # Errors
    /// [`FlashRecordError::InvalidValue`] if a value is non-finite or a spread is negative
    /// (such a record would be rejected at the next boot anyway).
    pub fn encode(&self) -> Result<[u8; RECORD_LEN], FlashRecordError> {
        if !values_ok(self) {
            return Err(FlashRecordError::InvalidValue);
        }
        let mut out = [0u8; RECORD_LEN];
        let mut w = Writer {
            buf: &mut out,
            pos: 0,
        };
        w.put(&RECORD_MAGIC);
        w.put(&RECORD_VERSION.to_le_bytes());
        w.put(&PAYLOAD_LEN.to_le_bytes());
        for v in self.mean.iter().chain(self.spread.iter()) {
            w.put(&v.to_le_bytes());
        }
        let iso = self.isolation.unwrap_or(Baseline {
            mean: ParityResiduals::default(),
            spread: ParityResiduals::default(),
            at: SteadyPoint::default(),
        });
        for v in iso.mean.to_array().iter().chain(&iso.spread.to_array()) {
            w.put(&v.to_le_bytes());
        }
        for v in point_fields(&iso.at) {
            w.put(&v.to_le_bytes());
        }
        let flags = if self.isolation.is_some() {
            FLAG_ISOLATION
        } else {
            0
        };
        w.put(&flags.to_le_bytes());
        let (body, crc_field) = out.split_at_mut(CRC_OFFSET);
        let crc = crc32(body);
        for (dst, src) in crc_field.iter_mut().zip(crc.to_le_bytes()) {
            *dst = src;
        }
        Ok(out)
    }

    /// Decode and validate a record read from flash. Only the first [`RECORD_LEN`]
    /// bytes are looked at; extra bytes (the rest of the page) are ignored.
    ///
    /// # Errors
    /// See [`FlashRecordError`]; checks run in the order truncated, erased, magic, version,
    /// length, checksum, values.
    pub fn decode(bytes: &[u8]) -> Result<Self, FlashRecordError> {
        let head = bytes.get(..8).ok_or(FlashRecordError::Truncated)?;
        if head.iter().all(|&b| b == 0xFF) {
            return Err(FlashRecordError::Erased);
        }
        let mut r = Reader { buf: head, pos: 0 };
        if r.take::<4>() != RECORD_MAGIC {
            return Err(FlashRecordError::BadMagic);
        }
        let version = u16::from_le_bytes(r.take::<2>());
        let (len, payload, crc_at) = match version {
            RECORD_VERSION => (RECORD_LEN, PAYLOAD_LEN, CRC_OFFSET),
            2 => (V2_LEN, V2_PAYLOAD_LEN, V2_CRC_OFFSET),
            1 => (V1_LEN, V1_PAYLOAD_LEN, V1_CRC_OFFSET),
            v => return Err(FlashRecordError::UnsupportedVersion(v)),
        };
        let rec = bytes.get(..len).ok_or(FlashRecordError::Truncated)?;
        if u16::from_le_bytes(r.take::<2>()) != payload {
            return Err(FlashRecordError::BadLength);
        }
        let stored_crc = u32::from_le_bytes(
            Reader {
                buf: rec,
                pos: crc_at,
            }
            .take::<4>(),
        );
        let body = rec.get(..crc_at).ok_or(FlashRecordError::Truncated)?;
        if crc32(body) != stored_crc {
            return Err(FlashRecordError::BadChecksum);
        }
        let mut r = Reader { buf: rec, pos: 8 };
        let mut out = Self {
            mean: [0.0; 4],
            spread: [0.0; 4],
            isolation: None,
        };
        for v in out.mean.iter_mut().chain(out.spread.iter_mut()) {
            *v = f32::from_le_bytes(r.take::<4>());
        }
        if version >= 2 {
            let mut b = Baseline {
                mean: r.residuals(),
                spread: r.residuals(),
                at: SteadyPoint::default(),
            };
            if version >= 3 {
                let mut f = [0.0f32; 6];
                for v in f.iter_mut() {
                    *v = f32::from_le_bytes(r.take::<4>());
                }
                let [id, iq, vd, vq, we, wr] = f;
                b.at = SteadyPoint {
                    i: monitor_core::Dq { d: id, q: iq },
                    v: monitor_core::Dq { d: vd, q: vq },
                    we_rad_s: we,
                    wr_rad_s: wr,
                };
            }
            let flags = u32::from_le_bytes(r.take::<4>());
            out.isolation = (flags & FLAG_ISOLATION != 0).then_some(b);
        }
        if !values_ok(&out) {
            return Err(FlashRecordError::InvalidValue);
        }
        Ok(out)
    }
}

/// The learned point's six numbers in the record's order.
fn point_fields(p: &SteadyPoint) -> [f32; 6] {
    [p.i.d, p.i.q, p.v.d, p.v.q, p.we_rad_s, p.wr_rad_s]
}

/// Where the record is kept: the flash page on the board, a byte array in the host tests
/// (the software-in-the-loop rig). Erase, write and read of the one record.
pub trait RecordStore {
    /// What a failed flash operation reports.
    type Error;
    /// Reads the first [`RECORD_LEN`] bytes of the record page.
    ///
    /// # Errors
    /// When the page cannot be read.
    fn read(&mut self, buf: &mut [u8; RECORD_LEN]) -> Result<(), Self::Error>;
    /// Erases the record page (every byte `0xFF`).
    ///
    /// # Errors
    /// When the erase fails.
    fn erase(&mut self) -> Result<(), Self::Error>;
    /// Writes `bytes` at the start of the (erased) record page.
    ///
    /// # Errors
    /// When the write fails.
    fn write(&mut self, bytes: &[u8; RECORD_LEN]) -> Result<(), Self::Error>;
}

/// Why no record could be loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadError<E> {
    /// The store could not be read.
    Read(E),
    /// The bytes are not a valid record.
    Record(FlashRecordError),
}

/// Reads and validates the stored record.
///
/// # Errors
/// [`LoadError`]: the read failed, or the bytes are not a valid record.
pub fn load<S: RecordStore>(store: &mut S) -> Result<CalibrationRecord, LoadError<S::Error>> {
    let mut buf = [0u8; RECORD_LEN];
    store.read(&mut buf).map_err(LoadError::Read)?;
    CalibrationRecord::decode(&buf).map_err(LoadError::Record)
}

/// The result of [`store`]: what went wrong, if anything, and what the store holds now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stored<E> {
    /// The first failure of encode, erase or write (`Ok` when all three worked).
    pub written: Result<(), StoreError<E>>,
    /// The record read back after the attempt (`None`: no valid record); this, not what
    /// was meant to be written, is what the monitor must use.
    pub read_back: Option<CalibrationRecord>,
}

/// Why a record could not be written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreError<E> {
    /// The record holds an unusable value and was not written.
    Encode(FlashRecordError),
    /// The page erase failed.
    Erase(E),
    /// The write failed.
    Write(E),
}

/// Erases the page, writes `rec` and reads the page back. Whatever fails, the result says
/// what the store holds afterwards ([`Stored::read_back`]), so the caller can make the
/// monitor use exactly that.
pub fn store<S: RecordStore>(store: &mut S, rec: &CalibrationRecord) -> Stored<S::Error> {
    let written = match rec.encode() {
        Err(e) => Err(StoreError::Encode(e)),
        Ok(bytes) => match store.erase() {
            Err(e) => Err(StoreError::Erase(e)),
            Ok(()) => store.write(&bytes).map_err(StoreError::Write),
        },
    };
    Stored {
        written,
        read_back: load(store).ok(),
    }
}

/// Sequential writer into a fixed buffer; silently stops at the end (the layout is
/// fixed and fits, so that never happens; no panic path either way).
struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) {
        if let Some(dst) = self.buf.get_mut(self.pos..self.pos + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
        self.pos += bytes.len();
    }
}

/// Sequential reader; reads past the end yield zeros (callers check the length first).
struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(src) = self.buf.get(self.pos..self.pos + N) {
            out.copy_from_slice(src);
        }
        self.pos += N;
        out
    }

    /// The next three values `[e_d, e_q, e_T]`.
    fn residuals(&mut self) -> ParityResiduals {
        let mut f = || f32::from_le_bytes(self.take::<4>());
        ParityResiduals::from_array([f(), f(), f()])
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
        assert_eq!(
            CalibrationRecord::decode(&page),
            Err(FlashRecordError::BadChecksum)
        );
    }

    #[test]
    fn a_zero_isolation_spread_is_rejected() {
        let mut r = sample();
        r.isolation = Some(Baseline {
            mean: ParityResiduals::default(),
            spread: ParityResiduals::from_array([0.0, 1e-3, 1e-3]),
            at: SteadyPoint::default(),
        });
        assert_eq!(r.encode(), Err(FlashRecordError::InvalidValue));
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
        assert_eq!(r.encode(), Err(FlashRecordError::InvalidValue));
        r.spread[2] = f32::NAN;
        assert_eq!(r.encode(), Err(FlashRecordError::InvalidValue));
    }
}
