//! [`LogFile`]: a log opened once, its header (or schema, or channel list) read once, its
//! rows streamed: a CSV by the fast path with the exact reader behind it, a TDMS or Parquet
//! log by its format's module ([`super::Format`]).

use super::mapping::{ColumnMapping, TimeKind};
use super::source::{BinarySource, ColumnMap, OpenOptions, Opened};
use super::{exact, fast, Channels, Column, Format, LogError, Row};
use std::io::{BufRead, BufReader, Read};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

mod start_time;
pub use start_time::{LogStart, LogStartFrom};

/// Receives the rows of [`LogFile::for_each_row`].
pub trait RowSink {
    /// One row, in file order; return false to stop reading.
    fn row(&mut self, row: &Row) -> bool;
    /// A block of rows in file order (what a columnar reader hands over at once):
    /// [`ControlFlow::Break`] with the index of the row that asked to stop. The same as
    /// [`RowSink::row`] of each row in turn, which it is by default.
    fn rows(&mut self, rows: &[Row]) -> ControlFlow<usize> {
        match rows.iter().position(|r| !self.row(r)) {
            Some(k) => ControlFlow::Break(k),
            None => ControlFlow::Continue(()),
        }
    }
    /// Forget every row received so far: the rows will come again from the first one (the
    /// fast path met something it does not accept and the exact reader takes over).
    fn restart(&mut self);
    /// After the last row: the blank lines the reader skipped (a CSV's; none by default).
    fn blank_lines(&mut self, _lines: u64) {}
}

/// A timestamp column's time counted from the first row with a finite time: passes the
/// rows on to `sink` with that time subtracted, then scaled to seconds by `factor`.
struct FromFirstRow<'a> {
    sink: &'a mut dyn RowSink,
    t0: Option<f64>,
    factor: f64,
}

impl RowSink for FromFirstRow<'_> {
    fn row(&mut self, row: &Row) -> bool {
        let mut r = *row;
        if r.t_s.is_finite() {
            r.t_s = (r.t_s - *self.t0.get_or_insert(row.t_s)) * self.factor;
        }
        self.sink.row(&r)
    }
    fn restart(&mut self) {
        self.t0 = None;
        self.sink.restart();
    }
    fn blank_lines(&mut self, lines: u64) {
        self.sink.blank_lines(lines);
    }
}

/// A log without a time column ([`ColumnMapping::sample_rate_hz`]): row `k` (from 0) is
/// handed on to `sink` at `t_s = k / rate`.
struct Clocked<'a> {
    sink: &'a mut dyn RowSink,
    next: u64,
    rate_hz: f64,
}

impl RowSink for Clocked<'_> {
    fn row(&mut self, row: &Row) -> bool {
        let mut r = *row;
        r.t_s = self.next as f64 / self.rate_hz;
        self.next += 1;
        self.sink.row(&r)
    }
    fn restart(&mut self) {
        self.next = 0;
        self.sink.restart();
    }
    fn blank_lines(&mut self, lines: u64) {
        self.sink.blank_lines(lines);
    }
}

/// Collects every row.
impl RowSink for Vec<Row> {
    fn row(&mut self, row: &Row) -> bool {
        self.push(*row);
        true
    }
    fn restart(&mut self) {
        self.clear();
    }
}

/// Where the rows come from.
#[derive(Debug, Clone)]
enum ReadSource {
    /// A CSV: the header's length (the data start after it).
    Csv { header_bytes: u64 },
    /// A TDMS file.
    Tdms(super::tdms::TdmsSource),
    /// A Parquet file.
    Parquet(super::parquet::ParquetSource),
    /// Data in memory ([`super::MemoryLog`]).
    Memory(super::memory::MemorySource),
}

/// A log opened for reading: its path, format, columns and size. Cheap to keep; every read
/// pass opens the file anew.
#[derive(Debug, Clone)]
pub struct LogFile {
    path: PathBuf,
    shown: String,
    columns: ColumnMap,
    channels: Channels,
    len_bytes: u64,
    est_rows: f64,
    source: ReadSource,
}

/// Bytes of the file's head read to estimate the bytes per row.
const HEAD_BYTES: usize = 1 << 16;

impl LogFile {
    /// Opens a log in the format its extension names ([`Format::of_path`]), reads and
    /// checks its header (CSV), schema (Parquet) or channels (TDMS, the file's only group),
    /// and estimates its number of rows.
    ///
    /// # Errors
    /// As [`LogFile::open_with`].
    pub fn open(path: &Path) -> Result<Self, LogError> {
        Self::open_with(path, &OpenOptions::default())
    }

