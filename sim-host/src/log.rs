//! Measurement logs in the DESIGN.md §3 CSV schema.
//!
//! Columns (header row, comma separated, SI units in the names):
//! `t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s` and optionally `enc_count`
//! (cumulative encoder count). `t_s` and the three currents are required; the voltages
//! (all three or none) and the speed (`wm_rad_s`, mechanical rad/s) are optional; extra
//! columns are ignored. Time must be strictly increasing.
//!
//! Reading is streaming ([`LogReader`]) or whole ([`Log::read`]); writing is atomic
//! ([`LogWriter`] writes a temporary file beside the target and renames it on
//! [`LogWriter::finish`]), so an interrupted run never leaves a half-written output and
//! never touches an input.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

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

/// Streaming reader of a log file: constant memory whatever the log's length.
pub struct LogReader {
    path: String,
    rdr: csv::Reader<BufReader<File>>,
    idx: Idx,
    channels: Channels,
    record: csv::ByteRecord,
    prev_t: Option<f64>,
}

#[derive(Debug, Clone, Copy)]
struct Idx {
    t: usize,
    v: Option<[usize; 3]>,
    i: [usize; 3],
    w: Option<usize>,
    enc: Option<usize>,
}

impl LogReader {
    /// Opens a log and checks its header.
    ///
    /// # Errors
    /// [`LogError::Io`] if unreadable, [`LogError::MissingColumn`] if `t_s` or a current is
    /// missing, or if only some of the three voltages are present.
    pub fn open(path: &Path) -> Result<Self, LogError> {
        let p = path.display().to_string();
        let f = File::open(path).map_err(|source| LogError::Io {
            path: p.clone(),
            source,
        })?;
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            // Rows end at '\n' only; a CRLF file's '\r' is trimmed as whitespace. (With the
            // default CRLF terminator the csv crate reports lines one too low in CRLF files,
            // so an error would name the wrong line.)
            .terminator(csv::Terminator::Any(b'\n'))
            .from_reader(BufReader::with_capacity(1 << 20, f));
        let headers = rdr
            .headers()
            .map_err(|e| LogError::Csv {
                path: p.clone(),
                line: 1,
                message: crate::params::one_line(&e.to_string()),
            })?
            .clone();
        let find = |name: &str| headers.iter().position(|h| h == name);
        let need = |name: &str, why: &str| {
            find(name).ok_or_else(|| LogError::MissingColumn {
                path: p.clone(),
                column: name.to_string(),
                why: why.to_string(),
            })
        };
        let t = need("t_s", "every analysis needs the time")?;
        let i = [
            need(
                "ia_A",
                "the phase currents are the minimum a log must carry",
            )?,
            need(
                "ib_A",
                "the phase currents are the minimum a log must carry",
            )?,
            need(
                "ic_A",
                "the phase currents are the minimum a log must carry",
            )?,
        ];
        let v = match (find("va_V"), find("vb_V"), find("vc_V")) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            (None, None, None) => None,
            (a, b, _) => {
                let column = if a.is_none() {
                    "va_V"
                } else if b.is_none() {
                    "vb_V"
                } else {
                    "vc_V"
                };
                return Err(LogError::MissingColumn {
                    path: p,
                    column: column.into(),
                    why: "the voltages come as all three phases or none".into(),
                });
            }
        };
        let w = find("wm_rad_s");
        let enc = find("enc_count");
        Ok(LogReader {
            path: p,
            rdr,
            idx: Idx { t, v, i, w, enc },
            channels: Channels {
                voltages: v.is_some(),
                speed: w.is_some(),
                encoder: enc.is_some(),
            },
            record: csv::ByteRecord::new(),
            prev_t: None,
        })
    }

    /// Which optional channels this log has.
    pub fn channels(&self) -> Channels {
        self.channels
    }

    /// The file's path as given.
    pub fn path(&self) -> &str {
        &self.path
    }

    fn cell(&self, col: usize, line: u64) -> Result<f64, LogError> {
        let raw = self.record.get(col).unwrap_or(b"");
        let s = std::str::from_utf8(raw).unwrap_or("");
        s.parse::<f64>().map_err(|_| LogError::NotNumeric {
            path: self.path.clone(),
            line,
            column: self.header_name(col),
            cell: s.chars().take(40).collect(),
        })
    }

    fn header_name(&self, col: usize) -> String {
        [
            (self.idx.t, "t_s"),
            (self.idx.i[0], "ia_A"),
            (self.idx.i[1], "ib_A"),
            (self.idx.i[2], "ic_A"),
        ]
        .iter()
        .chain(
            self.idx
                .v
                .map(|v| [(v[0], "va_V"), (v[1], "vb_V"), (v[2], "vc_V")])
                .iter()
                .flatten(),
        )
        .chain(self.idx.w.map(|w| (w, "wm_rad_s")).iter())
        .chain(self.idx.enc.map(|e| (e, "enc_count")).iter())
        .find(|(c, _)| *c == col)
        .map(|(_, n)| n.to_string())
        .unwrap_or_else(|| format!("#{col}"))
    }

    /// Reads the next row; `Ok(None)` at the end of the file.
    ///
    /// # Errors
    /// [`LogError::NotNumeric`], [`LogError::TimeNotIncreasing`] or [`LogError::Csv`],
    /// each naming the line.
    pub fn next_row(&mut self) -> Result<Option<Row>, LogError> {
        match self.rdr.read_byte_record(&mut self.record) {
            Ok(false) => return Ok(None),
            Ok(true) => {}
            Err(e) => {
                let line = e.position().map(|p| p.line()).unwrap_or(0);
                return Err(LogError::Csv {
                    path: self.path.clone(),
                    line,
                    message: crate::params::one_line(&e.to_string()),
                });
            }
        }
        let line = self.record.position().map(|p| p.line()).unwrap_or(0);
        let t = self.cell(self.idx.t, line)?;
        if !t.is_finite() {
            return Err(LogError::NotNumeric {
                path: self.path.clone(),
                line,
                column: "t_s".into(),
                cell: t.to_string(),
            });
        }
        if let Some(prev) = self.prev_t {
            if t <= prev {
                return Err(LogError::TimeNotIncreasing {
                    path: self.path.clone(),
                    line,
                    t,
                    prev,
                });
            }
        }
        self.prev_t = Some(t);
        let i_abc = [
            self.cell(self.idx.i[0], line)?,
            self.cell(self.idx.i[1], line)?,
            self.cell(self.idx.i[2], line)?,
        ];
        let v_abc = match self.idx.v {
            Some(v) => Some([
                self.cell(v[0], line)?,
                self.cell(v[1], line)?,
                self.cell(v[2], line)?,
            ]),
            None => None,
        };
        let wm_rad_s = match self.idx.w {
            Some(w) => Some(self.cell(w, line)?),
            None => None,
        };
        let enc_count = match self.idx.enc {
            Some(e) => Some(self.cell(e, line)?.round() as i64),
            None => None,
        };
        Ok(Some(Row {
            t_s: t,
            v_abc,
            i_abc,
            wm_rad_s,
            enc_count,
        }))
    }
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
    /// Reads a whole log into memory (use [`LogReader`] for logs too large for memory).
    ///
    /// # Errors
    /// As [`LogReader::open`] and [`LogReader::next_row`]; [`LogError::Empty`] for a log
    /// without data rows.
    pub fn read(path: &Path) -> Result<Self, LogError> {
        let mut r = LogReader::open(path)?;
        let mut rows = Vec::new();
        while let Some(row) = r.next_row()? {
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(LogError::Empty {
                path: path.display().to_string(),
            });
        }
        Ok(Log {
            channels: r.channels(),
            rows,
        })
    }

    /// Mean sample period [s] (0 for fewer than two rows).
    pub fn mean_dt_s(&self) -> f64 {
        match (self.rows.first(), self.rows.last()) {
            (Some(a), Some(b)) if self.rows.len() > 1 => {
                (b.t_s - a.t_s) / (self.rows.len() - 1) as f64
            }
            _ => 0.0,
        }
    }

    /// Writes the log atomically to `path` (see [`LogWriter`]).
    pub fn write(&self, path: &Path) -> Result<(), LogError> {
        let mut w = LogWriter::create(path, self.channels)?;
        for r in &self.rows {
            w.write_row(r)?;
        }
        w.finish()
    }
}

