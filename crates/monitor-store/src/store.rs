//! The store itself: an SQLite database (the source of truth, one transaction per log) and
//! its Parquet mirror partitioned by motor and day.

use crate::error::HistoryError;
use crate::mirror;
use crate::row::{utc_day, Cell, Kind, StoredRow, COLUMNS};
use rusqlite::types::{Value as SqlValue, ValueRef};
use rusqlite::{params_from_iter, Connection, OpenFlags};
use std::path::{Path, PathBuf};

/// What [`Store::append`] did with a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Appended {
    /// The row is stored (and mirrored).
    Stored,
    /// A row of the same log (`log_id`) was already stored: nothing written.
    AlreadyStored,
}

/// A store of judged logs: `PATH` (SQLite) and `PATH.parquet/` (the mirror).
#[derive(Debug)]
pub struct Store {
    conn: Connection,
    path: PathBuf,
}

const TABLE: &str = "logs";

impl Store {
    /// Opens the store at `path`, creating it (and its table) if it does not exist. A store
    /// of the version before the `time_source` column gets it (`ALTER TABLE ... ADD
    /// COLUMN`; null in its rows).
    ///
    /// # Errors
    /// [`HistoryError::Sqlite`] when the file cannot be opened or is not an SQLite store of
    /// this schema.
    pub fn open(path: &Path) -> Result<Self, HistoryError> {
        let conn = Connection::open(path).map_err(|e| sql(path, &e))?;
        let s = Store {
            conn,
            path: path.to_path_buf(),
        };
        s.init()?;
        Ok(s)
    }

