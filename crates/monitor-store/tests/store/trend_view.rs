//! A trend a planner can trust (issue 65): the alarm holds once raised until the indicator
//! is back at the motor's reference; the reference is the motor's own first healthy logs
//! (or the baseline the user marks), not all its logs; with few logs the stored values are
//! what is shown, and the report says why; the normalisation gives the actual reason; no
//! days to FAULT on a slope that may be flat. (Their words: crates/monitor-words/tests.)
//!
//! Every row is built here with values chosen in the test (`StoredRow` cells set by
//! column), and every expected value is the test's own.

use monitor_store::row::column_index;
use monitor_store::trend::{
    self, CovariateRange, IndicatorTrend, MotorTrend, Normalisation, TrendOptions, TrendReason,
};
use monitor_store::{Cell, LogIdentity, StoredRow};

/// 2026-11-01 06:00 UTC: day 1's log.
const START_S: i64 = 1_793_491_200 + 6 * 3600;

/// Day `day`'s log of `motor` with its `verdict` and the columns `values` set (all others
/// null).
fn row(motor: &str, day: i64, verdict: &str, values: &[(&str, f64)]) -> StoredRow {
    let id = LogIdentity {
        motor: motor.into(),
        path: format!("logs/{motor}_{day}.csv"),
        hash: monitor_store::content_hash(format!("{motor} {day}").as_bytes()),
        time_s: START_S + (day - 1) * 86_400,
    };
    let mut r = StoredRow::from_diagnose(&id, &serde_json::json!({ "verdict": verdict }));
    for (c, v) in values {
        let i = column_index(c).expect("a column");
        r.cells[i] = Cell::Real(*v);
    }
    r
}

fn motor(rows: &[StoredRow], upto_day: i64, opts: &TrendOptions) -> MotorTrend {
    let refs: Vec<&StoredRow> = rows
        .iter()
        .filter(|r| r.f64("log_time_s").expect("time") < (START_S + upto_day * 86_400) as f64)
        .collect();
    let name = refs[0].str("motor").expect("motor").to_string();
    trend::motor_trend(&name, &refs, opts)
}

fn ind<'a>(m: &'a MotorTrend, column: &str) -> &'a IndicatorTrend {
    m.indicators
        .iter()
        .find(|i| i.indicator == column)
        .expect("trended")
}

/// A small, fixed noise (±0.0005, no trend): day `d`'s.
fn noise(d: i64) -> f64 {
    0.0005 * [0.0, 0.8, -0.6, 0.3, -1.0, 0.5, -0.2, 0.9, -0.7, 0.1][(d % 10) as usize]
}

/// |I2w|/|I1| of a motor at one load (10 A): 0.01 to day 20, rising 0.002 a day from day
/// 21 to day 30 (0.03), flat at 0.03 to day 50, back at 0.01 from day 51 (repaired); its
/// FAULT level 0.05.
fn rise_plateau_repair(day: i64) -> StoredRow {
    let level = match day {
        ..=20 => 0.01,
        21..=30 => 0.01 + 0.002 * (day - 20) as f64,
        31..=50 => 0.03,
        _ => 0.01,
    };
    row(
        "pump",
        day,
        "watching",
        &[
            ("i2_over_i1", level + noise(day)),
            ("i2_least_change", 0.05),
            ("i1_peak_a", 10.0),
        ],
    )
}

#[test]
fn the_alarm_holds_once_raised_until_the_indicator_is_back_at_its_reference() {
    let rows: Vec<StoredRow> = (1..=75).map(rise_plateau_repair).collect();
    let opts = TrendOptions::default();
    let alarmed = |day: i64| ind(&motor(&rows, day, &opts), "i2_over_i1").alarm;
    let raised = (1..=50).find(|d| alarmed(*d)).expect("the rise is alarmed");
    assert!((22..=30).contains(&raised), "raised on day {raised}");
    // The plateau (days 31-50) stops the slope, not the fault: the alarm holds.
    let dropped: Vec<i64> = (raised..=50).filter(|d| !alarmed(*d)).collect();
    assert!(
        dropped.is_empty(),
        "raised on day {raised}, not alarmed on days {dropped:?}"
    );
    let m = motor(&rows, 50, &opts);
    let i2 = ind(&m, "i2_over_i1");
    assert!(m.alarm);
    assert_eq!(
        i2.alarm_since.as_deref(),
        Some(monitor_store::utc_day(START_S + (raised - 1) * 86_400).as_str())
    );
    assert!(
        matches!(i2.reason, TrendReason::Held { ref since, .. } if Some(since) == i2.alarm_since.as_ref()),
        "{:?}",
        i2.reason
    );
    // Repaired on day 51: the values are back at once, the 14-day line within two weeks.
    for day in 66..=75 {
        let i2 = ind(&motor(&rows, day, &opts), "i2_over_i1").clone();
        assert!(!i2.alarm, "day {day}: {:?}", i2.reason);
        assert_eq!(i2.alarm_since, None);
    }
}

