//! The columns of a typed log (Parquet, in-memory data): each field's type says whether it
//! holds numbers and whether it is a timestamp; both formats check them here, the same way.

use super::mapping::{ChannelUnit, ColumnMapping};
use super::source::ColumnMap;
use super::{Column, LogError};

/// What a typed log says of one field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct FieldType {
    /// Its type's name when it does not hold numbers (`None`: numbers).
    pub not_numbers: Option<String>,
    /// Its unit when it is a timestamp (`epoch_ms`, `epoch_us`, `epoch_ns`).
    pub timestamp: Option<&'static str>,
}

/// The units of the mapped columns, indexed like [`Column::ALL`]
/// ([`super::mapping::resolve_unit`]: the mapping's, checked against a timestamp's).
/// `numbers` names the number types the format reads, for the message.
///
/// # Errors
/// [`LogError::NotALog`] for a mapped column that does not hold numbers; [`LogError::Unit`]
/// as `resolve_unit`.
pub(super) fn column_units(
    types: &[FieldType],
    columns: &ColumnMap,
    found: &[String],
    mapping: &ColumnMapping,
    shown: &str,
    numbers: &str,
) -> Result<[Option<ChannelUnit>; Column::COUNT], LogError> {
    let mut units = [None; Column::COUNT];
    for (k, c) in Column::ALL.iter().enumerate() {
        let Some(j) = columns.field[k] else { continue };
        let Some(ty) = types.get(j) else { continue };
        if let Some(name) = &ty.not_numbers {
            return Err(LogError::NotALog {
                path: shown.to_string(),
                why: format!(
                    "column '{}' is of type {name}: it must hold numbers ({numbers})",
                    found[j]
                ),
            });
        }
        units[k] =
            super::mapping::resolve_unit(shown, *c, &found[j], mapping.unit_of(*c), ty.timestamp)?;
    }
    Ok(units)
}

/// Refuses a log without a time (no time column, no sample rate) that has a timestamp
/// column, naming it and how to map it (its unit read from `held_in`: "the file", "the
/// data").
///
/// # Errors
/// [`LogError::MissingColumn`] in that case.
pub(super) fn check_unmapped_timestamp(
    types: &[FieldType],
    columns: &ColumnMap,
    found: &[String],
    mapping: &ColumnMapping,
    shown: &str,
    held_in: &str,
) -> Result<(), LogError> {
    if columns.of(Column::Time).is_some() || columns.sample_rate_hz.is_some() {
        return Ok(());
    }
    let Some((j, unit)) = types
        .iter()
        .enumerate()
        .find_map(|(j, t)| t.timestamp.map(|u| (j, u)))
    else {
        return Ok(());
    };
    Err(super::mapping::missing_column_with(
        shown,
        mapping.name_of(Column::Time),
        " (every analysis needs the time)",
        found,
        &format!(
            "; column '{}' is a timestamp: make it the time in the parameter file's [columns] table: t_s = {{ name = \"{}\" }} (its unit, {unit}, is read from {held_in}; docs/design.md)",
            found[j], found[j]
        ),
    ))
}

/// The columns of a typed log: the mapping's columns located among `found`, their units
/// resolved against their types ([`column_units`]), a timestamp left unmapped refused
/// ([`check_unmapped_timestamp`]) and the columns every log needs checked
/// ([`super::source::check_columns`]), in that order, the same for every typed format.
/// `numbers`: the number types the format reads; `held_in`: "the file" or "the data".
///
/// # Errors
/// As the checks named above.
pub(super) fn typed_columns(
    found: &[String],
    types: &[FieldType],
    mapping: &ColumnMapping,
    shown: &str,
    (numbers, held_in): (&str, &str),
) -> Result<ColumnMap, LogError> {
    let mut columns = ColumnMap::locate(found, mapping, shown)?;
    let units = column_units(types, &columns, found, mapping, shown, numbers)?;
    columns.set_units(&units, mapping);
    check_unmapped_timestamp(types, &columns, found, mapping, shown, held_in)?;
    super::source::check_columns(&columns, shown, true, mapping, found)?;
    Ok(columns)
}
