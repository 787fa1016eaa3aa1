//! The atomic log writer: CSV here, TDMS and Parquet through their modules.

use super::{Channels, Column, Format, LogError, Row};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Atomic log writer in the format of the target's extension ([`Format::of_path`]): rows go
/// to a temporary file in the target's folder, renamed over the target only by
/// [`LogWriter::finish`]. Dropping it unfinished (an error, an interrupted
/// run) deletes the temporary file and leaves the target untouched. The output gets the
/// mode of any new file (0o666 less the umask).
///
/// Precision, the same in every format: `t_s` at f64 precision (CSV: shortest round-trip
/// digits; TDMS DBL; Parquet DOUBLE); voltages, currents and speed at f32 precision (CSV: (shortest round-trip of the f32 value: 7 significant digits,
/// a relative error up to 6e-8). That is far finer than any ADC (a 12-bit converter
/// resolves 2.4e-4 of its range) but coarser than the simulator's integration error on
/// ideal sensors: on the 2.2 kW reference start the written currents differ from the
/// simulated ones by up to 3.7e-6 A, four times the integrator's 9.7e-7 A (docs/performance.md's
/// benchmark table). Work that needs the simulator's full accuracy takes the rows in
/// memory (`monitor_sim::simulate`), not through a CSV.
pub struct LogWriter {
    path: PathBuf,
    tmp: Option<tempfile::NamedTempFile>,
    sink: Sink,
    channels: Channels,
    line: String,
}

/// The format-specific part of a [`LogWriter`].
enum Sink {
    Csv(BufWriter<File>),
    Tdms(BufWriter<File>, Box<super::tdms::TdmsLogWriter>),
    Parquet(Box<super::parquet::ParquetLogWriter>),
}

/// A Parquet error as the writer's I/O error.
fn pq_io(e: ::parquet::errors::ParquetError) -> std::io::Error {
    std::io::Error::other(crate::one_line(&e.to_string()))
}

impl LogWriter {
    /// Starts writing a log with the given optional channels, in the format of `path`'s
    /// extension. The temperature column (`t_winding_c`) is written to a CSV only: TDMS and
    /// Parquet outputs leave it out.
    ///
    /// # Errors
    /// [`LogError::Io`] when the temporary file cannot be created.
    pub fn create(path: &Path, channels: Channels) -> Result<Self, LogError> {
        let io = |source| LogError::Io {
            path: path.display().to_string(),
            source,
        };
        let tmp = temp_file_beside(path).map_err(io)?;
        let file = tmp.reopen().map_err(io)?;
        let format = Format::of_path(path);
        let channels = Channels {
            temperature: channels.temperature && format == Format::Csv,
            ..channels
        };
        let sink = match format {
            Format::Csv => Sink::Csv(Self::csv_header(file, channels).map_err(io)?),
            Format::Tdms => Sink::Tdms(
                BufWriter::with_capacity(1 << 20, file),
                Box::new(super::tdms::TdmsLogWriter::new(channels)),
            ),
            Format::Parquet => Sink::Parquet(Box::new(
                super::parquet::ParquetLogWriter::new(file, channels)
                    .map_err(pq_io)
                    .map_err(io)?,
            )),
        };
        Ok(LogWriter {
            path: path.to_path_buf(),
            tmp: Some(tmp),
            sink,
            channels,
            line: String::with_capacity(160),
        })
    }

    /// A CSV output with its header written.
    fn csv_header(file: File, channels: Channels) -> std::io::Result<BufWriter<File>> {
        let mut out = BufWriter::with_capacity(1 << 20, file);
        // The schema's columns this log has, in `Column` order.
        let names: Vec<&str> = Column::ALL
            .iter()
            .filter(|c| channels.has(**c))
            .map(|c| c.name())
            .collect();
        let mut header = names.join(",");
        header.push('\n');
        out.write_all(header.as_bytes())?;
        Ok(out)
    }

    /// The typical size of one row of a log with `channels` written to `path` [bytes]:
    /// [`LogWriter::estimated_row_bytes`] for a CSV, the exact bytes of the binary formats
    /// (8 for `t_s`, 4 a channel, 8 for `enc_count`).
    pub fn estimated_row_bytes_for(path: &Path, channels: Channels) -> u64 {
        match Format::of_path(path) {
            Format::Csv => Self::estimated_row_bytes(channels),
            Format::Tdms => super::tdms::TdmsLogWriter::row_bytes(channels),
            Format::Parquet => super::parquet::ParquetLogWriter::row_bytes(channels),
        }
    }

