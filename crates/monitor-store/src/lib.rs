//! A motor's history: every judged log stored per motor and time, and the trend of its
//! indicators with an alarm on the trend (docs/trend.md).
//!
//! - [`Store`]: an SQLite database (`PATH`), the source of truth, one transaction per
//!   log, a log never stored twice (the `log_id` column is unique), and its mirror, a
//!   Parquet dataset partitioned by motor and day (`PATH.parquet/`) that pandas, pyarrow
//!   and Dask read.
//! - [`StoredRow`]: one log's row ([`COLUMNS`]), taken from `diagnose --json`'s document
//!   ([`StoredRow::from_diagnose`]): nothing is analysed again.
//! - [`one_day_of_modified_times`]: the warning for a motor whose stored logs all took their
//!   files' modification times on one day (`time_source`).
//! - [`trend`]: per motor and indicator, Theil-Sen's slope with Sen's interval, against the
//!   indicator's own scatter, at like operating points; the alarm and the days to FAULT.

mod error;
pub mod mirror;
pub mod row;
mod store;
pub mod trend;

pub use error::HistoryError;
pub use row::{
    content_hash, parse_day, utc_day, Cell, Kind, LogIdentity, StoreColumn, StoredRow, COLUMNS,
};
pub use store::{one_day_of_modified_times, Appended, Store};
pub use trend::{MotorTrend, TrendOptions};
