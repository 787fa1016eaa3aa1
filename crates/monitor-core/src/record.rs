//! The one binary record format of the project: a header, fixed little-endian fields, a
//! CRC-32. The motor record (`MREC`, [`crate::motor_record`]), the firmware's commissioning
//! record in flash (`DMCR`) and its reset record in RAM (`DMRR`) are each a [`RecordFormat`]
//! over this module: their layouts differ only in their fields.
//!
//! # RecordLayout
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic, four ASCII bytes ([`RecordFormat::magic`]) |
//! | 4..6 | version, `u16` ([`RecordLayout::version`]) |
//! | 6..8 | length, `u16`: the layout's [`RecordLayout::length`] |
//! | 8..L-4 | the payload: the format's fields, little endian |
//! | L-4..L | CRC-32/ISO-HDLC of bytes 0..L-4, little endian ([`crc32`]) |
//!
//! where `L` is the layout's [`RecordLayout::stored_len`]. A [`RecordWriter`] writes the header,
//! the fields in order and the CRC; [`RecordFormat::open`] checks a stored record in the order
//! truncated header, erased, magic, version, truncated record, length, CRC
//! ([`RecordError`]) and hands back a [`RecordReader`] over the payload. The values' own
//! checks (ranges, finiteness) stay with each format.
//!
//! The CRC is the `crc` crate's CRC-32/ISO-HDLC (IEEE 802.3, zlib's `crc32`: reflected,
//! polynomial 0x04C11DB7, initial value and final XOR 0xFFFF_FFFF), computed without a
//! table ([`crc::NoTable`]): a record is checked a few times per boot, so speed does not
//! matter, and the 1 KiB table would cost flash. Its check value is
//! `crc32(b"123456789") == 0xCBF4_3926`, the value the project's former bit-by-bit
//! implementation gave, so records written before this module read unchanged.

use crc::{Crc, NoTable, CRC_32_ISO_HDLC};

/// Bytes of the header (magic, version, length).
pub const HEADER_LEN: usize = 8;
/// Bytes of the CRC at the end of a record.
pub const CRC_LEN: usize = 4;

/// CRC-32/ISO-HDLC, table-free (module docs).
const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// CRC-32/ISO-HDLC of `bytes` (IEEE 802.3, zlib's `crc32`; module docs).
/// `crc32(b"123456789") == 0xCBF4_3926`, `crc32(b"") == 0`.
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// Why stored bytes are not a usable record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum RecordError {
    /// Fewer bytes than the header, or than the layout its version names.
    Truncated,
    /// The header reads all `0xFF`: erased flash, no record was ever written.
    Erased,
    /// Another magic: not a record of this format.
    Magic,
    /// A version the format does not read (the stored version is given).
    Version(u16),
    /// The length field does not match the version's layout.
    Length,
    /// The CRC does not match the bytes: a bit flip, a torn write.
    Crc,
    /// The record is intact but a value fails the format's own checks (a range, a
    /// non-finite number).
    Invalid,
}

impl RecordError {
    /// A short description for logs.
    pub const fn describe(self) -> &'static str {
        match self {
            RecordError::Truncated => "record truncated",
            RecordError::Erased => "no record (erased flash)",
            RecordError::Magic => "bad record magic",
            RecordError::Version(_) => "unsupported record version",
            RecordError::Length => "bad record length",
            RecordError::Crc => "record checksum mismatch",
            RecordError::Invalid => "record holds an unusable value",
        }
    }
}

impl core::fmt::Display for RecordError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RecordError::Version(v) => write!(f, "unsupported record version {v}"),
            other => f.write_str(other.describe()),
        }
    }
}

impl core::error::Error for RecordError {}

