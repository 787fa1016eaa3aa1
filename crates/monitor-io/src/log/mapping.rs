//! Channel mapping: which channel of a log holds each column of the schema, and in which
//! unit ([`ColumnMapping`], the parameter file's `[columns]` table, `docs/design.md`).
//!
//! A data-acquisition system names its channels its own way (`Ia`, `Current A`, `Time`)
//! and records in its own units (ms, mA, rpm). The mapping names, per schema column, the
//! log's channel and its unit; every reader (CSV, TDMS, Parquet) looks the channel up by
//! that name and converts its values to the schema's SI units with one multiplication per
//! cell ([`ChannelUnit::factor`]), so everything behind the reader sees the schema as
//! `docs/design.md` defines it. A column the mapping leaves out is looked up by its schema
//! name, in its schema unit (or, in a TDMS file, the channel's `unit_string`).
//!
//! The units (case as written):
//! - time (`t_s`): `s`, `ms`, `us` (or `µs`); a timestamp column: `epoch_s`, `epoch_ms`,
//!   `epoch_us`, `epoch_ns` (seconds ... nanoseconds since 1970-01-01), `iso8601` (text
//!   such as `2024-05-01T12:00:00.125Z`, CSV only) or `timestamp` (either: ISO 8601 text or
//!   Unix epoch seconds, cell by cell; CSV only, and a Parquet `TIMESTAMP` column). ISO 8601
//!   text without a zone is UTC. A timestamp's time counts from the log's first row
//!   (`t_s = 0` there); its first time is the log's start
//!   ([`super::LogFile::start_time`]). A cell that is no time is a bad cell (NaN, held out
//!   and counted by the data-quality stage); a column without one time is refused.
//! - voltages: `V`, `kV`, `mV`; currents: `A`, `mA`;
//! - speed (`wm_rad_s`, mechanical): `rad/s`, `rpm` (mechanical revolutions per minute,
//!   times `2 pi / 60`) or `Hz_el` (the electrical frequency of the rotor speed, times
//!   `2 pi / Np` with `Np` the parameter file's pole pairs);
//! - `enc_count`: `count`;
//! - temperature (`t_winding_c`): `degC` (or `°C`, `C`), `K`, `degF` (or `°F`, `F`): the
//!   one column converted with an offset too ([`ChannelUnit::offset`]).
//!
//! Missing columns are reported with the channels the log has and the closest of them
//! ([`missing_column`]).

mod columns_error;
use super::{Column, LogError};
use crate::params::{ColumnsTable, ParamError, ParamFile};
pub use columns_error::ColumnsError;

mod iso8601;
mod suggest;
pub(super) use iso8601::parse_iso8601;
pub use suggest::{channel_list, closest, near_names};
pub(super) use suggest::{missing_column, missing_column_with};

/// The unit a log's channel is recorded in; see the module documentation for the list.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelUnit {
    /// Seconds.
    Seconds,
    /// Milliseconds.
    Milliseconds,
    /// Microseconds.
    Microseconds,
    /// Seconds since 1970-01-01 (the time counts from the first row).
    EpochSeconds,
    /// Milliseconds since 1970-01-01.
    EpochMilliseconds,
    /// Microseconds since 1970-01-01.
    EpochMicroseconds,
    /// Nanoseconds since 1970-01-01.
    EpochNanoseconds,
    /// ISO 8601 date and time text (`YYYY-MM-DDTHH:MM:SS[.f][Z|+HH:MM]`; no zone: UTC).
    Iso8601,
    /// A timestamp: ISO 8601 text as [`ChannelUnit::Iso8601`] or Unix epoch seconds
    /// (`1793685600.125`), cell by cell (a Parquet `TIMESTAMP` column: its own unit).
    Timestamp,
    /// Volts.
    Volts,
    /// Kilovolts.
    Kilovolts,
    /// Millivolts.
    Millivolts,
    /// Amperes.
    Amperes,
    /// Milliamperes.
    Milliamperes,
    /// Mechanical radians per second.
    RadPerSecond,
    /// Mechanical revolutions per minute.
    Rpm,
    /// Electrical hertz of the rotor speed (`Np` times the mechanical revolutions per
    /// second).
    ElectricalHz,
    /// Encoder counts.
    Count,
    /// Degrees Celsius.
    DegC,
    /// Kelvin (degC + 273.15).
    Kelvin,
    /// Degrees Fahrenheit (degC 9/5 + 32).
    DegF,
}

