//! `identify`'s words, spelled from [`monitor_analysis::identify`]'s typed values: why an
//! identification is not written.

use monitor_analysis::identify::IdentifyRefusal;

/// Why the identification is not written, naming the likely cause.
pub fn refusal(r: &IdentifyRefusal) -> String {
    match r {
        IdentifyRefusal::CurrentOutOfRange { i_a, low_a, high_a } => {
            let above = i_a > high_a;
            let ratio = if above { i_a / high_a } else { low_a / i_a };
            let hint = match (above, ratio) {
                (true, r) if r > 30.0 => " (about a thousand times: currents in mA read as A? give ia_A, ib_A, ic_A unit = \"mA\" in the parameter file's [columns])",
                (false, r) if r > 30.0 => " (about a thousand times too small: currents in A given the unit mA in [columns]?)",
                _ => " (a unit, a current transformer's ratio, or a [columns] mapping to another channel)",
            };
            format!(
                "the log's current ({i_a:.3} A, RMS of the current vector) is {} what the parameter file's motor can draw ({low_a:.3}..{high_a:.3} A from a third of its no-load current to its locked-rotor current){hint}",
                if above { "far above" } else { "far below" }
            )
        }
        IdentifyRefusal::PoorFit { error, termination } => format!(
            "the fit leaves a current error of {:.1} % of its RMS (solver {termination}; a good log leaves under 1 %): the model does not fit this log: check the [columns] mapping and units, give from_s to leave out what the model cannot follow, or start from a parameter file of this machine",
            100.0 * error
        ),
        IdentifyRefusal::NotAMachine { key, message } => format!(
            "an identified value is not one of a real machine ({key}: {message}): a unit or a mapping is likely wrong"
        ),
    }
}
