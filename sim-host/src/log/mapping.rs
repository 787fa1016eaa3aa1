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
//!   `epoch_us`, `epoch_ns` (seconds ... nanoseconds since 1970-01-01) or `iso8601` (text
//!   such as `2024-05-01T12:00:00.125Z`, CSV only). A timestamp's time counts from the
//!   log's first row: `t_s = 0` there.
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

pub use super::columns_error::ColumnsError;
use super::{Column, LogError};
use crate::params::{ColumnsTable, ParamError, ParamFile};

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
    /// ISO 8601 date and time text (`YYYY-MM-DDTHH:MM:SS[.f][Z|+HH:MM]`).
    Iso8601,
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
}

impl ChannelUnit {
    /// Every unit with its spellings (the first is the one written in messages).
    const SPELLINGS: [(ChannelUnit, &'static [&'static str]); 20] = [
        (ChannelUnit::Seconds, &["s", "sec", "Seconds"]),
        (ChannelUnit::Milliseconds, &["ms"]),
        (ChannelUnit::Microseconds, &["us", "µs"]),
        (ChannelUnit::EpochSeconds, &["epoch_s"]),
        (ChannelUnit::EpochMilliseconds, &["epoch_ms"]),
        (ChannelUnit::EpochMicroseconds, &["epoch_us"]),
        (ChannelUnit::EpochNanoseconds, &["epoch_ns"]),
        (ChannelUnit::Iso8601, &["iso8601"]),
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

    /// The factors to SI of every column (in [`Column::ALL`] order) for the `units` the
    /// channels are recorded in (`None`: SI).
    pub(super) fn factors(
        &self,
        units: &[Option<ChannelUnit>; Column::COUNT],
    ) -> [f64; Column::COUNT] {
        units.map(|u| u.map_or(1.0, |u| u.factor(self.pole_pairs)))
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
                (None, None) => {
                    return Err(ColumnsError::NoChannel {
                        key: key.clone(),
                        time: *c == Column::Time,
                    })
                }
            }
        }
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

/// Levenshtein distance between two short strings (characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Lower case, letters and digits only ("Ia [A]" -> "iaa", "ia_A" -> "iaa").
fn folded(s: &str) -> String {
    s.chars()
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect()
}

/// The names a channel of column `c` is commonly given (folded), besides the schema's.
fn usual_names(c: Column) -> &'static [&'static str] {
    match c {
        Column::Time => &["t", "ts", "time", "timestamp", "times"],
        Column::Va => &["va", "ua", "vas", "v1", "u1"],
        Column::Vb => &["vb", "ub", "vbs", "v2", "u2"],
        Column::Vc => &["vc", "uc", "vcs", "v3", "u3"],
        Column::Ia => &["ia", "ias", "i1", "ila", "currenta"],
        Column::Ib => &["ib", "ibs", "i2", "ilb", "currentb"],
        Column::Ic => &["ic", "ics", "i3", "ilc", "currentc"],
        Column::Speed => &["wm", "w", "speed", "n", "rpm", "omega", "wr", "speedrpm"],
        Column::Encoder => &["enc", "encoder", "count", "counts", "position"],
        Column::Temperature => &["temp", "temperature", "twinding", "tstator", "theta"],
    }
}

/// The channel of `found` closest to the name `wanted` of column `c`: the same name in
/// another case, else the smallest edit distance (a third of the channel's name, 1 to 3)
/// to the wanted name or one of the column's usual names, letters and digits only.
pub fn closest<'a>(c: Column, wanted: &str, found: &'a [String]) -> Option<&'a str> {
    if let Some(f) = found.iter().find(|f| f.eq_ignore_ascii_case(wanted)) {
        return Some(f);
    }
    let mut targets = vec![folded(wanted), folded(c.name())];
    targets.extend(usual_names(c).iter().map(|s| s.to_string()));
    found
        .iter()
        .filter_map(|f| {
            let ff = folded(f);
            let d = targets.iter().map(|t| edit_distance(&ff, t)).min()?;
            let limit = (ff.chars().count() / 3).clamp(1, 3);
            (d <= limit && !ff.is_empty()).then_some((d, f))
        })
        .min_by_key(|(d, _)| *d)
        .map(|(_, f)| f.as_str())
}

/// The channels of a log as a list for a message (at most 24 names, then how many more).
pub fn channel_list(found: &[String]) -> String {
    if found.is_empty() {
        return "no channels".to_string();
    }
    let s: Vec<&str> = found.iter().take(24).map(String::as_str).collect();
    match found.len().saturating_sub(24) {
        0 => s.join(", "),
        more => format!("{} and {more} more", s.join(", ")),
    }
}