/// How a log's time column is to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) enum TimeKind {
    /// A number in a time unit, as it is.
    #[default]
    Plain,
    /// A number since an epoch: counted from the first row.
    Epoch,
    /// ISO 8601 text: counted from the first row.
    Iso8601,
    /// ISO 8601 text or epoch seconds: counted from the first row.
    Timestamp,
}

impl TimeKind {
    /// True for a time column read as text (the exact reader's).
    pub(super) fn is_text(self) -> bool {
        matches!(self, TimeKind::Iso8601 | TimeKind::Timestamp)
    }
}

impl ChannelUnit {
    /// Every unit with its spellings (the first is the one written in messages).
    const SPELLINGS: [(ChannelUnit, &'static [&'static str]); 21] = [
        (ChannelUnit::Seconds, &["s", "sec", "Seconds"]),
        (ChannelUnit::Milliseconds, &["ms"]),
        (ChannelUnit::Microseconds, &["us", "µs"]),
        (ChannelUnit::EpochSeconds, &["epoch_s"]),
        (ChannelUnit::EpochMilliseconds, &["epoch_ms"]),
        (ChannelUnit::EpochMicroseconds, &["epoch_us"]),
        (ChannelUnit::EpochNanoseconds, &["epoch_ns"]),
        (ChannelUnit::Iso8601, &["iso8601"]),
        (ChannelUnit::Timestamp, &["timestamp"]),
        (ChannelUnit::Volts, &["V", "Volts"]),
        (ChannelUnit::Kilovolts, &["kV"]),
        (ChannelUnit::Millivolts, &["mV"]),
        (ChannelUnit::Amperes, &["A", "Amps"]),
        (ChannelUnit::Milliamperes, &["mA"]),
        (ChannelUnit::RadPerSecond, &["rad/s"]),
        (ChannelUnit::Rpm, &["rpm", "RPM", "1/min"]),
        (ChannelUnit::ElectricalHz, &["Hz_el"]),
        (ChannelUnit::Count, &["count"]),
        (ChannelUnit::DegC, &["degC", "°C", "C", "Celsius"]),
        (ChannelUnit::Kelvin, &["K", "Kelvin"]),
        (ChannelUnit::DegF, &["degF", "°F", "F", "Fahrenheit"]),
    ];

    /// The units a schema column may be recorded in.
    pub fn allowed(c: Column) -> &'static [ChannelUnit] {
        use ChannelUnit as U;
        match c {
            Column::Time => &[
                U::Seconds,
                U::Milliseconds,
                U::Microseconds,
                U::EpochSeconds,
                U::EpochMilliseconds,
                U::EpochMicroseconds,
                U::EpochNanoseconds,
                U::Iso8601,
                U::Timestamp,
            ],
            Column::Va | Column::Vb | Column::Vc => &[U::Volts, U::Kilovolts, U::Millivolts],
            Column::Ia | Column::Ib | Column::Ic => &[U::Amperes, U::Milliamperes],
            Column::Speed => &[U::RadPerSecond, U::Rpm, U::ElectricalHz],
            Column::Encoder => &[U::Count],
            Column::Temperature => &[U::DegC, U::Kelvin, U::DegF],
        }
    }

    /// The unit of schema column `c` spelled `text` (one of the spellings of
    /// [`ChannelUnit::allowed`]`(c)`).
    ///
    /// # Errors
    /// A one-line message naming the column, the text and the units it may take.
    pub fn parse(c: Column, text: &str) -> Result<Self, ColumnsError> {
        let t = text.trim();
        let allowed = Self::allowed(c);
        Self::SPELLINGS
            .iter()
            .find(|(u, names)| allowed.contains(u) && names.contains(&t))
            .map(|(u, _)| *u)
            .ok_or_else(|| ColumnsError::Unit {
                column: c,
                text: t.to_string(),
            })
    }

    /// The unit's name as written in the parameter file.
    pub fn name(self) -> &'static str {
        Self::SPELLINGS
            .iter()
            .find(|(u, _)| *u == self)
            .map_or("?", |(_, names)| names[0])
    }

    /// The factor from this unit to the schema's SI unit (s, V, A, mechanical rad/s,
    /// counts); `pole_pairs` for [`ChannelUnit::ElectricalHz`] (mechanical rad/s = 2 pi
    /// f_el / Np).
    pub fn factor(self, pole_pairs: u32) -> f64 {
        use std::f64::consts::TAU;
        match self {
            ChannelUnit::Seconds
            | ChannelUnit::EpochSeconds
            | ChannelUnit::Iso8601
            | ChannelUnit::Timestamp
            | ChannelUnit::Volts
            | ChannelUnit::Amperes
            | ChannelUnit::RadPerSecond
            | ChannelUnit::Count
            | ChannelUnit::DegC
            | ChannelUnit::Kelvin => 1.0,
            ChannelUnit::DegF => 5.0 / 9.0,
            ChannelUnit::Milliseconds
            | ChannelUnit::EpochMilliseconds
            | ChannelUnit::Millivolts
            | ChannelUnit::Milliamperes => 1e-3,
            ChannelUnit::Microseconds | ChannelUnit::EpochMicroseconds => 1e-6,
            ChannelUnit::EpochNanoseconds => 1e-9,
            ChannelUnit::Kilovolts => 1e3,
            ChannelUnit::Rpm => TAU / 60.0,
            ChannelUnit::ElectricalHz => TAU / f64::from(pole_pairs.max(1)),
        }
    }

    /// What is added to a value in this unit before [`ChannelUnit::factor`] multiplies it
    /// (the temperatures' zero: `-273.15` for kelvin, `-32` for degF; 0 for every other
    /// unit).
    pub fn offset(self) -> f64 {
        match self {
            ChannelUnit::Kelvin => -273.15,
            ChannelUnit::DegF => -32.0,
            _ => 0.0,
        }
    }

    /// How a time column in this unit is read.
    pub(super) fn time_kind(self) -> TimeKind {
        match self {
            ChannelUnit::EpochSeconds
            | ChannelUnit::EpochMilliseconds
            | ChannelUnit::EpochMicroseconds
            | ChannelUnit::EpochNanoseconds => TimeKind::Epoch,
            ChannelUnit::Iso8601 => TimeKind::Iso8601,
            ChannelUnit::Timestamp => TimeKind::Timestamp,
            _ => TimeKind::Plain,
        }
    }
}