    /// Opens a log with options (the TDMS group).
    ///
    /// # Errors
    /// [`LogError::Io`] if unreadable; [`LogError::MissingColumn`] if `t_s` (for TDMS: and
    /// the waveform time) or a current is missing, or if only some of the three voltages
    /// are present, the same in every format; [`LogError::Csv`] for a malformed CSV header;
    /// [`LogError::NotALog`] for a file that is not a log of its format (an empty CSV,
    /// another separator, a TDMS file with several groups and no `group`, the message
    /// listing them; a Parquet column that is not numeric), or a `group` given for a CSV
    /// or Parquet log.
    pub fn open_with(path: &Path, opts: &OpenOptions) -> Result<Self, LogError> {
        let shown = path.display().to_string();
        let format = Format::of_path(path);
        if let (Some(g), Format::Csv | Format::Parquet) = (&opts.group, format) {
            return Err(LogError::Group {
                path: shown,
                given: Some(g.clone()),
                why: format!(
                    "names a TDMS group, and a {} log has no groups",
                    format.name()
                ),
            });
        }
        let len_bytes = std::fs::metadata(path)
            .map_err(|source| LogError::Io {
                path: shown.clone(),
                source,
            })?
            .len();
        let (columns, source, est_rows) = match format {
            Format::Csv => Self::open_csv(path, &shown, len_bytes, &opts.columns)?,
            Format::Tdms => {
                let (t, c) = super::tdms::TdmsSource::open(path, &shown, opts)?;
                let n = t.rows() as f64;
                (c, ReadSource::Tdms(t), n)
            }
            Format::Parquet => {
                let (p, c) = super::parquet::ParquetSource::open(path, &shown, &opts.columns)?;
                let n = p.rows() as f64;
                (c, ReadSource::Parquet(p), n)
            }
        };
        Ok(LogFile {
            path: path.to_path_buf(),
            shown,
            channels: channels_of(&columns),
            columns,
            len_bytes,
            est_rows,
            source,
        })
    }

    /// A log held in memory, shown in messages as `shown` ("DataFrame"), read through the
    /// same path as a file's: the `[columns]` mapping and units of `opts`, the columns
    /// checked as a Parquet file's, the same rows for the data-quality stage. Its
    /// [`LogFile::format`] is Parquet's (typed columns) and its [`LogFile::path`] is
    /// `shown`.
    ///
    /// # Errors
    /// As [`LogFile::open_with`] for a Parquet file; a `group` (a TDMS group) given is
    /// [`LogError::NotALog`].
    pub fn from_memory(
        log: std::sync::Arc<super::MemoryLog>,
        shown: &str,
        opts: &OpenOptions,
    ) -> Result<Self, LogError> {
        if let Some(g) = &opts.group {
            return Err(LogError::Group {
                path: shown.to_string(),
                given: Some(g.clone()),
                why: "names a TDMS group, and data in memory has no groups".to_string(),
            });
        }
        let (m, columns) = super::memory::MemorySource::open(log, shown, &opts.columns)?;
        let rows = m.rows();
        Ok(LogFile {
            path: PathBuf::from(shown),
            shown: shown.to_string(),
            channels: channels_of(&columns),
            len_bytes: rows * 8 * Column::COUNT as u64,
            est_rows: rows as f64,
            columns,
            source: ReadSource::Memory(m),
        })
    }

    /// True for a log held in memory ([`LogFile::from_memory`]).
    pub fn is_in_memory(&self) -> bool {
        matches!(self.source, ReadSource::Memory(_))
    }

    /// Opens a CSV log of `len_bytes` bytes: parses its header, estimates its rows from the
    /// first rows' size.
    fn open_csv(
        path: &Path,
        shown: &str,
        len_bytes: u64,
        mapping: &ColumnMapping,
    ) -> Result<(ColumnMap, ReadSource, f64), LogError> {
        let io = |source| LogError::Io {
            path: shown.to_string(),
            source,
        };
        let f = std::fs::File::open(path).map_err(io)?;
        let mut r = BufReader::new(f);
        let mut header = Vec::new();
        r.read_until(b'\n', &mut header).map_err(io)?;
        let mut head = Vec::with_capacity(HEAD_BYTES);
        r.take(HEAD_BYTES as u64)
            .read_to_end(&mut head)
            .map_err(io)?;
        let (columns, has_header) = super::csv_header::parse_header(&header, shown, mapping)?;
        let header_bytes = if has_header { header.len() as u64 } else { 0 };
        let lines = head.iter().filter(|&&b| b == b'\n').count().max(1);
        let bytes_per_row = (head.len() as f64 / lines as f64).max(1.0);
        let est_rows = len_bytes.saturating_sub(header_bytes) as f64 / bytes_per_row;
        let source = ReadSource::Csv { header_bytes };
        Ok((columns, source, est_rows))
    }

    /// The log's format.
    pub fn format(&self) -> Format {
        match self.source {
            ReadSource::Csv { .. } => Format::Csv,
            ReadSource::Tdms(_) => Format::Tdms,
            // Typed columns, read as a Parquet file's.
            ReadSource::Parquet(_) | ReadSource::Memory(_) => Format::Parquet,
        }
    }