    /// Opens an existing store to read it (nothing is created; a store of the version
    /// before the `time_source` column gets it, as [`Store::open`]).
    ///
    /// # Errors
    /// [`HistoryError::Missing`] when there is no file at `path`; [`HistoryError::Sqlite`] when
    /// it is not a store.
    pub fn open_existing(path: &Path) -> Result<Self, HistoryError> {
        if !path.is_file() {
            return Err(HistoryError::Missing(path.display().to_string()));
        }
        let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_WRITE)
            .map_err(|e| sql(path, &e))?;
        let s = Store {
            conn,
            path: path.to_path_buf(),
        };
        s.check_schema()?;
        Ok(s)
    }

    /// The store's SQLite file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The mirror's folder: the store's path with `.parquet` added.
    pub fn mirror_dir(&self) -> PathBuf {
        mirror::dir_of(&self.path)
    }

    fn init(&self) -> Result<(), HistoryError> {
        // WAL: a reader (`sim-host trend`) never blocks the writer; synchronous FULL: a
        // committed row survives a power cut, not only a killed process.
        let cols: Vec<String> = COLUMNS
            .iter()
            .map(|c| {
                let t = match c.kind {
                    Kind::Text => "TEXT",
                    Kind::Int => "INTEGER",
                    Kind::Real => "REAL",
                };
                if c.name == "log_id" {
                    format!("{} {t} NOT NULL UNIQUE", c.name)
                } else {
                    format!("{} {t}", c.name)
                }
            })
            .collect();
        let ddl = format!(
            "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL;
             CREATE TABLE IF NOT EXISTS {TABLE} ({});
             CREATE INDEX IF NOT EXISTS logs_motor_time ON {TABLE} (motor, log_time_s);",
            cols.join(", ")
        );
        self.conn
            .execute_batch(&ddl)
            .map_err(|e| sql(&self.path, &e))?;
        self.check_schema()
    }

    fn check_schema(&self) -> Result<(), HistoryError> {
        let mut st = self
            .conn
            .prepare(&format!("SELECT name FROM pragma_table_info('{TABLE}')"))
            .map_err(|e| sql(&self.path, &e))?;
        let names: Vec<String> = st
            .query_map([], |r| r.get(0))
            .and_then(Iterator::collect)
            .map_err(|e| sql(&self.path, &e))?;
        let want: Vec<&str> = COLUMNS.iter().map(|c| c.name).collect();
        // A store of an earlier version (its columns a prefix of today's: `time_source` and
        // `stator_excess_pct` came last): the missing columns are added, null in its rows,
        // so that it opens and takes new rows.
        if names.len() < want.len() && want.iter().zip(&names).all(|(w, n)| w == n) {
            let kinds = COLUMNS.iter().skip(names.len());
            for c in kinds {
                let kind = match c.kind {
                    crate::row::Kind::Text => "TEXT",
                    crate::row::Kind::Int => "INTEGER",
                    crate::row::Kind::Real => "REAL",
                };
                self.conn
                    .execute_batch(&format!("ALTER TABLE {TABLE} ADD COLUMN {} {kind}", c.name))
                    .map_err(|e| sql(&self.path, &e))?;
            }
            return Ok(());
        }
        if names != want {
            return Err(HistoryError::Sqlite {
                path: self.path.display().to_string(),
                message: format!(
                    "not a store of this version (table `{TABLE}` has columns {names:?})"
                ),
            });
        }
        Ok(())
    }

    /// Appends one log's row in one transaction, then writes its Parquet file. A log
    /// already stored (the same `log_id`) is skipped: [`Appended::AlreadyStored`].
    ///
    /// # Errors
    /// [`HistoryError`] when SQLite or the mirror cannot be written; SQLite's row is then
    /// either whole or absent, and a missing mirror file is written by
    /// [`Store::sync_mirror`].
    pub fn append(&mut self, row: &StoredRow) -> Result<Appended, HistoryError> {
        let names: Vec<&str> = COLUMNS.iter().map(|c| c.name).collect();
        let marks = vec!["?"; names.len()].join(", ");
        let q = format!(
            "INSERT OR IGNORE INTO {TABLE} ({}) VALUES ({marks})",
            names.join(", ")
        );
        let values = row.cells.iter().map(|c| match c {
            Cell::Null => SqlValue::Null,
            Cell::Int(i) => SqlValue::Integer(*i),
            Cell::Real(x) => SqlValue::Real(*x),
            Cell::Text(t) => SqlValue::Text(t.clone()),
        });
        let tx = self.conn.transaction().map_err(|e| sql(&self.path, &e))?;
        let n = tx
            .execute(&q, params_from_iter(values))
            .map_err(|e| sql(&self.path, &e))?;
        tx.commit().map_err(|e| sql(&self.path, &e))?;
        if n == 0 {
            return Ok(Appended::AlreadyStored);
        }
        mirror::write_row(&self.mirror_dir(), row)?;
        Ok(Appended::Stored)
    }

    /// Whether a row of the log `log_id` is stored.
    ///
    /// # Errors
    /// [`HistoryError::Sqlite`] when the store cannot be read.
    pub fn contains(&self, log_id: &str) -> Result<bool, HistoryError> {
        self.conn
            .query_row(
                &format!("SELECT COUNT(*) FROM {TABLE} WHERE log_id = ?1"),
                [log_id],
                |r| r.get::<_, i64>(0),
            )
            .map(|n| n > 0)
            .map_err(|e| sql(&self.path, &e))
    }

    /// The stored rows, by motor and time: only `motor`'s where given, only from
    /// `since_s` (seconds since 1970-01-01 UTC) on where given.
    ///
    /// # Errors
    /// [`HistoryError::Sqlite`] when the store cannot be read.
    pub fn rows(
        &self,
        motor: Option<&str>,
        since_s: Option<i64>,
    ) -> Result<Vec<StoredRow>, HistoryError> {
        let names: Vec<&str> = COLUMNS.iter().map(|c| c.name).collect();
        let q = format!(
            "SELECT {} FROM {TABLE} WHERE (?1 IS NULL OR motor = ?1) AND (?2 IS NULL OR log_time_s >= ?2) ORDER BY motor, log_time_s, log_id",
            names.join(", ")
        );
        let mut st = self.conn.prepare(&q).map_err(|e| sql(&self.path, &e))?;
        let rows = st
            .query_map(rusqlite::params![motor, since_s], |r| {
                let mut cells = Vec::with_capacity(COLUMNS.len());
                for i in 0..COLUMNS.len() {
                    cells.push(match r.get_ref(i)? {
                        ValueRef::Null => Cell::Null,
                        ValueRef::Integer(v) => Cell::Int(v),
                        ValueRef::Real(v) => Cell::Real(v),
                        ValueRef::Text(t) | ValueRef::Blob(t) => {
                            Cell::Text(String::from_utf8_lossy(t).into_owned())
                        }
                    });
                }
                Ok(StoredRow { cells })
            })
            .and_then(Iterator::collect)
            .map_err(|e| sql(&self.path, &e))?;
        Ok(rows)
    }

    /// Writes the mirror's missing files (a run killed between SQLite's commit and the
    /// Parquet file's rename) and removes temporary files a killed run left; SQLite is the
    /// source of truth. Returns how many files were written.
    ///
    /// # Errors
    /// [`HistoryError`] when the store cannot be read or a file cannot be written.
    pub fn sync_mirror(&self) -> Result<usize, HistoryError> {
        let dir = self.mirror_dir();
        mirror::remove_temporaries(&dir)?;
        let mut written = 0;
        for row in self.rows(None, None)? {
            if !mirror::file_of(&dir, &row).is_file() {
                mirror::write_row(&dir, &row)?;
                written += 1;
            }
        }
        Ok(written)
    }
}

