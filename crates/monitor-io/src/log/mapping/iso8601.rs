//! ISO 8601 date and time text (the `iso8601` time unit, CSV only) into seconds since
//! 1970-01-01 UTC ([`parse_iso8601`]).

/// Parses ISO 8601 date and time text, `YYYY-MM-DD` then `T` or a space, `HH:MM:SS`, an
/// optional fraction (`.` or `,`), an optional zone (`Z`, `+HH:MM`, `-HHMM`), into whole
/// seconds since 1970-01-01 UTC and the fraction of a second (exact to the digits given).
/// `None` for anything else.
pub(in crate::log) fn parse_iso8601(s: &str) -> Option<(i64, f64)> {
    let b = s.trim().as_bytes();
    let [y, mo, d, h, mi, sec] = date_time(b)?;
    let mut i = 19;
    let frac = fraction(b, &mut i)?;
    let offset_s = zone_offset_s(b, i)?;
    let days = days_from_civil(y, mo, d);
    Some((days * 86_400 + h * 3600 + mi * 60 + sec - offset_s, frac))
}

/// The decimal number in bytes `r` of `b`: `None` unless all are digits (and there are
/// some).
#[inline]
fn digits(b: &[u8], r: std::ops::Range<usize>) -> Option<i64> {
    let t = b.get(r)?;
    if t.is_empty() || !t.iter().all(u8::is_ascii_digit) {
        return None;
    }
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// Year, month, day, hour, minute, second of `YYYY-MM-DDTHH:MM:SS` (`T`, `t` or a space)
/// at the start of `b`, in their ranges (a leap second, 60, is taken); `None` otherwise.
#[inline]
fn date_time(b: &[u8]) -> Option<[i64; 6]> {
    let (y, mo, d) = (digits(b, 0..4)?, digits(b, 5..7)?, digits(b, 8..10)?);
    if b.get(4) != Some(&b'-')
        || b.get(7) != Some(&b'-')
        || !matches!(b.get(10), Some(b'T' | b't' | b' '))
    {
        return None;
    }
    let (h, mi, sec) = (digits(b, 11..13)?, digits(b, 14..16)?, digits(b, 17..19)?);
    if b.get(13) != Some(&b':') || b.get(16) != Some(&b':') {
        return None;
    }
    if !(1..=12).contains(&mo) || !(1..=31).contains(&d) || h > 23 || mi > 59 || sec > 60 {
        return None;
    }
    Some([y, mo, d, h, mi, sec])
}

/// The fraction of a second at byte `*i` of `b` (`.` or `,` then digits; 0 when there is
/// none), moving `*i` past it; `None` for a separator without digits.
#[inline]
fn fraction(b: &[u8], i: &mut usize) -> Option<f64> {
    if !matches!(b.get(*i), Some(b'.' | b',')) {
        return Some(0.0);
    }
    let start = *i + 1;
    *i = start;
    while b.get(*i).is_some_and(u8::is_ascii_digit) {
        *i += 1;
    }
    if *i == start {
        return None;
    }
    format!("0.{}", std::str::from_utf8(&b[start..*i]).ok()?)
        .parse()
        .ok()
}

/// The zone from byte `i` of `b` to its end as an offset from UTC [s]: none or `Z` is 0,
/// `+HH:MM`, `+HHMM` or `+HH` (or `-`) ahead of UTC; `None` for anything else.
#[inline]
fn zone_offset_s(b: &[u8], i: usize) -> Option<i64> {
    Some(match b.get(i) {
        None => 0,
        Some(b'Z' | b'z') if i + 1 == b.len() => 0,
        Some(&sign @ (b'+' | b'-')) => {
            let rest = &b[i + 1..];
            let (oh, om) = match rest.len() {
                5 if rest[2] == b':' => (digits(b, i + 1..i + 3)?, digits(b, i + 4..i + 6)?),
                4 => (digits(b, i + 1..i + 3)?, digits(b, i + 3..i + 5)?),
                2 => (digits(b, i + 1..i + 3)?, 0),
                _ => return None,
            };
            let o = oh * 3600 + om * 60;
            if sign == b'+' {
                o
            } else {
                -o
            }
        }
        _ => return None,
    })
}

/// Days since 1970-01-01 of the civil date `y`-`mo`-`d` (Howard Hinnant's algorithm,
/// proleptic Gregorian).
#[inline]
fn days_from_civil(y: i64, mo: i64, d: i64) -> i64 {
    let (yy, m) = if mo <= 2 {
        (y - 1, mo + 9)
    } else {
        (y, mo - 3)
    };
    let era = yy.div_euclid(400);
    let yoe = yy - era * 400;
    let doy = (153 * m + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
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
