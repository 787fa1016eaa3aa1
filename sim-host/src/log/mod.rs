//! Measurement logs in the DESIGN.md §3 CSV schema: the one reader and the one writer of
//! the workspace.
//!
//! Columns (header row, comma separated, SI units in the names, [`Column`]):
//! `t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s` and optionally `enc_count`
//! (cumulative encoder count). `t_s` and the three currents are required; the voltages
//! (all three or none) and the speed (`wm_rad_s`, mechanical rad/s) are optional; extra
//! columns are ignored. Time must be strictly increasing.
//!
//! - Reading: [`LogFile::open`] parses the header once (columns by name); then
//!   [`LogFile::for_each_row`] streams the rows in file order with bounded memory, through
//!   a parallel fast path (`fast`) and, where that meets anything it does not accept, the
//!   exact reader (`exact`), whose message names the line and column. [`Log::read`] holds
//!   a whole log in memory.
//! - The sample rate of a log is estimated in one place, [`sample_rate_hz`].
//! - Writing is atomic ([`LogWriter`], [`write_atomic`]): a temporary file beside the
//!   target, renamed on [`LogWriter::finish`], so an interrupted run never leaves a
//!   half-written output and never touches an input.

mod exact;
mod fast;
mod reader;
mod writer;

pub use reader::{LogFile, RowSink};
pub use writer::{write_atomic, LogWriter};

/// Errors reading or writing a log. Every message is one line and names the problem.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// File could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A required column is missing.
    #[error("{path}: missing column '{column}' ({why})")]
    MissingColumn {
        /// The file.
        path: String,
        /// The column's name.
        column: String,
        /// Why it is needed.
        why: String,
    },
    /// A cell is not a number.
    #[error("{path}: line {line}, column '{column}': '{cell}' is not a number")]
    NotNumeric {
        /// The file.
        path: String,
        /// 1-based line number in the file (header is line 1).
        line: u64,
        /// The column's name.
        column: String,
        /// The offending text.
        cell: String,
    },
    /// Time does not increase.
    #[error("{path}: line {line}: time t_s = {t} does not increase (previous {prev})")]
    TimeNotIncreasing {
        /// The file.
        path: String,
        /// 1-based line number.
        line: u64,
        /// This row's time.
        t: f64,
        /// The previous row's time.
        prev: f64,
    },
    /// The CSV itself is malformed (wrong number of fields, bad UTF-8...).
    #[error("{path}: line {line}: {message}")]
    Csv {
        /// The file.
        path: String,
        /// 1-based line number (0 if unknown).
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// The log has no data rows.
    #[error("{path}: the log has no data rows")]
    Empty {
        /// The file.
        path: String,
    },
}

/// A column of the schema, in the order a [`Row`] holds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Column {
    /// `t_s`: time [s].
    Time,
    /// `va_V`: phase-a voltage to neutral [V].
    Va,
    /// `vb_V`.
    Vb,
    /// `vc_V`.
    Vc,
    /// `ia_A`: phase-a current [A].
    Ia,
    /// `ib_A`.
    Ib,
    /// `ic_A`.
    Ic,
    /// `wm_rad_s`: rotor mechanical speed [rad/s].
    Speed,
    /// `enc_count`: cumulative encoder count.
    Encoder,
}

impl Column {
    /// Every column of the schema, in [`Row`] order.
    pub const ALL: [Column; 9] = [
        Column::Time,
        Column::Va,
        Column::Vb,
        Column::Vc,
        Column::Ia,
        Column::Ib,
        Column::Ic,
        Column::Speed,
        Column::Encoder,
    ];

    /// The header name (DESIGN.md §3).
    pub fn name(self) -> &'static str {
        match self {
            Column::Time => "t_s",
            Column::Va => "va_V",
            Column::Vb => "vb_V",
            Column::Vc => "vc_V",
            Column::Ia => "ia_A",
            Column::Ib => "ib_A",
            Column::Ic => "ic_A",
            Column::Speed => "wm_rad_s",
            Column::Encoder => "enc_count",
        }
    }
}

/// One row of a log. Optional channels are `None` when the log lacks the column.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Row {
    /// Time [s].
    pub t_s: f64,
    /// Phase-to-neutral voltages a, b, c [V].
    pub v_abc: Option<[f64; 3]>,
    /// Phase currents a, b, c [A].
    pub i_abc: [f64; 3],
    /// Rotor mechanical speed [rad/s].
    pub wm_rad_s: Option<f64>,
    /// Cumulative encoder count (may be negative when running backwards).
    pub enc_count: Option<i64>,
}

/// Which optional channels a log carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Channels {
    /// `va_V, vb_V, vc_V` present.
    pub voltages: bool,
    /// `wm_rad_s` present.
    pub speed: bool,
    /// `enc_count` present.
    pub encoder: bool,
}

