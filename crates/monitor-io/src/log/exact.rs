//! The exact reader: row by row through the `csv` crate (quoting, any field count checks),
//! slow but with messages that name the line and column. Behind the fast path. Like it, it
//! hands over non-finite numbers, missing values ([`super::is_missing`], as NaN) and times
//! that do not increase (the data-quality stage judges them), skips blank lines and counts
//! them; other text in a measured column is handed over as NaN too (a bad cell the stage
//! counts), while text in the time column is an error naming the line and column. It alone
//! reads a time column of ISO 8601 text or of timestamps ([`super::mapping`]: `iso8601`,
//! `timestamp`); there a cell that is no time is a bad cell (NaN) and a column without one
//! time an error naming it.

use super::mapping::{parse_iso8601, TimeKind};
use super::source::{row_from_values, ColumnMap, Opened};
use super::{Column, LogError, Row};
use std::fs::File;
use std::io::BufReader;

/// Streams the data rows of a [`LogFile`].
pub(super) struct ExactRows {
    shown: String,
    rdr: csv::Reader<BufReader<File>>,
    columns: ColumnMap,
    record: csv::ByteRecord,
    /// The line of the last record (blank lines are the gaps between records).
    last_line: u64,
    /// Blank lines skipped so far.
    blank: u64,
    /// An ISO 8601 time column's first whole second (the times count from it).
    iso_t0: Option<i64>,
    /// A text time column's first cell that is no time, while no cell was one: its line
    /// and text, and how many such cells came (an error at the end of a column without one
    /// time, or after [`NO_TIME_CELLS`] of them).
    bad_time: Option<(u64, String, usize)>,
}

/// Leading cells of a text time column that are no time, none a time, before the column is
/// refused (fewer than the data-quality stage's first rows, so that its error is this one).
const NO_TIME_CELLS: usize = 1000;

impl ExactRows {
    /// Opens the file and skips its header line (a file without one starts with data).
    pub fn new(log: &Opened<'_>) -> Result<Self, LogError> {
        let shown = log.shown().to_string();
        let f = File::open(log.path()).map_err(|source| LogError::Io {
            path: shown.clone(),
            source,
        })?;
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .has_headers(false)
            // Rows end at '\n' only; a CRLF file's '\r' is trimmed as whitespace. (With the
            // default CRLF terminator the csv crate reports lines one too low in CRLF files,
            // so an error would name the wrong line.)
            .terminator(csv::Terminator::Any(b'\n'))
            .from_reader(BufReader::with_capacity(1 << 20, f));
        let mut record = csv::ByteRecord::new();
        // The header (already parsed by `LogFile::open`), unless the file has none.
        let header = log.header_bytes() > 0;
        if header {
            rdr.read_byte_record(&mut record)
                .map_err(|e| csv_error(&shown, &e))?;
        }
        Ok(ExactRows {
            shown,
            rdr,
            columns: log.columns().clone(),
            record,
            last_line: u64::from(header),
            blank: 0,
            iso_t0: None,
            bad_time: None,
        })
    }

    /// Blank lines skipped so far (at the end of the file: all of them).
    pub fn blank_lines(&self) -> u64 {
        self.blank
    }

    /// Bytes read so far.
    pub fn byte_offset(&self) -> u64 {
        self.rdr.position().byte()
    }

    fn cell(&mut self, c: Column, line: u64) -> Result<Option<f64>, LogError> {
        let Some(col) = self.columns.of(c) else {
            return Ok(None);
        };
        let raw = self.record.get(col).unwrap_or(b"");
        let s = std::str::from_utf8(raw).unwrap_or("");
        if c == Column::Time && self.columns.time.is_text() {
            let s = s.to_string();
            return self.iso_time(&s, line).map(Some);
        }
        if super::is_missing(s) {
            return Ok(Some(f64::NAN));
        }
        match s.parse::<f64>() {
            Ok(x) => Ok(Some(x)),
            // A measured value that is text (`abc`, a DAQ's `#OVF`) is a bad cell like
            // NaN: the data-quality stage holds it out and counts it (`bad_cells`).
            Err(_) if c != Column::Time => Ok(Some(f64::NAN)),
            // Without its time a row cannot be placed: the file is refused.
            Err(_) => Err(LogError::NotNumeric {
                path: self.shown.clone(),
                line,
                column: self.columns.name_of_field(col),
                cell: s.chars().take(40).collect(),
            }),
        }
    }

