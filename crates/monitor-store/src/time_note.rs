//! What a motor's stored times say of themselves ([`one_day_of_modified_times`]): a history
//! whose logs all took their files' modification times on one day is no history (a copy
//! without `cp -p` put them there), and a reader of the trend is to be told (docs/trend.md).

use crate::row::{utc_day, StoredRow};

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
