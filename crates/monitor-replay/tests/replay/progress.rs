//! `diagnose`'s progress (what `sim-host diagnose` draws its bar from): on a CSV log of
//! several parsing blocks the fraction moves forward in small steps through the whole
//! read, and reaches 1 only when the report is built (issue 65: a bar that stood at 56 %
//! and then jumped to done, the reader's fraction being of the bytes read ahead of the
//! rows replayed).

use monitor_io::log::{Channels, LogWriter};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_file, ReplayOptions};
use monitor_sim::{simulate_to_vec, Scenario};

/// A 12 s log of the 2.2 kW motor at 10 kHz written as a CSV (about 10 MB, three of the
/// reader's 4 MB parsing blocks) to `path`.
fn write_log(p: &ParamFile, path: &std::path::Path) {
    let rows = simulate_to_vec(p, &Scenario::steady(12.0, 10_000.0)).expect("simulated");
    let channels = Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let mut w = LogWriter::create(path, channels).expect("log created");
    for r in &rows {
        w.write_row(r).expect("row written");
    }
    w.finish().expect("log written");
}

#[test]
fn the_fraction_moves_through_the_whole_work_and_reaches_one_at_the_end() {
    let p = ParamFile::reference_2p2kw();
    let path = std::env::temp_dir().join(format!(
        "monitor_replay_progress_{}.csv",
        std::process::id()
    ));
    write_log(&p, &path);
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
        ..ReplayOptions::default()
    };
    let mut seen: Vec<f64> = Vec::new();
    let d = diagnose_file(&p, &path, opts, &mut |f| seen.push(f));
    let _ = std::fs::remove_file(&path);
    let d = d.expect("diagnosed");
    assert!(d.report.rows > 100_000, "{} rows", d.report.rows);
    assert!(seen.len() >= 20, "only {} reports: {seen:?}", seen.len());
    assert!(
        seen.windows(2).all(|w| w[1] >= w[0]),
        "the fraction went back: {seen:?}"
    );
    let jump = seen.windows(2).map(|w| w[1] - w[0]).fold(seen[0], f64::max);
    assert!(jump <= 0.25, "a jump of {jump:.2}: {seen:?}");
    assert_eq!(seen.last(), Some(&1.0), "{seen:?}");
    assert_eq!(
        seen.iter().filter(|f| **f >= 1.0).count(),
        1,
        "1 before the end: {seen:?}"
    );
    // The read's last report is near its end: no stall half-way.
    assert!(seen[seen.len() - 2] >= 0.8, "{seen:?}");
}