/// Atomic CSV writer: rows go to a temporary file in the target's folder, renamed over the
/// target only by [`LogWriter::finish`]. Dropping it unfinished leaves the target untouched.
pub struct LogWriter {
    path: PathBuf,
    tmp: Option<tempfile::NamedTempFile>,
    out: BufWriter<File>,
    channels: Channels,
    line: String,
}

impl LogWriter {
    /// Starts writing a log with the given optional channels.
    pub fn create(path: &Path, channels: Channels) -> Result<Self, LogError> {
        let io = |source| LogError::Io {
            path: path.display().to_string(),
            source,
        };
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let tmp = tempfile::Builder::new()
            .prefix(".sim-host-")
            .suffix(".tmp")
            .tempfile_in(dir)
            .map_err(io)?;
        let file = tmp.reopen().map_err(io)?;
        let mut out = BufWriter::with_capacity(1 << 20, file);
        let mut header = String::from("t_s");
        if channels.voltages {
            header.push_str(",va_V,vb_V,vc_V");
        }
        header.push_str(",ia_A,ib_A,ic_A");
        if channels.speed {
            header.push_str(",wm_rad_s");
        }
        if channels.encoder {
            header.push_str(",enc_count");
        }
        header.push('\n');
        out.write_all(header.as_bytes()).map_err(io)?;
        Ok(LogWriter {
            path: path.to_path_buf(),
            tmp: Some(tmp),
            out,
            channels,
            line: String::with_capacity(160),
        })
    }