/// One version of a format: its number, its length with header and CRC, and the value of
/// its header's length field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordLayout {
    /// The version in the header.
    pub version: u16,
    /// Bytes of the stored record, header and CRC included (at least
    /// [`HEADER_LEN`] + [`CRC_LEN`]; a shorter layout is never read).
    pub stored_len: usize,
    /// The header's length field for this layout. Each format fixed its meaning when it
    /// was introduced: the motor record counts the bytes the CRC covers
    /// (`stored_len - 4`), the commissioning and reset records their fields between header
    /// and CRC (`stored_len - 12`; version 1 of the commissioning record left its 4
    /// reserved bytes out). [`RecordFormat::open`] compares it; it is never used as an offset.
    pub length: u16,
}

/// A record format: its magic, the layout it writes and the older layouts it still reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordFormat {
    /// The four bytes a record starts with (`*b"MREC"`, ...).
    pub magic: [u8; 4],
    /// The layout written (and read).
    pub current: RecordLayout,
    /// Older layouts that are still read (empty: none).
    pub older: &'static [RecordLayout],
}

impl RecordFormat {
    /// The layout of `version`, if the format reads it.
    pub fn layout(&self, version: u16) -> Option<RecordLayout> {
        core::iter::once(&self.current)
            .chain(self.older)
            .find(|l| l.version == version)
            .copied()
    }

    /// A writer of a record in the current layout, its header written. `N` must be the
    /// current layout's [`RecordLayout::stored_len`] (each format checks that at compile time).
    pub fn writer<const N: usize>(&self) -> RecordWriter<N> {
        let mut w = RecordWriter {
            bytes: [0; N],
            at: 0,
        };
        w.bytes(&self.magic);
        w.u16(self.current.version);
        w.u16(self.current.length);
        w
    }

    /// Checks the record at the start of `bytes` (extra bytes after it, say the rest of a
    /// flash page, are ignored) and returns a reader of its payload.
    ///
    /// # Errors
    /// The first failed check, in the order [`RecordError::Truncated`] (no header),
    /// [`RecordError::Erased`], [`RecordError::Magic`], [`RecordError::Version`],
    /// [`RecordError::Truncated`] (shorter than the version's layout),
    /// [`RecordError::Length`], [`RecordError::Crc`].
    pub fn open<'a>(&self, bytes: &'a [u8]) -> Result<RecordReader<'a>, RecordError> {
        let head = bytes
            .first_chunk::<HEADER_LEN>()
            .ok_or(RecordError::Truncated)?;
        if head.iter().all(|&b| b == 0xFF) {
            return Err(RecordError::Erased);
        }
        let [m0, m1, m2, m3, v0, v1, l0, l1] = *head;
        if [m0, m1, m2, m3] != self.magic {
            return Err(RecordError::Magic);
        }
        let version = u16::from_le_bytes([v0, v1]);
        let layout = self.layout(version).ok_or(RecordError::Version(version))?;
        let stored = bytes
            .get(..layout.stored_len)
            .ok_or(RecordError::Truncated)?;
        if layout.stored_len < HEADER_LEN + CRC_LEN || u16::from_le_bytes([l0, l1]) != layout.length
        {
            return Err(RecordError::Length);
        }
        let (covered, crc) = stored
            .split_last_chunk::<CRC_LEN>()
            .ok_or(RecordError::Truncated)?;
        if crc32(covered) != u32::from_le_bytes(*crc) {
            return Err(RecordError::Crc);
        }
        let payload = covered.get(HEADER_LEN..).ok_or(RecordError::Truncated)?;
        Ok(RecordReader {
            payload,
            version,
            at: 0,
        })
    }
}

/// Reads a checked record's payload field by field, in order.
#[derive(Debug, Clone)]
pub struct RecordReader<'a> {
    payload: &'a [u8],
    version: u16,
    at: usize,
}

