//! The library's options and fields by name ([`OptionField`]; a front end says them in its
//! own words at the door, `monitor_words`: the command line as its flags, Python as its
//! keywords), the error that names a field ([`OptionError`]), and the one description of
//! `diagnose`'s options ([`DIAGNOSE_OPTIONS`]) that a front end which takes them by name
//! (Python) builds its signature, its stub's and its docs from.

use std::fmt;

/// An option or a request's field, by the name the library gives it (the Python keyword
/// and the fleet table's key where they have one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OptionField {
    /// The parameter file (`params`).
    Params,
    /// The commissioning window (`commission`, [`CommissionWindow`]).
    Commission,
    /// Report an incomplete commissioning (`allow_incomplete`).
    AllowIncomplete,
    /// The timeline's step (`timeline_step`, [`TimelineStep`]).
    TimelineStep,
    /// The winding's parallel paths (`parallel_paths`, [`PARALLEL_PATHS`]).
    ParallelPaths,
    /// A calibration of the shorted-turn level (`turn_calibration`).
    TurnCalibration,
    /// Healthy logs of the same motor (`baseline`).
    Baseline,
    /// What is known of the load (`load`).
    Load,
    /// The TDMS group (`group`).
    Group,
    /// The analysed window's start (`from_s`).
    From,
    /// The analysed window's end (`to_s`).
    To,
    /// Effects already in the model (`effects`).
    Effects,
    /// The parameter file whose `[columns]` a nameplate estimate carries (`columns_from`).
    ColumnsFrom,
    /// The frame's angle source (`angle`).
    Angle,
    /// The residual form the lamps act on (`residuals`).
    Residuals,
}

impl OptionField {
    /// The field's name (`commission`, `timeline_step`, ...).
    pub const fn name(self) -> &'static str {
        match self {
            OptionField::Params => "params",
            OptionField::Commission => "commission",
            OptionField::AllowIncomplete => "allow_incomplete",
            OptionField::TimelineStep => "timeline_step",
            OptionField::ParallelPaths => "parallel_paths",
            OptionField::TurnCalibration => "turn_calibration",
            OptionField::Baseline => "baseline",
            OptionField::Load => "load",
            OptionField::Group => "group",
            OptionField::From => "from_s",
            OptionField::To => "to_s",
            OptionField::Effects => "effects",
            OptionField::ColumnsFrom => "columns_from",
            OptionField::Angle => "angle",
            OptionField::Residuals => "residuals",
        }
    }
}

impl fmt::Display for OptionField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A value an option does not take: the field, the value as given, and why (`Display`:
/// `commission = 4:2: why`, the library's names; a front end names the field in its own
/// words at the door, `monitor_words`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: {why}", field_given(*field, value))]
pub struct OptionError {
    /// The option.
    pub field: OptionField,
    /// The value as given (empty where the field alone is meant).
    pub value: String,
    /// What is wrong, and what to give instead.
    pub why: String,
}

impl OptionError {
    /// `field` refused `value` because of `why`.
    pub fn new(field: OptionField, value: impl Into<String>, why: impl Into<String>) -> Self {
        OptionError {
            field,
            value: value.into(),
            why: why.into(),
        }
    }
}

/// `field = value` in the library's names, the field alone for an empty value.
pub fn field_given(field: OptionField, value: &str) -> String {
    if value.is_empty() {
        field.name().to_string()
    } else {
        format!("{} = {value}", field.name())
    }
}

/// What an option of `diagnose` takes, as a front end that names it hands it
/// ([`OptionValue`]): the kind decides how a keyword's value is read, not which option it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Takes {
    /// A window `START:END` [s], or the pair `(start_s, end_s)`.
    Window,
    /// One of these names.
    Choice(&'static [&'static str]),
    /// A number of seconds.
    Seconds,
    /// A whole number.
    Count,
    /// Yes or no.
    Flag,
    /// A file of JSON (a path), or the JSON's value itself (a dict).
    JsonFile,
}

