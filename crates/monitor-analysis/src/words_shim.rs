//! TEMPORARY (issue 79, being removed): the words the analyses' advice names a field in,
//! until the analyses return typed advice and the door (`monitor_words`) spells it.

use monitor_replay::{field_given, OptionField};
use std::fmt;

/// How a front end names a field given a value.
pub trait Spelling {
    /// `field` given `value` in the front end's words.
    fn option(&self, field: OptionField, value: &str) -> String;
    /// A report's advice to give `field` the value `value`.
    fn hint(&self, field: OptionField, value: &str) -> String {
        self.option(field, value)
    }
    /// A report's advice to run another command with `field`.
    fn command_with(&self, command: &str, field: OptionField) -> String {
        format!("{command}'s {}", self.hint(field, ""))
    }
}

/// The library's own names.
#[derive(Debug, Clone, Copy, Default)]
pub struct FieldNames;

impl Spelling for FieldNames {
    fn option(&self, field: OptionField, value: &str) -> String {
        field_given(field, value)
    }
}

/// A front end's spelling for a whole run.
#[derive(Clone, Copy)]
pub struct Words(pub &'static (dyn Spelling + Sync));

impl Words {
    /// The library's own words.
    pub const LIBRARY: Words = Words(&FieldNames);
}

impl Default for Words {
    fn default() -> Self {
        Words::LIBRARY
    }
}

impl fmt::Debug for Words {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Words")
    }
}

impl PartialEq for Words {
    fn eq(&self, _: &Words) -> bool {
        true
    }
}

impl std::ops::Deref for Words {
    type Target = dyn Spelling + Sync;

    fn deref(&self) -> &Self::Target {
        self.0
    }
}