impl RecordReader<'_> {
    /// The record's version (one of its format's layouts).
    pub fn version(&self) -> u16 {
        self.version
    }

    /// Bytes of the payload not read yet.
    pub fn remaining(&self) -> usize {
        self.payload.len().saturating_sub(self.at)
    }

    /// The next `N` bytes.
    ///
    /// # Errors
    /// [`RecordError::Truncated`] past the payload's end (a format reading more fields
    /// than its layout holds).
    pub fn take<const N: usize>(&mut self) -> Result<[u8; N], RecordError> {
        let end = self.at.saturating_add(N);
        let field = self
            .payload
            .get(self.at..end)
            .and_then(|s| s.first_chunk::<N>())
            .ok_or(RecordError::Truncated)?;
        self.at = end;
        Ok(*field)
    }

    /// The next byte.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn u8(&mut self) -> Result<u8, RecordError> {
        self.take::<1>().map(|[b]| b)
    }

    /// The next `u16`.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn u16(&mut self) -> Result<u16, RecordError> {
        self.take().map(u16::from_le_bytes)
    }

    /// The next `u32`.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn u32(&mut self) -> Result<u32, RecordError> {
        self.take().map(u32::from_le_bytes)
    }

    /// The next `f32`.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn f32(&mut self) -> Result<f32, RecordError> {
        self.take().map(f32::from_le_bytes)
    }

    /// The next `f64`.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn f64(&mut self) -> Result<f64, RecordError> {
        self.take().map(f64::from_le_bytes)
    }

    /// The next `K` values of `f32`.
    ///
    /// # Errors
    /// As [`RecordReader::take`].
    pub fn f32s<const K: usize>(&mut self) -> Result<[f32; K], RecordError> {
        let mut out = [0.0; K];
        for x in &mut out {
            *x = self.f32()?;
        }
        Ok(out)
    }
}

/// Writes a record of `N` bytes: the header (by [`RecordFormat::writer`]), the fields in order,
/// then the CRC ([`RecordWriter::finish`]). Fields past the CRC's place are dropped; a
/// format's test checks that its fields fill the payload exactly
/// ([`RecordWriter::payload_left`]).
#[derive(Debug, Clone)]
pub struct RecordWriter<const N: usize> {
    bytes: [u8; N],
    at: usize,
}

impl<const N: usize> RecordWriter<N> {
    /// Appends raw bytes (dropped past the CRC's place).
    pub fn bytes(&mut self, field: &[u8]) {
        let end = self.at.saturating_add(field.len());
        if let Some(dst) = self
            .bytes
            .get_mut(self.at..end.min(N.saturating_sub(CRC_LEN)))
        {
            if dst.len() == field.len() {
                dst.copy_from_slice(field);
            }
        }
        self.at = end;
    }

    /// Appends a byte.
    pub fn u8(&mut self, x: u8) {
        self.bytes(&[x]);
    }

    /// Appends a `u16`.
    pub fn u16(&mut self, x: u16) {
        self.bytes(&x.to_le_bytes());
    }

    /// Appends a `u32`.
    pub fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }

    /// Appends an `f32`.
    pub fn f32(&mut self, x: f32) {
        self.bytes(&x.to_le_bytes());
    }

    /// Appends an `f64`.
    pub fn f64(&mut self, x: f64) {
        self.bytes(&x.to_le_bytes());
    }

    /// Appends `f32` values.
    pub fn f32s(&mut self, xs: &[f32]) {
        for &x in xs {
            self.f32(x);
        }
    }

    /// Payload bytes not written yet (negative: fields were dropped past the end).
    pub fn payload_left(&self) -> isize {
        N as isize - CRC_LEN as isize - self.at as isize
    }

    /// The record: the CRC-32 of bytes `0..N-4` written into its last four bytes; payload
    /// bytes never written are zero.
    pub fn finish(mut self) -> [u8; N] {
        let covered = N.saturating_sub(CRC_LEN);
        let crc = crc32(self.bytes.get(..covered).unwrap_or(&[]));
        if let Some(dst) = self.bytes.get_mut(covered..) {
            for (d, s) in dst.iter_mut().zip(crc.to_le_bytes()) {
                *d = s;
            }
        }
        self.bytes
    }
}

#[cfg(test)]
#[allow(clippy::indexing_slicing, clippy::unwrap_used)]
mod tests {
    use super::*;

