//! Measurement logs in the CSV schema of `docs/design.md`: the one reader and the one
//! writer of the workspace, for three file formats chosen by the extension ([`Format`]): CSV, TDMS
//! (LabVIEW; channels named like the CSV columns, [`tdms`]) and Parquet (columns named like
//! the CSV columns, [`parquet`]). Every format hands over the same [`Row`]s, and every
//! command passes them through the same data-quality stage.
//!
//! Columns (header row, comma separated, SI units in the names, [`Column`]):
//! `t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s` and optionally `enc_count`
//! (cumulative encoder count) and `t_winding_c` (winding temperature, degC). `t_s` and the three currents are required; the voltages
//! (all three or none) and the speed (`wm_rad_s`, mechanical rad/s) are optional; extra
//! columns are ignored. The reader hands over what the file holds, non-finite cells and
//! times that do not increase included: judging them is the data-quality stage's
//! ([`quality`]), which every command runs before its analysis.
//!
//! - Reading: [`LogFile::open`] parses the header (schema, channel list) once (columns by
//!   name); then
//!   [`LogFile::for_each_row`] streams the rows in file order with bounded memory, through
//!   a parallel fast path (`fast`) and, where that meets anything it does not accept, the
//!   exact reader (`exact`), whose message names the line and column. [`Log::read`] holds
//!   a whole log in memory.
//! - The sample rate of a log is estimated in one place, [`sample_rate_hz`] (the median
//!   interval), and the time base is judged in one place, [`quality::QualityStage`].
//! - Writing is atomic ([`LogWriter`], [`write_atomic`]): a temporary file beside the
//!   target, renamed on [`LogWriter::finish`], so an interrupted run never leaves a
//!   half-written output; and before it, the one guard against overwriting an input
//!   ([`check_outputs`]: an output that is an input, by any path or link, is refused
//!   before anything is written), which every front end calls.

pub mod clipping;
mod csv_header;
mod csv_line;
mod exact;
mod fast;
mod format;
pub mod mapping;
mod memory;
mod overwrite;
pub mod parquet;
pub mod quality;
mod reader;
mod source;
pub mod tdms;
mod typed;
mod writer;

pub use format::Format;
pub use mapping::{ChannelUnit, ColumnMapping};
pub use memory::{MemoryLog, MemoryValues};
pub use overwrite::{check_output_folder, check_outputs, same_file, NamedFile, OverwriteError};
pub use reader::{LogFile, LogStart, LogStartFrom, RowSink};
pub use source::OpenOptions;
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
    /// A required column is missing: named, with why it is needed, the channels the log
    /// has and the closest of them ([`mapping`]).
    #[error("{path}: missing column '{column}'{detail}")]
    MissingColumn {
        /// The file.
        path: String,
        /// The column's name in the log (the schema's, or the one `[columns]` gives).
        column: String,
        /// The rest of the message: " (for ia_A in [columns])" when the name comes from
        /// the mapping, " (why it is needed)", "; the log has ...", the closest channel
        /// and where to map it.
        detail: String,
    },
    /// A column name appears twice in the log.
    #[error("{path}: column '{column}' appears twice, at columns {first} and {second}: which one is meant cannot be told")]
    DuplicateColumn {
        /// The file.
        path: String,
        /// The name.
        column: String,
        /// 1-based position of its first occurrence.
        first: usize,
        /// 1-based position of its second occurrence.
        second: usize,
    },
    /// A channel's unit disagrees with the mapping, or is not one the reader knows.
    #[error("{path}: channel '{channel}' {why}")]
    Unit {
        /// The file.
        path: String,
        /// The channel.
        channel: String,
        /// What is wrong, naming both units.
        why: String,
    },
    /// A channel holds no usable value at all.
    #[error("{path}: channel {channel} {why}")]
    NoValue {
        /// The file.
        path: String,
        /// The channel's schema name.
        channel: String,
        /// "holds no finite value", or what its values are instead.
        why: String,
    },
    /// A time cell is not a number (text in a measured column is a bad cell, read as
    /// NaN for the data-quality stage).
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
    /// The first rows give no sample period.
    #[error("{path}: cannot tell the sample period: t_s needs increasing finite values")]
    NoTimeBase {
        /// The file.
        path: String,
    },
    /// Sampled too slowly for any analysis.
    #[error("{path}: sampled at {rate_hz:.0} Hz, fewer than 8 samples per supply period: a {supply_hz} Hz supply needs at least {needed_hz:.0} Hz")]
    RateTooLow {
        /// The file.
        path: String,
        /// The log's rate [Hz].
        rate_hz: f64,
        /// The parameter file's supply frequency [Hz].
        supply_hz: f64,
        /// The lowest rate that works [Hz].
        needed_hz: f64,
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
    /// A TDMS group asked of a log that has none (`given`), or a TDMS file of several
    /// groups and none asked (`given` is `None`; `why` lists them). The option is named
    /// `group` ([`LogError::spelled`] names it in a front end's words).
    #[error("{}", self.spelled(&|name| name.to_string()))]
    Group {
        /// The file.
        path: String,
        /// The group asked for.
        given: Option<String>,
        /// What is wrong.
        why: String,
    },
    /// The file is not a log in the schema (empty, another separator, no header).
    #[error("{path}: {why}")]
    NotALog {
        /// The file.
        path: String,
        /// What it is instead.
        why: String,
    },
    /// The log has no data rows.
    #[error("{path}: the log has no data rows")]
    Empty {
        /// The file.
        path: String,
    },
    /// The log has rows, but too few usable ones in the window asked for.
    #[error("{path}: too few usable rows in the selected time window ({why})")]
    NoUsableRows {
        /// The file.
        path: String,
        /// What held them out.
        why: String,
    },
}