/// One option of `diagnose` by name: the field (its name is Python's keyword; the command
/// line's flag is the name in kebab case), what it takes, its default as a front end shows
/// it, and its documentation (one paragraph). The command line writes its flag by hand,
/// beside this (a test holds the two together, `sim-host/src/cli/mod.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OptionSpec {
    /// The field.
    pub field: OptionField,
    /// What it takes.
    pub takes: Takes,
    /// Its default, in Python's words (`None`: the library's default).
    pub default: &'static str,
    /// What it does.
    pub doc: &'static str,
}

/// `diagnose`'s options that a front end sets by name (`ReplayOptions::set`), in the order
/// they are documented: the one description Python's signature, its stub and its docs come
/// from. A new option is a row here, its field and default in `ReplayOptions`, its arm in
/// `ReplayOptions::set`, the stage that reads it, and its command-line flag.
pub const DIAGNOSE_OPTIONS: &[OptionSpec] = &[
    OptionSpec {
        field: OptionField::Commission,
        takes: Takes::Window,
        default: "None",
        doc: "Learn the healthy thresholds over this window of the log [s]: (start_s, end_s) \
              or \"START:END\"; None: the fixed thresholds against the parameter file.",
    },
    OptionSpec {
        field: OptionField::AllowIncomplete,
        takes: Takes::Flag,
        default: "False",
        doc: "Report even when the commissioning window was not learned (the fixed thresholds \
              are used and the verdict is withheld).",
    },
    OptionSpec {
        field: OptionField::Load,
        takes: Takes::Choice(&["unknown", "viscous"]),
        default: "None",
        doc: "What is known of the load: \"unknown\" (the default, service: a load change is an \
              operating-point change, never a named fault) or \"viscous\" (the paper's fixed \
              viscous load: a B/Bl change is the fault b/bl).",
    },
    OptionSpec {
        field: OptionField::Angle,
        takes: Takes::Choice(&["rotor-flux", "pll", "zero-crossing"]),
        default: "None",
        doc: "The frame's angle source (default \"rotor-flux\").",
    },
    OptionSpec {
        field: OptionField::Residuals,
        takes: Takes::Choice(&["steady", "full"]),
        default: "None",
        doc: "The residual form the lamps act on (\"steady\", eq. 37, the default; or \"full\", \
              eq. 36).",
    },
    OptionSpec {
        field: OptionField::TimelineStep,
        takes: Takes::Seconds,
        default: "None",
        doc: "Timeline resolution [s] (default 0.5 s, the command line's); finite and > 0.",
    },
    OptionSpec {
        field: OptionField::ParallelPaths,
        takes: Takes::Count,
        default: "None",
        doc: "Parallel paths of each phase of the winding, 1..8 (1, the default; 2 for a double \
              star): the shorted-turn level is sized with one path's resistance.",
    },
    OptionSpec {
        field: OptionField::TurnCalibration,
        takes: Takes::JsonFile,
        default: "None",
        doc: "A calibration of the shorted-turn level learned from labelled runs of the same \
              motor (a path to the JSON of sim-host calibrate-turns, or its dict): the level is \
              read from it instead of the model.",
    },
];

/// A value a front end hands an option by name ([`OptionSpec::takes`] says which).
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// Text: a window `START:END`, a name, a JSON document.
    Text(String),
    /// A number.
    Number(f64),
    /// A whole number.
    Whole(i64),
    /// Yes or no.
    Flag(bool),
    /// A pair of numbers (a window's start and end [s]).
    Pair(f64, f64),
}

impl OptionValue {
    /// The value as a message shows it (`3:2` for a pair).
    pub fn shown(&self) -> String {
        match self {
            OptionValue::Text(s) => s.clone(),
            OptionValue::Number(x) => x.to_string(),
            OptionValue::Whole(n) => n.to_string(),
            OptionValue::Flag(b) => b.to_string(),
            OptionValue::Pair(a, b) => format!("{a}:{b}"),
        }
    }
}
