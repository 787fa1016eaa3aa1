//! Encoder cells held out are held out of the verdict too (issue 40): a healthy 2.2 kW motor
//! logged with an encoder (8 s at 5 kHz, `enc_count` and no speed channel), whose
//! `enc_count` column carries 45 bad cells in 40 short bursts after commissioning (empty,
//! `nan`, counts far off, a count that steps back), as a corrupted file's tail or a
//! flaky DAQ channel gives. The data-quality stage holds those rows out; the verdict must
//! not be FAULT and the speed sensor must not be named. The same log without the bad cells
//! is the control. About 2 s in the test profile.

use sim_host::api::{self, DiagnoseRequest, ParamsSource};
use sim_host::replay::{IsolationName, Verdict};
use std::path::{Path, PathBuf};

const SCENARIO: &str = "duration_s = 8.0\nsample_rate_hz = 5000.0\nseed = 5\n[sensors]\nencoder = true\nspeed = false\n";

fn params() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/params/2p2kw.toml")
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
    let req = DiagnoseRequest {
        commission: Some((2.0, 4.0)),
        ..Default::default()
    };
    for (name, log) in [("clean", &clean), ("45 bad enc_count cells", &bad)] {
        let d = api::diagnose(ParamsSource::Path(&params()), log, &req, &mut |_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = &d.report;
        let speed_named = r.isolation.named
            == Some(IsolationName::Fault(monitor_core::Fault::SpeedSensor))
            || r.candidates.first().is_some_and(|c| {
                c.fault == monitor_core::Fault::SpeedSensor && c.probability >= 0.5
            });
        let seen = r
            .data_quality
            .bad_cells
            .get("enc_count")
            .copied()
            .unwrap_or(0);
        // (The data-quality stage saw every spoilt cell, and none in the clean log.)
        assert_eq!(seen, if log == &bad { 45 } else { 0 }, "{name}");
        eprintln!(
            "{name}: {:?}, named {:?}, bad enc_count cells {}",
            r.verdict, r.isolation.named, seen
        );
        assert!(
            r.verdict != Verdict::Fault && !speed_named,
            "{name}: verdict {:?}, named {:?}, candidates {:?}",
            r.verdict,
            r.isolation.named,
            r.candidates
        );
    }
}
