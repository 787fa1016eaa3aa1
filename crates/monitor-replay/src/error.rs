//! What can go wrong in setting up or running a replay ([`ReplayError`]), in the library's
//! words and, through [`ReplayError::spelled`], in a front end's.

use crate::words::{FieldNames, OptionError, OptionField, Spelling};
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
    #[error("{}", self.spelled(&FieldNames))]
    IncompleteCommissioning {
        /// The window asked for (`START:END`).
        window: String,
        /// What happened.
        why: String,
    },
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] LogError),
}

impl ReplayError {
    /// The message in a front end's words (`spell` names the options it refers to).
    pub fn spelled(&self, spell: &dyn Spelling) -> String {
        match self {
            ReplayError::Option(e) => e.spelled(spell),
            ReplayError::IncompleteCommissioning { window, why } => format!(
                "{}: {why}: give a window inside the log's healthy running, or {} to report with the fixed thresholds",
                spell.option(OptionField::Commission, window),
                spell.option(OptionField::AllowIncomplete, "")
            ),
            e => e.to_string(),
        }
    }
}
