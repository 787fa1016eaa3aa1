//! The log a command reads: a file (CSV, TDMS or Parquet, by extension) or data held in
//! memory ([`MemoryLog`]: the Python package's DataFrames, Arrow tables and dicts), both
//! read through the same path ([`LogFile::open_with`], [`LogFile::from_memory`]).

use monitor_io::log::{LogError, LogFile, MemoryLog, OpenOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A log: a file, or data held in memory with the name messages give it.
#[derive(Debug, Clone)]
pub enum LogSource {
    /// A log file (or, as a `--baseline`, a folder of them).
    File(PathBuf),
    /// Columns in memory.
    Data {
        /// The columns.
        log: Arc<MemoryLog>,
        /// How messages name the data ("DataFrame", "pyarrow Table", "dict").
        origin: String,
    },
}

impl LogSource {
    /// Data in memory, named `origin` in messages.
    pub fn data(log: MemoryLog, origin: impl Into<String>) -> Self {
        LogSource::Data {
            log: Arc::new(log),
            origin: origin.into(),
        }
    }

    /// The log as messages name it: the path, or the data's origin.
    pub fn shown(&self) -> String {
        match self {
            LogSource::File(p) => p.display().to_string(),
            LogSource::Data { origin, .. } => origin.clone(),
        }
    }

    /// The file's path (`None` for data in memory).
    pub fn path(&self) -> Option<&Path> {
        match self {
            LogSource::File(p) => Some(p),
            LogSource::Data { .. } => None,
        }
    }

    /// Opens the log with `opts` (the `[columns]` mapping, the TDMS group).
    ///
    /// # Errors
    /// As [`LogFile::open_with`] and [`LogFile::from_memory`].
    pub fn open(&self, opts: &OpenOptions) -> Result<LogFile, LogError> {
        match self {
            LogSource::File(p) => LogFile::open_with(p, opts),
            LogSource::Data { log, origin } => LogFile::from_memory(Arc::clone(log), origin, opts),
        }
    }
}

impl From<PathBuf> for LogSource {
    fn from(p: PathBuf) -> Self {
        LogSource::File(p)
    }
}

impl From<&Path> for LogSource {
    fn from(p: &Path) -> Self {
        LogSource::File(p.to_path_buf())
    }
}

impl From<&PathBuf> for LogSource {
    fn from(p: &PathBuf) -> Self {
        LogSource::File(p.clone())
    }
}

impl From<&LogSource> for LogSource {
    fn from(l: &LogSource) -> Self {
        l.clone()
    }
}