#[test]
fn one_quiet_log_does_not_clear_a_raised_alarm() {
    // The plateau at 0.03 with one log back at 0.01 (day 40): one log in the band is not
    // two in a row.
    let rows: Vec<StoredRow> = (1..=45)
        .map(|d| {
            if d == 40 {
                row(
                    "pump",
                    d,
                    "watching",
                    &[
                        ("i2_over_i1", 0.01),
                        ("i2_least_change", 0.05),
                        ("i1_peak_a", 10.0),
                    ],
                )
            } else {
                rise_plateau_repair(d)
            }
        })
        .collect();
    let opts = TrendOptions::default();
    for day in 35..=45 {
        assert!(
            ind(&motor(&rows, day, &opts), "i2_over_i1").alarm,
            "day {day}"
        );
    }
}

/// e_d of a motor that degrades: 0.002 ± noise for 14 days, then rising 0.001 a day to day
/// 40 (0.028); load and temperature fixed (no operating-point fit: raw values).
fn degrading(day: i64, verdict: &str) -> StoredRow {
    let e_d = 0.002 + 0.001 * (day - 14).max(0) as f64 + noise(day);
    row(
        "fan",
        day,
        verdict,
        &[
            ("residual_d", e_d),
            ("i1_peak_a", 7.0),
            ("winding_rise_k", 20.0),
        ],
    )
}

#[test]
fn the_reference_is_the_motor_s_first_healthy_logs_not_all_its_logs() {
    // Days 1 and 2 judged FAULT (a wrong parameter file on commissioning day, say): left
    // out; days 3-14 are the reference.
    let rows: Vec<StoredRow> = (1..=40)
        .map(|d| degrading(d, if d <= 2 { "fault" } else { "healthy" }))
        .collect();
    let m = motor(&rows, 40, &TrendOptions::default());
    assert_eq!(m.reference.logs, 12, "{:?}", m.reference);
    assert_eq!(m.reference.first_day.as_deref(), Some("2026-11-03"));
    assert_eq!(m.reference.last_day.as_deref(), Some("2026-11-14"));
    assert!(!m.reference.marked);
    let e_d = ind(&m, "residual_d");
    let in_ref = e_d.series.iter().filter(|p| p.in_reference).count();
    assert_eq!(in_ref, 12);
    // The healthy level is 0.002 (the median of all 40 logs would be about 0.015).
    let centre = e_d.reference_centre.expect("centre");
    assert!((centre - 0.002).abs() < 0.0005, "centre {centre}");
    let scatter = e_d.reference_scatter.expect("scatter");
    assert!(scatter > 0.0 && scatter < 0.001, "scatter {scatter}");
    // Day 40 stands 0.026 above the healthy level: over 26 of its scatters.
    let from = e_d.from_reference_scatters.expect("from the reference");
    assert!(from > 26.0, "{from}");
    // Every healthy first day within the band (k = 3 scatters) of the reference.
    for p in e_d.series.iter().filter(|p| p.in_reference) {
        let z = (p.normalised - centre) / scatter;
        assert!(z.abs() <= 3.0, "{z} on day {}", p.t_days);
    }
}