/// The error for column `c` missing from the log shown as `shown`, whose channels are
/// `found`: it names the column (and the channel the mapping gives it), lists the channels
/// found, suggests the closest ([`closest`]) and points to the `[columns]` table.
pub(super) fn missing_column(
    shown: &str,
    c: Column,
    mapping: &ColumnMapping,
    found: &[String],
    why: &str,
) -> LogError {
    let wanted = mapping.name_of(c);
    let mapped = match mapping.get(c) {
        Some(_) => format!(" (for {} in [columns])", c.name()),
        None => String::new(),
    };
    // Channels another column already reads are no candidates.
    let free: Vec<String> = found
        .iter()
        .filter(|f| {
            Column::ALL
                .iter()
                .all(|o| mapping.name_of(*o) != f.as_str())
        })
        .cloned()
        .collect();
    let hint = match closest(c, wanted, &free) {
        Some(f) => format!(
            "; did you mean '{f}'? Map it in the parameter file's [columns] table: {} = {{ name = \"{f}\", unit = \"...\" }} (docs/design.md)",
            c.name()
        ),
        None => "; map the log's channel in the parameter file's [columns] table (docs/design.md)"
            .to_string(),
    };
    missing_column_with(shown, wanted, &format!("{mapped} ({why})"), found, &hint)
}

/// [`LogError::MissingColumn`] for the log's column `column`, with `why` (" (...)" or "")
/// after its name, the channels `found`, and `hint` ("; ...") at the end.
pub(super) fn missing_column_with(
    shown: &str,
    column: &str,
    why: &str,
    found: &[String],
    hint: &str,
) -> LogError {
    LogError::MissingColumn {
        path: shown.to_string(),
        column: column.to_string(),
        detail: format!("{why}; the log has {}{hint}", channel_list(found)),
    }
}

