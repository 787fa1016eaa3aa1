//! The motor record: the board's own machine, stored in a flash page and written from the
//! host (`sim-host board-record P.toml --out motor.bin`, `docs/firmware.md`).
//!
//! One little-endian fixed layout of [`RECORD_LEN`] = 128 bytes, parsed here only (the
//! firmware and the host's tests use [`MotorRecord::parse`]):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `"MREC"` ([`FORMAT`]) |
//! | 4 | 2 | version [`VERSION`] |
//! | 6 | 2 | length [`RECORD_LEN`] |
//! | 8 | 64 | `[motor]` `rs_ohm rr_ohm ls_h lr_h lm_h j_kgm2 b_nms bl_nms`, `f64` each |
//! | 72 | 4 | `[motor]` `poles`, `u32` |
//! | 76 | 16 | `[supply]` `v_ll_rms f_hz`, `f64` each |
//! | 92 | 8 | sensor full scale: current [A], voltage [V], `f32` each |
//! | 100 | 24 | sensor offsets: currents a, b, c then voltages a, b, c [ADC counts], `f32` each |
//! | 124 | 2 | encoder lines per revolution, `u16` (counts = 4 x lines) |
//! | 126 | 2 | encoder flags, `u16`: bit 0 reversed ([`ENCODER_REVERSED`]), bit 1 internal pull-ups off ([`ENCODER_NO_PULL_UP`]), the other bits 0 |
//! | 128 | 4 | CRC-32/ISO-HDLC of bytes 0..128 ([`crate::record::crc32`]) |
//!
//! so the record with its CRC is [`RECORD_LEN`] + 4 = 132 bytes.
//!
//! # The encoder flags
//!
//! The word at 126 was the encoder's direction (0 forward, 1 reversed), and the firmware
//! turned the encoder inputs' internal pull-ups on whatever the record said. Bit 1 now
//! turns them off; its zero value is what every record written before meant, so those
//! records read unchanged (pull-ups on) and a record with the pull-ups on is written byte for
//! byte as before, still version 1. A firmware built before this bit rejects a record that
//! sets it ([`RecordError::Invalid`]: it read only 0 and 1) and falls back to its built-in
//! default, never to a wrong encoder setting. Any other bit set is
//! [`RecordError::Invalid`] here too, so a later flag cannot be misread by this reader. Header, CRC, reader and
//! writer are the project's one record format ([`crate::record`]: the length field holds
//! the bytes the CRC covers). A record that fails any check is rejected with a
//! [`RecordError`]; the caller falls back to its built-in default.

use crate::machine::{MotorParameters, SupplyParameters};
pub use crate::record::RecordError;
use crate::record::{RecordFormat, RecordLayout, RecordReader};

/// The layout's version; a record of another version is [`RecordError::Version`].
pub const VERSION: u16 = 1;
/// Bytes covered by the CRC (header and payload).
pub const RECORD_LEN: usize = 128;
/// Bytes of a stored record: [`RECORD_LEN`] plus the 4-byte CRC.
pub const STORED_LEN: usize = RECORD_LEN + 4;

/// Bit 0 of the encoder flags: the encoder counts down when the motor turns forward.
pub const ENCODER_REVERSED: u16 = 1 << 0;
/// Bit 1 of the encoder flags: the internal pull-ups on the encoder inputs A and B are off
/// (clear: on, as in every record written before the bit existed; module docs).
pub const ENCODER_NO_PULL_UP: u16 = 1 << 1;
/// The encoder flags this reader knows; a record with any other bit set is
/// [`RecordError::Invalid`].
const ENCODER_FLAGS: u16 = ENCODER_REVERSED | ENCODER_NO_PULL_UP;

/// The motor record's format: magic `MREC`, version [`VERSION`], [`STORED_LEN`] bytes.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"MREC",
    current: RecordLayout {
        version: VERSION,
        stored_len: STORED_LEN,
        length: RECORD_LEN as u16,
    },
    older: &[],
};

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
    /// The encoder counts down when the motor turns forward ([`ENCODER_REVERSED`]).
    pub encoder_reversed: bool,
    /// The MCU's internal pull-ups (about 40 kohm) on the encoder inputs A and B: needed by
    /// an open-collector encoder; off ([`ENCODER_NO_PULL_UP`] set) for one that drives both
    /// levels or has pull-ups of its own on the board. `true` in records written before the
    /// flag existed (module docs, "The encoder flags").
    pub encoder_pull_up: bool,
}