/// One schema column's channel in the log: its name there (or its place in a line) and,
/// when given, its unit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MappedChannel {
    /// The channel's name in the log (CSV header field, TDMS channel, Parquet column); for
    /// a channel given by its place, `column N` (as messages show it).
    pub name: String,
    /// Its unit; `None`: the schema's SI unit (a TDMS channel's `unit_string` when it has
    /// one).
    pub unit: Option<ChannelUnit>,
    /// The channel's place among a line's fields (or the file's columns), from 0, when it
    /// is given by place (`column = N` in `[columns]`, N from 1) rather than by name.
    pub position: Option<usize>,
    /// Its sign is turned (`invert = true`).
    pub invert: bool,
}

/// Slowest and fastest sample rate `t_s = { sample_rate_hz = ... }` may give [Hz].
pub const SAMPLE_RATE_RANGE_HZ: (f64, f64) = (1.0, 10e6);

/// The mapping from the schema's columns to a log's channels (the parameter file's
/// `[columns]` table; see the module documentation). The default maps nothing: every
/// column by its schema name, in SI units.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ColumnMapping {
    channels: [Option<MappedChannel>; Column::COUNT],
    pole_pairs: u32,
    /// The rows are samples at this rate [Hz]: the log has no time column
    /// (`t_s = { sample_rate_hz = ... }`).
    sample_rate_hz: Option<f64>,
}