    /// Which optional channels the log has.
    pub fn channels(&self) -> Channels {
        self.channels
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path as shown in messages.
    pub fn shown(&self) -> &str {
        &self.shown
    }

    /// Estimated number of data rows (CSV: from the file size and the first rows' length;
    /// TDMS and Parquet: exact).
    pub fn estimated_rows(&self) -> f64 {
        self.est_rows
    }

    /// Streams every data row in file order into `sink` (bounded memory), until the end or
    /// until the sink returns false. `progress` gets the fraction of the file read, at most
    /// a few hundred times. Returns the number of rows handed over.
    ///
    /// TDMS and Parquet logs are read by their modules (`tdms`, `parquet`), which hand over
    /// what the file holds in the same way. A CSV's rows are parsed in parallel by the fast path; if it meets anything it does not
    /// accept (quotes, text, a wrong field count), the sink is told to
    /// [`RowSink::restart`] and the exact reader reads the log again from the start: the
    /// same rows, or the error naming the line and column. Non-finite numbers and times
    /// that do not increase are handed over as they are: judging them is the data-quality
    /// stage's ([`super::quality`]).
    ///
    /// # Errors
    /// [`LogError::Io`], [`LogError::NotNumeric`] or [`LogError::Csv`], each naming the
    /// file and, for a bad row, the line and column; [`LogError::NotALog`] for a TDMS or
    /// Parquet file that cannot be decoded.
    pub fn for_each_row(
        &self,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        if let (None, Some(rate_hz)) = (self.columns.of(Column::Time), self.columns.sample_rate_hz)
        {
            let mut clocked = Clocked {
                sink,
                next: 0,
                rate_hz,
            };
            return self.rows_in_order(progress, &mut clocked);
        }
        if self.columns.time != TimeKind::Plain {
            let mut from_first = FromFirstRow {
                sink,
                t0: None,
                factor: self.columns.time_factor,
            };
            return self.rows_in_order(progress, &mut from_first);
        }
        self.rows_in_order(progress, sink)
    }

    /// [`LogFile::for_each_row`] with the times as read.
    fn rows_in_order(
        &self,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        let binary: &dyn BinarySource = match &self.source {
            ReadSource::Csv { .. } => return self.csv_rows(progress, sink),
            ReadSource::Tdms(t) => t,
            ReadSource::Parquet(p) => p,
            ReadSource::Memory(m) => m,
        };
        binary.for_each_block(&self.opened(), progress, sink)
    }

    /// [`LogFile::for_each_row`] of a CSV log: the fast path, else the exact reader.
    fn csv_rows(
        &self,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        let mut handed = 0u64;
        let accepted =
            fast::for_each_row(&self.opened(), fast::BLOCK_BYTES, progress, &mut |rows| {
                let flow = sink.rows(rows);
                handed += match flow {
                    ControlFlow::Break(k) => k as u64 + 1,
                    ControlFlow::Continue(()) => rows.len() as u64,
                };
                flow
            })?;
        if let Some(blank) = accepted {
            sink.blank_lines(blank);
            return Ok(handed);
        }
        sink.restart();
        let mut rows = exact::ExactRows::new(&self.opened())?;
        let mut handed = 0u64;
        while let Some(row) = rows.next_row()? {
            handed += 1;
            if !sink.row(&row) {
                break;
            }
            if handed.is_multiple_of(65_536) {
                progress((rows.byte_offset() as f64 / self.len_bytes.max(1) as f64).min(1.0));
            }
        }
        sink.blank_lines(rows.blank_lines());
        Ok(handed)
    }

    /// What a format's reader needs of this log.
    pub(super) fn opened(&self) -> Opened<'_> {
        Opened {
            path: &self.path,
            shown: &self.shown,
            columns: &self.columns,
            len_bytes: self.len_bytes,
            header_bytes: match self.source {
                ReadSource::Csv { header_bytes } => header_bytes,
                _ => 0,
            },
        }
    }
}

/// The optional channels a column map has.
fn channels_of(columns: &ColumnMap) -> Channels {
    let has = |c: Column| columns.of(c).is_some();
    Channels {
        voltages: has(Column::Va),
        speed: has(Column::Speed),
        encoder: has(Column::Encoder),
        temperature: has(Column::Temperature),
    }
}
/// A log error in a front end's words.
impl LogError {
    /// The message with the options it refers to named by `name` (the command line: its
    /// flag, `--group`); the library's words name them by their field (`group`).
    pub fn spelled(&self, name: &dyn Fn(&str) -> String) -> String {
        match self {
            LogError::Group {
                path,
                given: Some(g),
                why,
            } => format!("{path}: {} '{g}' {why}", name("group")),
            LogError::Group {
                path,
                given: None,
                why,
            } => format!("{path}: {why}: name one with {}", name("group")),
            e => e.to_string(),
        }
    }
}