/// True for the text of a missing value in a CSV cell: empty, `NA` or `null` (any case).
/// Such a cell is read as NaN, like the cells `NaN` and `inf`: the data-quality stage
/// holds them all out and counts them alike (`docs/data-quality.md`).
pub fn is_missing(cell: &str) -> bool {
    let c = cell.trim();
    c.is_empty() || c.eq_ignore_ascii_case("na") || c.eq_ignore_ascii_case("null")
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
    /// `t_winding_c`: winding (or stator frame) temperature [degC], optional; not judged
    /// by the data-quality stage (the isolation judges its plausibility).
    Temperature,
}

impl Column {
    /// The measured channels stored at f32 precision by every writer (voltages, currents,
    /// speed), in [`Row`] order: [`Column::ALL`] without the time, the encoder count and the
    /// temperature (written at f32 too, but not judged by the data-quality stage).
    pub const MEASURED: [Column; 7] = {
        let all = Column::ALL;
        [all[1], all[2], all[3], all[4], all[5], all[6], all[7]]
    };

    /// How many columns the schema has.
    pub const COUNT: usize = 10;

    /// Every column of the schema, in [`Row`] order.
    pub const ALL: [Column; Column::COUNT] = [
        Column::Time,
        Column::Va,
        Column::Vb,
        Column::Vc,
        Column::Ia,
        Column::Ib,
        Column::Ic,
        Column::Speed,
        Column::Encoder,
        Column::Temperature,
    ];

    /// The header name (the schema of `docs/design.md`).
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
            Column::Temperature => "t_winding_c",
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
    /// Winding (or stator frame) temperature [degC] (`t_winding_c`).
    pub t_winding_c: Option<f64>,
}

/// The [`Row::enc_count`] of a cell that holds no readable count: not finite, or beyond
/// `±2^53` where the readers' `f64` no longer carries every integer (a 64-bit counter
/// near its overflow). The data-quality stage marks such a cell bad
/// ([`quality::BadCells`]), as it does a non-finite current.
pub const ENC_COUNT_UNREADABLE: i64 = i64::MIN;

/// The largest encoder count the readers carry exactly, `2^53`.
pub const ENC_COUNT_EXACT_MAX: f64 = 9_007_199_254_740_992.0;

/// The encoder count of a cell's value: the nearest integer, or
/// [`ENC_COUNT_UNREADABLE`] for a value that is not finite or beyond
/// `±`[`ENC_COUNT_EXACT_MAX`].
pub fn enc_count_of(x: f64) -> i64 {
    if x.is_finite() && x.abs() <= ENC_COUNT_EXACT_MAX {
        x.round() as i64
    } else {
        ENC_COUNT_UNREADABLE
    }
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
    /// `t_winding_c` present.
    pub temperature: bool,
}

impl Channels {
    /// Whether the log has `c` (time and currents always).
    pub fn has(&self, c: Column) -> bool {
        match c {
            Column::Time | Column::Ia | Column::Ib | Column::Ic => true,
            Column::Va | Column::Vb | Column::Vc => self.voltages,
            Column::Speed => self.speed,
            Column::Encoder => self.encoder,
            Column::Temperature => self.temperature,
        }
    }
}

