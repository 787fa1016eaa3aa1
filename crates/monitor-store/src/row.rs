//! The store's row: one judged log of one motor ([`StoredRow`]), its columns ([`COLUMNS`]),
//! and how a row is taken from `diagnose --json`'s document ([`StoredRow::from_diagnose`]):
//! nothing is analysed again, every value is one the diagnosis already reported.

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};
use serde_json::Value;

/// A column's type: what SQLite and Parquet store it as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Text (SQLite TEXT, Parquet UTF-8 byte array).
    Text,
    /// A whole number (SQLite INTEGER, Parquet INT64).
    Int,
    /// A real number (SQLite REAL, Parquet DOUBLE).
    Real,
}

/// One column of the store: its name, type, and what it holds (with its unit and the
/// `diagnose --json` key it is taken from).
#[derive(Debug, Clone, Copy)]
pub struct StoreColumn {
    /// The column's name (SQLite, Parquet, pandas).
    pub name: &'static str,
    /// Its type.
    pub kind: Kind,
    /// What it holds.
    pub doc: &'static str,
}

const fn c(name: &'static str, kind: Kind, doc: &'static str) -> StoreColumn {
    StoreColumn { name, kind, doc }
}

/// The columns, in order. The first six say which log of which motor and when; every value
/// after them is one `diagnose --json` reported (the key in brackets); null where the
/// diagnosis had none (a fault not named, a rotor not judged); `time_source` says where the
/// log's time came from. Columns added since the first version come last, so that an older
/// store takes them with `ALTER TABLE ... ADD COLUMN` ([`Store::open`](crate::Store::open)).
pub const COLUMNS: [StoreColumn; 36] = [
    c(
        "log_id",
        Kind::Text,
        "the log's identity: its content hash, a colon, its path (unique)",
    ),
    c(
        "log_hash",
        Kind::Text,
        "FNV-1a 64-bit hash of the log file's bytes, 16 hex digits",
    ),
    c("log_path", Kind::Text, "the log's path as given"),
    c("motor", Kind::Text, "the motor's id"),
    c(
        "log_time_s",
        Kind::Int,
        "the log's start, seconds since 1970-01-01 UTC",
    ),
    c("day", Kind::Text, "the log's UTC day, YYYY-MM-DD"),
    c(
        "verdict",
        Kind::Text,
        "fault, watching, healthy or could_not_judge [verdict]",
    ),
    c(
        "fault",
        Kind::Text,
        "the fault the verdict names [verdict_finding.fault]",
    ),
    c(
        "size",
        Kind::Real,
        "its size in size_unit [verdict_finding.size]",
    ),
    c(
        "size_unit",
        Kind::Text,
        "relative, turns_fraction, of_i1, db_below_line",
    ),
    c(
        "phase",
        Kind::Text,
        "its phase a, b or c [verdict_finding.phase]",
    ),
    c(
        "confidence",
        Kind::Real,
        "its calibrated confidence 0..1 [verdict_finding.confidence]",
    ),
    c(
        "isolation_named",
        Kind::Text,
        "the isolation's named fault [isolation.named]",
    ),
    c(
        "named_change_pct",
        Kind::Real,
        "its change in % [isolation.named_change]",
    ),
    c(
        "rs_change_pct",
        Kind::Real,
        "Rs change in % where listed [candidates rs.change]",
    ),
    c(
        "rr_change_pct",
        Kind::Real,
        "Rr change in % where listed [candidates rr.change]",
    ),
    c(
        "winding_rise_k",
        Kind::Real,
        "the windings' rise the isolation read, K [isolation.winding_rise_k]",
    ),
    c(
        "heating_explains",
        Kind::Int,
        "1 when heating explains the change [isolation.heating_explains]",
    ),
    c(
        "winding_temperature_c",
        Kind::Real,
        "the log's temperature channel, degC [isolation.winding_temperature_c]",
    ),
    c(
        "residual_d",
        Kind::Real,
        "parity residual e_d minus the baseline [isolation.residuals[0]]; null where the isolation judged no point (no voltages)",
    ),
    c(
        "residual_q",
        Kind::Real,
        "parity residual e_q minus the baseline [isolation.residuals[1]]; null where the isolation judged no point (no voltages)",
    ),
    c(
        "residual_t",
        Kind::Real,
        "parity residual e_T minus the baseline [isolation.residuals[2]]; null where the isolation judged no point (no voltages)",
    ),
    c(
        "deviation_sigma",
        Kind::Real,
        "the change in healthy standard deviations [isolation.deviation_sigma]",
    ),
    c(
        "i2_over_i1",
        Kind::Real,
        "the winding's negative-sequence change |I2w|/|I1| [unbalance.winding_ratio]",
    ),
    c(
        "i2_angle_deg",
        Kind::Real,
        "its angle arg(I2w/I1), deg [unbalance.angle_deg]",
    ),
    c(
        "i2_least_change",
        Kind::Real,
        "the change of |I2w|/|I1| that names a phase [unbalance.least_change]",
    ),
    c(
        "sideband_db",
        Kind::Real,
        "the rotor's lower sideband, dB to the line, where judged [rotor.level_db]",
    ),
    c("slip", Kind::Real, "slip [rotor.slip]"),
    c(
        "i1_peak_a",
        Kind::Real,
        "positive-sequence current peak, A [unbalance.measured.i1_peak_a]",
    ),
    c(
        "speed_rad_s",
        Kind::Real,
        "electrical rotor speed, rad/s [unbalance.measured.wr_rad_s]",
    ),
    c(
        "supply_hz",
        Kind::Real,
        "supply frequency, Hz [data_quality.current_frequency_hz]",
    ),
    c("rows", Kind::Int, "rows read [data_quality.rows_read]"),
    c(
        "rate_hz",
        Kind::Real,
        "sample rate, Hz [data_quality.sample_rate_hz]",
    ),
    c(
        "trusted",
        Kind::Int,
        "1 when the data quality is trusted [data_quality.trusted]",
    ),
    c(
        "time_source",
        Kind::Text,
        "where log_time_s comes from: log (a time column of timestamps), tdms (wf_start_time), file_name (the motor table's time_from_name), modified (the file's modification time); null in rows stored before it was kept",
    ),
    c(
        "stator_excess_pct",
        Kind::Real,
        "Rs's change beyond Rr's in %, free of the winding's temperature [isolation.resistances.stator_excess]",
    ),
];

