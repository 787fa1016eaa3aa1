//! The library's errors in a front end's words: an option named by its flag or keyword.

use crate::spelling::Spelling;
use monitor_replay::{OptionError, OptionField, ReplayError};

/// An option's refusal in a front end's words (`--commission 4:2: why`).
pub fn option_error(e: &OptionError, sp: &dyn Spelling) -> String {
    format!("{}: {}", sp.option(e.field, &e.value), e.why)
}

/// A replay's error in a front end's words: an option named by its flag or keyword, the
/// commissioning window that was not learned with why and what to give instead.
pub fn replay_error(e: &ReplayError, sp: &dyn Spelling) -> String {
    match e {
        ReplayError::Option(e) => option_error(e, sp),
        ReplayError::IncompleteCommissioning {
            not_learned,
            data_quality,
        } => {
            let mut why = crate::diagnose::not_learned_why(&not_learned.why);
            if !data_quality.is_empty() {
                why = format!("{why}; data quality: {}", data_quality.join("; "));
            }
            format!(
                "{}: {why}: give a window inside the log's healthy running, or {} to report with the fixed thresholds",
                sp.option(OptionField::Commission, &not_learned.window.to_string()),
                sp.option(OptionField::AllowIncomplete, "")
            )
        }
        e => e.to_string(),
    }
}
