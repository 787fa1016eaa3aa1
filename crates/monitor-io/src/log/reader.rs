//! [`LogFile`]: a log opened once, its header (or schema, or channel list) read once, its
//! rows streamed: a CSV by the fast path with the exact reader behind it, a TDMS or Parquet
//! log by its format's module ([`super::Format`]).

use super::mapping::{ChannelUnit, ColumnMapping, TimeKind};
use super::{exact, fast, Channels, Column, Format, LogError, Row};
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Receives the rows of [`LogFile::for_each_row`].
pub trait RowSink {
    /// One row, in file order; return false to stop reading.
    fn row(&mut self, row: &Row) -> bool;
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

/// Where each schema column sits in a line (a CSV), a leaf column (Parquet) or the
/// group's channels (TDMS), and how its values become the schema's: `field[c]` is the
/// field index of [`Column::ALL`]`[c]`, `None` when the log lacks it.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ColumnMap {
    pub field: [Option<usize>; Column::COUNT],
    /// Fields per line (the header's).
    pub n_fields: usize,
    /// The factor from each column's unit to the schema's SI unit ([`ColumnMapping`]).
    pub scale: [f64; Column::COUNT],
    /// False when every factor is 1 (the rows need no multiplication).
    pub scaled: bool,
    /// How the time column is read.
    pub time: TimeKind,
    /// A timestamp's factor to seconds, applied after the first row's time is subtracted
    /// (so that the difference is exact; `scale[0]` is then 1).
    pub time_factor: f64,
    /// What is added to the temperature's values before `scale` ([`ChannelUnit::offset`]).
    pub temp_offset: f64,
    /// Each column's channel name in the log (the schema's name unless mapped).
    pub names: [String; Column::COUNT],
    /// The log has no time column: its rows are samples at this rate [Hz]
    /// ([`ColumnMapping::sample_rate_hz`]).
    pub sample_rate_hz: Option<f64>,
}

impl ColumnMap {
    /// The columns of a log whose fields (CSV header fields, Parquet leaf columns, TDMS
    /// channels) are named `found`, each looked up by the name `mapping` gives it, in the
    /// unit it gives.
    ///
    /// # Errors
    /// [`LogError::DuplicateColumn`] when a name looked up appears twice.
    pub fn locate(
        found: &[String],
        mapping: &ColumnMapping,
        shown: &str,
    ) -> Result<Self, LogError> {
        let mut field = [None; Column::COUNT];
        for (f, c) in field.iter_mut().zip(Column::ALL) {
            if let Some(p) = mapping.position_of(c) {
                // Past the last field: missing (`check_columns` says so).
                *f = (p < found.len()).then_some(p);
                continue;
            }
            let name = mapping.name_of(c);
            let mut at = found
                .iter()
                .enumerate()
                .filter(|(_, h)| *h == name)
                .map(|(i, _)| i);
            *f = at.next();
            if let (Some(first), Some(second)) = (*f, at.next()) {
                return Err(LogError::DuplicateColumn {
                    path: shown.to_string(),
                    column: name.to_string(),
                    first: first + 1,
                    second: second + 1,
                });
            }
        }
        let mut map = ColumnMap {
            field,
            n_fields: found.len(),
            scale: [1.0; Column::COUNT],
            scaled: false,
            time: TimeKind::Plain,
            time_factor: 1.0,
            temp_offset: 0.0,
            names: Column::ALL.map(|c| mapping.name_of(c).to_string()),
            sample_rate_hz: mapping.sample_rate_hz(),
        };
        map.set_units(&Column::ALL.map(|c| mapping.unit_of(c)), mapping);
        Ok(map)
    }

    /// Reads each column in `units` (`None`: the schema's SI unit).
    pub fn set_units(
        &mut self,
        units: &[Option<ChannelUnit>; Column::COUNT],
        mapping: &ColumnMapping,
    ) {
        self.scale = mapping.factors(units);
        self.temp_offset = units[Column::Temperature as usize].map_or(0.0, ChannelUnit::offset);
        self.time = units[0].map_or(TimeKind::Plain, ChannelUnit::time_kind);
        self.time_factor = 1.0;
        if self.time != TimeKind::Plain {
            self.time_factor = std::mem::replace(&mut self.scale[0], 1.0);
        }
        self.scaled = self.scale.iter().any(|k| *k != 1.0);
    }

    /// The channel name of field `i` (for messages).
    pub fn name_of_field(&self, i: usize) -> String {
        self.field
            .iter()
            .position(|f| *f == Some(i))
            .map(|k| self.names[k].clone())
            .unwrap_or_else(|| format!("#{i}"))
    }

    /// The field index of a present column.
    pub fn of(&self, c: Column) -> Option<usize> {
        self.field[c as usize]
    }
}

/// How to open a log ([`LogFile::open_with`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OpenOptions {
    /// The TDMS group holding the channels (`--group`); needed only when a TDMS file has
    /// several groups. An error for the other formats, which have no groups.
    pub group: Option<String>,
    /// Which channel holds each schema column, and its unit (the parameter file's
    /// `[columns]` table; empty: the schema's names and SI units).
    pub columns: ColumnMapping,
}