/// The index of column `name` in [`COLUMNS`].
pub fn column_index(name: &str) -> Option<usize> {
    COLUMNS.iter().position(|c| c.name == name)
}

/// One value of a row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value.
    Null,
    /// A whole number.
    Int(i64),
    /// A real number (finite).
    Real(f64),
    /// Text.
    Text(String),
}

impl Cell {
    /// The value as a real number (a whole number too), if it is one.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Cell::Real(x) => Some(*x),
            Cell::Int(i) => Some(*i as f64),
            _ => None,
        }
    }

    /// The value as text, if it is text.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Cell::Text(s) => Some(s),
            _ => None,
        }
    }
}

/// One stored row: a value per column of [`COLUMNS`], in order. JSON: an object keyed by
/// the columns' names.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredRow {
    /// The values, one per column of [`COLUMNS`].
    pub cells: Vec<Cell>,
}

/// Which log of which motor, and when: the first columns of a row.
#[derive(Debug, Clone, PartialEq)]
pub struct LogIdentity {
    /// The motor's id.
    pub motor: String,
    /// The log's path as given.
    pub path: String,
    /// The hash of its bytes ([`content_hash`]).
    pub hash: String,
    /// Its start, seconds since 1970-01-01 UTC.
    pub time_s: i64,
}

impl LogIdentity {
    /// The identity of the log file at `path` as motor `motor`'s: the hash of its bytes
    /// (read in 1 MiB pieces) and its time, the file's modification time: the last resort
    /// (`monitor_api::fleet::log_time` finds the log's own time first; docs/trend.md) that
    /// a caller replaces with a better one.
    ///
    /// # Errors
    /// The file cannot be read or has no modification time.
    pub fn of_file(motor: &str, path: &std::path::Path) -> std::io::Result<Self> {
        use std::io::Read;
        let mut f = std::fs::File::open(path)?;
        let time = f.metadata()?.modified()?;
        let mut h: u64 = FNV_OFFSET;
        let mut buf = vec![0u8; 1 << 20];
        loop {
            let n = f.read(&mut buf)?;
            if n == 0 {
                break;
            }
            h = fnv1a(h, buf.get(..n).unwrap_or_default());
        }
        let time_s = match time.duration_since(std::time::UNIX_EPOCH) {
            Ok(d) => d.as_secs() as i64,
            Err(e) => -(e.duration().as_secs_f64().ceil() as i64),
        };
        Ok(LogIdentity {
            motor: motor.to_string(),
            path: path.display().to_string(),
            hash: format!("{h:016x}"),
            time_s,
        })
    }

