//! The trend's words (issue 79): each sentence is spelled here from the trend's typed
//! reason, and says what the reason says: the FAULT level on logs in a row, the stored
//! values where there is no trend, the normalisation's actual reason, the reference; the
//! JSON keeps its keys (`sentence`, `normalisation`, `how`) with the typed reasons beside
//! them.

use monitor_store::row::column_index;
use monitor_store::trend::{self, MotorTrend, TrendOptions, TrendReason};
use monitor_store::{Cell, LogIdentity, StoredRow};
use monitor_words::trend::{normalisation, reference_how, sentence, spelled};

/// 2026-11-01 06:00 UTC: day 1's log.
const START_S: i64 = 1_793_491_200 + 6 * 3600;

/// Day `day`'s log of `motor` with its `verdict` and the columns `values` set.
fn row(motor: &str, day: i64, verdict: &str, values: &[(&str, f64)]) -> StoredRow {
    let id = LogIdentity {
        motor: motor.into(),
        path: format!("logs/{motor}_{day}.csv"),
        hash: monitor_store::content_hash(format!("{motor} {day}").as_bytes()),
        time_s: START_S + (day - 1) * 86_400,
    };
    let mut r = StoredRow::from_diagnose(&id, &serde_json::json!({ "verdict": verdict }));
    for (c, v) in values {
        r.cells[column_index(c).expect("a column")] = Cell::Real(*v);
    }
    r
}

fn motor(rows: &[StoredRow]) -> MotorTrend {
    let refs: Vec<&StoredRow> = rows.iter().collect();
    trend::motor_trend("m", &refs, &TrendOptions::default())
}

fn ind<'a>(m: &'a MotorTrend, column: &str) -> &'a trend::IndicatorTrend {
    m.indicators
        .iter()
        .find(|i| i.indicator == column)
        .expect("trended")
}

/// |I2w|/|I1| of a bench at one load: 0.03 on `healthy` days, then 0.2 (its level 0.08).
fn bench(days: i64, healthy: i64) -> Vec<StoredRow> {
    (1..=days)
        .map(|d| {
            let (x, verdict) = if d <= healthy {
                (0.03 + 0.001 * (d % 3) as f64, "healthy")
            } else {
                (0.2, "fault")
            };
            row(
                "m",
                d,
                verdict,
                &[
                    ("i2_over_i1", x),
                    ("i2_least_change", 0.08),
                    ("i1_peak_a", 3.0 + 0.1 * (d % 4) as f64),
                ],
            )
        })
        .collect()
}

#[test]
fn the_fault_level_on_logs_in_a_row_is_said_as_an_alarm_and_one_log_as_not_yet() {
    let m = motor(&bench(6, 4));
    let i2 = ind(&m, "i2_over_i1");
    assert!(
        matches!(i2.reason, TrendReason::FaultLevelInARow { logs: 2, .. }),
        "{:?}",
        i2.reason
    );
    let s = sentence(i2);
    assert!(
        s.contains("TREND ALARM, at the FAULT level on the last 2 logs in a row, since 2026-11-05"),
        "{s}"
    );
    assert!(
        s.contains("(the last log 20.0 % of I1 against its level 8.00)"),
        "{s}"
    );
    assert!(
        s.ends_with("; a short between turns growing in one phase"),
        "{s}"
    );

    let m = motor(&bench(5, 4));
    let i2 = ind(&m, "i2_over_i1");
    assert!(!i2.alarm);
    let s = sentence(i2);
    assert!(!s.contains("TREND ALARM"), "{s}");
    assert!(
        s.contains("no alarm yet, at the FAULT level on the last 1 of the 2 logs in a row needed"),
        "{s}"
    );
    assert!(!s.contains("a short between turns"), "{s}");
}

/// Four logs of one motor, Rs 0/+10/+20/+40 %, each a FAULT verdict, the load 6.4-7.6 A,
/// e_d rising 0.0001 -> 0.026 (sim-host/tests/cli/trend_view.rs's store).
fn four_fault_logs() -> Vec<StoredRow> {
    let e_d = [0.0001, 0.0082, 0.0155, 0.026];
    let i1 = [6.4, 7.6, 7.0, 6.9];
    (0..4)
        .map(|k| {
            row(
                "m",
                k as i64 + 1,
                "fault",
                &[
                    ("residual_d", e_d[k]),
                    ("i1_peak_a", i1[k]),
                    ("winding_rise_k", 10.0),
                ],
            )
        })
        .collect()
}

#[test]
fn too_few_logs_say_their_stored_values_and_the_normalisation_its_reason() {
    let m = motor(&four_fault_logs());
    let e_d = ind(&m, "residual_d");
    assert_eq!(
        sentence(e_d),
        "residual_d: 4 logs in the last 14 days, too few for a trend or a scatter (at least 6); \
         the stored values 1.00e-4 to 0.0260 pu (first 1.00e-4, last 0.0260)"
    );
    assert_eq!(
        normalisation(&e_d.normalisation),
        "not yet: raw values, too few logs for the operating-point fit (4 of the 28 needed); \
         the load (I1) varied 6.400-7.600 A (i1_peak_a) and is not taken out; its slope does \
         not alarm until then"
    );
    // Every verdict FAULT: the reference is the first days' logs, and says so.
    assert_eq!(
        reference_how(&m.reference),
        "the motor's first 14 days of logs (no log's verdict is healthy or watching)"
    );
    // Only what the logs measured: no |I2w|/|I1|, no sideband, no Rs beyond Rr.
    let names: Vec<&str> = m.indicators.iter().map(|i| i.indicator.as_str()).collect();
    assert_eq!(names, ["residual_d"]);
}

#[test]
fn the_json_keeps_its_keys_with_the_typed_reasons_beside_them() {
    let m = motor(&bench(6, 4));
    let doc = serde_json::to_value(spelled(std::slice::from_ref(&m))).expect("json");
    let i2 = &doc[0]["indicators"][0];
    assert_eq!(i2["indicator"], "i2_over_i1");
    assert_eq!(i2["sentence"], sentence(ind(&m, "i2_over_i1")));
    assert_eq!(i2["reason"]["kind"], "fault_level_in_a_row");
    assert_eq!(i2["reason"]["logs"], 2);
    assert_eq!(i2["reason"]["first_day"], "2026-11-05");
    assert!(i2["normalisation"]
        .as_str()
        .is_some_and(|s| s.starts_with("not yet")));
    assert_eq!(i2["normalisation_reason"]["kind"], "too_few_logs");
    assert_eq!(i2["normalisation_reason"]["needed"], 16);
    let r = &doc[0]["reference"];
    assert_eq!(
        r["how"],
        "the motor's first 4 logs whose verdict is healthy or watching"
    );
    assert_eq!(r["basis"]["kind"], "first_healthy_logs");
    assert_eq!(r["logs"], 4);
}