/// A log format read by its own decoder (TDMS, Parquet), whose rows are counted when it
/// is opened.
pub(super) trait BinarySource {
    /// Rows in the log.
    fn rows(&self) -> u64;

    /// Streams the rows of `log` (opened as this source) in order, as
    /// [`LogFile::for_each_row`] does; `on_row` returns false to stop. Returns the rows
    /// handed over.
    ///
    /// # Errors
    /// [`LogError::NotALog`] for a file that cannot be decoded.
    fn for_each_row(
        &self,
        log: &LogFile,
        progress: &mut dyn FnMut(f64),
        on_row: &mut dyn FnMut(&Row) -> bool,
    ) -> Result<u64, LogError>;
}

/// Where the rows come from.
#[derive(Debug, Clone)]
enum Source {
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
    source: Source,
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
            return Err(LogError::NotALog {
                path: shown,
                why: format!(
                    "--group '{g}' names a TDMS group, and a {} log has no groups",
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
                (c, Source::Tdms(t), n)
            }
            Format::Parquet => {
                let (p, c) = super::parquet::ParquetSource::open(path, &shown, &opts.columns)?;
                let n = p.rows() as f64;
                (c, Source::Parquet(p), n)
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
            return Err(LogError::NotALog {
                path: shown.to_string(),
                why: format!("--group '{g}' names a TDMS group, and data in memory has no groups"),
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
            source: Source::Memory(m),
        })
    }

    /// True for a log held in memory ([`LogFile::from_memory`]).
    pub fn is_in_memory(&self) -> bool {
        matches!(self.source, Source::Memory(_))
    }

    /// Opens a CSV log of `len_bytes` bytes: parses its header, estimates its rows from the
    /// first rows' size.
    fn open_csv(
        path: &Path,
        shown: &str,
        len_bytes: u64,
        mapping: &ColumnMapping,
    ) -> Result<(ColumnMap, Source, f64), LogError> {
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
        let source = Source::Csv { header_bytes };
        Ok((columns, source, est_rows))
    }

    /// The log's format.
    pub fn format(&self) -> Format {
        match self.source {
            Source::Csv { .. } => Format::Csv,
            Source::Tdms(_) => Format::Tdms,
            // Typed columns, read as a Parquet file's.
            Source::Parquet(_) | Source::Memory(_) => Format::Parquet,
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
            Source::Csv { .. } => return self.csv_rows(progress, sink),
            Source::Tdms(t) => t,
            Source::Parquet(p) => p,
            Source::Memory(m) => m,
        };
        binary.for_each_row(self, progress, &mut |r| sink.row(r))
    }

    /// [`LogFile::for_each_row`] of a CSV log: the fast path, else the exact reader.
    fn csv_rows(
        &self,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        let mut handed = 0u64;
        let accepted = fast::for_each_row(self, fast::BLOCK_BYTES, progress, &mut |row| {
            handed += 1;
            sink.row(row)
        })?;
        if let Some(blank) = accepted {
            sink.blank_lines(blank);
            return Ok(handed);
        }
        sink.restart();
        let mut rows = exact::ExactRows::new(self)?;
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

    pub(super) fn columns(&self) -> &ColumnMap {
        &self.columns
    }

    pub(super) fn len_bytes(&self) -> u64 {
        self.len_bytes
    }

    pub(super) fn header_bytes(&self) -> u64 {
        match self.source {
            Source::Csv { header_bytes } => header_bytes,
            _ => 0,
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

/// The columns every log needs, in every format: `t_s` (unless `need_time` is false: a
/// TDMS log timed by its waveform properties), the three currents, and the voltages as all
/// three phases or none.
///
/// # Errors
/// [`LogError::MissingColumn`] naming the column and why it is needed, listing the
/// channels `found` and suggesting the closest ([`super::mapping::missing_column`]).
pub(super) fn check_columns(
    map: &ColumnMap,
    shown: &str,
    need_time: bool,
    mapping: &ColumnMapping,
    found: &[String],
) -> Result<(), LogError> {
    let missing =
        |c: Column, why: &str| super::mapping::missing_column(shown, c, mapping, found, why);
    if need_time && map.of(Column::Time).is_none() && map.sample_rate_hz.is_none() {
        return Err(missing(
            Column::Time,
            "every analysis needs the time: a time column, or the sample rate of a log without one, t_s = { sample_rate_hz = ... }",
        ));
    }
    for c in [Column::Ia, Column::Ib, Column::Ic] {
        if map.of(c).is_none() {
            return Err(missing(
                c,
                "the phase currents are the minimum a log must carry",
            ));
        }
    }
    let volts = [Column::Va, Column::Vb, Column::Vc].map(|c| map.of(c).is_some());
    if volts.iter().any(|v| *v) {
        if let Some(k) = volts.iter().position(|v| !v) {
            return Err(missing(
                [Column::Va, Column::Vb, Column::Vc][k],
                "the voltages come as all three phases or none",
            ));
        }
    }
    Ok(())
}