impl MotorRecord {
    /// The stored form ([`STORED_LEN`] bytes, layout in the module docs), CRC included.
    pub fn to_bytes(&self) -> [u8; STORED_LEN] {
        let mut w = FORMAT.writer::<STORED_LEN>();
        let m = &self.motor;
        for x in [
            m.rs_ohm, m.rr_ohm, m.ls_h, m.lr_h, m.lm_h, m.j_kgm2, m.b_nms, m.bl_nms,
        ] {
            w.f64(x);
        }
        w.u32(m.poles);
        w.f64(self.supply.v_ll_rms);
        w.f64(self.supply.f_hz);
        w.f32(self.current_full_scale_a);
        w.f32(self.voltage_full_scale_v);
        w.f32s(&self.current_offset_counts);
        w.f32s(&self.voltage_offset_counts);
        w.u16(self.encoder_lines);
        w.u16(self.encoder_flags());
        w.finish()
    }

    /// The encoder flags word (module docs): [`ENCODER_REVERSED`] and
    /// [`ENCODER_NO_PULL_UP`] as the record's fields say.
    pub fn encoder_flags(&self) -> u16 {
        let reversed = if self.encoder_reversed {
            ENCODER_REVERSED
        } else {
            0
        };
        let no_pull_up = if self.encoder_pull_up {
            0
        } else {
            ENCODER_NO_PULL_UP
        };
        reversed | no_pull_up
    }

    /// Parses and checks a stored record (extra bytes after [`STORED_LEN`] are ignored, so a
    /// whole flash page can be passed).
    ///
    /// # Errors
    /// The record module's checks ([`RecordFormat::open`]: truncated, erased, magic, version,
    /// length, CRC), then [`RecordError::Invalid`] for values the core rejects.
    pub fn parse(bytes: &[u8]) -> Result<MotorRecord, RecordError> {
        let mut r = FORMAT.open(bytes)?;
        let record = Self::fields(&mut r)?;
        let scale_ok = |x: f32| x.is_finite() && x > 0.0;
        let valid = record.motor.validate().is_ok()
            && record.supply.validate().is_ok()
            && scale_ok(record.current_full_scale_a)
            && scale_ok(record.voltage_full_scale_v)
            && record
                .current_offset_counts
                .iter()
                .chain(&record.voltage_offset_counts)
                .all(|x| x.is_finite())
            && record.encoder_lines >= 1;
        if valid {
            Ok(record)
        } else {
            Err(RecordError::Invalid)
        }
    }

    /// The payload's fields in order (the encoder flags checked: no unknown bit).
    fn fields(r: &mut RecordReader<'_>) -> Result<MotorRecord, RecordError> {
        let [rs_ohm, rr_ohm, ls_h, lr_h, lm_h, j_kgm2, b_nms, bl_nms] = {
            let mut f = [0.0f64; 8];
            for x in &mut f {
                *x = r.f64()?;
            }
            f
        };
        let motor = MotorParameters {
            rs_ohm,
            rr_ohm,
            ls_h,
            lr_h,
            lm_h,
            poles: r.u32()?,
            j_kgm2,
            b_nms,
            bl_nms,
            rotor_bars: None,
            lm_at: None,
        };
        let supply = SupplyParameters {
            v_ll_rms: r.f64()?,
            f_hz: r.f64()?,
        };
        let current_full_scale_a = r.f32()?;
        let voltage_full_scale_v = r.f32()?;
        let current_offset_counts = r.f32s::<3>()?;
        let voltage_offset_counts = r.f32s::<3>()?;
        let encoder_lines = r.u16()?;
        let flags = r.u16()?;
        if flags & !ENCODER_FLAGS != 0 {
            return Err(RecordError::Invalid);
        }
        Ok(MotorRecord {
            motor,
            supply,
            current_full_scale_a,
            voltage_full_scale_v,
            current_offset_counts,
            voltage_offset_counts,
            encoder_lines,
            encoder_reversed: flags & ENCODER_REVERSED != 0,
            encoder_pull_up: flags & ENCODER_NO_PULL_UP == 0,
        })
    }
}

