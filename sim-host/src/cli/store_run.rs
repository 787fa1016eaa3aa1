//! `sim-host fleet --store PATH`: the logs judged in parallel, each judged log appended to
//! the store by this one thread as it comes (one writer, one transaction per log), so that a
//! run killed mid-way keeps every log stored before the kill. Each log's time comes from the
//! log where it can ([`monitor_api::fleet::log_time`]); the run warns of times that are
//! files' modification times ([`monitor_api::fleet::time_warnings`]).

use monitor_api::fleet::{FleetRow, LogTime, MotorTable};
use monitor_store::{Appended, LogIdentity, Store, StoredRow};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// One log's outcome from a worker.
enum Judged {
    /// Judged: its fleet row, and the store's row where it gave a report (with its motor and
    /// time).
    Row(usize, Box<FleetRow>, Option<(StoredRow, String, LogTime)>),
    /// Already in the store: not judged again.
    Stored(PathBuf),
}

/// Opens (or creates) the store and writes the mirror files a killed run left out.
///
/// # Errors
/// The store cannot be opened or its mirror written.
fn open(path: &Path) -> anyhow::Result<Store> {
    let store = Store::open(path)?;
    let rebuilt = store.sync_mirror()?;
    if rebuilt > 0 {
        eprintln!(
            "store {}: {rebuilt} Parquet file(s) the last run did not write, written now",
            path.display()
        );
    }
    Ok(store)
}

/// Each log's identity (where its motor is known and the file readable) and whether it is
/// stored already: known before the workers start (one reader, this thread).
///
/// # Errors
/// The store cannot be read.
fn identities(
    table: &MotorTable,
    logs: &[PathBuf],
    store: &Store,
) -> anyhow::Result<Vec<(Option<LogIdentity>, bool)>> {
    let mut known = Vec::with_capacity(logs.len());
    for log in logs {
        let id = table
            .motor_of(log)
            .and_then(|m| LogIdentity::of_file(&m.name, log).ok());
        let stored = match &id {
            Some(id) => store.contains(&id.log_id())?,
            None => false,
        };
        known.push((id, stored));
    }
    Ok(known)
}

/// One worker's log: already stored, or judged (its fleet row and store row).
fn judge_one(table: &MotorTable, log: &Path, id: Option<&LogIdentity>, stored: bool) -> Judged {
    if stored {
        return Judged::Stored(log.to_path_buf());
    }
    let (row, doc) = monitor_api::fleet::row_and_report(table, log);
    let kept = id.zip(doc.as_ref()).and_then(|(id, d)| {
        let m = table.motor_of(log)?;
        let time = monitor_api::fleet::log_time(m, log, &log.display().to_string()).ok()?;
        let id = LogIdentity {
            time_s: time.time_s,
            ..id.clone()
        };
        let r = StoredRow::from_diagnose(&id, d).with_time_source(time.source.name());
        Some((r, id.motor, time))
    });
    Judged::Row(0, Box::new(row), kept)
}

/// Judges `logs` with `table`, appending each report to the store at `path`; the fleet rows
/// in the logs' order (a log already stored has none). Counts go to stderr.
///
/// # Errors
/// The store cannot be opened or written (a log's own error is its row's).
pub fn judge_into(
    table: &MotorTable,
    logs: &[PathBuf],
    path: &Path,
) -> anyhow::Result<Vec<FleetRow>> {
    let mut store = open(path)?;
    let known = identities(table, logs, &store)?;
    let (tx, rx) = std::sync::mpsc::channel::<Judged>();
    let mut rows: Vec<Option<FleetRow>> = vec![None; logs.len()];
    let (mut stored, mut skipped, mut unstored) = (0usize, 0usize, 0usize);
    let mut times: Vec<(String, LogTime)> = Vec::new();
    std::thread::scope(|s| -> anyhow::Result<()> {
        let known = &known;
        s.spawn(move || {
            logs.par_iter()
                .enumerate()
                .for_each_with(tx, |tx, (i, log)| {
                    let Some((id, stored)) = known.get(i) else {
                        return;
                    };
                    let msg = match judge_one(table, log, id.as_ref(), *stored) {
                        Judged::Row(_, row, kept) => Judged::Row(i, row, kept),
                        other => other,
                    };
                    // The receiver lives as long as this scope.
                    let _ = tx.send(msg);
                });
        });
        for msg in rx {
            match msg {
                Judged::Stored(log) => {
                    eprintln!("already stored, skipped: {}", log.display());
                    skipped += 1;
                }
                Judged::Row(i, row, kept) => {
                    match kept {
                        Some((r, motor, time)) => match store.append(&r)? {
                            Appended::Stored => {
                                stored += 1;
                                times.push((motor, time));
                            }
                            Appended::AlreadyStored => skipped += 1,
                        },
                        None => unstored += 1,
                    }
                    if let Some(slot) = rows.get_mut(i) {
                        *slot = Some(*row);
                    }
                }
            }
        }
        Ok(())
    })?;
    say_counts(path, [stored, skipped, unstored], table, &times);
    Ok(rows.into_iter().flatten().collect())
}

/// The run's counts (stored, skipped, without a report) and what the stored logs' `times`
/// have to say ([`monitor_api::fleet::time_warnings`]), on stderr.
fn say_counts(
    path: &Path,
    [stored, skipped, unstored]: [usize; 3],
    table: &MotorTable,
    times: &[(String, LogTime)],
) {
    eprintln!(
        "store {}: {stored} log(s) stored, {skipped} already stored (skipped), {unstored} without a report (not stored)",
        path.display()
    );
    for w in monitor_api::fleet::time_warnings(table, times) {
        eprintln!("{w}");
    }
}
