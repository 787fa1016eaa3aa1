//! `sim-host trend` on few logs and with a marked baseline (issue 65): the plot draws the
//! stored values where there are too few logs for a scatter (it drew e_d, e_q, e_T as flat
//! lines at 0 while the store held e_d rising 0.0001 -> 0.026), the table says there is no
//! trend and shows the values, and `--reference-until` marks each motor's reference.
//!
//! The store is built here: four logs of one motor (Rs 0/+10/+20/+40 %, each a FAULT
//! verdict) with the residuals and the load the test sets.

use crate::chart_legend;

use assert_cmd::Command;
use monitor_store::row::column_index;
use monitor_store::{Cell, LogIdentity, Store, StoredRow};
use std::path::Path;

/// 2026-11-01 06:00 UTC.
const START_S: i64 = 1_793_491_200 + 6 * 3600;

const E_D: [f64; 4] = [0.0001, 0.0082, 0.0155, 0.026];
const E_Q: [f64; 4] = [-0.0002, -0.004, -0.0081, -0.0163];

fn store_of_four(path: &Path) {
    let mut s = Store::open(path).expect("store");
    let i1 = [6.4, 7.6, 7.0, 6.9];
    for k in 0..4 {
        let id = LogIdentity {
            motor: "bench".into(),
            path: format!("logs/rs{}.csv", 10 * k),
            hash: monitor_store::content_hash(format!("bench {k}").as_bytes()),
            time_s: START_S + k as i64 * 86_400,
        };
        let mut r = StoredRow::from_diagnose(&id, &serde_json::json!({ "verdict": "fault" }));
        for (c, v) in [
            ("residual_d", E_D[k]),
            ("residual_q", E_Q[k]),
            ("residual_t", 0.5 * E_D[k]),
            ("rs_change_pct", [0.0, 10.0, 20.0, 40.0][k]),
            ("i1_peak_a", i1[k]),
            ("winding_rise_k", 10.0),
        ] {
            r.cells[column_index(c).expect("column")] = Cell::Real(v);
        }
        s.append(&r).expect("append");
    }
}

fn sim_host() -> Command {
    Command::cargo_bin("sim-host").expect("sim-host")
}

/// The `<polyline>`s of an SVG: each one's points.
fn polylines(svg: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|el| {
            let pts = el.split("points=\"").nth(1)?.split('"').next()?;
            Some(
                pts.split_whitespace()
                    .filter_map(|p| {
                        let (x, y) = p.split_once(',')?;
                        Some((x.parse().ok()?, y.parse().ok()?))
                    })
                    .collect(),
            )
        })
        .collect()
}

#[test]
fn four_logs_are_drawn_as_their_stored_values_not_flat_lines() {
    let dir = tempfile::tempdir().expect("tmp");
    let db = dir.path().join("h.db");
    store_of_four(&db);
    let svg_path = dir.path().join("bench.svg");
    let out = sim_host()
        .args(["trend", "--store"])
        .arg(&db)
        .args(["--motor", "bench", "--plot"])
        .arg(&svg_path)
        .output()
        .expect("runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&svg_path).expect("svg");
    // The panels are 260 px high, one under the other, one per indicator the logs measured
    // (no |I2w|/|I1| here: issue 79): e_d's is the first (0-260), e_q's the second
    // (260-520). A motor's line has its four points.
    let line_in = |lo: f64, hi: f64| {
        polylines(&svg)
            .into_iter()
            .find(|l| l.len() == 4 && l.iter().all(|p| p.1 > lo && p.1 < hi))
            .unwrap_or_else(|| panic!("no line of 4 points in {lo}-{hi} px"))
    };
    for (panel, (lo, hi), rising) in [("e_d", (0.0, 260.0), true), ("e_q", (260.0, 520.0), false)] {
        let ys: Vec<f64> = line_in(lo, hi).iter().map(|p| p.1).collect();
        let spread = ys.iter().copied().fold(f64::MIN, f64::max)
            - ys.iter().copied().fold(f64::MAX, f64::min);
        // The stored values span most of the panel (flat: under a pixel).
        assert!(spread > 100.0, "{panel}: {ys:?}");
        // SVG's y grows downwards: a rising value has a falling y.
        let first_above_last = ys[0] > ys[3];
        assert_eq!(first_above_last, rising, "{panel}: {ys:?}");
    }
    assert!(
        svg.contains("the stored values"),
        "the title says what is drawn"
    );
    // The motor is named beside a line of its own: these logs hold no |I2w|/|I1|, so the
    // legend is on the first panel the motor has a point on (issue 79).
    let legend = chart_legend::check(&svg, "trend --plot");
    assert_eq!(legend.len(), 1, "{legend:?}");
    assert_eq!(legend[0].label, "bench");
    // The table: no trend, and why, with the values.
    assert!(stdout.contains("too few for a trend"), "{stdout}");
    assert!(stdout.contains("0.0260"), "{stdout}");
    assert!(stdout.contains("4 of the 28 needed"), "{stdout}");
    assert!(stdout.contains("6.400-7.600 A"), "{stdout}");
    assert!(!stdout.contains("does not vary"), "{stdout}");
    let line = stdout.lines().nth(1).expect("the motor's line");
    assert!(!line.contains(" 0.0 "), "{line}");
}

#[test]
fn reference_until_marks_the_baseline() {
    let dir = tempfile::tempdir().expect("tmp");
    let db = dir.path().join("h.db");
    store_of_four(&db);
    let out = sim_host()
        .args(["trend", "--store"])
        .arg(&db)
        .args(["--reference-until", "2026-11-02", "--json"])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    // The end of 2026-11-02.
    let until = monitor_store::parse_day("2026-11-03").expect("day");
    assert_eq!(doc["options"]["reference_until_s"], until);
    let r = &doc["motors"][0]["reference"];
    assert_eq!(r["marked"], true, "{r}");
    assert_eq!(r["logs"], 2, "{r}");
    assert_eq!(r["last_day"], "2026-11-02", "{r}");
    // The first indicator the logs measured (they have no |I2w|/|I1|: absent, issue 79).
    let e_d = &doc["motors"][0]["indicators"][0];
    assert_eq!(e_d["indicator"], "residual_d");
    let marked: Vec<bool> = e_d["series"]
        .as_array()
        .expect("series")
        .iter()
        .map(|p| p["in_reference"] == true)
        .collect();
    assert_eq!(marked, vec![true, true, false, false]);

    let bad = sim_host()
        .args(["trend", "--store"])
        .arg(&db)
        .args(["--reference-until", "2026-13-01"])
        .output()
        .expect("runs");
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("--reference-until 2026-13-01: not a date"),
        "{err}"
    );
}