impl ColumnMapping {
    /// An empty mapping for a machine of `pole_pairs` pole pairs (needed by
    /// [`ChannelUnit::ElectricalHz`]).
    pub fn new(pole_pairs: u32) -> Self {
        ColumnMapping {
            channels: Default::default(),
            pole_pairs,
            sample_rate_hz: None,
        }
    }

    /// Maps schema column `c` to the log's field at `position` (from 0) of every line, for
    /// a file without a header row (or whose header names are not to be used), recorded in
    /// `unit`. Messages name the channel `column N` (N = `position + 1`).
    ///
    /// # Errors
    /// As [`ColumnMapping::set`] (two columns at one place among them).
    pub fn set_position(
        &mut self,
        c: Column,
        position: usize,
        unit: Option<ChannelUnit>,
    ) -> Result<(), ColumnsError> {
        self.set(c, &format!("column {}", position + 1), unit)?;
        if let Some(m) = self.channels[c as usize].as_mut() {
            m.position = Some(position);
        }
        Ok(())
    }

    /// The log has no time column: its rows are samples at `rate_hz` [Hz] (the first row
    /// at `t_s = 0`). Replaces a mapping of the time column.
    ///
    /// # Errors
    /// A one-line message for a rate that is not finite or lies outside
    /// [`SAMPLE_RATE_RANGE_HZ`].
    pub fn set_sample_rate(&mut self, rate_hz: f64) -> Result<(), ColumnsError> {
        let (lo, hi) = SAMPLE_RATE_RANGE_HZ;
        if !(rate_hz.is_finite() && (lo..=hi).contains(&rate_hz)) {
            return Err(ColumnsError::SampleRate { rate_hz });
        }
        self.channels[Column::Time as usize] = None;
        self.sample_rate_hz = Some(rate_hz);
        Ok(())
    }

    /// The sample rate of a log without a time column ([`ColumnMapping::set_sample_rate`]).
    pub fn sample_rate_hz(&self) -> Option<f64> {
        self.sample_rate_hz
    }

    /// The place of column `c` among a line's fields (from 0), when it is mapped by place.
    pub fn position_of(&self, c: Column) -> Option<usize> {
        self.get(c).and_then(|m| m.position)
    }

    /// True when some column is mapped by its place ([`ColumnMapping::set_position`]): a
    /// CSV whose first line holds numbers is then read as a file without a header row.
    pub fn by_position(&self) -> bool {
        self.channels.iter().flatten().any(|m| m.position.is_some())
    }

    /// Maps schema column `c` to the log's channel `name`, recorded in `unit`.
    ///
    /// # Errors
    /// A one-line message for an empty name, a unit column `c` cannot be recorded in, or a
    /// channel already mapped to another column.
    pub fn set(
        &mut self,
        c: Column,
        name: &str,
        unit: Option<ChannelUnit>,
    ) -> Result<(), ColumnsError> {
        if name.trim().is_empty() {
            return Err(ColumnsError::EmptyName(c));
        }
        if let Some(u) = unit {
            if !ChannelUnit::allowed(c).contains(&u) {
                return Err(ColumnsError::Key {
                    key: c.name().to_string(),
                    source: Box::new(ColumnsError::Unit {
                        column: c,
                        text: u.name().to_string(),
                    }),
                });
            }
        }
        if let Some(other) = Column::ALL
            .iter()
            .find(|o| **o != c && self.name_of(**o) == name && self.get(**o).is_some())
        {
            return Err(ColumnsError::SameChannel {
                first: *other,
                second: c,
                name: name.to_string(),
            });
        }
        self.channels[c as usize] = Some(MappedChannel {
            name: name.to_string(),
            unit,
            position: None,
            invert: false,
        });
        Ok(())
    }

