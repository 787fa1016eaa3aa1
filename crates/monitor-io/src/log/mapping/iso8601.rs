//! ISO 8601 date and time text (the `iso8601` and `timestamp` time units, CSV only) into
//! seconds since 1970-01-01 UTC ([`parse_iso8601`]), by chrono's parser.

use chrono::format::{parse, Parsed, StrftimeItems};

/// Parses ISO 8601 date and time text, `YYYY-MM-DD` then `T` or a space, `HH:MM:SS`, an
/// optional fraction (`.` or `,`), an optional zone (`Z`, `+HH:MM`, `-HHMM`, `+HH`; none:
/// UTC), into whole seconds since 1970-01-01 UTC and the fraction of a second (to the
/// nanosecond). A leap second (`:60`) is the next minute's first. `None` for anything else.
pub(in crate::log) fn parse_iso8601(s: &str) -> Option<(i64, f64)> {
    let t = s.trim();
    // chrono's items take one spelling: `T`, `.`, an offset; the others are brought to it.
    let mut text = String::with_capacity(t.len() + 6);
    for (i, ch) in t.char_indices() {
        text.push(match (i, ch) {
            (10, ' ' | 't') => 'T',
            (19, ',') => '.',
            _ => ch,
        });
    }
    match text.as_bytes().last() {
        Some(b'Z' | b'z') if text.len() > 19 => {
            text.pop();
            text.push_str("+00:00");
        }
        Some(b'0'..=b'9') if !has_zone(&text) => text.push_str("+00:00"),
        _ => {}
    }
    let mut p = Parsed::new();
    parse(&mut p, &text, StrftimeItems::new("%Y-%m-%dT%H:%M:%S%.f%#z")).ok()?;
    let at = p.to_datetime().ok()?;
    let nanos = at.timestamp_subsec_nanos();
    Some((at.timestamp(), f64::from(nanos) * 1e-9))
}

/// Whether `text` (at least `YYYY-MM-DDTHH:MM:SS`) ends in a zone offset (`+`/`-` after
/// the seconds).
fn has_zone(text: &str) -> bool {
    text.get(19..).is_some_and(|rest| rest.contains(['+', '-']))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso8601_text() {
        assert_eq!(parse_iso8601("1970-01-01T00:00:00Z"), Some((0, 0.0)));
        assert_eq!(
            parse_iso8601("2000-03-01 00:00:01.25"),
            Some((951_868_801, 0.25))
        );
        assert_eq!(
            parse_iso8601("2024-05-01T12:00:00.125+02:00"),
            Some((1_714_557_600, 0.125))
        );
        assert_eq!(
            parse_iso8601("2024-05-01T10:00:00Z").map(|x| x.0),
            Some(1_714_557_600)
        );
        // The other spellings: an offset without a colon or minutes, a comma, a `t`.
        for same in [
            "2024-05-01T12:00:00+0200",
            "2024-05-01t07:00:00-03",
            "2024-05-01 10:00:00,000Z",
        ] {
            assert_eq!(parse_iso8601(same), Some((1_714_557_600, 0.0)), "{same}");
        }
        for bad in [
            "2024-05-01",
            "2024-13-01T00:00:00",
            "12:00:00",
            "2024-05-01T10:00:00Q",
            "x",
        ] {
            assert_eq!(parse_iso8601(bad), None, "{bad}");
        }
    }
}