/// SQLite's error on the store `path`, as [`HistoryError::Permission`] when SQLite cannot
/// open or write it because the file or its folder is not writable.
fn sql(path: &Path, e: &rusqlite::Error) -> HistoryError {
    use rusqlite::ErrorCode;
    let cannot_open = matches!(
        e.sqlite_error_code(),
        Some(ErrorCode::CannotOpen | ErrorCode::ReadOnly | ErrorCode::PermissionDenied)
    );
    if let Some(why) = cannot_open.then(|| not_writable(path)).flatten() {
        return HistoryError::Permission {
            path: path.display().to_string(),
            why,
        };
    }
    HistoryError::Sqlite {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Why the store `path` cannot be written, if that is so: the file is read-only, or its
/// folder (where SQLite makes the store and its `-wal` and `-shm` files) is not writable.
/// Tried, not read from the mode bits, so that a superuser who can write anyway is not
/// told otherwise.
fn not_writable(path: &Path) -> Option<String> {
    let denied = |e: std::io::Error| e.kind() == std::io::ErrorKind::PermissionDenied;
    if path.exists() {
        if let Err(e) = std::fs::OpenOptions::new().append(true).open(path) {
            return denied(e).then(|| "the file is read-only".to_string());
        }
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let probe = folder.join(format!(".store-write-test-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            // (A probe left behind would only be a stray empty file.)
            let _ = std::fs::remove_file(&probe);
            None
        }
        Err(e) => denied(e).then(|| format!("the folder {} is not writable", folder.display())),
    }
}

/// What a motor's stored times say of themselves: a history whose logs all took their
/// files' modification times on one day is no history (a copy without `cp -p` put them
/// there), and a reader of the trend is to be told (docs/trend.md).
/// For each motor of `rows` whose logs (two or more) all have modification times for their
/// times (`time_source` `modified`, or null: rows stored before the column was kept, whose
/// times were all modification times) and fall on one UTC day: the one-line warning, in the
/// motors' order of first appearance.
pub fn one_day_of_modified_times(rows: &[StoredRow]) -> Vec<String> {
    let mut motors: Vec<&str> = Vec::new();
    for r in rows {
        let m = r.str("motor").unwrap_or_default();
        if !motors.contains(&m) {
            motors.push(m);
        }
    }
    let mut out = Vec::new();
    for m in motors {
        let own: Vec<&StoredRow> = rows
            .iter()
            .filter(|r| r.str("motor").unwrap_or_default() == m)
            .collect();
        let modified = own
            .iter()
            .all(|r| matches!(r.str("time_source"), None | Some("modified")));
        let days: std::collections::BTreeSet<String> = own
            .iter()
            .map(|r| utc_day(r.f64("log_time_s").unwrap_or(0.0) as i64))
            .collect();
        if let (true, true, Some(day)) = (own.len() >= 2 && modified, days.len() == 1, days.first())
        {
            out.push(format!(
                "WARNING: motor {m}: the times of {} logs are their files' modification times and all fall on {day}: copy logs with `cp -p`, give the log a time column, or set `time_from_name` in the motor table (docs/trend.md)",
                own.len()
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::row::LogIdentity;

    fn row(motor: &str, t: i64, source: Option<&str>) -> StoredRow {
        let id = LogIdentity {
            motor: motor.into(),
            path: format!("{motor}{t}"),
            hash: "00".into(),
            time_s: t,
        };
        let r = StoredRow::from_diagnose(&id, &serde_json::json!({}));
        match source {
            Some(s) => r.with_time_source(s),
            None => r,
        }
    }

    #[test]
    fn one_day_of_modification_times_is_said() {
        let day = 86_400 * 20_000;
        let rows = [
            row("a", day, Some("modified")),
            row("a", day + 60, None),
            row("b", day, Some("modified")),
            row("b", day + 60, Some("log")),
            row("c", day, Some("modified")),
            row("c", day + 86_400, Some("modified")),
            row("d", day, Some("modified")),
        ];
        let said = one_day_of_modified_times(&rows);
        assert_eq!(said.len(), 1, "{said:?}");
        // Day 20 000 of the Unix epoch: 2024-10-04 (`date -u -d @1728000000 +%F`).
        assert!(
            said[0].starts_with("WARNING: motor a: the times of 2 logs are their files' modification times and all fall on 2024-10-04: copy logs with `cp -p`"),
            "{said:?}"
        );
    }
}
