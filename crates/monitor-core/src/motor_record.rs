//! The motor record: the board's own machine, stored in a flash page and written from the
//! host (`sim-host board-record P.toml --out motor.bin`, `docs/firmware.md`).
//!
//! One little-endian fixed layout of [`RECORD_LEN`] = 128 bytes, parsed here only (the
//! firmware and the host's tests use [`MotorRecord::parse`]):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic [`MAGIC`] (`"MREC"`) |
//! | 4 | 2 | version [`VERSION`] |
//! | 6 | 2 | length [`RECORD_LEN`] |
//! | 8 | 64 | `[motor]` `rs_ohm rr_ohm ls_h lr_h lm_h j_kgm2 b_nms bl_nms`, `f64` each |
//! | 72 | 4 | `[motor]` `poles`, `u32` |
//! | 76 | 16 | `[supply]` `v_ll_rms f_hz`, `f64` each |
//! | 92 | 8 | sensor full scale: current [A], voltage [V], `f32` each |
//! | 100 | 24 | sensor offsets: currents a, b, c then voltages a, b, c [ADC counts], `f32` each |
//! | 124 | 2 | encoder lines per revolution, `u16` (counts = 4 x lines) |
//! | 126 | 2 | encoder direction: 0 forward, 1 reversed, `u16` |
//! | 128 | 4 | CRC-32 (IEEE 802.3, reflected, poly 0xEDB88320) of bytes 0..128 |
//!
//! so the record with its CRC is [`RECORD_LEN`] + 4 = 132 bytes. A record that fails any
//! check is rejected with a [`RecordError`]; the caller falls back to its built-in default.

use crate::machine::{MotorParameters, SupplyParameters};

/// `"MREC"` read as a little-endian `u32`.
pub const MAGIC: u32 = u32::from_le_bytes(*b"MREC");
/// The layout's version; a record of another version is [`RecordError::Version`].
pub const VERSION: u16 = 1;
/// Bytes covered by the CRC (header and payload).
pub const RECORD_LEN: usize = 128;
/// Bytes of a stored record: [`RECORD_LEN`] plus the 4-byte CRC.
pub const STORED_LEN: usize = RECORD_LEN + 4;

/// Why a stored record was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordError {
    /// Fewer than [`STORED_LEN`] bytes.
    Truncated,
    /// No [`MAGIC`]: the page holds no record (erased flash reads `0xFF`).
    Magic,
    /// A version other than [`VERSION`].
    Version,
    /// The length field is not [`RECORD_LEN`].
    Length,
    /// The CRC-32 does not match the bytes.
    Crc,
    /// The values fail the core's checks ([`MotorParameters::validate`],
    /// [`SupplyParameters::validate`], positive finite full scales, finite offsets, 1 or more
    /// encoder lines, direction 0 or 1).
    Invalid,
}

/// The values a motor record holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorRecord {
    /// The parameter file's `[motor]`.
    pub motor: MotorParameters,
    /// The parameter file's `[supply]`.
    pub supply: SupplyParameters,
    /// Current sensor full scale [A], > 0 (the reading at the ADC's full scale).
    pub current_full_scale_a: f32,
    /// Voltage sensor full scale [V], > 0.
    pub voltage_full_scale_v: f32,
    /// Zero-current readings of phases a, b, c [ADC counts], finite.
    pub current_offset_counts: [f32; 3],
    /// Zero-voltage readings of phases a, b, c [ADC counts], finite.
    pub voltage_offset_counts: [f32; 3],
    /// Encoder lines per revolution, >= 1 (quadrature counts are 4 x lines).
    pub encoder_lines: u16,
    /// The encoder counts down when the motor turns forward.
    pub encoder_reversed: bool,
}

