//! `sim-host fleet --store PATH`: the logs judged in parallel, each judged log appended to
//! the store by this one thread as it comes (one writer, one transaction per log), so that a
//! run killed mid-way keeps every log stored before the kill.

use monitor_api::fleet::{FleetRow, MotorTable};
use monitor_store::{Appended, LogIdentity, Store, StoredRow};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// One log's outcome from a worker.
enum Judged {
    /// Judged: its fleet row, and the store's row where it gave a report.
    Row(usize, Box<FleetRow>, Option<StoredRow>),
    /// Already in the store: not judged again.
    Stored(PathBuf),
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
    let mut store = Store::open(path)?;
    let rebuilt = store.sync_mirror()?;
    if rebuilt > 0 {
        eprintln!(
            "store {}: {rebuilt} Parquet file(s) the last run did not write, written now",
            path.display()
        );
    }
    // Logs already stored are known before the workers start (one reader: this thread).
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
    let (tx, rx) = std::sync::mpsc::channel::<Judged>();
    let mut rows: Vec<Option<FleetRow>> = vec![None; logs.len()];
    let (mut stored, mut skipped, mut unstored) = (0usize, 0usize, 0usize);
    std::thread::scope(|s| -> anyhow::Result<()> {
        let known = &known;
        s.spawn(move || {
            logs.par_iter()
                .enumerate()
                .for_each_with(tx, |tx, (i, log)| {
                    let msg = match known.get(i) {
                        Some((_, true)) => Judged::Stored(log.clone()),
                        Some((id, false)) => {
                            let (row, doc) = monitor_api::fleet::row_and_report(table, log);
                            let kept = id
                                .as_ref()
                                .zip(doc.as_ref())
                                .map(|(id, d)| StoredRow::from_diagnose(id, d));
                            Judged::Row(i, Box::new(row), kept)
                        }
                        None => return,
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
                        Some(r) => match store.append(&r)? {
                            Appended::Stored => stored += 1,
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
    eprintln!(
        "store {}: {stored} log(s) stored, {skipped} already stored (skipped), {unstored} without a report (not stored)",
        path.display()
    );
    Ok(rows.into_iter().flatten().collect())
}
