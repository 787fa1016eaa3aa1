//! A stored commissioning record that is not exactly what the firmware wrote is never
//! used: every single-bit flip, a wrong version, a truncated record, an erased page and
//! values the core would reject all come back as errors. And a power cut at any step of a
//! store (the erase, each double word of the write) leaves the old record or the new one in
//! force, never none: the two pages in turn.

use drive_monitor::app::{Command, SamplePath};
use drive_monitor::flash_record::{
    crc32, load, store, CalibrationRecord, LoadError, RecordError, RecordPage, RecordStore,
    RECORD_LEN, RECORD_VERSION,
};
use monitor_core::isolation::{Baseline, ParityResiduals};

/// A record with the isolation baseline (every byte of the layout in use).
fn record() -> CalibrationRecord {
    CalibrationRecord {
        mean: [0.01, -0.02, 0.003, 0.0],
        spread: [0.05, 0.04, 0.06, 0.07],
        isolation: Some(Baseline {
            mean: ParityResiduals::from_array([1e-4, -2e-4, 3e-3]),
            spread: ParityResiduals::from_array([4e-4, 4e-4, 1e-3]),
            at: monitor_core::isolation::SteadyPoint {
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
fn every_single_bit_flip_is_rejected() {
    let good = record().encode().unwrap();
    for bit in 0..RECORD_LEN * 8 {
        let mut bad = good;
        bad[bit / 8] ^= 1 << (bit % 8);
        let r = CalibrationRecord::decode(&bad);
        assert!(r.is_err(), "bit {bit} flipped and still accepted: {r:?}");
    }
}

#[test]
fn wrong_version_is_rejected_even_with_a_valid_crc() {
    let mut bad = record().encode().unwrap();
    bad[4..6].copy_from_slice(&(RECORD_VERSION + 1).to_le_bytes());
    let crc = crc32(&bad[..RECORD_LEN - 4]);
    bad[RECORD_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    assert_eq!(
        CalibrationRecord::decode(&bad),
        Err(RecordError::Version(RECORD_VERSION + 1))
    );
}

#[test]
fn truncated_erased_and_torn_records_are_rejected() {
    let good = record().encode().unwrap();
    for len in 0..RECORD_LEN {
        assert_eq!(
            CalibrationRecord::decode(&good[..len]),
            Err(RecordError::Truncated)
        );
    }
    assert_eq!(
        CalibrationRecord::decode(&[0xFF; 2048]),
        Err(RecordError::Erased)
    );
    // Torn write: the first 16 bytes made it, the rest is still erased.
    let mut torn = [0xFFu8; RECORD_LEN];
    torn[..16].copy_from_slice(&good[..16]);
    assert_eq!(CalibrationRecord::decode(&torn), Err(RecordError::Crc));
    assert_eq!(
        CalibrationRecord::decode(&[0u8; RECORD_LEN]),
        Err(RecordError::Magic)
    );
}

#[test]
fn values_out_of_the_cores_range_are_not_applied() {
    // CRC-valid but the core's calibration range excludes it (|mean| > 1).
    let rec = CalibrationRecord {
        mean: [5.0, 0.0, 0.0, 0.0],
        spread: [0.1; 4],
        isolation: None,
        vdda_v: None,
    };
    let bytes = rec.encode().unwrap();
    let decoded = CalibrationRecord::decode(&bytes).unwrap();
    let mut path = SamplePath::for_board(10_000).unwrap();
    assert!(path.command(Command::SetCalibration(decoded)).is_err());
    assert!(path.monitor().calibration().is_none());
    // And a good one is applied.
    assert!(path.command(Command::SetCalibration(record())).is_ok());
    assert!(path.monitor().calibration().is_some());
}

/// Flash records refused below the brown-out goal (`drive_monitor::supply::BorGate`): a
/// commissioning's record at the factory's level 0 is neither erased nor written (the page
/// keeps the old record, and the store says why); at level 4 it is stored.
#[test]
fn records_are_refused_while_the_brown_out_level_is_below_the_goal() {
    use drive_monitor::flash_record::StoreError;
    use drive_monitor::supply::{BorCheck, BorGate, BorLevel, FromBorRefusal};

    #[derive(Debug, PartialEq)]
    enum E {
        Bor(BorCheck),
    }
    impl FromBorRefusal for E {
        fn bor_refused(check: BorCheck) -> Self {
            E::Bor(check)
        }
    }
    /// The two pages and the erases and writes they took.
    struct Page([u8; RECORD_LEN], [u8; RECORD_LEN], u32);
    impl RecordStore for Page {
        type Error = E;
        fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), E> {
            *buf = if page == RecordPage::A {
                self.0
            } else {
                self.1
            };
            Ok(())
        }
        fn erase(&mut self, page: RecordPage) -> Result<(), E> {
            self.write(page, &[0xFF; RECORD_LEN])
        }
        fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), E> {
            match page {
                RecordPage::A => self.0 = *bytes,
                RecordPage::B => self.1 = *bytes,
            }
            self.2 += 1;
            Ok(())
        }
    }
    let old = record().encode().unwrap();
    let erased = [0xFF; RECORD_LEN];
    let mut new = record();
    new.mean[0] = 0.02;
    let factory = BorCheck::of_optr(0xFFEF_F8AA);
    assert_eq!(factory, BorCheck::BelowGoal(BorLevel::Level0));
    let mut gate = BorGate {
        store: Page(old, erased, 0),
        bor: factory,
    };
    let stored = store(&mut gate, &new);
    assert_eq!(stored.written, Err(StoreError::Erase(E::Bor(factory))));
    assert_eq!((gate.store.0, gate.store.1, gate.store.2), (old, erased, 0));
    assert_eq!(stored.read_back, Some(record()));

    let at_goal = BorCheck::of_optr((0xFFEF_F8AA & !(0b111 << 8)) | (4 << 8));
    let mut gate = BorGate {
        store: Page(old, erased, 0),
        bor: at_goal,
    };
    let stored = store(&mut gate, &new);
    assert_eq!(stored.written, Ok(()));
    assert_eq!(stored.read_back, Some(new));
    // The new copy went to the other page; the old one is still there.
    assert_eq!(gate.store.0, old);
    assert_eq!(CalibrationRecord::decode_copy(&gate.store.1), Ok((new, 1)));
}

/// The record's two pages at the level of the flash: an erase, and writes of 8-byte double
/// words (the G4's unit, each with its ECC), and a power cut after `cut_after` more steps
/// (an erase, or one double word): the erase it cuts leaves the page neither erased nor
/// written (its reads fail: an ECC double error), the double word it cuts is torn (its
/// read fails), the later ones never written.
#[derive(Clone)]
struct Cuttable {
    pages: [[u8; RECORD_LEN]; 2],
    /// A read of the page fails (an ECC error in it).
    unreadable: [bool; 2],
    cut_after: Option<u32>,
    powered: bool,
}

#[derive(Debug, PartialEq)]
struct PowerCut;

impl Cuttable {
    fn index(page: RecordPage) -> usize {
        usize::from(page == RecordPage::B)
    }

    /// One step; `false`: the power went during it.
    fn step(&mut self) -> bool {
        if !self.powered {
            return false;
        }
        match self.cut_after.as_mut() {
            Some(0) => {
                self.powered = false;
                false
            }
            Some(n) => {
                *n -= 1;
                true
            }
            None => true,
        }
    }
}

impl RecordStore for Cuttable {
    type Error = PowerCut;
    fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), PowerCut> {
        let k = Self::index(page);
        if !self.powered || self.unreadable[k] {
            return Err(PowerCut);
        }
        *buf = self.pages[k];
        Ok(())
    }
    fn erase(&mut self, page: RecordPage) -> Result<(), PowerCut> {
        let k = Self::index(page);
        if !self.step() {
            // Half erased: neither the old bytes nor all 0xFF, an ECC error to read.
            for b in self.pages[k].iter_mut().step_by(2) {
                *b = 0xFF;
            }
            self.unreadable[k] = true;
            return Err(PowerCut);
        }
        self.pages[k] = [0xFF; RECORD_LEN];
        self.unreadable[k] = false;
        Ok(())
    }
    fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), PowerCut> {
        let k = Self::index(page);
        for (dw, chunk) in bytes.chunks(8).enumerate() {
            if !self.step() {
                // The double word being written is torn: its ECC does not match.
                self.pages[k][dw * 8] = chunk[0];
                self.unreadable[k] = true;
                return Err(PowerCut);
            }
            self.pages[k][dw * 8..dw * 8 + chunk.len()].copy_from_slice(chunk);
        }
        Ok(())
    }
}

/// A power cut at every step of a store (the erase, each of the 13 double words), from
/// every starting point (no record, the record in either page): the next boot finds the
/// old record or the new one, never none (and the new one only once its write completed);
/// the next store after the cut succeeds.
#[test]
fn a_power_cut_at_any_step_of_a_store_keeps_the_old_or_the_new_record() {
    let old = record();
    let mut new = record();
    new.mean[0] = 0.02;
    let mut newer = record();
    newer.mean[1] = 0.03;
    let steps = 1 + (RECORD_LEN / 8) as u32;
    assert_eq!(steps, 14);
    let erased = [0xFF; RECORD_LEN];
    let starts = [
        ("the old copy in A", [old.encode_copy(7).unwrap(), erased]),
        ("the old copy in B", [erased, old.encode_copy(8).unwrap()]),
        (
            "the old copy in B, an older in A",
            [
                record().encode_copy(3).unwrap(),
                old.encode_copy(4).unwrap(),
            ],
        ),
        (
            "a record written before the two pages",
            [old.encode().unwrap(), erased],
        ),
    ];
    for (what, pages) in starts {
        for cut in 0..=steps {
            let mut flash = Cuttable {
                pages,
                unreadable: [false; 2],
                cut_after: Some(cut),
                powered: true,
            };
            let stored = store(&mut flash, &new);
            // Power back.
            flash.powered = true;
            flash.cut_after = None;
            let found = load(&mut flash);
            if cut == steps {
                assert_eq!(stored.written, Ok(()), "{what}");
                assert_eq!(found, Ok(new), "{what}: the complete store");
            } else {
                assert!(stored.written.is_err(), "{what}, cut {cut}");
                assert_eq!(found, Ok(old), "{what}: cut after {cut} steps");
            }
            // The next commissioning stores over the torn page, never over the one in force.
            let again = store(&mut flash, &newer);
            assert_eq!(
                (again.written, again.read_back),
                (Ok(()), Some(newer)),
                "{what}"
            );
            assert_eq!(load(&mut flash), Ok(newer));
        }
    }
    // With no record at all, a cut leaves none, and never a torn one in force.
    for cut in 0..steps {
        let mut flash = Cuttable {
            pages: [erased; 2],
            unreadable: [false; 2],
            cut_after: Some(cut),
            powered: true,
        };
        let _ = store(&mut flash, &new);
        flash.powered = true;
        assert!(matches!(
            load(&mut flash),
            Err(LoadError::Record(_) | LoadError::Read(_))
        ));
    }
}

/// With no valid copy, the boot's log names the reason that says most: a corrupt copy's
/// (its CRC) over an erased page's, whichever page holds which.
#[test]
fn no_valid_copy_names_the_corrupt_page_over_the_erased_one() {
    let mut corrupt = record().encode_copy(3).unwrap();
    corrupt[20] ^= 0x10;
    let erased = [0xFF; RECORD_LEN];
    for pages in [[corrupt, erased], [erased, corrupt]] {
        let mut flash = Cuttable {
            pages,
            unreadable: [false; 2],
            cut_after: None,
            powered: true,
        };
        assert_eq!(
            load(&mut flash),
            Err(LoadError::Record(RecordError::Crc)),
            "{:?}",
            pages.map(|p| p[0])
        );
    }
    let mut flash = Cuttable {
        pages: [erased; 2],
        unreadable: [false; 2],
        cut_after: None,
        powered: true,
    };
    assert_eq!(
        load(&mut flash),
        Err(LoadError::Record(RecordError::Erased))
    );
}
