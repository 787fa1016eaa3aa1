//! `identify`'s words, spelled from [`monitor_analysis::identify`]'s typed values: why an
//! identification is not written.

use crate::Spelling;
use monitor_analysis::identify::{IdentifyError, IdentifyRefusal, SupplyFromLog};
use monitor_replay::OptionField;

/// Why the identification could not run on a log: the error's own message, except where it
/// names the analysed window's fields, which are spelled in the front end's words (`sp`:
/// `--from`/`--to` on the command line, `from_s`/`to_s` in Python).
pub fn failed(e: &IdentifyError, sp: &dyn Spelling) -> String {
    match *e {
        IdentifyError::Irregular {
            at_s,
            interval_s,
            dt_s,
        } => format!(
            "the samples are not regular at t = {at_s} s (an interval of {interval_s:.3e} s where the rate gives {dt_s:.3e} s): give a window without gaps ({}/{})",
            sp.option(OptionField::From, ""),
            sp.option(OptionField::To, "")
        ),
        ref other => other.to_string(),
    }
}

/// Why the identification is not written, naming the likely cause (`sp` names the window's
/// start as the front end does).
pub fn refusal(r: &IdentifyRefusal, sp: &dyn Spelling) -> String {
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
            "the fit leaves a current error of {:.1} % of its RMS (solver {termination}; a good log leaves under 1 %): the model does not fit this log: check the [columns] mapping and units, give {} to leave out what the model cannot follow, or start from a parameter file of this machine",
            100.0 * error,
            sp.option(OptionField::From, "")
        ),
        IdentifyRefusal::NotAMachine { key, message } => format!(
            "an identified value is not one of a real machine ({key}: {message}): a unit or a mapping is likely wrong"
        ),
    }
}

/// The log's supply where it differs from the start file's: what the identified file takes.
pub fn supply_from_log(l: &SupplyFromLog) -> String {
    format!(
        "the log's supply is {:.0} V {:.1} Hz, the start file's {:.0} V {:.1} Hz: the identified file takes the log's (check f_hz and v_ll_rms)",
        l.log_v_ll_rms, l.log_f_hz, l.file_v_ll_rms, l.file_f_hz
    )
}
