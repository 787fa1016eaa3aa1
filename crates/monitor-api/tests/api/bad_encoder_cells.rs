//! Encoder cells held out are held out of the verdict too (issues 40 and 48): a healthy
//! 2.2 kW motor logged with an encoder (8 s at 5 kHz, `enc_count` and no speed channel),
//! whose `enc_count` column carries 45 bad cells in 40 short bursts after commissioning, as
//! a corrupted file's tail or a flaky DAQ channel gives. The data-quality stage holds those
//! rows out; the verdict must not be FAULT and the speed sensor must not be named, by the
//! isolation or by the lamps' matching. The same log without the bad cells is the control.
//!
//! Two kinds of damage, in CSV and in TDMS: cells that are no count (empty, `nan`, counts
//! far off, a count that steps back), and counts 60-500 off the true one (a damaged
//! file's bytes that still read as counts near it; a burst of two such rows used to pass
//! its second row as good, judged against the last good count two rows back, and hold out
//! the true count after it: the count handed on jumped out and back, the monitor flagged
//! the encoder and the verdict was `FAULT` with the lamps' matching naming speed_sensor).
//! About 4 s in the test profile.

use monitor_api::{self as api, DiagnoseRequest, ParamsSource};
use monitor_io::log::Log;
use monitor_replay::{IsolationName, Verdict};
use std::path::{Path, PathBuf};

const SCENARIO: &str = "duration_s = 8.0\nsample_rate_hz = 5000.0\nseed = 5\n[sensors]\nencoder = true\nspeed = false\n";

fn params() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/params/2p2kw.toml")
}

/// The log with `enc_count` cells spoilt: 40 bursts from 4.5 s, every 70 ms, of one or
/// two rows (45 rows in all), each burst of one kind.
fn spoil(csv: &str) -> (String, usize) {
    let mut lines: Vec<String> = csv.lines().map(str::to_string).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "enc_count")
        .expect("an enc_count column");
    let kinds = ["", "nan", "1e12", "99999999", "-3"];
    let mut spoilt = 0;
    for b in 0..40usize {
        let first = 1 + 22_500 + 350 * b; // row of 4.5 s + 70 ms per burst (5 kHz)
        let rows = if b % 8 == 0 { 2 } else { 1 };
        for line in lines.iter_mut().skip(first).take(rows) {
            let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
            cells[col] = kinds[b % kinds.len()].to_string();
            *line = cells.join(",");
            spoilt += 1;
        }
    }
    (lines.join("\n") + "\n", spoilt)
}

/// The first row of each of the 40 bursts (4.5 s + 70 ms per burst at 5 kHz) and its
/// length: 45 rows in all.
fn bursts() -> impl Iterator<Item = (usize, usize, usize)> {
    (0..40usize).map(|b| (b, 22_500 + 350 * b, if b % 8 == 0 { 2 } else { 1 }))
}

/// The log's counts in the bursts moved `base` to `base + 4 step` counts off the true
/// ones, up and down by turns (a count moves by about 20 between two rows here, the
/// data-quality stage's largest believable step is 4 x 34): 45 rows.
fn counts_off(log: &Log, base: i64, step: i64) -> (Log, usize) {
    let mut out = log.clone();
    let mut spoilt = 0;
    for (b, first, rows) in bursts() {
        let off = (base + step * (b % 5) as i64) * if b % 2 == 0 { 1 } else { -1 };
        for r in out.rows.iter_mut().skip(first).take(rows) {
            r.enc_count = r.enc_count.map(|c| c + off);
            spoilt += 1;
        }
    }
    (out, spoilt)
}

/// The log's counts in the bursts made no count at all (unreadable, 1e12, 99999999, -3),
/// as [`spoil`] does to the CSV text.
fn no_counts(log: &Log) -> Log {
    let kinds = [
        monitor_io::log::ENC_COUNT_UNREADABLE,
        1_000_000_000_000,
        99_999_999,
        -3,
    ];
    let mut out = log.clone();
    for (b, first, rows) in bursts() {
        for r in out.rows.iter_mut().skip(first).take(rows) {
            r.enc_count = Some(kinds[b % kinds.len()]);
        }
    }
    out
}

#[test]
fn bad_encoder_cells_do_not_make_a_speed_sensor_fault() {
    let dir = tempfile::tempdir().expect("temp dir");
    let clean = dir.path().join("clean.csv");
    api::simulate_to_file(ParamsSource::Path(&params()), SCENARIO, &clean).expect("simulates");
    let text = std::fs::read_to_string(&clean).expect("reads");
    let (bad_text, spoilt) = spoil(&text);
    assert_eq!(spoilt, 45);
    let bad = dir.path().join("bad_cells.csv");
    std::fs::write(&bad, bad_text).expect("writes");
    let log = Log::read(&clean).expect("reads the clean log");
    let (off, spoilt_off) = counts_off(&log, 300, 50);
    assert_eq!(spoilt_off, 45);
    let (near, _) = counts_off(&log, 60, 10);
    let mut logs = vec![("clean".to_string(), clean.clone(), 0)];
    logs.push(("45 bad enc_count cells, CSV".into(), bad, 45));
    let no = no_counts(&log);
    for (what, spoilt_log) in [
        ("counts 300-500 off", &off),
        ("counts 60-100 off", &near),
        ("no counts", &no),
    ] {
        for ext in ["csv", "tdms"] {
            let path = dir.path().join(format!("{}.{ext}", what.replace(' ', "_")));
            spoilt_log.write(&path).expect("writes");
            logs.push((format!("45 {what}, {ext}"), path, 45));
        }
    }
    let req = DiagnoseRequest {
        options: monitor_replay::ReplayOptions {
            commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut bad_verdicts = Vec::new();
    for (name, path, expect_bad) in &logs {
        let d = api::diagnose(ParamsSource::Path(&params()), path, &req, &mut |_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = &d.report;
        let speed =
            |f: monitor_core::Fault, p: f32| f == monitor_core::Fault::SpeedSensor && p >= 0.5;
        let speed_named = r.isolation.named
            == Some(IsolationName::Fault(monitor_core::Fault::SpeedSensor))
            || r.candidates.iter().any(|c| speed(c.fault, c.probability))
            || r.signature_candidates
                .iter()
                .any(|c| speed(c.fault, c.probability))
            || r.detections
                .iter()
                .any(|d| d.fault == monitor_core::Fault::SpeedSensor);
        let seen = r
            .data_quality
            .bad_cells
            .get("enc_count")
            .copied()
            .unwrap_or(0);
        let line = format!(
            "{name}: {:?}, named {:?}, lamps named {:?}, bad enc_count cells {seen}",
            r.verdict,
            r.isolation.named,
            r.detections
                .iter()
                .map(|d| (d.fault, d.t_s))
                .collect::<Vec<_>>()
        );
        eprintln!("{line}");
        // (The data-quality stage saw every spoilt cell, and none in the clean log.)
        if seen != *expect_bad || r.verdict == Verdict::Fault || speed_named {
            bad_verdicts.push(line);
        }
    }
    assert!(bad_verdicts.is_empty(), "{bad_verdicts:#?}");
}
