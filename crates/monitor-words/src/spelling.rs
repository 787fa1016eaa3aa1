//! How a front end names the library's fields ([`Spelling`]): the command line as its
//! flags (`--commission 2:4`), Python as its keywords (`commission='2:4'`), the library as
//! the field's name ([`FieldNames`]: `commission = 2:4`). A front end passes its spelling to
//! the function that spells; no options type carries it.

use monitor_replay::{field_given, OptionField};

/// How a front end names a field given a value, so that its messages speak its words.
pub trait Spelling {
    /// `field` given `value` (empty: the field alone, as in a hint) in the front end's
    /// words.
    fn option(&self, field: OptionField, value: &str) -> String;

    /// Any other field a message names by its name (a nameplate's `speed_rpm`), in the
    /// front end's words; the library's own name unless a front end says otherwise.
    fn key(&self, name: &str) -> String {
        name.to_string()
    }

    /// A report's advice to give `field` the value `value` (a placeholder such as
    /// `START:END`, or a value to copy; empty: the field alone), as its user would type it;
    /// [`Spelling::option`] unless a front end says otherwise (Python: `commission='2:4'`).
    fn hint(&self, field: OptionField, value: &str) -> String {
        self.option(field, value)
    }

    /// A report's advice to run another command (`diagnose`) with `field`, as its user
    /// would (the command line: `diagnose --baseline`; the library: `diagnose's baseline`).
    fn command_with(&self, command: &str, field: OptionField) -> String {
        format!("{command}'s {}", self.hint(field, ""))
    }
}

/// The library's own words: `commission = 4:2` (a fleet table's), the field alone
/// without a value; what the errors' `Display` says.
#[derive(Debug, Clone, Copy, Default)]
pub struct FieldNames;

impl Spelling for FieldNames {
    fn option(&self, field: OptionField, value: &str) -> String {
        field_given(field, value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_library_names_fields_by_their_names() {
        let w = FieldNames;
        assert_eq!(
            w.hint(OptionField::Commission, "START:END"),
            "commission = START:END"
        );
        assert_eq!(w.hint(OptionField::Baseline, ""), "baseline");
        assert_eq!(
            w.command_with("diagnose", OptionField::Baseline),
            "diagnose's baseline"
        );
    }
}