#[test]
fn a_marked_baseline_is_the_reference() {
    let rows: Vec<StoredRow> = (1..=40).map(|d| degrading(d, "healthy")).collect();
    let opts = TrendOptions {
        // The end of day 8 (2026-11-08): days 1-8.
        reference_until_s: Some(monitor_store::parse_day("2026-11-09").expect("day")),
        ..TrendOptions::default()
    };
    let m = motor(&rows, 40, &opts);
    assert!(m.reference.marked);
    assert_eq!(m.reference.logs, 8);
    assert_eq!(m.reference.last_day.as_deref(), Some("2026-11-08"));
    let e_d = ind(&m, "residual_d");
    assert_eq!(e_d.series.iter().filter(|p| p.in_reference).count(), 8);
}

/// The users' case: four logs of one motor, Rs 0/+10/+20/+40 %, each a FAULT verdict, the
/// load 6.4-7.6 A, e_d rising 0.0001 -> 0.026.
fn four_fault_logs() -> Vec<StoredRow> {
    let e_d = [0.0001, 0.0082, 0.0155, 0.026];
    let e_q = [-0.0002, -0.004, -0.0081, -0.0163];
    let i1 = [6.4, 7.6, 7.0, 6.9];
    (0..4)
        .map(|k| {
            row(
                "bench",
                k as i64 + 1,
                "fault",
                &[
                    ("residual_d", e_d[k]),
                    ("residual_q", e_q[k]),
                    ("residual_t", 0.5 * e_d[k]),
                    ("rs_change_pct", 10.0 * k as f64),
                    ("i1_peak_a", i1[k]),
                    ("winding_rise_k", 10.0),
                ],
            )
        })
        .collect()
}

