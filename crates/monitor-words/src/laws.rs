//! The words of a user's laws: an effect name the library and the law file do not have.

use crate::Spelling;

/// `effect 'load_torq' is not in the library (did you mean 'load_torque'?); known: ...`:
/// the name `name` given, the names spelled alike `near`, every known name `known`, and
/// whether a law file was given (`laws`: then its laws are among the names).
pub fn unknown_effect(
    name: &str,
    near: &[String],
    known: &[String],
    laws: bool,
    _spell: &dyn Spelling,
) -> String {
    let whose = if laws {
        "in the library or the law file"
    } else {
        "in the library (a law of your own: give its file with the laws option)"
    };
    let meant = match near {
        [] => String::new(),
        [a] => format!("; did you mean '{a}'?"),
        more => format!(
            "; did you mean one of {}?",
            more.iter()
                .map(|n| format!("'{n}'"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    format!(
        "effect '{name}' is not {whose}{meant} (known: {})",
        known.join(", ")
    )
}
