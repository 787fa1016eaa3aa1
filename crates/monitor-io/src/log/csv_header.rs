//! A CSV log's header: its columns by name (or by place, for a file without a header row).

use super::mapping::ColumnMapping;
use super::source::{check_columns, ColumnMap};
use super::LogError;

/// Parses the header line (CSV quoting allowed, names trimmed) into the column map; true
/// with it when line 1 is a header. A first line of numbers is data when `[columns]` maps
/// the channels by their place (a file without a header row); without such a mapping it
/// is refused with the table to write.
pub(super) fn parse_header(
    line: &[u8],
    shown: &str,
    mapping: &ColumnMapping,
) -> Result<(ColumnMap, bool), LogError> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .has_headers(false)
        .terminator(csv::Terminator::Any(b'\n'))
        .from_reader(line);
    let mut rec = csv::StringRecord::new();
    let ok = rdr.read_record(&mut rec).map_err(|e| LogError::Csv {
        path: shown.to_string(),
        line: 1,
        message: crate::one_line(&e.to_string()),
    })?;
    if !ok {
        return Err(LogError::NotALog {
            path: shown.to_string(),
            why: "the file is empty: line 1 must be the header (t_s, ia_A, ib_A, ic_A, ...)"
                .to_string(),
        });
    }
    if rec.iter().all(|h| h.is_empty()) {
        return Err(LogError::NotALog {
            path: shown.to_string(),
            why: "the file is empty: line 1 must be the header (t_s, ia_A, ib_A, ic_A, ...)"
                .to_string(),
        });
    }
    if rec.len() == 1 {
        if let Some(sep) = [';', '\t', '|'].into_iter().find(|c| rec[0].contains(*c)) {
            return Err(LogError::NotALog {
                path: shown.to_string(),
                why: format!(
                    "the fields are separated by {sep:?}: the log must be comma-separated (docs/design.md)"
                ),
            });
        }
    }
    let numbers = rec.get(0).is_some_and(|h| h.parse::<f64>().is_ok());
    if numbers && !mapping.by_position() {
        return Err(LogError::NotALog {
            path: shown.to_string(),
            why: format!(
                "line 1 holds numbers: the file has no header row naming the columns; say which of its {} fields is which, by place, in the parameter file's [columns] table, and the sample rate if no field is the time, e.g. t_s = {{ sample_rate_hz = 1000.0 }}, ia_A = {{ column = 1 }}, ib_A = {{ column = 2 }}, ic_A = {{ column = 3 }} (docs/design.md)",
                rec.len()
            ),
        });
    }
    let found: Vec<String> = if numbers {
        (1..=rec.len()).map(|k| format!("column {k}")).collect()
    } else {
        rec.iter().map(str::to_string).collect()
    };
    let map = ColumnMap::locate(&found, mapping, shown)?;
    check_columns(&map, shown, true, mapping, &found)?;
    Ok((map, !numbers))
}