    /// The typical size of one row with `channels` [bytes], for estimating an output's
    /// size before writing it: `t_s` about 10 characters, each f32 channel about 10 digits
    /// and a comma, `enc_count` about 8, the newline. Measured on simulated logs (3 hp and
    /// 2.2 kW machines, 10 kHz, ideal and 12-bit sensors): 87 bytes a row with every
    /// channel, against 97 estimated.
    pub fn estimated_row_bytes(channels: Channels) -> u64 {
        let f32_channels =
            3 + if channels.voltages { 3 } else { 0 } + if channels.speed { 1 } else { 0 };
        10 + 11 * f32_channels + if channels.encoder { 9 } else { 0 } + 1
    }

    /// Appends one row. Channels the writer was not created with are skipped; a channel it
    /// was created with but the row lacks is written as 0.
    ///
    /// # Errors
    /// [`LogError::Io`] when the file cannot be written.
    pub fn write_row(&mut self, r: &Row) -> Result<(), LogError> {
        let io = |source| LogError::Io {
            path: self.path.display().to_string(),
            source,
        };
        let out = match &mut self.sink {
            Sink::Csv(out) => out,
            Sink::Tdms(out, w) => return w.write_row(out, r).map_err(io),
            Sink::Parquet(w) => return w.write_row(r).map_err(pq_io).map_err(io),
        };
        // ryu: shortest round-trip formatting, an order of magnitude faster than `{:e}`.
        // Time keeps f64 precision (1e-4 s steps over hours); the channels are written at
        // f32 precision (see the type's docs).
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
            // Writing into a String cannot fail.
            match r.enc_count.unwrap_or_default() {
                // (A count that was not a number stays one.)
                super::ENC_COUNT_UNREADABLE => l.push_str("NaN"),
                n => {
                    let _ = write!(l, "{n}");
                }
            }
        }
        if self.channels.temperature {
            l.push(',');
            push_f32(l, r.t_winding_c.unwrap_or(f64::NAN) as f32);
        }
        l.push('\n');
        out.write_all(l.as_bytes()).map_err(io)
    }

    /// Flushes (TDMS: the last segment; Parquet: the last row group and the footer) and
    /// renames the temporary file over the target.
    ///
    /// # Errors
    /// [`LogError::Io`] when the file cannot be written or renamed.
    pub fn finish(self) -> Result<(), LogError> {
        let LogWriter {
            path, tmp, sink, ..
        } = self;
        let io = |source| LogError::Io {
            path: path.display().to_string(),
            source,
        };
        match sink {
            Sink::Csv(mut out) => out.flush().map_err(io)?,
            Sink::Tdms(mut out, mut w) => super::tdms::finish(&mut w, &mut out).map_err(io)?,
            Sink::Parquet(w) => w.finish().map_err(pq_io).map_err(io)?,
        }
        if let Some(tmp) = tmp {
            tmp.persist(&path).map_err(|e| LogError::Io {
                path: path.display().to_string(),
                source: e.error,
            })?;
        }
        Ok(())
    }
}

/// Shortest round-trip digits of `x` (f64 or f32), "NaN" for a non-finite value.
fn push_number<F: ryu::Float>(l: &mut String, x: F, finite: bool) {
    if finite {
        l.push_str(ryu::Buffer::new().format_finite(x));
    } else {
        l.push_str("NaN");
    }
}

fn push_f64(l: &mut String, x: f64) {
    push_number(l, x, x.is_finite());
}

fn push_f32(l: &mut String, x: f32) {
    push_number(l, x, x.is_finite());
}

/// A temporary file in `path`'s folder (renamed over `path` when complete), created with
/// the mode an ordinary new file gets (0o666 less the umask: 0o644 under umask 022).
fn temp_file_beside(path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut b = tempfile::Builder::new();
    b.prefix(".sim-host-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // The mode of any new file: 0o666 less the umask, which the kernel applies at
        // creation (tempfile's own default, 0o600, would hide the output from the group).
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
}

/// Writes `bytes` to `path` atomically (temporary file in the same folder, then rename; the
/// temporary file is deleted on error). The file gets the mode of any new file (0o666
/// less the umask).
///
/// # Errors
/// I/O errors creating, writing or renaming the file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = temp_file_beside(path)?;
    tmp.write_all(bytes)?;
    tmp.flush()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}
