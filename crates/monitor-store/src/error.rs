//! The store's errors, below the store and its mirror, which both return them.

/// Errors of the store.
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    /// SQLite failed (the store cannot be opened, is not a store, or a write failed).
    #[error("store {path}: {message}")]
    Sqlite {
        /// The store's file.
        path: String,
        /// SQLite's message.
        message: String,
    },
    /// The Parquet mirror cannot be written.
    #[error("Parquet mirror {path}: {message}")]
    Mirror {
        /// The file or folder.
        path: String,
        /// What failed.
        message: String,
    },
    /// The store (or the folder it is to be made in) cannot be written: SQLite's own word
    /// for it is "unable to open database file".
    #[error("permission denied: cannot write the store {path} ({why})")]
    Permission {
        /// The store's file.
        path: String,
        /// Which of the file and its folder is not writable.
        why: String,
    },
    /// Reading a store that does not exist.
    #[error("no store at {0} (a fleet run writes one where it is given a store)")]
    Missing(String),
}
