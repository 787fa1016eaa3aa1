//! The drive monitor's inputs, the lowest host library: everything that reads or writes a
//! file the user owns.
//!
//! - [`params`]: the parameter file (TOML), and the sensor ranges derived from it;
//! - [`log`]: measurement logs (CSV, TDMS, Parquet; the one reader and writer, the DAQ's own
//!   column names and units through `[columns]`, the data-quality stage, the sample-rate
//!   estimate);
//! - [`nameplate`]: a parameter file estimated from a motor's nameplate
//!   (`params from-nameplate`).
//!
//! Inside the crate, `log` and `nameplate` use `params`, and `params` uses neither.
//! Functions return values and `thiserror` errors; rendering is the applications'.

pub mod log;
pub mod nameplate;
pub mod params;

/// Folds a multi-line message onto one line (CLI and Python errors are one line).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
