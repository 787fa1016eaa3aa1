//! The boot block: what the boot keeps in RAM across a reset beside the reset record
//! (cortex-m-rt's `.uninit`, which the start-up code leaves alone), so that no boot loop
//! goes unseen.
//!
//! - **The phase mark**: the [`BootPhase`] the run entered last, written before each step
//!   that may hang (the clock set-up first, before embassy-stm32's `init`, whose waits for
//!   the crystal and the PLL have no bound). A watchdog reset with no record is then
//!   placed by the next boot ("the firmware hung in its clock phase",
//!   `PreviousRun::hung_in`).
//! - **Failed boots in a row**: a run that failed (a reset record, or a watchdog reset with
//!   none: `PreviousRun::failed`) before it was **up** (sampling with the watchdog petted
//!   for [`UP_AFTER_MS`]) and was reset by the firmware (`ResetSource::caused_by_firmware`:
//!   the watchdog, the fault path's software reset) counts one more; a run that was up, or
//!   a reset the firmware did not cause (power-on, brown-out, the reset button, a debugger's
//!   reset during a stall's or a set-up's record, `PreviousRun::ResetDuring`), starts the
//!   count again, whatever record the run left.
//!   After [`SAFE_MODE_AFTER`] failed boots in a row the boot enters the safe mode
//!   (`crate::startup`): it blinks its code and records why instead of failing again.
//! - **Long up**: the run was up for [`LONG_UP_AFTER_MS`]: the next boot writes the reset
//!   log's "up" mark, which gives the log's rate limit its full entries back
//!   (`reset_record::log`).
//! - **Whether RAM survived**: a valid block after a reset by the power-on/brown-out flag
//!   (`RCC_CSR.BORRSTF`, which both set) means the supply dipped below the brown-out level
//!   but not far enough to lose RAM: a brown-out; no valid block, a power-on ([`ResetKind`]).
//! - **The reset log's counts not yet in flash** ([`Pending`]): a boot counts its reset here
//!   instead of writing it, until the write is due (`crate::reset_record::log::record_boot`),
//!   so a supply chattering at the brown-out threshold costs the log one write every
//!   [`FLUSH_AFTER`](crate::reset_record::log::FLUSH_AFTER) boots, not one a boot.
//!
//! # RecordLayout ([`BOOT_BLOCK_LEN`] = 32 bytes, the project's record format, magic `DMBB`)
//!
//! | bytes | field |
//! |---|---|
//! | 0..8 | header: magic `DMBB`, version 2, length 20 ([`monitor_core::record`]) |
//! | 8 | the phase mark ([`BootPhase::number`]; 255: none) |
//! | 9 | failed boots in a row |
//! | 10 | flags: bit 0 up, bit 1 long up |
//! | 11 | reserved, 0 |
//! | 12..28 | the counts not yet in flash ([`Pending::encode`]) |
//! | 28..32 | CRC-32 of bytes 0..28 |
//!
//! Version 1 (16 bytes, without the counts) is not read: the block lives in RAM across one
//! reset, and the first boot after an update reads none (a power-on).

pub use crate::reset_record::log::Pending;
use crate::reset_record::log::PENDING_LEN;
pub use crate::reset_record::ResetKind;
use crate::reset_record::{BootPhase, PreviousRun, ResetSource};
use monitor_core::record::{RecordFormat, RecordLayout, CRC_LEN, HEADER_LEN};

/// Bytes of the block.
pub const BOOT_BLOCK_LEN: usize = 32;
/// Failed boots in a row after which the boot enters the safe mode.
pub const SAFE_MODE_AFTER: u8 = 5;
pub use crate::liveness::{LONG_UP_AFTER_MS, UP_AFTER_MS};

/// The block's format: magic `DMBB`, version 1.
pub const FORMAT: RecordFormat = RecordFormat {
    magic: *b"DMBB",
    current: RecordLayout {
        version: 2,
        stored_len: BOOT_BLOCK_LEN,
        length: (BOOT_BLOCK_LEN - HEADER_LEN - CRC_LEN) as u16,
    },
    older: &[],
};

/// No phase marked.
const NO_PHASE: u8 = 0xFF;
/// Flag bits.
const FLAG_UP: u8 = 1;
const FLAG_LONG_UP: u8 = 2;