impl Channels {
    /// Whether the log has `c` (time and currents always).
    pub fn has(&self, c: Column) -> bool {
        match c {
            Column::Time | Column::Ia | Column::Ib | Column::Ic => true,
            Column::Va | Column::Vb | Column::Vc => self.voltages,
            Column::Speed => self.speed,
            Column::Encoder => self.encoder,
        }
    }
}

/// Rows a sample-rate estimate looks at: the first 200 (0.02 s at 10 kHz).
pub const RATE_ESTIMATE_ROWS: usize = 200;

/// The workspace's one sample-rate estimate: rows per second over the first
/// [`RATE_ESTIMATE_ROWS`] times given, `(n - 1) / (t_{n-1} - t_0)` [Hz]. `None` for fewer
/// than two times or a span that is not positive and finite.
pub fn sample_rate_hz(times: &[f64]) -> Option<f64> {
    let t = &times[..times.len().min(RATE_ESTIMATE_ROWS)];
    let (first, last) = (t.first()?, t.last()?);
    let span = last - first;
    (t.len() > 1 && span.is_finite() && span > 0.0).then(|| (t.len() - 1) as f64 / span)
}

/// A whole log in memory, one vector per row.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Log {
    /// Which optional channels are present.
    pub channels: Channels,
    /// The rows, in time order.
    pub rows: Vec<Row>,
}

impl Log {
    /// Reads a whole log into memory (stream with [`LogFile::for_each_row`] for logs too
    /// large for memory).
    ///
    /// # Errors
    /// As [`LogFile::open`] and [`LogFile::for_each_row`]; [`LogError::Empty`] for a log
    /// without data rows.
    pub fn read(path: &std::path::Path) -> Result<Self, LogError> {
        let file = LogFile::open(path)?;
        let mut rows: Vec<Row> = Vec::new();
        file.for_each_row(&mut |_| {}, &mut rows)?;
        if rows.is_empty() {
            return Err(LogError::Empty {
                path: path.display().to_string(),
            });
        }
        Ok(Log {
            channels: file.channels(),
            rows,
        })
    }

    /// The sample rate ([`sample_rate_hz`] of the first rows), `None` for fewer than two
    /// rows.
    pub fn sample_rate_hz(&self) -> Option<f64> {
        let head: Vec<f64> = self
            .rows
            .iter()
            .take(RATE_ESTIMATE_ROWS)
            .map(|r| r.t_s)
            .collect();
        sample_rate_hz(&head)
    }

    /// Writes the log atomically to `path` (see [`LogWriter`]).
    ///
    /// # Errors
    /// [`LogError::Io`] when the file cannot be written.
    pub fn write(&self, path: &std::path::Path) -> Result<(), LogError> {
        let mut w = LogWriter::create(path, self.channels)?;
        for r in &self.rows {
            w.write_row(r)?;
        }
        w.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn write(text: &str) -> tempfile::NamedTempFile {
        let mut f = tempfile::NamedTempFile::new().unwrap();
        f.write_all(text.as_bytes()).unwrap();
        f
    }

    #[test]
    fn round_trip_and_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.csv");
        let log = Log {
            channels: Channels {
                voltages: true,
                speed: true,
                encoder: false,
            },
            rows: (0..10)
                .map(|k| Row {
                    t_s: k as f64 * 1e-4,
                    v_abc: Some([1.0, -0.5, -0.5]),
                    i_abc: [0.1 * k as f64, 2.0, -3.0],
                    wm_rad_s: Some(150.0),
                    enc_count: None,
                })
                .collect(),
        };
        log.write(&p).unwrap();
        let back = Log::read(&p).unwrap();
        assert_eq!(back.rows.len(), 10);
        assert!((back.rows[9].i_abc[0] - 0.9).abs() < 1e-9);
        assert!((back.sample_rate_hz().unwrap() - 1e4).abs() < 1e-6);

        let missing = write("t_s,ia_A,ib_A\n0,1,2\n");
        let e = Log::read(missing.path()).unwrap_err().to_string();
        assert!(e.contains("ic_A"), "{e}");
        let nonnum = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0.1,1,abc,3\n");
        let e = Log::read(nonnum.path()).unwrap_err().to_string();
        assert!(e.contains("ib_A") && e.contains("line 3"), "{e}");
        let back_in_time = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0,1,2,3\n");
        let e = Log::read(back_in_time.path()).unwrap_err().to_string();
        assert!(e.contains("does not increase"), "{e}");
        let empty = write("t_s,ia_A,ib_A,ic_A\n");
        let e = Log::read(empty.path()).unwrap_err().to_string();
        assert!(e.contains("no data rows"), "{e}");
    }

    #[test]
    fn sample_rate_from_the_first_rows() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 2e-4).collect();
        assert!((sample_rate_hz(&t).unwrap() - 5000.0).abs() < 1e-6);
        assert_eq!(sample_rate_hz(&[1.0]), None);
        assert_eq!(sample_rate_hz(&[1.0, 1.0]), None);
        assert_eq!(sample_rate_hz(&[]), None);
    }
}
