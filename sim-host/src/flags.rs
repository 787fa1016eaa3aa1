//! The command line's names of the library's fields: its flags (`commission` ->
//! `--commission 4:2`), the [`Spelling`] the door (`monitor_api::words`) spells every
//! advice and error of the command line and its HMI in.

use monitor_api::replay::OptionField;
use monitor_api::words::Spelling;

/// The command line's spelling of the library's fields: their flags.
#[derive(Debug, Clone, Copy, Default)]
pub struct CliWords;

impl Spelling for CliWords {
    fn option(&self, field: OptionField, value: &str) -> String {
        let flag = match field {
            OptionField::From => "from".to_string(),
            OptionField::To => "to".to_string(),
            f => f.name().replace('_', "-"),
        };
        if value.is_empty() {
            format!("--{flag}")
        } else {
            format!("--{flag} {value}")
        }
    }

    fn key(&self, name: &str) -> String {
        format!("--{}", name.replace('_', "-"))
    }

    fn command_with(&self, command: &str, field: OptionField) -> String {
        format!("{command} {}", self.option(field, ""))
    }
}
