//! Issue 65: the store keeps where each log's time came from (`time_source`), and a store
//! written before that column existed still opens, keeps its rows and takes new ones.

use monitor_store::{Cell, Kind, LogIdentity, Store, StoredRow, COLUMNS};

fn row(path: &str, source: Option<&str>) -> StoredRow {
    let id = LogIdentity {
        motor: "m".into(),
        path: path.into(),
        hash: monitor_store::content_hash(path.as_bytes()),
        time_s: 1_793_685_600,
    };
    let doc = serde_json::json!({"verdict": "healthy", "data_quality": {"rows_read": 10}});
    let r = StoredRow::from_diagnose(&id, &doc);
    match source {
        Some(s) => r.with_time_source(s),
        None => r,
    }
}

/// A store as the version before `time_source` (and `stator_excess_pct`, added after it)
/// wrote it: every other column, one row.
fn old_store(path: &std::path::Path) {
    let conn = rusqlite::Connection::open(path).unwrap();
    let older = &COLUMNS[..COLUMNS.len() - 2];
    assert!(older.iter().all(|c| c.name != "time_source"));
    let cols: Vec<String> = older
        .iter()
        .map(|c| {
            let t = match c.kind {
                Kind::Text => "TEXT",
                Kind::Int => "INTEGER",
                Kind::Real => "REAL",
            };
            let unique = if c.name == "log_id" {
                " NOT NULL UNIQUE"
            } else {
                ""
            };
            format!("{} {t}{unique}", c.name)
        })
        .collect();
    conn.execute_batch(&format!("CREATE TABLE logs ({});", cols.join(", ")))
        .unwrap();
    conn.execute(
        "INSERT INTO logs (log_id, motor, log_time_s, day, verdict) VALUES ('x:old.csv', 'm', 1793000000, '2026-10-26', 'healthy')",
        [],
    )
    .unwrap();
}

#[test]
fn the_time_source_is_stored_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Store::open(&dir.path().join("h.db")).unwrap();
    s.append(&row("a.csv", Some("file_name"))).unwrap();
    s.append(&row("b.csv", None)).unwrap();
    let rows = s.rows(None, None).unwrap();
    assert_eq!(rows[0].str("time_source"), Some("file_name"));
    assert_eq!(rows[1].get("time_source"), &Cell::Null);
}

#[test]
fn an_old_store_without_time_source_opens_and_takes_new_rows() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.db");
    old_store(&path);
    // Read first (what `sim-host trend` does), then written to (a fleet run).
    let s = Store::open_existing(&path).unwrap();
    let rows = s.rows(None, None).unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].log_id(), "x:old.csv");
    assert_eq!(rows[0].get("time_source"), &Cell::Null);
    drop(s);
    let mut s = Store::open(&path).unwrap();
    s.append(&row("new.csv", Some("log"))).unwrap();
    let rows = s.rows(Some("m"), None).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[1].str("time_source"), Some("log"));
    assert_eq!(rows[0].str("day"), Some("2026-10-26"));
}

#[test]
fn a_table_of_other_columns_is_still_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.db");
    let conn = rusqlite::Connection::open(&path).unwrap();
    conn.execute_batch("CREATE TABLE logs (log_id TEXT, motor TEXT);")
        .unwrap();
    drop(conn);
    let e = Store::open_existing(&path).unwrap_err().to_string();
    assert!(e.contains("not a store of this version"), "{e}");
}