    /// The `log_id` of this log (unique in a store): `<hash>:<path>`.
    pub fn log_id(&self) -> String {
        format!("{}:{}", self.hash, self.path)
    }
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

impl StoredRow {
    /// The value of column `name` (null for an unknown name).
    pub fn get(&self, name: &str) -> &Cell {
        column_index(name)
            .and_then(|i| self.cells.get(i))
            .unwrap_or(&Cell::Null)
    }

    /// Column `name` as a real number, if it holds one.
    pub fn f64(&self, name: &str) -> Option<f64> {
        self.get(name).as_f64()
    }

    /// Column `name` as text, if it holds text.
    pub fn str(&self, name: &str) -> Option<&str> {
        self.get(name).as_str()
    }

    /// The log's identity (`log_id`, unique in a store).
    pub fn log_id(&self) -> &str {
        self.str("log_id").unwrap_or_default()
    }

    /// The row of one log from its `diagnose --json` document `doc` (the one
    /// `monitor_api::diagnose` reports; `serde_json::to_value` of the report).
    pub fn from_diagnose(id: &LogIdentity, doc: &Value) -> Self {
        let mut cells = vec![
            Cell::Text(id.log_id()),
            Cell::Text(id.hash.clone()),
            Cell::Text(id.path.clone()),
            Cell::Text(id.motor.clone()),
            Cell::Int(id.time_s),
            Cell::Text(utc_day(id.time_s)),
        ];
        cells.extend(report_cells(doc));
        StoredRow { cells }
    }

    /// The row with its `time_source` (`log`, `tdms`, `file_name` or `modified`: where its
    /// `log_time_s` comes from; null until set).
    pub fn with_time_source(mut self, source: &str) -> Self {
        if let Some(c) = column_index("time_source").and_then(|i| self.cells.get_mut(i)) {
            *c = Cell::Text(source.to_string());
        }
        self
    }
}

impl StoredRow {
    /// A row from its JSON object (the one [`StoredRow`]'s `Serialize` writes: keyed by
    /// the columns' names; a missing key is null), or `None` when a value has the wrong
    /// type or `log_id` is missing.
    pub fn from_json(v: &Value) -> Option<Self> {
        let obj = v.as_object()?;
        let cells: Option<Vec<Cell>> = COLUMNS
            .iter()
            .map(|c| match (obj.get(c.name), c.kind) {
                (None | Some(Value::Null), _) => Some(Cell::Null),
                (Some(Value::String(s)), Kind::Text) => Some(Cell::Text(s.clone())),
                (Some(x), Kind::Int) => x.as_i64().map(Cell::Int),
                (Some(x), Kind::Real) => x.as_f64().map(Cell::Real),
                _ => None,
            })
            .collect();
        let row = StoredRow { cells: cells? };
        (!row.log_id().is_empty()).then_some(row)
    }
}

/// The cells after the identity's, from the report `doc` (in [`COLUMNS`]' order).
fn report_cells(doc: &Value) -> Vec<Cell> {
    let num = |p: &str| {
        doc.pointer(p)
            .and_then(Value::as_f64)
            .filter(|x| x.is_finite())
    };
    let text = |p: &str| doc.pointer(p).and_then(Value::as_str).map(str::to_string);
    let flag = |p: &str| doc.pointer(p).and_then(Value::as_bool).map(i64::from);
    let candidate = |fault: &str| candidate_change_pct(doc, fault);
    let named = doc.pointer("/isolation/named").and_then(|v| match v {
        Value::String(s) => Some(s.clone()),
        Value::Null => None,
        other => Some(other.to_string()),
    });
    let judged = doc.pointer("/rotor/judged") == Some(&Value::Bool(true));
    // The isolation's residuals, their deviation and its heating flag are measured only
    // where it judged an operating point (a log without voltages reports them as zeros
    // with the state `not_judged`): null there, never a 0 that reads as healthy.
    let isolated = doc.pointer("/isolation/state").and_then(Value::as_str) != Some("not_judged");
    let iso = |x: Option<f64>| x.filter(|_| isolated);
    let finding = is_named(doc);
    let real = |x: Option<f64>| x.map_or(Cell::Null, Cell::Real);
    let txt = |x: Option<String>| x.map_or(Cell::Null, Cell::Text);
    let int = |x: Option<i64>| x.map_or(Cell::Null, Cell::Int);
    vec![
        txt(text("/verdict")),
        txt(text("/verdict_finding/fault").filter(|_| finding)),
        real(num("/verdict_finding/size").filter(|_| finding)),
        txt(text("/verdict_finding/size_unit").filter(|_| finding)),
        txt(text("/verdict_finding/phase").filter(|_| finding)),
        real(num("/verdict_finding/confidence").filter(|_| finding)),
        txt(named),
        real(num("/isolation/named_change").map(|x| 100.0 * x)),
        real(candidate("rs")),
        real(candidate("rr")),
        real(num("/isolation/winding_rise_k")),
        int(flag("/isolation/heating_explains").filter(|_| isolated)),
        real(num("/isolation/winding_temperature_c")),
        real(iso(num("/isolation/residuals/0"))),
        real(iso(num("/isolation/residuals/1"))),
        real(iso(num("/isolation/residuals/2"))),
        real(iso(num("/isolation/deviation_sigma"))),
        real(num("/unbalance/winding_ratio")),
        real(num("/unbalance/angle_deg")),
        real(num("/unbalance/least_change")),
        real(num("/rotor/level_db").filter(|_| judged)),
        real(num("/rotor/slip")),
        real(num("/unbalance/measured/i1_peak_a")),
        real(num("/unbalance/measured/wr_rad_s")),
        real(num("/data_quality/current_frequency_hz")),
        int(doc
            .pointer("/data_quality/rows_read")
            .and_then(Value::as_i64)),
        real(num("/data_quality/sample_rate_hz")),
        int(flag("/data_quality/trusted")),
        // time_source: the caller's ([`StoredRow::with_time_source`]).
        Cell::Null,
        real(num("/isolation/resistances/stator_excess").map(|x| 100.0 * x)),
    ]
}

/// The change in % of the candidate `fault` of the report `doc`, where it lists one.
fn candidate_change_pct(doc: &Value, fault: &str) -> Option<f64> {
    doc.pointer("/candidates")
        .and_then(Value::as_array)
        .and_then(|c| c.iter().find(|x| x["fault"] == fault))
        .and_then(|x| x["change"].as_f64())
        .map(|x| 100.0 * x)
}

/// The verdict's finding names a fault (a FAULT's or a watched one).
fn is_named(doc: &Value) -> bool {
    doc.pointer("/verdict_finding/state")
        .and_then(Value::as_str)
        == Some("named")
}

impl Serialize for StoredRow {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(COLUMNS.len()))?;
        for (col, cell) in COLUMNS.iter().zip(&self.cells) {
            match cell {
                Cell::Null => m.serialize_entry(col.name, &())?,
                Cell::Int(i) => m.serialize_entry(col.name, i)?,
                Cell::Real(x) => m.serialize_entry(col.name, x)?,
                Cell::Text(t) => m.serialize_entry(col.name, t)?,
            }
        }
        m.end()
    }
}