impl Row {
    /// The value of column `c` in the schema's unit; `None` where the log lacks the
    /// column, or for an encoder count that was not a number ([`ENC_COUNT_UNREADABLE`]).
    pub fn value(&self, c: Column) -> Option<f64> {
        let v = self.v_abc;
        match c {
            Column::Time => Some(self.t_s),
            Column::Va => v.map(|v| v[0]),
            Column::Vb => v.map(|v| v[1]),
            Column::Vc => v.map(|v| v[2]),
            Column::Ia => Some(self.i_abc[0]),
            Column::Ib => Some(self.i_abc[1]),
            Column::Ic => Some(self.i_abc[2]),
            Column::Speed => self.wm_rad_s,
            Column::Encoder => self
                .enc_count
                .filter(|n| *n != ENC_COUNT_UNREADABLE)
                .map(|n| n as f64),
            Column::Temperature => self.t_winding_c,
        }
    }
}

/// The workspace's one sample-rate estimate [Hz], from the first [`quality::HEAD_ROWS`]
/// times given (in the times' unit): the median interval `T_med` first, robust to a
/// sample dropped or a timestamp glitch among the rows; then the mean period over the
/// intervals of up to 16 periods, each counted as its nearest whole number `m` of `T_med`,
/// `sum(d) / sum(m)`: as fine as the times' printed resolution and their jitter allow (the
/// median alone is one printed interval: 0.000700 or 0.000699 s for 1428.6 Hz, 0.1 %
/// off). `None` without a positive finite interval.
pub fn sample_rate_hz(times: &[f64]) -> Option<f64> {
    let t = &times[..times.len().min(quality::HEAD_ROWS)];
    let d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let t_med = quality::median_positive(&mut d.clone())?;
    let (mut sum_d, mut sum_m) = (0.0, 0.0);
    for x in d {
        let m = (x / t_med).round();
        if (1.0..=16.0).contains(&m) {
            sum_d += x;
            sum_m += m;
        }
    }
    Some(sum_m / sum_d)
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
                temperature: false,
            },
            rows: (0..10)
                .map(|k| Row {
                    t_s: k as f64 * 1e-4,
                    v_abc: Some([1.0, -0.5, -0.5]),
                    i_abc: [0.1 * k as f64, 2.0, -3.0],
                    wm_rad_s: Some(150.0),
                    enc_count: None,
                    t_winding_c: None,
                })
                .collect(),
        };
        log.write(&p).unwrap();
        let back = Log::read(&p).unwrap();
        assert_eq!(back.rows.len(), 10);
        assert!((back.rows[9].i_abc[0] - 0.9).abs() < 1e-9);
        let times: Vec<f64> = back.rows.iter().map(|r| r.t_s).collect();
        assert!((sample_rate_hz(&times).unwrap() - 1e4).abs() < 1e-6);

        let missing = write("t_s,ia_A,ib_A\n0,1,2\n");
        let e = Log::read(missing.path()).unwrap_err().to_string();
        assert!(e.contains("ic_A"), "{e}");
        // Text in a measured column is a bad cell (NaN); in the time column, an error
        // naming the line and column.
        let text = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0.1,1,abc,3\n");
        let rows = Log::read(text.path()).unwrap().rows;
        assert!(rows.len() == 2 && rows[1].i_abc[1].is_nan(), "{rows:?}");
        let nonnum = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\nabc,1,2,3\n");
        let e = Log::read(nonnum.path()).unwrap_err().to_string();
        assert!(e.contains("t_s") && e.contains("line 3"), "{e}");
        // Times that do not increase are handed over (the data-quality stage judges them).
        let back_in_time = write("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0,1,2,3\n");
        assert_eq!(Log::read(back_in_time.path()).unwrap().rows.len(), 2);
        let empty = write("t_s,ia_A,ib_A,ic_A\n");
        let e = Log::read(empty.path()).unwrap_err().to_string();
        assert!(e.contains("no data rows"), "{e}");
        // An empty file, another separator and a file without a header say so (they used
        // to say "missing column 't_s'").
        for (text, says) in [
            ("", "the file is empty"),
            ("\n", "the file is empty"),
            ("t_s;ia_A;ib_A;ic_A\n0;1;2;3\n", "separated by ';'"),
            ("t_s\tia_A\tib_A\tic_A\n0\t1\t2\t3\n", "separated by '\\t'"),
            ("0,1,2,3\n1,1,2,3\n", "no header row"),
        ] {
            let f = write(text);
            let e = Log::read(f.path()).unwrap_err().to_string();
            assert!(
                e.contains(says) && !e.contains("missing column"),
                "{text:?}: {e}"
            );
        }
    }

    /// Rows and the blank lines the reader reports.
    #[derive(Default)]
    struct Counted {
        rows: Vec<Row>,
        blank: u64,
    }

    impl RowSink for Counted {
        fn row(&mut self, row: &Row) -> bool {
            self.rows.push(*row);
            true
        }
        fn restart(&mut self) {
            self.rows.clear();
        }
        fn blank_lines(&mut self, lines: u64) {
            self.blank = lines;
        }
    }

    fn counted(text: &str, columns: ColumnMapping) -> Counted {
        let f = write(text);
        let opts = OpenOptions {
            columns,
            ..OpenOptions::default()
        };
        let file = LogFile::open_with(f.path(), &opts).unwrap();
        let mut c = Counted::default();
        file.for_each_row(&mut |_| {}, &mut c).unwrap();
        c
    }

    #[test]
    fn missing_values_blank_lines_and_units_alike_on_both_csv_paths() {
        let text = "t_s,ia_A,ib_A,ic_A,enc_count\n0,1,,3,5\n\n0.1,NA,null,NaN,\n0.2,1,2,3,NA\n\n";
        // The fast path takes it; a quoted cell sends it to the exact reader.
        let exact = text.replace("0.2,1", "0.2,\"1\"");
        for t in [text, exact.as_str()] {
            let c = counted(t, ColumnMapping::default());
            assert_eq!(c.blank, 2, "{t:?}");
            assert_eq!(c.rows.len(), 3);
            assert!(c.rows[0].i_abc[1].is_nan() && c.rows[1].i_abc.iter().all(|x| x.is_nan()));
            assert_eq!(c.rows[0].enc_count, Some(5));
            assert_eq!(c.rows[1].enc_count, Some(ENC_COUNT_UNREADABLE));
            assert_eq!(c.rows[2].value(Column::Encoder), None);
        }
        // Units: ms and mA, one multiplication each; epoch ms counted from the first row.
        let mut m = ColumnMapping::new(2);
        m.set(Column::Time, "T", Some(ChannelUnit::EpochMilliseconds))
            .unwrap();
        m.set(Column::Ia, "I1", Some(ChannelUnit::Milliamperes))
            .unwrap();
        let text = "I1,T,ib_A,ic_A\n1500,1714564800000,2,3\n-250,1714564800000.5,2,3\n";
        for t in [text.to_string(), text.replace(",2,3\n-", ",\"2\",3\n-")] {
            let c = counted(&t, m.clone());
            assert_eq!(c.rows[0].t_s, 0.0, "{t:?}");
            assert!((c.rows[1].t_s - 5e-4).abs() < 1e-9);
            assert!((c.rows[0].i_abc[0] - 1.5).abs() < 1e-12);
            assert!((c.rows[1].i_abc[0] + 0.25).abs() < 1e-12);
        }
    }

    #[test]
    fn sample_rate_from_the_first_rows() {
        let mut t: Vec<f64> = (0..1000).map(|k| k as f64 * 2e-4).collect();
        assert!((sample_rate_hz(&t).unwrap() - 5000.0).abs() < 1e-6);
        // One sample missing and one glitched timestamp among the first rows do not move
        // the median interval ((n - 1) / span would give 4995 Hz).
        t.remove(3);
        t[10] += 1e-3;
        assert!((sample_rate_hz(&t).unwrap() - 5000.0).abs() < 1e-6);
        // Times printed to the microsecond at 1428.57 Hz: intervals of 700 and 699 us.
        let t: Vec<f64> = (0..2000)
            .map(|k| (k as f64 / 1_428.571_428 * 1e6).round() * 1e-6)
            .collect();
        assert!((sample_rate_hz(&t).unwrap() / 1_428.571_428 - 1.0).abs() < 1e-5);
        assert_eq!(sample_rate_hz(&[1.0]), None);
        assert_eq!(sample_rate_hz(&[1.0, 1.0]), None);
        assert_eq!(sample_rate_hz(&[]), None);
    }
}