#[test]
fn four_logs_show_their_stored_values_and_say_why_there_is_no_trend() {
    let rows = four_fault_logs();
    let m = motor(&rows, 4, &TrendOptions::default());
    let e_d = ind(&m, "residual_d");
    let stored: Vec<f64> = e_d.series.iter().map(|p| p.normalised).collect();
    assert_eq!(stored, vec![0.0001, 0.0082, 0.0155, 0.026]);
    assert!(!e_d.operating_point_fitted);
    assert_eq!(e_d.scatter, None);
    assert_eq!(e_d.reference_scatter, None);
    match &e_d.reason {
        TrendReason::TooFewLogs {
            logs: 4,
            needed: 6,
            values: Some(v),
            ..
        } => assert_eq!(
            (v.low, v.high, v.first, v.last),
            (0.0001, 0.026, 0.0001, 0.026)
        ),
        other => panic!("{other:?}"),
    }
    // The reason for the raw values: too few logs, 4 of 28, while the load moved.
    match &e_d.normalisation {
        Normalisation::TooFewLogs {
            logs: 4,
            needed: 28,
            lacking: 0,
            total: 4,
            moved,
        } => {
            // The load moved; the rise (10 K on every log) did not.
            assert_eq!(moved.len(), 1, "{moved:?}");
            near(&moved[0], "i1_peak_a", 6.4, 7.6);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn raw_values_say_the_actual_reason() {
    // 30 logs; the load moves (6.4-7.6 A) but only 10 logs have the windings' rise (the
    // isolation ran on those): too few for the fit, though the motor has 30 logs.
    let rows: Vec<StoredRow> = (1..=30)
        .map(|d| {
            let i1 = 7.0 + 0.6 * ((d * 7) % 5 - 2) as f64 / 2.0;
            let mut v = vec![("residual_d", 0.002 + noise(d)), ("i1_peak_a", i1)];
            if d % 3 == 0 {
                v.push(("winding_rise_k", 10.0 + d as f64));
            }
            row("m", d, "healthy", &v)
        })
        .collect();
    let n = ind(&motor(&rows, 30, &TrendOptions::default()), "residual_d")
        .normalisation
        .clone();
    match n {
        Normalisation::TooFewLogs {
            logs: 10,
            needed: 28,
            lacking: 20,
            total: 30,
            moved,
        } => near(&moved[0], "i1_peak_a", 6.4, 7.6),
        other => panic!("{other:?}"),
    }

    // 30 logs at one load (7.0 A) with a temperature that moves: the load really does
    // not vary, the temperature does.
    let rows: Vec<StoredRow> = (1..=30)
        .map(|d| {
            let v = [
                ("residual_d", 0.002 + noise(d)),
                ("i1_peak_a", 7.0),
                ("winding_temperature_c", 30.0 + (d % 7) as f64),
            ];
            row("m", d, "healthy", &v)
        })
        .collect();
    let n = ind(&motor(&rows, 30, &TrendOptions::default()), "residual_d")
        .normalisation
        .clone();
    match n {
        Normalisation::Flat { flat, moved } => {
            assert_eq!((flat.len(), moved.len()), (1, 1), "{flat:?} {moved:?}");
            near(&flat[0], "i1_peak_a", 7.0, 7.0);
            near(&moved[0], "winding_temperature_c", 30.0, 36.0);
        }
        other => panic!("{other:?}"),
    }
}

/// `r` is covariate `column`'s range `low`-`high` (to 1e-9).
fn near(r: &CovariateRange, column: &str, low: f64, high: f64) {
    assert_eq!(r.column, column, "{r:?}");
    assert!(
        (r.low - low).abs() < 1e-9 && (r.high - high).abs() < 1e-9,
        "{r:?}"
    );
}

#[test]
fn a_slope_that_may_be_flat_projects_no_days_to_fault() {
    // A healthy |I2w|/|I1| at one load: 0.01 with noise and a drift of 2e-6 a day, far
    // inside the noise; FAULT level 0.05 (at this slope: 20 000 days).
    let rows: Vec<StoredRow> = (1..=30)
        .map(|d| {
            let x = 0.01 + 2e-6 * d as f64 + 2.0 * noise(d * 3);
            row(
                "m",
                d,
                "healthy",
                &[
                    ("i2_over_i1", x),
                    ("i2_least_change", 0.05),
                    ("i1_peak_a", 10.0),
                ],
            )
        })
        .collect();
    let m = motor(&rows, 30, &TrendOptions::default());
    let i2 = ind(&m, "i2_over_i1");
    let (slope, low) = (i2.slope_per_day.expect("slope"), i2.slope_low.expect("low"));
    // The premise: a rising median slope whose interval takes in zero.
    assert!(slope > 0.0 && low <= 0.0, "slope {slope}, low {low}");
    assert_eq!(i2.days_to_fault, None, "{:?}", i2.reason);
    assert_eq!(i2.days_to_fault_recent, None, "{:?}", i2.reason);
    assert_eq!(
        i2.reason,
        TrendReason::NoAlarm {
            days_to_fault: None
        }
    );
    assert!(!i2.alarm);
}

/// Issue 86: fourteen daily logs of a motor whose short grows to the FAULT level (from day
/// 9 on |I2w|/|I1| at or beyond its level, 0.05), every log's verdict `healthy` (judged
/// alone against the file). The trend says "at the FAULT level on the last 6 logs in a
/// row"; the reference, the motor's first healthy logs, must not take in those at the
/// FAULT level, so that the plot's band (the reference's centre and scatter) says what
/// the text says: the last log many reference scatters out.
#[test]
fn logs_at_the_fault_level_are_no_reference_whatever_their_verdict() {
    let rows: Vec<StoredRow> = (1..=14)
        .map(|d| {
            let v = if d <= 8 {
                0.01
            } else {
                0.052 + 0.004 * (d - 9) as f64
            };
            row(
                "fan",
                d,
                "healthy",
                &[
                    ("i2_over_i1", v + noise(d)),
                    ("i2_least_change", 0.05),
                    ("i1_peak_a", 10.0),
                ],
            )
        })
        .collect();
    let m = motor(&rows, 15, &TrendOptions::default());
    let t = ind(&m, "i2_over_i1");
    assert!(t.alarm, "{:?}", t.reason);
    let refs: Vec<f64> = t
        .series
        .iter()
        .filter(|p| p.in_reference)
        .map(|p| p.value)
        .collect();
    assert_eq!(refs.len(), 8, "{refs:?}");
    assert!(refs.iter().all(|v| *v < 0.02), "{refs:?}");
    let centre = t.reference_centre.expect("a centre");
    assert!((centre - 0.01).abs() < 0.002, "{centre}");
    assert!(
        t.from_reference_scatters.is_some_and(|s| s > 10.0),
        "{:?}",
        t.from_reference_scatters
    );
}