    /// The mapping of column `c`, if any.
    pub fn get(&self, c: Column) -> Option<&MappedChannel> {
        self.channels[c as usize].as_ref()
    }

    /// True when nothing is mapped.
    pub fn is_empty(&self) -> bool {
        self.channels.iter().all(Option::is_none) && self.sample_rate_hz.is_none()
    }

    /// The name column `c` has in the log: the mapped name, else the schema's.
    pub fn name_of(&self, c: Column) -> &str {
        self.get(c).map_or(c.name(), |m| m.name.as_str())
    }

    /// The unit given for column `c`, if any.
    pub fn unit_of(&self, c: Column) -> Option<ChannelUnit> {
        self.get(c).and_then(|m| m.unit)
    }

    /// The machine's pole pairs.
    pub fn pole_pairs(&self) -> u32 {
        self.pole_pairs
    }

    /// Turns the sign of column `c`'s channel (`invert = true`), mapping it by its schema
    /// name where nothing maps it yet.
    ///
    /// # Errors
    /// As [`ColumnMapping::set`]; the time column's sign cannot be turned.
    pub fn set_invert(&mut self, c: Column) -> Result<(), ColumnsError> {
        if c == Column::Time {
            return Err(ColumnsError::InvertTime);
        }
        if self.get(c).is_none() {
            self.set(c, c.name(), None)?;
        }
        if let Some(m) = self.channels[c as usize].as_mut() {
            m.invert = true;
        }
        Ok(())
    }

    /// Whether column `c`'s sign is turned.
    pub fn inverted(&self, c: Column) -> bool {
        self.get(c).is_some_and(|m| m.invert)
    }

    /// The factors to SI of every column (in [`Column::ALL`] order) for the `units` the
    /// channels are recorded in (`None`: SI), negative for a column whose sign is turned.
    pub(super) fn factors(
        &self,
        units: &[Option<ChannelUnit>; Column::COUNT],
    ) -> [f64; Column::COUNT] {
        let mut f = units.map(|u| u.map_or(1.0, |u| u.factor(self.pole_pairs)));
        for (k, c) in Column::ALL.iter().enumerate() {
            if self.inverted(*c) {
                f[k] = -f[k];
            }
        }
        f
    }
}

/// The unit column `c` of the log shown as `shown` is read in: the one `[columns]` gives
/// (`declared`), checked against the one the file records for channel `channel` (a TDMS
/// `unit_string`, a Parquet timestamp's unit), else the recorded one, else `None` (SI).
///
/// # Errors
/// [`LogError::Unit`] naming the channel and both units when they differ, or naming a
/// recorded unit this reader does not know when `[columns]` gives none.
pub(super) fn resolve_unit(
    shown: &str,
    c: Column,
    channel: &str,
    declared: Option<ChannelUnit>,
    recorded: Option<&str>,
) -> Result<Option<ChannelUnit>, LogError> {
    let Some(text) = recorded.map(str::trim).filter(|t| !t.is_empty()) else {
        return Ok(declared);
    };
    let err = |why: String| LogError::Unit {
        path: shown.to_string(),
        channel: channel.to_string(),
        why,
    };
    match (ChannelUnit::parse(c, text), declared) {
        // `timestamp` takes a typed timestamp column in the unit the file records.
        (Ok(r), Some(ChannelUnit::Timestamp)) if r.time_kind() == TimeKind::Epoch => Ok(Some(r)),
        (Ok(r), Some(d)) if r != d => Err(err(format!(
            "is recorded in '{text}' but the parameter file's [columns] gives {} in '{}'",
            c.name(),
            d.name()
        ))),
        (Ok(r), _) => Ok(Some(r)),
        (Err(_), Some(d)) => Ok(Some(d)),
        (Err(why), None) => Err(err(format!(
            "is recorded in '{text}': {why}; give its unit in the parameter file's [columns] table: {} = {{ name = \"{channel}\", unit = \"...\" }} (docs/design.md)",
            c.name()
        ))),
    }
}