/// CRC-32 (IEEE 802.3: reflected, polynomial 0xEDB88320, init and final xor 0xFFFFFFFF),
/// bitwise (no table). `crc32(b"123456789") == 0xCBF4_3926`.
pub fn crc32(bytes: &[u8]) -> u32 {
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

/// Reads fixed-size fields from the front of a byte slice.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], RecordError> {
        let (head, rest) = self
            .0
            .split_first_chunk::<N>()
            .ok_or(RecordError::Truncated)?;
        self.0 = rest;
        Ok(*head)
    }
    fn f64(&mut self) -> Result<f64, RecordError> {
        self.take().map(f64::from_le_bytes)
    }
    fn f32(&mut self) -> Result<f32, RecordError> {
        self.take().map(f32::from_le_bytes)
    }
    fn u16(&mut self) -> Result<u16, RecordError> {
        self.take().map(u16::from_le_bytes)
    }
}

/// Appends fixed-size fields to a byte array.
struct Writer {
    bytes: [u8; STORED_LEN],
    at: usize,
}

impl Writer {
    fn put(&mut self, field: &[u8]) {
        let end = self.at + field.len();
        if let Some(dst) = self.bytes.get_mut(self.at..end) {
            dst.copy_from_slice(field);
        }
        self.at = end;
    }
}

impl MotorRecord {
    /// The stored form ([`STORED_LEN`] bytes, layout in the module docs), CRC included.
    pub fn to_bytes(&self) -> [u8; STORED_LEN] {
        let mut w = Writer {
            bytes: [0; STORED_LEN],
            at: 0,
        };
        let m = &self.motor;
        w.put(&MAGIC.to_le_bytes());
        w.put(&VERSION.to_le_bytes());
        w.put(&(RECORD_LEN as u16).to_le_bytes());
        for x in [
            m.rs_ohm, m.rr_ohm, m.ls_h, m.lr_h, m.lm_h, m.j_kgm2, m.b_nms, m.bl_nms,
        ] {
            w.put(&x.to_le_bytes());
        }
        w.put(&m.poles.to_le_bytes());
        w.put(&self.supply.v_ll_rms.to_le_bytes());
        w.put(&self.supply.f_hz.to_le_bytes());
        w.put(&self.current_full_scale_a.to_le_bytes());
        w.put(&self.voltage_full_scale_v.to_le_bytes());
        for x in self
            .current_offset_counts
            .iter()
            .chain(&self.voltage_offset_counts)
        {
            w.put(&x.to_le_bytes());
        }
        w.put(&self.encoder_lines.to_le_bytes());
        w.put(&u16::from(self.encoder_reversed).to_le_bytes());
        let crc = crc32(w.bytes.get(..RECORD_LEN).unwrap_or(&[]));
        w.put(&crc.to_le_bytes());
        w.bytes
    }