/// Parses ISO 8601 date and time text, `YYYY-MM-DD` then `T` or a space, `HH:MM:SS`, an
/// optional fraction (`.` or `,`), an optional zone (`Z`, `+HH:MM`, `-HHMM`), into whole
/// seconds since 1970-01-01 UTC and the fraction of a second (exact to the digits given).
/// `None` for anything else.
pub(super) fn parse_iso8601(s: &str) -> Option<(i64, f64)> {
    let b = s.trim().as_bytes();
    let num = |r: std::ops::Range<usize>| -> Option<i64> {
        let t = b.get(r)?;
        if t.is_empty() || !t.iter().all(u8::is_ascii_digit) {
            return None;
        }
        std::str::from_utf8(t).ok()?.parse().ok()
    };
    let (y, mo, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    if b.get(4) != Some(&b'-')
        || b.get(7) != Some(&b'-')
        || !matches!(b.get(10), Some(b'T' | b't' | b' '))
    {
        return None;
    }
    let (h, mi, sec) = (num(11..13)?, num(14..16)?, num(17..19)?);
    if b.get(13) != Some(&b':') || b.get(16) != Some(&b':') {
        return None;
    }
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) || h > 23 || mi > 59 || sec > 60 {
        return None;
    }
    let mut i = 19;
    let mut frac = 0.0;
    if matches!(b.get(i), Some(b'.' | b',')) {
        let start = i + 1;
        i = start;
        while b.get(i).is_some_and(u8::is_ascii_digit) {
            i += 1;
        }
        if i == start {
            return None;
        }
        frac = format!("0.{}", std::str::from_utf8(&b[start..i]).ok()?)
            .parse()
            .ok()?;
    }
    let offset_s = match b.get(i) {
        None => 0,
        Some(b'Z' | b'z') if i + 1 == b.len() => 0,
        Some(&sign @ (b'+' | b'-')) => {
            let rest = &b[i + 1..];
            let (oh, om) = match rest.len() {
                5 if rest[2] == b':' => (num(i + 1..i + 3)?, num(i + 4..i + 6)?),
                4 => (num(i + 1..i + 3)?, num(i + 3..i + 5)?),
                2 => (num(i + 1..i + 3)?, 0),
                _ => return None,
            };
            let o = oh * 3600 + om * 60;
            if sign == b'+' {
                o
            } else {
                -o
            }
        }
        _ => return None,
    };
    // Days from the civil date (Howard Hinnant's algorithm, proleptic Gregorian).
    let (yy, m) = if mo <= 2 {
        (y - 1, mo + 9)
    } else {
        (y, mo - 3)
    };
    let era = yy.div_euclid(400);
    let yoe = yy - era * 400;
    let doy = (153 * m + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some((days * 86_400 + h * 3600 + mi * 60 + sec - offset_s, frac))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_and_factors() {
        assert_eq!(
            ChannelUnit::parse(Column::Time, "ms"),
            Ok(ChannelUnit::Milliseconds)
        );
        assert_eq!(
            ChannelUnit::parse(Column::Time, "µs"),
            Ok(ChannelUnit::Microseconds)
        );
        assert_eq!(
            ChannelUnit::parse(Column::Time, "us"),
            Ok(ChannelUnit::Microseconds)
        );
        assert_eq!(
            ChannelUnit::parse(Column::Ia, "mA"),
            Ok(ChannelUnit::Milliamperes)
        );
        let e = ChannelUnit::parse(Column::Ia, "mV")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("'mV'") && e.contains("ia_A") && e.contains("A, mA"),
            "{e}"
        );
        assert!(ChannelUnit::parse(Column::Speed, "Hz").is_err());
        assert_eq!(
            ChannelUnit::Rpm.factor(2) * 1500.0,
            1500.0 * std::f64::consts::TAU / 60.0
        );
        // 50 Hz electrical on a 4-pole machine: 25 rev/s, 157.08 rad/s.
        assert!((ChannelUnit::ElectricalHz.factor(2) * 50.0 - 157.079_632_7).abs() < 1e-6);
        assert_eq!(ChannelUnit::Kilovolts.factor(2), 1000.0);
    }

    #[test]
    fn a_channel_maps_to_one_column() {
        let mut m = ColumnMapping::new(2);
        m.set(Column::Ia, "I", None).unwrap();
        let e = m.set(Column::Ib, "I", None).unwrap_err();
        assert_eq!(
            e,
            ColumnsError::SameChannel {
                first: Column::Ia,
                second: Column::Ib,
                name: "I".into()
            }
        );
        assert!(
            e.to_string()
                .contains("ia_A and ib_A both name channel 'I'"),
            "{e}"
        );
        let e = m
            .set(Column::Va, "U1", Some(ChannelUnit::Amperes))
            .unwrap_err()
            .to_string();
        assert!(e.contains("va_V") && e.contains("'A'"), "{e}");
    }

    #[test]
    fn a_table_of_the_parameter_file() {
        let entry = |name: &str, unit: Option<&str>| crate::params::ColumnEntry {
            name: Some(name.into()),
            unit: unit.map(Into::into),
            ..Default::default()
        };
        let mut t = ColumnsTable::new();
        t.insert("wm_rad_s".into(), entry("n", Some("Hz_el")));
        t.insert("ia_A".into(), entry("ib_A", None));
        let e = ColumnMapping::from_table(&t, 2).unwrap_err().to_string();
        assert!(e.contains("ia_A and ib_A both name channel 'ib_A'"), "{e}");
        // A swap of two phases is fine.
        t.insert("ib_A".into(), entry("ia_A", None));
        let m = ColumnMapping::from_table(&t, 2).unwrap();
        assert_eq!(m.name_of(Column::Ib), "ia_A");
        assert_eq!(m.unit_of(Column::Speed), Some(ChannelUnit::ElectricalHz));
        assert_eq!(m.name_of(Column::Time), "t_s");
    }

    #[test]
    fn the_closest_channel() {
        let found: Vec<String> = ["t", "Ia", "Ib", "Ic", "Va", "Vb", "Vc", "speed_rpm"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(closest(Column::Ia, "ia_A", &found), Some("Ia"));
        assert_eq!(closest(Column::Ic, "ic_A", &found), Some("Ic"));
        assert_eq!(closest(Column::Time, "t_s", &found), Some("t"));
        assert_eq!(
            closest(Column::Speed, "wm_rad_s", &found),
            Some("speed_rpm")
        );
        assert_eq!(closest(Column::Encoder, "enc_count", &found), None);
        let other: Vec<String> = vec!["Time".into(), "Strom 1".into()];
        assert_eq!(closest(Column::Time, "t_s", &other), Some("Time"));
    }

    #[test]
    fn iso8601_text() {
        assert_eq!(parse_iso8601("1970-01-01T00:00:00Z"), Some((0, 0.0)));
        assert_eq!(
            parse_iso8601("2000-03-01 00:00:01.25"),
            Some((951_868_801, 0.25))
        );
        assert_eq!(
            parse_iso8601("2024-05-01T12:00:00.125+02:00"),
            Some((1_714_557_600, 0.125))
        );
        assert_eq!(
            parse_iso8601("2024-05-01T10:00:00Z").map(|x| x.0),
            Some(1_714_557_600)
        );
        for bad in [
            "2024-05-01",
            "2024-13-01T00:00:00",
            "12:00:00",
            "2024-05-01T10:00:00Q",
            "x",
        ] {
            assert_eq!(parse_iso8601(bad), None, "{bad}");
        }
    }
}
