//! What can go wrong in setting up or running a replay ([`ReplayError`]), in the library's
//! names (a front end's own words for the fields are the door's, `monitor_words`).

use crate::fields::OptionError;
use crate::lamps::commission::NotLearned;
use monitor_core::ConfigError;
use monitor_io::log::LogError;

/// Errors from setting up or running a replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The core rejected the configuration built from the parameter file and the log.
    #[error("cannot configure the monitor: {source} (sample rate {sample_rate_hz:.1} Hz)")]
    Config {
        /// The field and what it must satisfy.
        source: ConfigError,
        /// The log's sample rate.
        sample_rate_hz: f64,
    },
    /// An option the replay does not take, naming its field.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The log holds no row to replay.
    #[error("{log}: no rows to replay")]
    NoRows {
        /// How messages name the log.
        log: String,
    },
    /// The commissioning window was not learned (and `allow_incomplete` was not asked).
    #[error("commission = {}: the window was not learned", not_learned.window)]
    IncompleteCommissioning {
        /// The window asked for and why it was not learned.
        not_learned: NotLearned,
        /// What the data-quality stage does not trust, often why nothing was learned
        /// (swapped channels, a dead sensor): its words.
        data_quality: Vec<String>,
    },
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] LogError),
}
