//! What every format's reader shares, below them all and below [`super::LogFile`] that
//! dispatches to them: the column map ([`ColumnMap`]: where each schema column sits and its
//! unit), the check of the columns every log needs ([`check_columns`]), a row from the
//! schema's values ([`row_from_values`]), the options a log is opened with
//! ([`OpenOptions`]), what a reader is handed of an opened log ([`Opened`]), and the trait
//! of the formats with their own decoder ([`BinarySource`]). The formats use this module,
//! never `LogFile`'s.

use super::mapping::{ChannelUnit, ColumnMapping, TimeKind};
use super::{Channels, Column, LogError, Row, RowSink};
use std::path::Path;

/// What a format's reader needs of an opened log (`LogFile` hands it down): the file,
/// how messages name it, its column map, its size and a CSV header's length.
#[derive(Debug, Clone, Copy)]
pub(super) struct Opened<'a> {
    pub(super) path: &'a Path,
    pub(super) shown: &'a str,
    pub(super) columns: &'a ColumnMap,
    pub(super) len_bytes: u64,
    pub(super) header_bytes: u64,
}

impl<'a> Opened<'a> {
    /// The file's path.
    pub(super) fn path(&self) -> &'a Path {
        self.path
    }

    /// The path (or the data's name) as shown in messages.
    pub(super) fn shown(&self) -> &'a str {
        self.shown
    }

    /// The log's column map.
    pub(super) fn columns(&self) -> &'a ColumnMap {
        self.columns
    }

    /// The file's size [bytes].
    pub(super) fn len_bytes(&self) -> u64 {
        self.len_bytes
    }

    /// A CSV header's length [bytes] (0: no header, or not a CSV).
    pub(super) fn header_bytes(&self) -> u64 {
        self.header_bytes
    }
}

/// The bytes of one row in the binary formats (TDMS, Parquet), for size estimates: the
/// time (8) and each single-precision channel (4), the encoder count (8).
pub(super) fn binary_row_bytes(channels: Channels) -> u64 {
    let sgl = 3 + if channels.voltages { 3 } else { 0 } + u64::from(channels.speed);
    8 + 4 * sgl + if channels.encoder { 8 } else { 0 }
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
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        on_row: &mut dyn FnMut(&Row) -> bool,
    ) -> Result<u64, LogError>;

    /// [`BinarySource::for_each_row`] into `sink`, in blocks of rows where the source
    /// has them ([`RowSink::rows`]); by default row by row.
    ///
    /// # Errors
    /// As [`BinarySource::for_each_row`].
    fn for_each_block(
        &self,
        log: &Opened<'_>,
        progress: &mut dyn FnMut(f64),
        sink: &mut dyn RowSink,
    ) -> Result<u64, LogError> {
        self.for_each_row(log, progress, &mut |r| sink.row(r))
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

/// The row of the values of every schema column (in [`Column::ALL`] order; absent columns
/// are ignored) for a log with `columns`.
#[inline]
pub(super) fn row_from_values(v: &[f64; Column::COUNT], columns: &ColumnMap) -> Row {
    let has = |c: Column| columns.of(c).is_some();
    // To the schema's SI units: one multiplication per cell (none without a mapping).
    let k = &columns.scale;
    let t_winding_c = has(Column::Temperature).then(|| (v[9] + columns.temp_offset) * k[9]);
    if !columns.scaled {
        return Row {
            t_s: v[0],
            v_abc: has(Column::Va).then_some([v[1], v[2], v[3]]),
            i_abc: [v[4], v[5], v[6]],
            wm_rad_s: has(Column::Speed).then_some(v[7]),
            enc_count: has(Column::Encoder).then_some(super::enc_count_of(v[8])),
            t_winding_c,
        };
    }
    Row {
        t_s: v[0] * k[0],
        v_abc: has(Column::Va).then_some([v[1] * k[1], v[2] * k[2], v[3] * k[3]]),
        i_abc: [v[4] * k[4], v[5] * k[5], v[6] * k[6]],
        wm_rad_s: has(Column::Speed).then_some(v[7] * k[7]),
        enc_count: has(Column::Encoder).then_some(super::enc_count_of(v[8])),
        t_winding_c,
    }
}

/// A file (or data, `shown`) that cannot be read as a log, and why: [`LogError::NotALog`],
/// the one constructor of every reader.
pub(super) fn not_a_log(shown: &str, why: String) -> LogError {
    LogError::NotALog {
        path: shown.to_string(),
        why,
    }
}
