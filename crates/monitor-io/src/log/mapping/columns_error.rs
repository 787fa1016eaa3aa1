//! The `[columns]` table's and the column mapping's errors ([`ColumnsError`]).

use super::{ChannelUnit, SAMPLE_RATE_RANGE_HZ};
use crate::log::Column;

/// What is wrong with a `[columns]` table or a mapping call, naming the key or column (the
/// messages are one line each; [`crate::params::ParamError::Columns`] carries them with the file's name).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ColumnsError {
    /// A unit the column cannot be recorded in.
    #[error("unit '{text}' is not one {} may be recorded in ({})", .column.name(), allowed_units(*.column))]
    Unit {
        /// The schema column.
        column: Column,
        /// The unit as written.
        text: String,
    },
    /// An error of one key of the table (`key: why`).
    #[error("{key}: {source}")]
    Key {
        /// The key (a schema column's name).
        key: String,
        /// What is wrong with it.
        source: Box<ColumnsError>,
    },
    /// A channel name that is empty.
    #[error("{}: the channel name is empty", .0.name())]
    EmptyName(Column),
    /// Two schema columns name one channel of the log.
    #[error("{} and {} both name channel '{name}'", .first.name(), .second.name())]
    SameChannel {
        /// The column mapped first.
        first: Column,
        /// The other.
        second: Column,
        /// The channel both name.
        name: String,
    },
    /// A sample rate that is not finite or outside [`SAMPLE_RATE_RANGE_HZ`].
    #[error("t_s: sample_rate_hz = {rate_hz} is not a sample rate ({lo}..{hi:e} Hz)", lo = SAMPLE_RATE_RANGE_HZ.0, hi = SAMPLE_RATE_RANGE_HZ.1)]
    SampleRate {
        /// The rate given [Hz].
        rate_hz: f64,
    },
    /// A key that is no schema column.
    #[error("'{0}' is not a column of the schema (the keys are {keys})", keys = schema_keys())]
    NotAColumn(String),
    /// `sample_rate_hz` given to a column other than `t_s`.
    #[error("{0}: sample_rate_hz belongs to t_s (a log without a time column: t_s = {{ sample_rate_hz = 1000.0 }})")]
    RateNotForTime(String),
    /// `sample_rate_hz` and a time column both given.
    #[error("{0}: sample_rate_hz says the log has no time column; give either it or the time column (name or column, with its unit), not both")]
    RateAndTimeColumn(String),
    /// `invert` given to the time column.
    #[error("t_s: invert = true turns a channel's sign; the time's cannot be turned")]
    InvertTime,
    /// `column = 0`.
    #[error("{0}: column = 0; the fields of a line are counted from 1")]
    ColumnZero(String),
    /// Both a name and a place.
    #[error("{0}: give the channel by name or by column, not both")]
    NameAndColumn(String),
    /// Neither a name nor a place (nor, for the time, a sample rate).
    #[error("{key}: give the channel's name (name = \"Ia\") or its place in a line (column = 1){}", if *.time { ", or sample_rate_hz = ... for a log without a time column" } else { "" })]
    NoChannel {
        /// The key.
        key: String,
        /// It is the time column's.
        time: bool,
    },
}

/// The units column `c` may be recorded in, by name, comma-separated.
fn allowed_units(c: Column) -> String {
    ChannelUnit::allowed(c)
        .iter()
        .map(|u| u.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The schema's column names, comma-separated.
fn schema_keys() -> String {
    Column::ALL
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
}