/// The block's content (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BootBlock {
    /// The phase the run entered last (`None`: none marked yet).
    pub phase: Option<BootPhase>,
    /// Failed boots in a row, this run's boot included when it followed one.
    pub failed_boots: u8,
    /// The run is up ([`UP_AFTER_MS`]).
    pub up: bool,
    /// The run is long up ([`LONG_UP_AFTER_MS`]).
    pub long_up: bool,
    /// The reset log's counts not yet in flash.
    pub pending: Pending,
}

impl BootBlock {
    /// The bytes to keep in RAM.
    pub fn encode(&self) -> [u8; BOOT_BLOCK_LEN] {
        let mut w = FORMAT.writer::<BOOT_BLOCK_LEN>();
        let flags = (u8::from(self.up) * FLAG_UP) | (u8::from(self.long_up) * FLAG_LONG_UP);
        w.bytes(&[
            self.phase.map_or(NO_PHASE, BootPhase::number),
            self.failed_boots,
            flags,
            0,
        ]);
        w.bytes(&self.pending.encode());
        w.finish()
    }

    /// The block in `bytes`, or `None` (power-on garbage, another layout).
    pub fn decode(bytes: &[u8; BOOT_BLOCK_LEN]) -> Option<BootBlock> {
        let mut r = FORMAT.open(bytes).ok()?;
        let [phase, failed_boots, flags, _] = r.take::<4>().ok()?;
        let pending = Pending::decode(&r.take::<PENDING_LEN>().ok()?);
        Some(BootBlock {
            phase: BootPhase::from_number(phase),
            failed_boots,
            up: flags & FLAG_UP != 0,
            long_up: flags & FLAG_LONG_UP != 0,
            pending,
        })
    }

    /// The same block with `phase` marked.
    #[must_use]
    pub fn in_phase(self, phase: BootPhase) -> BootBlock {
        BootBlock {
            phase: Some(phase),
            ..self
        }
    }

    /// The same block marked up (the failed boots in a row end), and long up with `long`.
    #[must_use]
    pub fn marked_up(self, long: bool) -> BootBlock {
        BootBlock {
            failed_boots: 0,
            up: true,
            long_up: self.long_up || long,
            ..self
        }
    }
}

/// What the boot concludes from the block the previous run left and the reset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BootHistory {
    /// The reset's kind.
    pub kind: ResetKind,
    /// Failed boots in a row, counting the previous run's if it failed before it was up.
    pub failed_boots: u8,
    /// The previous run's phase mark (`None`: RAM lost, or none marked).
    pub last_phase: Option<BootPhase>,
    /// The previous run was long up (the reset log's "up" mark is due).
    pub previous_long_up: bool,
    /// The previous run was up (the counts in RAM are written now).
    pub previous_up: bool,
    /// RAM survived the reset (the previous run's block was valid).
    pub ram_kept: bool,
    /// The reset log's counts the previous runs left in RAM.
    pub pending: Pending,
}

impl BootHistory {
    /// The history from the block the previous run left (`left`: `None` when RAM did not
    /// keep one), the reset's `source` and the previous run's end (`previous`, from the
    /// reset record and the flags).
    pub fn of(left: Option<BootBlock>, source: ResetSource, previous: &PreviousRun) -> Self {
        let kind = ResetKind::of(source, left.is_some());
        let before = left.unwrap_or_default();
        // A stall's or a set-up's record with another reset than the watchdog's: someone
        // (the button, a debugger, the supply) reset the MCU before the firmware would have.
        let reset_by_someone = matches!(previous, PreviousRun::ResetDuring { .. });
        let failed = previous.failed() && source.caused_by_firmware() && !reset_by_someone;
        let failed_boots = if failed && !before.up {
            before.failed_boots.saturating_add(1)
        } else {
            0
        };
        BootHistory {
            kind,
            failed_boots,
            last_phase: before.phase,
            previous_long_up: before.long_up,
            previous_up: before.up,
            ram_kept: left.is_some(),
            pending: before.pending,
        }
    }

    /// Whether the boot enters the safe mode: [`SAFE_MODE_AFTER`] failed boots in a row.
    pub const fn safe_mode(&self) -> bool {
        self.failed_boots >= SAFE_MODE_AFTER
    }

