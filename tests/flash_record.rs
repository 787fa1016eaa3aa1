//! A stored commissioning record that is not exactly what the firmware wrote is never
//! used: every single-bit flip, a wrong version, a truncated record, an erased page and
//! values the core would reject all come back as errors.

use drive_monitor::app::{Command, SamplePath};
use drive_monitor::flash_record::{
    crc32, CalibrationRecord, RecordError, RECORD_LEN, RECORD_VERSION,
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
    use drive_monitor::flash_record::{store, RecordStore, StoreError};
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
    struct Page([u8; RECORD_LEN], u32);
    impl RecordStore for Page {
        type Error = E;
        fn read(&mut self, buf: &mut [u8; RECORD_LEN]) -> Result<(), E> {
            *buf = self.0;
            Ok(())
        }
        fn erase(&mut self) -> Result<(), E> {
            self.0 = [0xFF; RECORD_LEN];
            self.1 += 1;
            Ok(())
        }
        fn write(&mut self, bytes: &[u8; RECORD_LEN]) -> Result<(), E> {
            self.0 = *bytes;
            self.1 += 1;
            Ok(())
        }
    }
    let old = record().encode().unwrap();
    let mut new = record();
    new.mean[0] = 0.02;
    let factory = BorCheck::of_optr(0xFFEF_F8AA);
    assert_eq!(factory, BorCheck::BelowGoal(BorLevel::Level0));
    let mut gate = BorGate {
        store: Page(old, 0),
        bor: factory,
    };
    let stored = store(&mut gate, &new);
    assert_eq!(stored.written, Err(StoreError::Erase(E::Bor(factory))));
    assert_eq!((gate.store.0, gate.store.1), (old, 0));
    assert_eq!(stored.read_back, Some(record()));

    let at_goal = BorCheck::of_optr((0xFFEF_F8AA & !(0b111 << 8)) | (4 << 8));
    let mut gate = BorGate {
        store: Page(old, 0),
        bor: at_goal,
    };
    let stored = store(&mut gate, &new);
    assert_eq!(stored.written, Ok(()));
    assert_eq!(stored.read_back, Some(new));
}