#[cfg(test)]
#[allow(clippy::indexing_slicing, clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::machine::reference::MOTOR_2P2KW;

    fn sample() -> MotorRecord {
        MotorRecord {
            // The record holds the equations' values; which Lm a file holds (`lm_at`) is
            // the host's saturation law's alone and not in it.
            motor: MotorParameters {
                lm_at: None,
                ..MOTOR_2P2KW.motor
            },
            supply: MOTOR_2P2KW.supply,
            current_full_scale_a: 20.0,
            voltage_full_scale_v: 500.0,
            current_offset_counts: [2047.0, 2050.5, 2044.0],
            voltage_offset_counts: [2048.0, 2046.0, 2049.0],
            encoder_lines: 1024,
            encoder_reversed: true,
            encoder_pull_up: true,
        }
    }

    /// `sample()` as the motor record's code before the record module wrote it (its own
    /// field writer and bit-by-bit CRC-32).
    const WRITTEN_BEFORE: &str = "4d524543010080009a99999999990d4000000000000004405c8fc2f5285ccf3ff4fdd478e926d13f5c8fc2f5285ccf3fb81e85eb51b88e3f7b14ae47e17a743ff6285c8fc2f5b83f04000000000000000000794000000000000049400000a0410000fa4300e0ff44002800450080ff440000004500c0ff44001000450004010081c1ded8";

    fn from_hex(s: &str) -> Vec<u8> {
        (0..s.len() / 2)
            .map(|k| u8::from_str_radix(&s[2 * k..2 * k + 2], 16).unwrap_or(0))
            .collect()
    }

    #[test]
    fn a_record_written_by_the_former_code_reads_and_is_rewritten_byte_for_byte() {
        let old = from_hex(WRITTEN_BEFORE);
        assert_eq!(MotorRecord::parse(&old), Ok(sample()));
        assert_eq!(sample().to_bytes().as_slice(), old.as_slice());
    }

    #[test]
    fn a_former_record_reads_with_the_pull_ups_on() {
        let old = from_hex(WRITTEN_BEFORE);
        assert_eq!(old[126..128], [1, 0], "the former direction word: reversed");
        let rec = MotorRecord::parse(&old).unwrap();
        assert!(rec.encoder_pull_up && rec.encoder_reversed);
        // The former code's forward record (word 0), re-sealed with its CRC.
        let mut forward = old.clone();
        forward[126] = 0;
        let crc = crate::record::crc32(&forward[..RECORD_LEN]);
        forward[RECORD_LEN..].copy_from_slice(&crc.to_le_bytes());
        let rec = MotorRecord::parse(&forward).unwrap();
        assert!(rec.encoder_pull_up && !rec.encoder_reversed);
    }

    #[test]
    fn every_encoder_setting_round_trips_and_unknown_flags_are_refused() {
        for (reversed, pull_up, word) in [
            (false, true, 0u16),
            (true, true, 1),
            (false, false, 2),
            (true, false, 3),
        ] {
            let rec = MotorRecord {
                encoder_reversed: reversed,
                encoder_pull_up: pull_up,
                ..sample()
            };
            let bytes = rec.to_bytes();
            assert_eq!(bytes[126..128], word.to_le_bytes(), "{reversed} {pull_up}");
            assert_eq!(bytes[4..6], [1, 0], "still version 1");
            assert_eq!(MotorRecord::parse(&bytes), Ok(rec));
        }
        for word in [4u16, 8, 0x8000, 0xFFFF] {
            let mut bytes = sample().to_bytes();
            bytes[126..128].copy_from_slice(&word.to_le_bytes());
            let crc = crate::record::crc32(&bytes[..RECORD_LEN]);
            bytes[RECORD_LEN..].copy_from_slice(&crc.to_le_bytes());
            assert_eq!(
                MotorRecord::parse(&bytes),
                Err(RecordError::Invalid),
                "{word:#x}"
            );
        }
    }

    #[test]
    fn the_fields_fill_the_layout_exactly() {
        let bytes = sample().to_bytes();
        let mut r = FORMAT.open(&bytes).unwrap();
        assert!(MotorRecord::fields(&mut r).is_ok());
        assert_eq!(r.remaining(), 0);
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
        assert_eq!(MotorRecord::parse(&[0xFF; 2048]), Err(RecordError::Erased));
        assert_eq!(
            MotorRecord::parse(&bytes[..STORED_LEN - 1]),
            Err(RecordError::Truncated)
        );
        let mut old = bytes;
        old[4] = 0;
        assert_eq!(MotorRecord::parse(&old), Err(RecordError::Version(0)));
        let mut bad = sample();
        bad.motor.poles = 3;
        assert_eq!(
            MotorRecord::parse(&bad.to_bytes()),
            Err(RecordError::Invalid)
        );
    }
}