    /// The block this run starts with: its failed boots in a row, not up, the counts the
    /// previous runs left.
    pub const fn block(&self) -> BootBlock {
        BootBlock {
            phase: None,
            failed_boots: self.failed_boots,
            up: false,
            long_up: false,
            pending: self.pending,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reset_record::ResetRecord;

    #[test]
    fn the_block_round_trips_and_garbage_is_no_block() {
        let b = BootBlock {
            phase: Some(BootPhase::Clock),
            failed_boots: 3,
            up: false,
            long_up: true,
            pending: Pending::EMPTY,
        };
        assert_eq!(BootBlock::decode(&b.encode()), Some(b));
        assert_eq!(BootBlock::decode(&[0x5A; BOOT_BLOCK_LEN]), None);
        assert_eq!(BootBlock::decode(&[0; BOOT_BLOCK_LEN]), None);
        // The header the module docs give: magic, version 2, a payload of 20 bytes.
        assert_eq!(b.encode()[..8], *b"DMBB\x02\x00\x14\x00");
        assert_eq!(b.encode()[8..12], [BootPhase::Clock.number(), 3, 2, 0]);
        // The counts in RAM round trip: a brown-out twice, a failed watchdog reset once.
        let mut pending = Pending::EMPTY;
        assert!(pending.add(ResetKind::BrownOut, false, false));
        assert!(pending.add(ResetKind::BrownOut, false, false));
        assert!(pending.add(ResetKind::Watchdog, true, false));
        let with = BootBlock { pending, ..b };
        let bytes = with.encode();
        assert_eq!(BootBlock::decode(&bytes), Some(with));
        assert_eq!(
            bytes[12..20],
            [
                ResetKind::BrownOut.index() as u8,
                0,
                2,
                0,
                0x40 | 3,
                0,
                1,
                0
            ]
        );
        assert_eq!(BootBlock::decode(&bytes).unwrap().pending.count(), 3);
        // Every flag alone round trips.
        for (up, long_up) in [(false, false), (true, false), (false, true), (true, true)] {
            let b = BootBlock {
                up,
                long_up,
                ..BootBlock::default()
            };
            assert_eq!(BootBlock::decode(&b.encode()), Some(b));
        }
        // Marked up: the failed boots in a row end there.
        let marked = b.marked_up(false);
        assert_eq!(
            (marked.failed_boots, marked.up, marked.long_up),
            (0, true, true)
        );
    }

    /// Five runs that fail before they are up: the sixth boot is the safe mode's. A run
    /// that was up, a reset the firmware did not cause, a clean end: the count starts
    /// again.
    #[test]
    fn failed_boots_in_a_row_lead_to_the_safe_mode_and_anything_else_starts_again() {
        let hung = PreviousRun::WatchdogReset { phase: None };
        let wd = ResetSource::IndependentWatchdog;
        let mut left = None;
        let mut history = Vec::new();
        for _ in 0..6 {
            let h = BootHistory::of(left, wd, &hung);
            history.push((h.failed_boots, h.safe_mode()));
            left = Some(h.block().in_phase(BootPhase::Clock));
        }
        assert_eq!(
            history,
            [
                (1, false),
                (2, false),
                (3, false),
                (4, false),
                (5, true),
                (6, true)
            ]
        );
        // The first boot after power-on (no block) counts the hang it follows as one.
        assert_eq!(BootHistory::of(None, wd, &hung).failed_boots, 1);
        let four = BootBlock {
            failed_boots: 4,
            ..BootBlock::default()
        };
        assert!(BootHistory::of(Some(four), wd, &hung).safe_mode());
        // Up before it failed: no boot loop.
        assert_eq!(
            BootHistory::of(Some(four.marked_up(false)), wd, &hung).failed_boots,
            0
        );
        // The reset button, a power-on, a clean end: not a failure.
        let pin = BootHistory::of(Some(four), ResetSource::Pin, &PreviousRun::Clean);
        assert_eq!((pin.failed_boots, pin.kind), (0, ResetKind::Pin));
        // A panic's record with the fault path's software reset counts (and the watchdog's,
        // when the software reset did not come)...
        let panic = PreviousRun::Recorded(ResetRecord::panic("x", "f.rs", 1));
        let sw = BootHistory::of(Some(four), ResetSource::Software, &panic);
        assert!(sw.safe_mode() && sw.kind == ResetKind::Software);
        assert!(BootHistory::of(Some(four), wd, &panic).safe_mode());
        // ... but the reset button, a brown-out or a power-on after it is a person's or the
        // supply's: the count starts again.
        for source in [ResetSource::Pin, ResetSource::PowerOnOrBrownOut] {
            assert_eq!(BootHistory::of(Some(four), source, &panic).failed_boots, 0);
        }
    }

    /// A stalled sample path writes its record and the watchdog ends the run 200 ms later:
    /// that counts. The reset button pressed (or a debugger's reset) before the watchdog's:
    /// the count starts again, and the boot still reports the stall (`ResetDuring`).
    #[test]
    fn a_button_press_after_a_stall_starts_the_count_again() {
        let stall = ResetRecord::sample_stall(300).encode();
        let four = BootBlock {
            failed_boots: 4,
            ..BootBlock::default()
        };
        let wd = ResetSource::IndependentWatchdog;
        let by_watchdog = PreviousRun::at_boot(&stall, wd);
        assert!(BootHistory::of(Some(four), wd, &by_watchdog).safe_mode());
        for source in [ResetSource::Pin, ResetSource::Software] {
            let pressed = PreviousRun::at_boot(&stall, source);
            assert!(
                matches!(pressed, PreviousRun::ResetDuring { .. }),
                "{source:?}"
            );
            let h = BootHistory::of(Some(four), source, &pressed);
            assert_eq!((h.failed_boots, h.safe_mode()), (0, false), "{source:?}");
        }
        // The firmware's resets and the others', by the flags.
        for (source, firmware) in [
            (wd, true),
            (ResetSource::WindowWatchdog, true),
            (ResetSource::Software, true),
            (ResetSource::LowPower, true),
            (ResetSource::Pin, false),
            (ResetSource::PowerOnOrBrownOut, false),
            (ResetSource::OptionBytes, false),
            (ResetSource::Unknown, false),
        ] {
            assert_eq!(source.caused_by_firmware(), firmware, "{source:?}");
        }
    }

    #[test]
    fn the_power_on_flag_is_a_brown_out_when_ram_survived() {
        let block = Some(BootBlock::default());
        let src = ResetSource::PowerOnOrBrownOut;
        let clean = PreviousRun::Clean;
        assert_eq!(
            BootHistory::of(block, src, &clean).kind,
            ResetKind::BrownOut
        );
        assert_eq!(BootHistory::of(None, src, &clean).kind, ResetKind::PowerOn);
        let long = BootBlock::default()
            .marked_up(true)
            .in_phase(BootPhase::Sampling);
        let h = BootHistory::of(Some(long), ResetSource::Pin, &clean);
        assert!(h.previous_long_up);
        assert_eq!(h.last_phase, Some(BootPhase::Sampling));
        for (k, kind) in ResetKind::ALL.iter().enumerate() {
            assert_eq!(kind.index(), k);
        }
    }

    /// Four kinds of counts in the four slots round trip through the block; a full slot
    /// (65 535 counts, the writes refused all along) takes no more: nothing wraps.
    #[test]
    fn the_counts_in_ram_fill_four_slots_and_never_wrap() {
        let mut pending = Pending::EMPTY;
        for (k, kind) in [
            ResetKind::BrownOut,
            ResetKind::Pin,
            ResetKind::Software,
            ResetKind::Watchdog,
        ]
        .into_iter()
        .enumerate()
        {
            for _ in 0..=k {
                assert!(pending.add(kind, kind == ResetKind::Watchdog, false));
            }
        }
        assert!(!pending.add(ResetKind::Other, false, false), "a fifth kind");
        let block = BootBlock {
            pending,
            ..BootBlock::default()
        };
        let back = BootBlock::decode(&block.encode()).unwrap();
        assert_eq!(back.pending, pending);
        assert_eq!(back.pending.count(), 1 + 2 + 3 + 4);
        // A slot at 65 535: full.
        let mut bytes = [0u8; crate::reset_record::log::PENDING_LEN];
        bytes[..4].copy_from_slice(&[ResetKind::BrownOut.index() as u8, 0, 0xFF, 0xFF]);
        let mut full = Pending::decode(&bytes);
        assert_eq!(full.count(), 65_535);
        assert!(!full.add(ResetKind::BrownOut, false, false));
        assert_eq!(full.count(), 65_535);
    }
}