    /// Parses and checks a stored record (extra bytes after [`STORED_LEN`] are ignored, so a
    /// whole flash page can be passed).
    ///
    /// # Errors
    /// The first failed check, in the order [`RecordError::Truncated`], `Magic`, `Version`,
    /// `Length`, `Crc`, `Invalid`.
    pub fn parse(bytes: &[u8]) -> Result<MotorRecord, RecordError> {
        let stored = bytes.get(..STORED_LEN).ok_or(RecordError::Truncated)?;
        let mut r = Reader(stored);
        if u32::from_le_bytes(r.take()?) != MAGIC {
            return Err(RecordError::Magic);
        }
        if r.u16()? != VERSION {
            return Err(RecordError::Version);
        }
        if usize::from(r.u16()?) != RECORD_LEN {
            return Err(RecordError::Length);
        }
        let (body, crc) = stored
            .split_last_chunk::<4>()
            .ok_or(RecordError::Truncated)?;
        if crc32(body) != u32::from_le_bytes(*crc) {
            return Err(RecordError::Crc);
        }
        let mut f = [0.0f64; 8];
        for x in &mut f {
            *x = r.f64()?;
        }
        let [rs_ohm, rr_ohm, ls_h, lr_h, lm_h, j_kgm2, b_nms, bl_nms] = f;
        let poles = u32::from_le_bytes(r.take()?);
        let motor = MotorParameters {
            rs_ohm,
            rr_ohm,
            ls_h,
            lr_h,
            lm_h,
            poles,
            j_kgm2,
            b_nms,
            bl_nms,
        };
        let supply = SupplyParameters {
            v_ll_rms: r.f64()?,
            f_hz: r.f64()?,
        };
        let current_full_scale_a = r.f32()?;
        let voltage_full_scale_v = r.f32()?;
        let mut offsets = [0.0f32; 6];
        for x in &mut offsets {
            *x = r.f32()?;
        }
        let [ia, ib, ic, va, vb, vc] = offsets;
        let encoder_lines = r.u16()?;
        let direction = r.u16()?;
        let record = MotorRecord {
            motor,
            supply,
            current_full_scale_a,
            voltage_full_scale_v,
            current_offset_counts: [ia, ib, ic],
            voltage_offset_counts: [va, vb, vc],
            encoder_lines,
            encoder_reversed: direction == 1,
        };
        let scale_ok = |x: f32| x.is_finite() && x > 0.0;
        let valid = motor.validate().is_ok()
            && supply.validate().is_ok()
            && scale_ok(current_full_scale_a)
            && scale_ok(voltage_full_scale_v)
            && offsets.iter().all(|x| x.is_finite())
            && encoder_lines >= 1
            && direction <= 1;
        if valid {
            Ok(record)
        } else {
            Err(RecordError::Invalid)
        }
    }
}

#[cfg(test)]
#[allow(clippy::indexing_slicing)]
mod tests {
    use super::*;
    use crate::machine::reference::MOTOR_2P2KW;

    fn sample() -> MotorRecord {
        MotorRecord {
            motor: MOTOR_2P2KW.motor,
            supply: MOTOR_2P2KW.supply,
            current_full_scale_a: 20.0,
            voltage_full_scale_v: 500.0,
            current_offset_counts: [2047.0, 2050.5, 2044.0],
            voltage_offset_counts: [2048.0, 2046.0, 2049.0],
            encoder_lines: 1024,
            encoder_reversed: true,
        }
    }

    #[test]
    fn crc32_check_value() {
        // The standard check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn round_trip_and_header() {
        let bytes = sample().to_bytes();
        assert_eq!(&bytes[..4], b"MREC");
        assert_eq!(bytes[4..6], [1, 0]);
        assert_eq!(bytes[6..8], [128, 0]);
        assert_eq!(MotorRecord::parse(&bytes), Ok(sample()));
        let mut page = [0xFFu8; 2048];
        page[..STORED_LEN].copy_from_slice(&bytes);
        assert_eq!(MotorRecord::parse(&page), Ok(sample()));
    }

    #[test]
    fn every_single_bit_flip_is_rejected() {
        let bytes = sample().to_bytes();
        for bit in 0..STORED_LEN * 8 {
            let mut b = bytes;
            b[bit / 8] ^= 1 << (bit % 8);
            assert!(MotorRecord::parse(&b).is_err(), "bit {bit}");
        }
    }

    #[test]
    fn erased_truncated_old_and_invalid() {
        let bytes = sample().to_bytes();
        assert_eq!(MotorRecord::parse(&[0xFF; 2048]), Err(RecordError::Magic));
        assert_eq!(
            MotorRecord::parse(&bytes[..STORED_LEN - 1]),
            Err(RecordError::Truncated)
        );
        let mut old = bytes;
        old[4] = 0;
        assert_eq!(MotorRecord::parse(&old), Err(RecordError::Version));
        let mut bad = sample();
        bad.motor.poles = 3;
        assert_eq!(
            MotorRecord::parse(&bad.to_bytes()),
            Err(RecordError::Invalid)
        );
    }
}
