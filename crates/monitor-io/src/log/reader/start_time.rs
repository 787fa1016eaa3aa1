//! A log's absolute start ([`LogFile::start_time`]): what the log itself says of when it was
//! recorded, for the motors' history (docs/trend.md). The file's modification time is not
//! the log's: it is the caller's last resort.

use super::{LogFile, ReadSource, RowSink};
use crate::log::{exact, Column, LogError, Row};

/// Where a log's absolute start comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogStartFrom {
    /// Its time column holds timestamps (`[columns]` unit `timestamp`, `iso8601` or
    /// `epoch_*`, or a Parquet `TIMESTAMP` column): its first finite time.
    TimeColumn,
    /// A TDMS channel's `wf_start_time` property.
    TdmsStartTime,
}

/// A log's absolute start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogStart {
    /// The start [s since 1970-01-01 UTC].
    pub utc_s: f64,
    /// Where it comes from.
    pub from: LogStartFrom,
}

/// The first finite time handed over.
struct FirstTime(Option<f64>);

impl RowSink for FirstTime {
    fn row(&mut self, row: &Row) -> bool {
        if row.t_s.is_finite() {
            self.0 = Some(row.t_s);
        }
        self.0.is_none()
    }
    fn restart(&mut self) {
        self.0 = None;
    }
}

impl LogFile {
    /// The log's absolute start, if the log says it: the first finite time of a time column
    /// of timestamps, else (a TDMS log) a channel's `wf_start_time`; `None` for a log whose
    /// time counts from its own start (`s`, `ms`, `us`, a sample rate) without
    /// `wf_start_time`. Reads the rows only up to the first finite time.
    ///
    /// # Errors
    /// As [`LogFile::for_each_row`] (a timestamp column without one time among them).
    pub fn start_time(&self) -> Result<Option<LogStart>, LogError> {
        if self.columns.time != crate::log::mapping::TimeKind::Plain
            && self.columns.of(Column::Time).is_some()
        {
            if let Some(utc_s) = self.first_timestamp_s()? {
                return Ok(Some(LogStart {
                    utc_s,
                    from: LogStartFrom::TimeColumn,
                }));
            }
        }
        if let ReadSource::Tdms(t) = &self.source {
            return Ok(t.start_utc_s().map(|utc_s| LogStart {
                utc_s,
                from: LogStartFrom::TdmsStartTime,
            }));
        }
        Ok(None)
    }

    /// The first finite time of a timestamp column [s since 1970-01-01 UTC].
    fn first_timestamp_s(&self) -> Result<Option<f64>, LogError> {
        if self.columns.time.is_text() {
            if !matches!(self.source, ReadSource::Csv { .. }) {
                return Ok(None);
            }
            let mut rows = exact::ExactRows::new(&self.opened())?;
            while let Some(r) = rows.next_row()? {
                if r.t_s.is_finite() {
                    return Ok(rows.time_origin_s().map(|o| o as f64 + r.t_s));
                }
            }
            return Ok(None);
        }
        let mut first = FirstTime(None);
        self.rows_in_order(&mut |_| {}, &mut first)?;
        Ok(first.0.map(|t| t * self.columns.time_factor))
    }
}

#[cfg(test)]
mod tests {
    use crate::log::{ChannelUnit, Column, ColumnMapping, LogFile, LogStartFrom, OpenOptions};
    use std::path::Path;

    /// A CSV of `times` in a `Time` column read as `unit`, and its rows' times.
    fn read(dir: &Path, name: &str, unit: &str, times: &[&str]) -> (LogFile, Vec<f64>) {
        let p = dir.join(name);
        let mut text = String::from("Time,ia_A,ib_A,ic_A\n");
        for t in times {
            text.push_str(&format!("{t},1,2,3\n"));
        }
        std::fs::write(&p, text).unwrap();
        let mut columns = ColumnMapping::new(2);
        let u = ChannelUnit::parse(Column::Time, unit).unwrap();
        columns.set(Column::Time, "Time", Some(u)).unwrap();
        let opts = OpenOptions {
            group: None,
            columns,
        };
        let log = LogFile::open_with(&p, &opts).unwrap();
        let mut t = Vec::new();
        let mut sink = |r: &crate::log::Row| {
            t.push(r.t_s);
            true
        };
        log.for_each_row(&mut |_| {}, &mut Sink(&mut sink)).unwrap();
        (log, t)
    }

    struct Sink<'a>(&'a mut dyn FnMut(&crate::log::Row) -> bool);
    impl crate::log::RowSink for Sink<'_> {
        fn row(&mut self, r: &crate::log::Row) -> bool {
            (self.0)(r)
        }
        fn restart(&mut self) {}
    }

    // 2026-11-03T06:00:00Z (`date -u -d 2026-11-03T06:00:00Z +%s`).
    const NOV3_6H: f64 = 1_793_685_600.0;

    #[test]
    fn iso_text_gives_the_logs_start_and_times_from_the_first_row() {
        let d = tempfile::tempdir().unwrap();
        let (log, t) = read(
            d.path(),
            "a.csv",
            "timestamp",
            &[
                "2026-11-03T08:00:00.125+02:00",
                "2026-11-03 06:00:00.375",
                "not a time",
                "2026-11-03T06:00:00.625Z",
            ],
        );
        let s = log.start_time().unwrap().unwrap();
        assert_eq!(s.from, LogStartFrom::TimeColumn);
        assert!((s.utc_s - (NOV3_6H + 0.125)).abs() < 1e-6, "{s:?}");
        assert_eq!(t[0], 0.0);
        assert!(
            (t[1] - 0.25).abs() < 1e-9 && (t[3] - 0.5).abs() < 1e-9,
            "{t:?}"
        );
        // The bad cell is handed over as a bad cell (NaN), not an error.
        assert!(t[2].is_nan(), "{t:?}");
    }

    #[test]
    fn epoch_seconds_give_the_logs_start() {
        let d = tempfile::tempdir().unwrap();
        for unit in ["timestamp", "epoch_s"] {
            let (log, t) = read(
                d.path(),
                "b.csv",
                unit,
                &["1793685600.5", "1793685600.75", "1793685601"],
            );
            let s = log.start_time().unwrap().unwrap();
            assert!((s.utc_s - (NOV3_6H + 0.5)).abs() < 1e-6, "{unit} {s:?}");
            assert!((t[2] - 0.5).abs() < 1e-6, "{unit} {t:?}");
        }
        // A time column in seconds from the log's start says nothing of its date.
        let (log, _) = read(d.path(), "c.csv", "s", &["0", "0.25"]);
        assert_eq!(log.start_time().unwrap(), None);
    }

    #[test]
    fn a_column_without_one_time_is_an_error_naming_it() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("bad.csv");
        std::fs::write(&p, "Time,ia_A,ib_A,ic_A\nyesterday,1,2,3\nsoon,1,2,3\n").unwrap();
        let mut columns = ColumnMapping::new(2);
        columns
            .set(Column::Time, "Time", Some(ChannelUnit::Timestamp))
            .unwrap();
        let opts = OpenOptions {
            group: None,
            columns,
        };
        let log = LogFile::open_with(&p, &opts).unwrap();
        let e = log.start_time().unwrap_err().to_string();
        assert!(
            e.contains("column 'Time' holds no time") && e.contains("'yesterday'"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
