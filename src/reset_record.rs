//! Why the previous run ended: a small record in RAM that survives a reset.
//!
//! The panic handler (and thread mode, when the sample path has stalled long enough that
//! the watchdog is about to reset the MCU) writes a [`ResetRecord`] into a RAM area the
//! start-up code leaves alone (cortex-m-rt's `.uninit` section). The next boot reads it:
//! a valid record (magic, then a CRC-32 over the rest) is logged and shown, then erased;
//! anything else (power-on garbage, an erased record) means "no reason recorded". So a
//! panic, a stalled sample path and a hang without either no longer all read "watchdog
//! reset".
//!
//! # Layout ([`RESET_RECORD_LEN`] = 128 bytes, little endian)
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `b"DMRR"` |
//! | 4 | cause: 1 = panic, 2 = sample path stalled |
//! | 5 | message length (0..=[`MESSAGE_LEN`]) |
//! | 6 | file length (0..=[`FILE_LEN`]) |
//! | 7 | reserved, zero |
//! | 8..12 | line (panic) or stall time in ms (stall), `u32` |
//! | 12..76 | message, UTF-8, zero padded |
//! | 76..124 | file (the end of the path), UTF-8, zero padded |
//! | 124..128 | CRC-32 of bytes 0..124 ([`crate::flash_record::crc32`]) |

use crate::flash_record::crc32;

/// Encoded length of a record, bytes.
pub const RESET_RECORD_LEN: usize = 128;
/// Longest message kept, bytes (longer ones are cut at a character boundary).
pub const MESSAGE_LEN: usize = 64;
/// Longest file path kept, bytes (longer paths keep their end: the file name).
pub const FILE_LEN: usize = 48;
const MAGIC: [u8; 4] = *b"DMRR";
const MESSAGE_AT: usize = 12;
const FILE_AT: usize = MESSAGE_AT + MESSAGE_LEN;
const CRC_AT: usize = FILE_AT + FILE_LEN;

/// What ended the previous run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetCause {
    /// A panic: the message and where it was raised.
    Panic,
    /// No samples arrived and the restarts did not help; the watchdog reset the MCU.
    SampleStall,
}

/// The record: the cause, a message, and a location (panic) or a duration (stall).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResetRecord {
    cause: ResetCause,
    number: u32,
    message: Text<MESSAGE_LEN>,
    file: Text<FILE_LEN>,
}

/// Up to `N` bytes of UTF-8 text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Text<const N: usize> {
    bytes: [u8; N],
    len: u8,
}

impl<const N: usize> Text<N> {
    /// `s`, cut to at most `N` bytes at a character boundary: its start, or with
    /// `keep_end` its end.
    fn new(s: &str, keep_end: bool) -> Self {
        let mut from = 0;
        let mut to = s.len();
        if s.len() > N {
            if keep_end {
                from = s.len() - N;
                while !s.is_char_boundary(from) {
                    from += 1;
                }
            } else {
                to = N;
                while !s.is_char_boundary(to) {
                    to -= 1;
                }
            }
        }
        let kept = s.get(from..to).unwrap_or("").as_bytes();
        let mut bytes = [0u8; N];
        for (dst, src) in bytes.iter_mut().zip(kept) {
            *dst = *src;
        }
        Self {
            bytes,
            len: kept.len().min(N) as u8,
        }
    }

    fn from_bytes(bytes: &[u8], len: u8) -> Option<Self> {
        let mut out = Self { bytes: [0; N], len };
        for (dst, src) in out.bytes.iter_mut().zip(bytes) {
            *dst = *src;
        }
        core::str::from_utf8(out.bytes.get(..usize::from(len))?).ok()?;
        Some(out)
    }

    fn as_str(&self) -> &str {
        let bytes = self.bytes.get(..usize::from(self.len)).unwrap_or(&[]);
        core::str::from_utf8(bytes).unwrap_or("")
    }
}

impl ResetRecord {
    /// A panic with `message` at `file`:`line`.
    pub fn panic(message: &str, file: &str, line: u32) -> Self {
        Self {
            cause: ResetCause::Panic,
            number: line,
            message: Text::new(message, false),
            file: Text::new(file, true),
        }
    }

    /// A stalled sample path, `stalled_ms` without samples when recorded.
    pub fn sample_stall(stalled_ms: u32) -> Self {
        Self {
            cause: ResetCause::SampleStall,
            number: stalled_ms,
            message: Text::new("sample path stalled", false),
            file: Text::new("", true),
        }
    }

    /// The cause.
    pub fn cause(&self) -> ResetCause {
        self.cause
    }

    /// The message (possibly cut to [`MESSAGE_LEN`] bytes).
    pub fn message(&self) -> &str {
        self.message.as_str()
    }

    /// The file of a panic (its last [`FILE_LEN`] bytes); empty for a stall.
    pub fn file(&self) -> &str {
        self.file.as_str()
    }

    /// The line of a panic; the time without samples, ms, for a stall.
    pub fn line_or_ms(&self) -> u32 {
        self.number
    }

