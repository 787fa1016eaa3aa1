//! Missing columns: the error that lists the log's channels ([`channel_list`]) and
//! suggests the closest to the one wanted ([`closest`]).

use super::ColumnMapping;
use crate::log::{Column, LogError};

/// Levenshtein distance between two short strings (characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Lower case, letters and digits only ("Ia [A]" -> "iaa", "ia_A" -> "iaa").
fn folded(s: &str) -> String {
    s.chars()
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect()
}

/// The names a channel of column `c` is commonly given (folded), besides the schema's.
fn usual_names(c: Column) -> &'static [&'static str] {
    match c {
        Column::Time => &["t", "ts", "time", "timestamp", "times"],
        Column::Va => &["va", "ua", "vas", "v1", "u1"],
        Column::Vb => &["vb", "ub", "vbs", "v2", "u2"],
        Column::Vc => &["vc", "uc", "vcs", "v3", "u3"],
        Column::Ia => &["ia", "ias", "i1", "ila", "currenta"],
        Column::Ib => &["ib", "ibs", "i2", "ilb", "currentb"],
        Column::Ic => &["ic", "ics", "i3", "ilc", "currentc"],
        Column::Speed => &["wm", "w", "speed", "n", "rpm", "omega", "wr", "speedrpm"],
        Column::Encoder => &["enc", "encoder", "count", "counts", "position"],
        Column::Temperature => &["temp", "temperature", "twinding", "tstator", "theta"],
    }
}

/// The channel of `found` closest to the name `wanted` of column `c`: the same name in
/// another case, else the smallest edit distance (a third of the channel's name, 1 to 3)
/// to the wanted name or one of the column's usual names, letters and digits only.
pub fn closest<'a>(c: Column, wanted: &str, found: &'a [String]) -> Option<&'a str> {
    if let Some(f) = found.iter().find(|f| f.eq_ignore_ascii_case(wanted)) {
        return Some(f);
    }
    let mut targets = vec![folded(wanted), folded(c.name())];
    targets.extend(usual_names(c).iter().map(|s| s.to_string()));
    found
        .iter()
        .filter_map(|f| {
            let ff = folded(f);
            let d = targets.iter().map(|t| edit_distance(&ff, t)).min()?;
            let limit = (ff.chars().count() / 3).clamp(1, 3);
            (d <= limit && !ff.is_empty()).then_some((d, f))
        })
        .min_by_key(|(d, _)| *d)
        .map(|(_, f)| f.as_str())
}

/// The names of `known` near the misspelt `wanted`, nearest first: an edit distance (letters
/// and digits only, case folded) of at most a third of the longer name (1 to 3), or one
/// name the start of the other (`load_torq` -> `load_torque`). For the messages that refuse
/// an unknown name of a list (an effect, a fault) and say what was meant.
pub fn near_names<'a>(wanted: &str, known: &[&'a str]) -> Vec<&'a str> {
    let w = folded(wanted);
    let mut near: Vec<(usize, &'a str)> = known
        .iter()
        .filter_map(|k| {
            let kf = folded(k);
            let d = edit_distance(&w, &kf);
            let limit = (w.chars().count().max(kf.chars().count()) / 3).clamp(1, 3);
            let prefix = !w.is_empty() && (kf.starts_with(&w) || w.starts_with(&kf));
            (d <= limit || prefix).then_some((d, *k))
        })
        .collect();
    near.sort_by_key(|(d, _)| *d);
    near.into_iter().map(|(_, k)| k).collect()
}

/// The channels of a log as a list for a message (at most 24 names, then how many more).
pub fn channel_list(found: &[String]) -> String {
    if found.is_empty() {
        return "no channels".to_string();
    }
    let s: Vec<&str> = found.iter().take(24).map(String::as_str).collect();
    match found.len().saturating_sub(24) {
        0 => s.join(", "),
        more => format!("{} and {more} more", s.join(", ")),
    }
}

/// The error for column `c` missing from the log shown as `shown`, whose channels are
/// `found`: it names the column (and the channel the mapping gives it), lists the channels
/// found, suggests the closest ([`closest`]) and points to the `[columns]` table.
pub(in crate::log) fn missing_column(
    shown: &str,
    c: Column,
    mapping: &ColumnMapping,
    found: &[String],
    why: &str,
) -> LogError {
    let wanted = mapping.name_of(c);
    let mapped = match mapping.get(c) {
        Some(_) => format!(" (for {} in [columns])", c.name()),
        None => String::new(),
    };
    // Channels another column already reads are no candidates.
    let free: Vec<String> = found
        .iter()
        .filter(|f| {
            Column::ALL
                .iter()
                .all(|o| mapping.name_of(*o) != f.as_str())
        })
        .cloned()
        .collect();
    let hint = match closest(c, wanted, &free) {
        Some(f) => format!(
            "; did you mean '{f}'? Map it in the parameter file's [columns] table: {} = {{ name = \"{f}\", unit = \"...\" }} (docs/design.md)",
            c.name()
        ),
        None => "; map the log's channel in the parameter file's [columns] table (docs/design.md)"
            .to_string(),
    };
    missing_column_with(shown, wanted, &format!("{mapped} ({why})"), found, &hint)
}

/// [`LogError::MissingColumn`] for the log's column `column`, with `why` (" (...)" or "")
/// after its name, the channels `found`, and `hint` ("; ...") at the end.
pub(in crate::log) fn missing_column_with(
    shown: &str,
    column: &str,
    why: &str,
    found: &[String],
    hint: &str,
) -> LogError {
    LogError::MissingColumn {
        path: shown.to_string(),
        column: column.to_string(),
        detail: format!("{why}; the log has {}{hint}", channel_list(found)),
    }
}