impl ColumnMapping {
    /// The mapping of a `[columns]` table for a machine of `pole_pairs` pole pairs.
    ///
    /// # Errors
    /// A one-line message naming the key: not a schema column (the message lists them), a
    /// unit the column cannot be recorded in, an empty name, two columns naming one
    /// channel.
    pub fn from_table(table: &ColumnsTable, pole_pairs: u32) -> Result<Self, ColumnsError> {
        let mut m = ColumnMapping::new(pole_pairs);
        for (key, e) in table {
            let Some(c) = Column::ALL.iter().find(|c| c.name() == key.as_str()) else {
                return Err(ColumnsError::NotAColumn(key.clone()));
            };
            if let Some(rate) = e.sample_rate_hz {
                if *c != Column::Time {
                    return Err(ColumnsError::RateNotForTime(key.clone()));
                }
                if e.name.is_some() || e.column.is_some() || e.unit.is_some() {
                    return Err(ColumnsError::RateAndTimeColumn(key.clone()));
                }
                m.set_sample_rate(rate)?;
                continue;
            }
            let unit = e
                .unit
                .as_deref()
                .map(|u| {
                    ChannelUnit::parse(*c, u).map_err(|why| ColumnsError::Key {
                        key: key.clone(),
                        source: Box::new(why),
                    })
                })
                .transpose()?;
            match (&e.name, e.column) {
                (Some(name), None) => m.set(*c, name, unit)?,
                (None, Some(n)) if n >= 1 => m.set_position(*c, n as usize - 1, unit)?,
                (None, Some(_)) => return Err(ColumnsError::ColumnZero(key.clone())),
                (Some(_), Some(_)) => return Err(ColumnsError::NameAndColumn(key.clone())),
                (None, None) if e.invert.is_some() => m.set(*c, c.name(), unit)?,
                (None, None) => {
                    return Err(ColumnsError::NoChannel {
                        key: key.clone(),
                        time: *c == Column::Time,
                    })
                }
            }
        }
        m.invert_from(table)?;
        // A column left out keeps its schema name: no mapped column may take it.
        for (i, a) in Column::ALL.iter().enumerate() {
            if let Some(b) = Column::ALL[i + 1..]
                .iter()
                .find(|b| m.name_of(**b) == m.name_of(*a))
            {
                return Err(ColumnsError::SameChannel {
                    first: *a,
                    second: *b,
                    name: m.name_of(*a).to_string(),
                });
            }
        }
        Ok(m)
    }
}

impl ColumnMapping {
    /// Turns the signs the `[columns]` table's `invert = true` entries ask for.
    fn invert_from(&mut self, table: &ColumnsTable) -> Result<(), ColumnsError> {
        for (key, e) in table {
            let c = Column::ALL.iter().find(|c| c.name() == key.as_str());
            if let (Some(c), Some(true)) = (c, e.invert) {
                self.set_invert(*c).map_err(|why| ColumnsError::Key {
                    key: key.clone(),
                    source: Box::new(why),
                })?;
            }
        }
        Ok(())
    }
}

/// Reads and checks the parameter file `path` and the mapping of its `[columns]` table
/// (the machine's pole pairs for `Hz_el`): what a command that reads a log loads.
///
/// # Errors
/// As [`ParamFile::load_with_columns`]; [`ParamError::Columns`] naming the `[columns]` key
/// that is wrong ([`ColumnMapping::from_table`]).
pub fn load_params(path: &std::path::Path) -> Result<(ParamFile, ColumnMapping), ParamError> {
    let (p, table) = ParamFile::load_with_columns(path)?;
    let columns =
        ColumnMapping::from_table(&table, p.motor.poles / 2).map_err(|e| ParamError::Columns {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
    Ok((p, columns))
}

#[cfg(test)]
mod tests;