    /// An ISO 8601 time (or, for `timestamp`, epoch seconds) [s since the first time's
    /// whole second]; a missing value, or text that is no time, is NaN (a bad cell).
    fn iso_time(&mut self, s: &str, line: u64) -> Result<f64, LogError> {
        if super::is_missing(s) {
            return Ok(f64::NAN);
        }
        let parsed = parse_iso8601(s).or_else(|| {
            (self.columns.time == TimeKind::Timestamp)
                .then(|| epoch_seconds(s))
                .flatten()
        });
        let Some((secs, frac)) = parsed else {
            if self.iso_t0.is_none() {
                let bad = self
                    .bad_time
                    .get_or_insert_with(|| (line, s.chars().take(40).collect(), 0));
                bad.2 += 1;
                if bad.2 >= NO_TIME_CELLS {
                    self.no_time_at_all()?;
                }
            }
            return Ok(f64::NAN);
        };
        let t0 = *self.iso_t0.get_or_insert(secs);
        Ok((secs - t0) as f64 + frac)
    }

    /// The whole second the first time of a text time column counts from [s since
    /// 1970-01-01 UTC] (`None` before it, and for other time columns): the log's start is
    /// it plus that row's `t_s`.
    pub fn time_origin_s(&self) -> Option<i64> {
        self.iso_t0
    }

    /// At the end of the file: the error of a text time column without one time.
    fn no_time_at_all(&self) -> Result<(), LogError> {
        let Some((line, cell, _)) = self.bad_time.as_ref().filter(|_| self.iso_t0.is_none()) else {
            return Ok(());
        };
        let what = if self.columns.time == TimeKind::Timestamp {
            "ISO 8601 date-time text (YYYY-MM-DDTHH:MM:SS[.fff][Z|+HH:MM]) or Unix epoch seconds"
        } else {
            "ISO 8601 date-time text (YYYY-MM-DDTHH:MM:SS[.fff][Z|+HH:MM])"
        };
        Err(LogError::Csv {
            path: self.shown.clone(),
            line: *line,
            message: format!(
                "column '{}' holds no time: '{cell}' (the first of its cells) is not {what}, as [columns] says",
                self.columns.names[0]
            ),
        })
    }

    /// Reads the next row; `Ok(None)` at the end of the file.
    ///
    /// # Errors
    /// [`LogError::NotNumeric`] or [`LogError::Csv`], each naming the line.
    pub fn next_row(&mut self) -> Result<Option<Row>, LogError> {
        match self.rdr.read_byte_record(&mut self.record) {
            Ok(false) => {
                // Blank lines at the end: the lines after the last record's.
                let end = self.rdr.position().line();
                self.blank += end.saturating_sub(self.last_line + 1);
                self.last_line = end;
                self.no_time_at_all()?;
                return Ok(None);
            }
            Ok(true) => {}
            Err(e) => return Err(csv_error(&self.shown, &e)),
        }
        let line = self.record.position().map(|p| p.line()).unwrap_or(0);
        self.blank += line.saturating_sub(self.last_line + 1);
        self.last_line = line;
        let t = self.cell(Column::Time, line)?.unwrap_or(f64::NAN);
        let mut v = [0.0f64; Column::COUNT];
        v[0] = t;
        // Currents first: a row with several bad cells names the required column.
        for c in [
            Column::Ia,
            Column::Ib,
            Column::Ic,
            Column::Va,
            Column::Vb,
            Column::Vc,
            Column::Speed,
            Column::Encoder,
            Column::Temperature,
        ] {
            v[c as usize] = self.cell(c, line)?.unwrap_or(0.0);
        }
        Ok(Some(row_from_values(&v, &self.columns)))
    }
}

/// Unix epoch seconds written as a number (`1793685600`, `1793685600.125`, `1.79e9`): whole
/// seconds and the fraction (exact to the digits given for plain decimals).
fn epoch_seconds(s: &str) -> Option<(i64, f64)> {
    let t = s.trim();
    let (int, frac) = t.split_once('.').unwrap_or((t, ""));
    let digits = |x: &str| x.bytes().all(|b| b.is_ascii_digit());
    if !int.is_empty() && digits(int) && digits(frac) {
        return Some((int.parse().ok()?, format!("0.{frac}0").parse().ok()?));
    }
    let x: f64 = t.parse().ok().filter(|x: &f64| x.is_finite())?;
    let secs = x.floor();
    Some((secs as i64, x - secs))
}

fn csv_error(shown: &str, e: &csv::Error) -> LogError {
    LogError::Csv {
        path: shown.to_string(),
        line: e.position().map(|p| p.line()).unwrap_or(0),
        message: crate::one_line(&e.to_string()),
    }
}