    /// The bytes to keep in RAM (layout in the module docs).
    pub fn encode(&self) -> [u8; RESET_RECORD_LEN] {
        let mut out = [0u8; RESET_RECORD_LEN];
        let header = [
            MAGIC[0],
            MAGIC[1],
            MAGIC[2],
            MAGIC[3],
            match self.cause {
                ResetCause::Panic => 1,
                ResetCause::SampleStall => 2,
            },
            self.message.len,
            self.file.len,
            0,
        ];
        let number = self.number.to_le_bytes();
        let fields = header
            .iter()
            .chain(number.iter())
            .chain(self.message.bytes.iter())
            .chain(self.file.bytes.iter());
        for (dst, src) in out.iter_mut().zip(fields) {
            *dst = *src;
        }
        let crc = crc32(out.get(..CRC_AT).unwrap_or(&[]));
        if let Some(dst) = out.get_mut(CRC_AT..) {
            dst.copy_from_slice(&crc.to_le_bytes());
        }
        out
    }

    /// The record in `bytes`, or `None` when they do not hold one (wrong magic or CRC,
    /// an unknown cause, lengths out of range, text that is not UTF-8).
    pub fn decode(bytes: &[u8; RESET_RECORD_LEN]) -> Option<Self> {
        let (body, crc) = bytes.split_at(CRC_AT);
        if body.get(..4)? != MAGIC || crc32(body).to_le_bytes() != *crc {
            return None;
        }
        let cause = match body.get(4)? {
            1 => ResetCause::Panic,
            2 => ResetCause::SampleStall,
            _ => return None,
        };
        let (message_len, file_len) = (*body.get(5)?, *body.get(6)?);
        if usize::from(message_len) > MESSAGE_LEN || usize::from(file_len) > FILE_LEN {
            return None;
        }
        let mut number = [0u8; 4];
        number.copy_from_slice(body.get(8..12)?);
        Some(Self {
            cause,
            number: u32::from_le_bytes(number),
            message: Text::from_bytes(body.get(MESSAGE_AT..FILE_AT)?, message_len)?,
            file: Text::from_bytes(body.get(FILE_AT..CRC_AT)?, file_len)?,
        })
    }
}

/// What the previous run ended with, as the boot sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PreviousRun {
    /// A power-on or a reset with no record and no watchdog flag.
    Clean,
    /// A record says why (a panic or a stalled sample path).
    Recorded(ResetRecord),
    /// The watchdog reset the MCU and nothing recorded why: the firmware hung.
    WatchdogReset,
}

impl PreviousRun {
    /// From the record area's bytes and the watchdog reset flag.
    pub fn at_boot(record: &[u8; RESET_RECORD_LEN], watchdog_reset: bool) -> Self {
        match ResetRecord::decode(record) {
            Some(rec) => PreviousRun::Recorded(rec),
            None if watchdog_reset => PreviousRun::WatchdogReset,
            None => PreviousRun::Clean,
        }
    }

    /// The previous run failed (the panel shows "monitor failed" for a while).
    pub fn failed(&self) -> bool {
        !matches!(self, PreviousRun::Clean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_round_trips_and_long_texts_keep_their_useful_end() {
        let rec = ResetRecord::panic("index out of bounds", "src/app.rs", 42);
        let back = ResetRecord::decode(&rec.encode()).unwrap();
        assert_eq!(back, rec);
        assert_eq!(
            (back.cause(), back.message(), back.file(), back.line_or_ms()),
            (ResetCause::Panic, "index out of bounds", "src/app.rs", 42)
        );
        let long_path =
            "/home/someone/.cargo/registry/src/index/embassy-stm32-0.6.0/src/adc/ringbuffered.rs";
        // 81 bytes; byte 64 is inside a character, so the cut falls before it.
        let long_msg = format!("a{}", "é".repeat(40));
        let rec = ResetRecord::panic(&long_msg, long_path, 7);
        let back = ResetRecord::decode(&rec.encode()).unwrap();
        assert_eq!(back.message(), format!("a{}", "é".repeat(31)));
        assert!(back.file().ends_with("src/adc/ringbuffered.rs"));
        assert!(back.file().len() <= FILE_LEN);
        let stall = ResetRecord::sample_stall(300);
        assert_eq!(ResetRecord::decode(&stall.encode()), Some(stall));
    }

    #[test]
    fn anything_but_an_intact_record_reads_as_none() {
        let good = ResetRecord::panic("boom", "src/main.rs", 1).encode();
        for bit in 0..RESET_RECORD_LEN * 8 {
            let mut bad = good;
            bad[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(ResetRecord::decode(&bad), None, "bit {bit}");
        }
        assert_eq!(ResetRecord::decode(&[0; RESET_RECORD_LEN]), None);
        assert_eq!(ResetRecord::decode(&[0xA5; RESET_RECORD_LEN]), None);
        assert_eq!(
            PreviousRun::at_boot(&[0; RESET_RECORD_LEN], true),
            PreviousRun::WatchdogReset
        );
        assert_eq!(
            PreviousRun::at_boot(&[0; RESET_RECORD_LEN], false),
            PreviousRun::Clean
        );
        assert!(matches!(
            PreviousRun::at_boot(&good, true),
            PreviousRun::Recorded(r) if r.cause() == ResetCause::Panic
        ));
    }
}