    /// The former bit-by-bit CRC-32 (IEEE 802.3, reflected, poly 0xEDB88320), kept here to
    /// show the crate's gives the same values.
    fn bitwise_crc32(bytes: &[u8]) -> u32 {
        let mut crc = u32::MAX;
        for &byte in bytes {
            crc ^= u32::from(byte);
            for _ in 0..8 {
                let mask = (crc & 1).wrapping_neg();
                crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
            }
        }
        !crc
    }

    const TEST: RecordFormat = RecordFormat {
        magic: *b"TEST",
        current: RecordLayout {
            version: 2,
            stored_len: 20,
            length: 8,
        },
        older: &[RecordLayout {
            version: 1,
            stored_len: 16,
            length: 4,
        }],
    };

    fn record() -> [u8; 20] {
        let mut w = TEST.writer::<20>();
        w.u32(0xDEAD_BEEF);
        w.f32(1.5);
        assert_eq!(w.payload_left(), 0);
        w.finish()
    }

    #[test]
    fn the_crc_is_crc32_iso_hdlc_as_before() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
        let mut x = 0x1234_5678u32;
        let bytes: [u8; 300] = core::array::from_fn(|_| {
            x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (x >> 24) as u8
        });
        for n in [1, 7, 8, 63, 124, 300] {
            assert_eq!(crc32(&bytes[..n]), bitwise_crc32(&bytes[..n]), "{n}");
        }
    }

    #[test]
    fn a_record_round_trips_with_its_header() {
        let r = record();
        assert_eq!(&r[..4], b"TEST");
        assert_eq!(r[4..8], [2, 0, 8, 0]);
        let mut rd = TEST.open(&r).unwrap();
        assert_eq!(rd.version(), 2);
        assert_eq!(rd.u32(), Ok(0xDEAD_BEEF));
        assert_eq!(rd.f32(), Ok(1.5));
        assert_eq!(rd.remaining(), 0);
        assert_eq!(rd.u8(), Err(RecordError::Truncated));
    }

    #[test]
    fn every_check_in_its_order() {
        let r = record();
        assert_eq!(TEST.open(&r[..7]).err(), Some(RecordError::Truncated));
        assert_eq!(TEST.open(&[0xFF; 64]).err(), Some(RecordError::Erased));
        let mut other = r;
        other[0] = b'X';
        assert_eq!(TEST.open(&other).err(), Some(RecordError::Magic));
        let mut newer = r;
        newer[4] = 9;
        assert_eq!(TEST.open(&newer).err(), Some(RecordError::Version(9)));
        assert_eq!(TEST.open(&r[..19]).err(), Some(RecordError::Truncated));
        let mut long = r;
        long[6] = 9;
        assert_eq!(TEST.open(&long).err(), Some(RecordError::Length));
        for bit in 0..(20 - 8) * 8 {
            let mut b = r;
            b[8 + bit / 8] ^= 1 << (bit % 8);
            assert_eq!(TEST.open(&b).err(), Some(RecordError::Crc), "bit {bit}");
        }
    }

    #[test]
    fn an_older_layout_is_read_with_its_own_length() {
        let mut old = [0u8; 16];
        old[..8].copy_from_slice(&[b'T', b'E', b'S', b'T', 1, 0, 4, 0]);
        old[8..12].copy_from_slice(&7u32.to_le_bytes());
        let crc = crc32(&old[..12]);
        old[12..].copy_from_slice(&crc.to_le_bytes());
        let mut rd = TEST.open(&old).unwrap();
        assert_eq!((rd.version(), rd.u32(), rd.remaining()), (1, Ok(7), 0));
    }

    #[test]
    fn fields_past_the_end_are_dropped_and_counted() {
        let mut w = TEST.writer::<20>();
        w.f32s(&[1.0, 2.0, 3.0]);
        assert_eq!(w.payload_left(), -4);
        let r = w.finish();
        assert!(TEST.open(&r).is_ok(), "the CRC is intact");
    }
}
