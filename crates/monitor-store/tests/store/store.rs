//! The store on its own: a log stored once, the rows by motor and day, the mirror rebuilt
//! from SQLite, and what is not a store refused.

use monitor_store::{mirror, Appended, LogIdentity, Store, StoredRow};

fn row(motor: &str, day: i64, verdict: &str) -> StoredRow {
    let id = LogIdentity {
        motor: motor.into(),
        path: format!("logs/{motor}_{day}.csv"),
        hash: monitor_store::content_hash(format!("{motor}{day}").as_bytes()),
        time_s: 1_793_491_200 + day * 86_400,
    };
    let doc = serde_json::json!({
        "verdict": verdict,
        "unbalance": {"winding_ratio": 0.001 * day as f64},
        "data_quality": {"rows_read": 1000}
    });
    StoredRow::from_diagnose(&id, &doc)
}

#[test]
fn a_log_is_stored_once_and_read_back_by_motor_and_day() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("h.db");
    let mut s = Store::open(&path).unwrap();
    for d in 0..5 {
        assert_eq!(s.append(&row("a", d, "healthy")).unwrap(), Appended::Stored);
        assert_eq!(s.append(&row("b/2", d, "fault")).unwrap(), Appended::Stored);
    }
    assert_eq!(
        s.append(&row("a", 3, "healthy")).unwrap(),
        Appended::AlreadyStored
    );
    assert_eq!(s.rows(None, None).unwrap().len(), 10);
    let a = s.rows(Some("a"), None).unwrap();
    assert_eq!(a.len(), 5);
    assert!(a
        .windows(2)
        .all(|w| w[0].f64("log_time_s") < w[1].f64("log_time_s")));
    let since = monitor_store::parse_day("2026-11-03").unwrap();
    assert_eq!(s.rows(Some("b/2"), Some(since)).unwrap().len(), 3);
    assert_eq!(a[2], row("a", 2, "healthy"));
    // The mirror: a file per row, in motor=/day= folders, the motor's '/' encoded.
    let f = mirror::file_of(&s.mirror_dir(), &row("b/2", 1, "fault"));
    assert!(f.is_file(), "{f:?}");
    assert!(
        f.to_string_lossy().contains("motor=b%2F2/day=2026-11-02/"),
        "{f:?}"
    );
    // A file lost (a run killed between SQLite's commit and the rename) is written again,
    // a temporary one removed.
    std::fs::remove_file(&f).unwrap();
    let tmp = f.with_extension("parquet.tmp");
    std::fs::write(&tmp, b"half").unwrap();
    assert_eq!(s.sync_mirror().unwrap(), 1);
    assert!(f.is_file() && !tmp.exists());
    assert_eq!(s.sync_mirror().unwrap(), 0);
}

#[test]
fn what_is_not_a_store_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("none.db");
    let e = Store::open_existing(&missing).unwrap_err().to_string();
    assert!(e.starts_with("no store at"), "{e}");
    let text = dir.path().join("notes.txt");
    std::fs::write(&text, "not a database, just some text that is long enough").unwrap();
    let e = Store::open_existing(&text).unwrap_err().to_string();
    assert!(e.contains("not a database"), "{e}");
    // An SQLite database whose `logs` table is another one.
    let other = dir.path().join("other.db");
    rusqlite::Connection::open(&other)
        .unwrap()
        .execute_batch("CREATE TABLE logs (x INTEGER);")
        .unwrap();
    let e = Store::open_existing(&other).unwrap_err().to_string();
    assert!(e.contains("not a store of this version"), "{e}");
    assert!(!e.contains('\n'));
}
