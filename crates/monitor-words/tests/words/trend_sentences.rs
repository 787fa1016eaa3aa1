//! The trend's report never contradicts itself: an indicator's sentence says TREND ALARM
//! exactly when its alarm is raised, also where the alarm is held back because the motor
//! has too few logs for the operating-point fit (a real bench's shorted-turn series, ten
//! logs, reported "TREND ALARM" beside "no alarm until then" before this was checked).

use monitor_store::trend::{self, fit_logs, TrendOptions, INDICATORS};
use monitor_store::{LogIdentity, StoredRow};
use monitor_words::trend::sentence;

/// Day `day`'s log of a motor whose negative sequence grows 1 % of I1 a day while its load
/// moves (I1 between 9 and 11 A).
fn row(day: i64) -> StoredRow {
    let id = LogIdentity {
        motor: "m1".into(),
        path: format!("logs/m1_{day}.csv"),
        hash: monitor_store::content_hash(format!("m1 {day}").as_bytes()),
        time_s: 1_793_491_200 + day * 86_400,
    };
    let i1 = 10.0 + ((day * 7) % 5 - 2) as f64 * 0.5;
    let doc = serde_json::json!({
        "verdict": "watching",
        "unbalance": {
            "winding_ratio": 0.01 * day as f64 + 0.0005 * ((day * 3) % 4) as f64,
            "least_change": 0.3,
            "measured": {"i1_peak_a": i1}
        },
        "data_quality": {"rows_read": 1000, "trusted": true}
    });
    StoredRow::from_diagnose(&id, &doc)
}

fn consistent(t: &trend::MotorTrend) {
    for i in &t.indicators {
        let s = sentence(i);
        assert_eq!(s.contains("TREND ALARM"), i.alarm, "{}: {s}", i.indicator);
        assert_eq!(i.reason.alarms(), i.alarm, "{}: {s}", i.indicator);
    }
    assert_eq!(t.alarm, t.indicators.iter().any(|i| i.alarm));
}

#[test]
fn a_steep_rise_on_too_few_logs_is_reported_as_no_alarm_yet_and_alarmed_once_there_are_enough() {
    let i2 = INDICATORS
        .iter()
        .find(|i| i.column == "i2_over_i1")
        .expect("indicator");
    let needed = fit_logs(i2.covariates[0]);
    let opts = TrendOptions::default();

    let few: Vec<StoredRow> = (1..needed as i64).map(row).collect();
    let refs: Vec<&StoredRow> = few.iter().collect();
    let t = trend::motor_trend("m1", &refs, &opts);
    consistent(&t);
    let s = &sentence(
        t.indicators
            .iter()
            .find(|i| i.indicator == "i2_over_i1")
            .expect("trended"),
    );
    assert!(!t.alarm, "{s}");
    assert!(s.contains("no alarm yet"), "{s}");

    let enough: Vec<StoredRow> = (1..=needed as i64 + 2).map(row).collect();
    let refs: Vec<&StoredRow> = enough.iter().collect();
    let t = trend::motor_trend("m1", &refs, &opts);
    consistent(&t);
    assert!(
        t.indicators
            .iter()
            .any(|i| i.indicator == "i2_over_i1" && i.alarm),
        "{:#?}",
        t.indicators.iter().map(sentence).collect::<Vec<_>>()
    );
}

/// Day `day`'s log of a motor at one operating point whose negative sequence is flat for
/// a week and then grows 1 % of I1 a day; its FAULT level 30 % of I1.
fn bend(day: i64) -> StoredRow {
    let id = LogIdentity {
        motor: "m2".into(),
        path: format!("logs/m2_{day}.csv"),
        hash: monitor_store::content_hash(format!("m2 {day}").as_bytes()),
        time_s: 1_793_491_200 + day * 86_400,
    };
    let doc = serde_json::json!({
        "verdict": "watching",
        "unbalance": {
            "winding_ratio": 0.01 * (day - 7).max(0) as f64,
            "least_change": 0.3,
            "measured": {"i1_peak_a": 10.0}
        },
        "data_quality": {"rows_read": 1000, "trusted": true}
    });
    StoredRow::from_diagnose(&id, &doc)
}

#[test]
fn a_rise_that_began_inside_the_window_is_projected_from_the_window_s_second_half() {
    // Days 1..=15: flat to day 7, then 0.01 a day; on day 15 the value is 0.08, and the
    // level 0.3 is 22 days on at the rise's own slope.
    let rows: Vec<StoredRow> = (1..=15).map(bend).collect();
    let refs: Vec<&StoredRow> = rows.iter().collect();
    let t = trend::motor_trend("m2", &refs, &TrendOptions::default());
    let i2 = t
        .indicators
        .iter()
        .find(|i| i.indicator == "i2_over_i1")
        .expect("trended");
    let recent = i2.days_to_fault_recent.expect("recent projection");
    let whole = i2.days_to_fault.expect("window projection");
    assert!(
        (recent - 22.0).abs() < 1.0,
        "recent {recent}, window {whole}"
    );
    assert!(whole > recent + 5.0, "recent {recent}, window {whole}");
}