/// FNV-1a, 64 bits, of `bytes`, as 16 hex digits: a log's content identity (not a
/// cryptographic hash: it tells logs apart, it does not guard against forgery).
pub fn content_hash(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a(FNV_OFFSET, bytes))
}

/// The Julian day number of 1970-01-01.
const UNIX_EPOCH_JULIAN_DAY: i64 = 2_440_588;

/// The UTC day `YYYY-MM-DD` of `t_s` seconds since 1970-01-01 (the proleptic Gregorian
/// calendar, by the `time` crate); `invalid-day` outside the years -9999..=9999.
pub fn utc_day(t_s: i64) -> String {
    let jd = t_s.div_euclid(86_400) + UNIX_EPOCH_JULIAN_DAY;
    i32::try_from(jd)
        .ok()
        .and_then(|jd| time::Date::from_julian_day(jd).ok())
        .map_or_else(
            || "invalid-day".to_string(),
            |d| format!("{:04}-{:02}-{:02}", d.year(), u8::from(d.month()), d.day()),
        )
}

/// Seconds since 1970-01-01 UTC of the day `YYYY-MM-DD` (its midnight), if it is one (a
/// real calendar day: `2026-02-30` is not).
pub fn parse_day(day: &str) -> Option<i64> {
    let mut it = day.trim().splitn(3, '-');
    let y: i32 = it.next()?.parse().ok()?;
    let m: u8 = it.next()?.parse().ok()?;
    let d: u8 = it.next()?.parse().ok()?;
    let date = time::Date::from_calendar_date(y, time::Month::try_from(m).ok()?, d).ok()?;
    Some((i64::from(date.to_julian_day()) - UNIX_EPOCH_JULIAN_DAY) * 86_400)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn days_and_hashes() {
        // 2000-03-01 is day 11 017 of the Unix epoch (30 years of 365 days, 7 leap days,
        // Jan and Feb 2000: 10 950 + 7 + 60).
        assert_eq!(utc_day(11_017 * 86_400 + 5), "2000-03-01");
        assert_eq!(utc_day(0), "1970-01-01");
        assert_eq!(utc_day(-1), "1969-12-31");
        assert_eq!(parse_day("2000-03-01"), Some(11_017 * 86_400));
        assert_eq!(parse_day("2026-02-30"), None);
        // 2024-02-29: day 19 782 (54 years of 365 days, 13 leap days, 31 + 28 days of 2024).
        assert_eq!(parse_day("2024-02-29"), Some(19_782 * 86_400));
        assert_eq!(parse_day("2001-02-29"), None);
        assert_eq!(parse_day("soon"), None);
        // FNV-1a's published test vectors: "" and "a".
        assert_eq!(content_hash(b""), "cbf29ce484222325");
        assert_eq!(content_hash(b"a"), "af63dc4c8601ec8c");
    }

    #[test]
    fn a_row_takes_the_reports_values() {
        let doc = serde_json::json!({
            "verdict": "fault",
            "verdict_finding": {"state": "named", "fault": "shorted_turns", "size": 0.02,
                "size_unit": "turns_fraction", "phase": "a", "confidence": 0.9},
            "candidates": [{"fault": "rs", "change": 0.12}],
            "isolation": {"named": null, "residuals": [0.1, 0.2, 0.3], "heating_explains": true},
            "unbalance": {"winding_ratio": 0.05, "measured": {"i1_peak_a": 9.5}},
            "data_quality": {"rows_read": 4000, "trusted": true}
        });
        let id = LogIdentity {
            motor: "m1".into(),
            path: "/x/m1.csv".into(),
            hash: "00ff".into(),
            time_s: 86_400,
        };
        let r = StoredRow::from_diagnose(&id, &doc);
        assert_eq!(r.cells.len(), COLUMNS.len());
        assert_eq!(r.log_id(), "00ff:/x/m1.csv");
        assert_eq!(r.str("day"), Some("1970-01-02"));
        assert_eq!(r.str("fault"), Some("shorted_turns"));
        assert_eq!(r.f64("rs_change_pct"), Some(12.0));
        assert_eq!(r.f64("rr_change_pct"), None);
        assert_eq!(r.f64("residual_q"), Some(0.2));
        assert_eq!(r.f64("i2_over_i1"), Some(0.05));
        assert_eq!(r.f64("heating_explains"), Some(1.0));
        assert_eq!(r.f64("rows"), Some(4000.0));
        assert_eq!(r.get("isolation_named"), &Cell::Null);
        let back = StoredRow::from_json(&serde_json::to_value(&r).unwrap()).unwrap();
        assert_eq!(back, r);
        assert!(StoredRow::from_json(&serde_json::json!({"log_id": 3})).is_none());
    }

    #[test]
    fn what_a_log_without_voltages_cannot_measure_is_null_not_zero() {
        // `diagnose --json` of a current-only log: the isolation judged no point and
        // reports its residuals as zeros.
        let doc = serde_json::json!({
            "verdict": "healthy",
            "isolation": {"state": "not_judged", "residuals": [0.0, 0.0, 0.0],
                "deviation_sigma": 0.0, "heating_explains": false},
            "unbalance": {"winding_ratio": 0.03, "measured": {"i1_peak_a": 7.5}}
        });
        let id = LogIdentity {
            motor: "m1".into(),
            path: "/x/m1.csv".into(),
            hash: "00ff".into(),
            time_s: 0,
        };
        let r = StoredRow::from_diagnose(&id, &doc);
        for c in [
            "residual_d",
            "residual_q",
            "residual_t",
            "deviation_sigma",
            "heating_explains",
            "stator_excess_pct",
        ] {
            assert_eq!(r.get(c), &Cell::Null, "{c}");
        }
        assert_eq!(r.f64("i2_over_i1"), Some(0.03));
        // Judged (no deviation): its zeros are measured values.
        let mut judged = doc.clone();
        judged["isolation"]["state"] = "no_deviation".into();
        let r = StoredRow::from_diagnose(&id, &judged);
        assert_eq!(r.f64("residual_d"), Some(0.0));
        assert_eq!(r.f64("heating_explains"), Some(0.0));
    }
}