    /// Appends one row. Channels the writer was not created with are skipped; a channel it
    /// was created with but the row lacks is written as 0.
    pub fn write_row(&mut self, r: &Row) -> Result<(), LogError> {
        // ryu: shortest round-trip formatting, an order of magnitude faster than `{:e}`.
        // Time keeps f64 precision (1e-4 s steps over hours); the channels are written at
        // f32 precision (7 significant digits), far finer than any ADC.
        let l = &mut self.line;
        l.clear();
        push_f64(l, r.t_s);
        if self.channels.voltages {
            let v = r.v_abc.unwrap_or_default();
            for x in v {
                l.push(',');
                push_f32(l, x as f32);
            }
        }
        for x in r.i_abc {
            l.push(',');
            push_f32(l, x as f32);
        }
        if self.channels.speed {
            l.push(',');
            push_f32(l, r.wm_rad_s.unwrap_or_default() as f32);
        }
        if self.channels.encoder {
            l.push(',');
            l.push_str(itoa_i64(r.enc_count.unwrap_or_default()).as_str());
        }
        l.push('\n');
        self.out
            .write_all(l.as_bytes())
            .map_err(|source| LogError::Io {
                path: self.path.display().to_string(),
                source,
            })
    }

    /// Flushes and renames the temporary file over the target.
    pub fn finish(mut self) -> Result<(), LogError> {
        let io = |source| LogError::Io {
            path: self.path.display().to_string(),
            source,
        };
        self.out.flush().map_err(io)?;
        if let Some(tmp) = self.tmp.take() {
            tmp.persist(&self.path).map_err(|e| LogError::Io {
                path: self.path.display().to_string(),
                source: e.error,
            })?;
        }
        Ok(())
    }
}

fn push_f64(l: &mut String, x: f64) {
    if x.is_finite() {
        l.push_str(ryu::Buffer::new().format_finite(x));
    } else {
        l.push_str("NaN");
    }
}

fn push_f32(l: &mut String, x: f32) {
    if x.is_finite() {
        l.push_str(ryu::Buffer::new().format_finite(x));
    } else {
        l.push_str("NaN");
    }
}

fn itoa_i64(x: i64) -> String {
    x.to_string()
}

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::Builder::new()
        .prefix(".sim-host-")
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.flush()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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

        let missing = write("t_s,ia_A,ib_A\n0,1,2\n");
        let e = Log::read(missing.path()).unwrap_err().to_string();
        assert!(e.contains("ic_A"), "{e}");
        let nonnum = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0.1,1,abc,3\n");
        let e = Log::read(nonnum.path()).unwrap_err().to_string();
        assert!(e.contains("ib_A") && e.contains("line 3"), "{e}");
        let back_in_time = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0,1,2,3\n");
        let e = Log::read(back_in_time.path()).unwrap_err().to_string();
        assert!(e.contains("does not increase"), "{e}");
    }
}
