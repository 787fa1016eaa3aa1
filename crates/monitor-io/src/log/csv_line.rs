//! The CSV fast path's line parser ([`super::fast`]): the numbers of a line read where
//! they stand, correctly rounded (the values `str::parse::<f64>` gives).
//!
//! Two paths, one result. A line of plain decimals (`-12.5`, `0.036621094`, `6.408294e-9`:
//! what every log writer prints) separated by single commas, one field per schema column,
//! is read by [`parse_line_plain`]: the digits eight at a time, each number `w 10^e` with
//! `w <= 2^53`, `|e| <= 22` (Clinger's fast path: one correctly rounded operation). Any
//! other line (spaces, a missing value, columns not read, longer numbers, a line the block
//! ends without a line end) is read by [`parse_line`] from its start: plain decimals of up to
//! 19 digits as above ([`parse_plain_parts`]), everything else by `fast-float2`.

use super::Column;

/// Largest number of parsed columns (every column of the schema).
const MAX_COLS: usize = Column::COUNT;
/// Marker of a column that is not parsed.
const SKIP: usize = usize::MAX;

/// Which field of a line goes to which slot of the row.
#[derive(Debug, Clone)]
pub(super) struct Cols {
    /// For each field of the line, its slot in the row or [`SKIP`].
    slot_of: Vec<usize>,
    /// Slots per row.
    pub(super) width: usize,
    /// Every field of a line goes to a slot ([`parse_line_plain`] can read the line).
    plain: bool,
}

impl Cols {
    /// Slot `j` holds field `idx[j]` of each line of `nfields` fields.
    pub(super) fn new(idx: &[usize], nfields: usize) -> Self {
        let mut slot_of = vec![SKIP; nfields];
        for (j, &c) in idx.iter().enumerate() {
            if c < nfields {
                slot_of[c] = j;
            }
        }
        Cols {
            plain: nfields > 0 && !slot_of.contains(&SKIP),
            slot_of,
            width: idx.len(),
        }
    }
}

/// Powers of ten that are exact in an `f64` (10^0 ..= 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Appends the decimal digits starting at `b[i]` to `w` (`w = 10 w + digit`, wrapping:
/// the caller discards more than 19 digits) and counts them in `digits`; returns the index
/// after the last digit. Eight bytes at a time where the block has them (the digits of
/// one 8-byte word converted with three multiplications instead of a chain of one per
/// digit).
#[inline]
fn digit_run(b: &[u8], mut i: usize, w: &mut u64, digits: &mut usize) -> usize {
    while let Some(word) = b.get(i..i + 8) {
        let mut a = [0u8; 8];
        a.copy_from_slice(word);
        let x = u64::from_le_bytes(a);
        let k = leading_digits(x);
        if k == 0 {
            return i;
        }
        *w = w
            .wrapping_mul(POW10_INT[k])
            .wrapping_add(digits_value(x, k));
        *digits += k;
        i += k;
        if k < 8 {
            return i;
        }
    }
    while i < b.len() && b[i].is_ascii_digit() {
        *w = w.wrapping_mul(10).wrapping_add(u64::from(b[i] - b'0'));
        *digits += 1;
        i += 1;
    }
    i
}

/// Powers of ten as integers, 10^0 ..= 10^8.
const POW10_INT: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// How many of the eight bytes of `x` (the first in the lowest byte) are ASCII digits
/// before the first that is not. (A byte below `0` borrows from the bytes after it, and
/// one above `9` carries into them: only bytes after the first non-digit are disturbed.)
#[inline]
fn leading_digits(x: u64) -> usize {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let t = x.wrapping_sub(0x30 * ONES);
    let not_digit = (t | t.wrapping_add(0x76 * ONES)) & (0x80 * ONES);
    (not_digit.trailing_zeros() / 8) as usize
}

/// The value of the first `k` (1..=8) bytes of `x`, all ASCII digits, the first the most
/// significant.
#[inline]
fn digits_value(x: u64, k: usize) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    // The k digits moved to the top bytes: the bytes below read as leading zeros.
    let v = (x.wrapping_sub(0x30 * ONES) & (0x0f * ONES)) << (8 * (8 - k));
    let v = (v.wrapping_mul(10 * 256 + 1) >> 8) & 0x00ff_00ff_00ff_00ff;
    let v = (v.wrapping_mul(100 * 65_536 + 1) >> 16) & 0x0000_ffff_0000_ffff;
    v.wrapping_mul(10_000 * (1 << 32) + 1) >> 32
}

/// Splits a plain decimal at the start of `b` (optional sign, digits with an optional
/// point, optional exponent) into `(+-w, e, bytes used)` when its value is `w 10^e` with `w <= 2^53`, `|e| <= 22` and
/// at most 19 digits: then `w` and `10^|e|` are exact and one multiplication or division
/// rounds correctly (Clinger's fast path, [`scaled`]), the same value `fast_float2` gives;
/// `None` for anything else (more digits, `inf`, `NaN`, a bare
/// sign, an exponent without digits), which `fast_float2` then takes, so the accepted text
/// and the values are exactly `fast_float2::parse_partial`'s. Most cells of a log written
/// at f32 precision (8-9 digits) take this path, several times faster.
#[inline]
fn parse_plain_parts(b: &[u8]) -> Option<(f64, i32, usize)> {
    let n = b.len();
    let mut i = 0;
    let neg = match b.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut w: u64 = 0;
    let (mut digits, mut frac) = (0usize, 0usize);
    i = digit_run(b, i, &mut w, &mut digits);
    if i < n && b[i] == b'.' {
        let before = digits;
        i = digit_run(b, i + 1, &mut w, &mut digits);
        frac = digits - before;
    }
    // (19 digits cannot overflow a u64.)
    if digits == 0 || digits > 19 || w > 1 << 53 {
        return None;
    }
    let mut e = -(frac as i64);
    if i < n && (b[i] | 0x20) == b'e' {
        let mut j = i + 1;
        let eneg = match b.get(j) {
            Some(b'-') => {
                j += 1;
                true
            }
            Some(b'+') => {
                j += 1;
                false
            }
            _ => false,
        };
        let (mut x, start) = (0i64, j);
        while j < n && b[j].is_ascii_digit() && j - start < 4 {
            x = 10 * x + i64::from(b[j] - b'0');
            j += 1;
        }
        if j == start || (j < n && b[j].is_ascii_digit()) {
            return None;
        }
        e += if eneg { -x } else { x };
        i = j;
    }
    if !(-22..=22).contains(&e) {
        return None;
    }
    let v = w as f64;
    Some((if neg { -v } else { v }, e as i32, i))
}

/// `v 10^e` for `|e| <= 22`, one correctly rounded operation (with the sign in `v`: the
/// rounding is symmetric, so the same value as negating after).
#[inline]
fn scaled(v: f64, e: i32) -> f64 {
    if e >= 0 {
        v * POW10[e as usize]
    } else {
        v / POW10[(-e) as usize]
    }
}

/// [`parse_plain_parts`] as a value.
#[cfg(test)]
fn parse_plain(b: &[u8]) -> Option<(f64, usize)> {
    parse_plain_parts(b).map(|(v, e, k)| (scaled(v, e), k))
}

/// One number at the start of `b`, as `(v, e, bytes used)` with the value `v 10^e`
/// ([`scaled`]): [`parse_plain_parts`], else `fast_float2` (`e` = 0).
#[inline]
fn parse_number_parts(b: &[u8]) -> Option<(f64, i32, usize)> {
    match parse_plain_parts(b) {
        Some(r) => Some(r),
        None => fast_float2::parse_partial::<f64, _>(b)
            .ok()
            .map(|(v, k)| (v, 0, k)),
    }
}

/// A missing value at the start of `b` ([`super::is_missing`]: an empty cell, `NA`,
/// `null`), ended by a field or line end or a space: `(NaN, 0, bytes used)`. Tried only
/// where no number parses, so it costs nothing on a cell that is a number.
#[cold]
#[inline(never)]
fn missing_cell(b: &[u8]) -> Option<(f64, i32, usize)> {
    let k = b
        .iter()
        .position(|c| matches!(c, b',' | b'\n' | b'\r' | b' '))
        .unwrap_or(b.len());
    let text = std::str::from_utf8(&b[..k]).ok()?;
    super::is_missing(text).then_some((f64::NAN, 0, k))
}

/// One number at the start of `b` and the bytes used.
#[cfg(test)]
fn parse_number(b: &[u8]) -> Option<(f64, usize)> {
    parse_number_parts(b).map(|(v, e, k)| (scaled(v, e), k))
}

/// Parses the line starting at `i` into `row`; returns the index after its line end, or
/// `None` when a field is not a number or the field count is wrong. One pass: fields are
/// parsed where they stand, the parser's end must be a `,` or the line end (`\n`, `\r\n`,
/// or the end of the block), spaces around a number are allowed.
#[inline]
fn parse_line(b: &[u8], mut i: usize, cols: &Cols, row: &mut [f64; MAX_COLS]) -> Option<usize> {
    let n = b.len();
    // Each slot's power of ten, applied once the line is read: the divisions of a line
    // then run side by side instead of each holding up the parsing after it.
    let mut exp = [0i32; MAX_COLS];
    for (field, &slot) in cols.slot_of.iter().enumerate() {
        if field > 0 {
            if i >= n || b[i] != b',' {
                return None;
            }
            i += 1;
        }
        if slot == SKIP {
            i += memchr::memchr2(b',', b'\n', &b[i..]).unwrap_or(n - i);
            if i > 0 && i < n && b[i] == b'\n' && b[i - 1] == b'\r' {
                i -= 1;
            }
            continue;
        }
        while i < n && b[i] == b' ' {
            i += 1;
        }
        let (v, e, k) = match parse_number_parts(&b[i..]) {
            Some(p) => p,
            None => missing_cell(&b[i..])?,
        };
        row[slot] = v;
        exp[slot] = e;
        i += k;
        while i < n && b[i] == b' ' {
            i += 1;
        }
    }
    if i < n && b[i] == b'\r' {
        i += 1;
    }
    let end = if i == n {
        n
    } else if b[i] == b'\n' {
        i + 1
    } else {
        return None;
    };
    for (v, &e) in row.iter_mut().zip(&exp).take(cols.width) {
        *v = scaled(*v, e);
    }
    Some(end)
}

/// The eight bytes of `b` from `p` (the first in the lowest byte), `None` past the end.
#[inline(always)]
fn word_at(b: &[u8], p: usize) -> Option<u64> {
    let w: [u8; 8] = b.get(p..p + 8)?.try_into().ok()?;
    Some(u64::from_le_bytes(w))
}

/// `w` with the first `k` (0..=8) digits of the word `x` appended (wrapping: the caller
/// discards more than 19 digits).
#[inline(always)]
fn append_digits(w: u64, x: u64, k: usize) -> u64 {
    if k == 0 {
        w
    } else {
        w.wrapping_mul(POW10_INT[k])
            .wrapping_add(digits_value(x, k))
    }
}

/// The run of at most 15 digits at `b[p]` appended to `w`, and its length; `None` for a
/// longer run or fewer than 16 bytes left in the block (the caller takes the general path).
#[inline(always)]
fn digits16(b: &[u8], p: usize, w: u64) -> Option<(u64, usize)> {
    let x = word_at(b, p)?;
    let k = leading_digits(x);
    let w = append_digits(w, x, k);
    if k < 8 {
        return Some((w, k));
    }
    let y = word_at(b, p + 8)?;
    let m = leading_digits(y);
    if m == 8 {
        return None;
    }
    Some((append_digits(w, y, m), 8 + m))
}

/// A plain decimal at `b[p]`: an optional `-`, digits with an optional point (at least one
/// digit, at most 19, `w <= 2^53`), an optional exponent `e`/`E` with an optional sign and
/// one to three digits, `|e| <= 22`: `(+-w, e, end)` as [`parse_plain_parts`] gives it for
/// the same text. `None` for anything else.
#[inline(always)]
fn plain_number(b: &[u8], p: usize) -> Option<(f64, i32, usize)> {
    let neg = *b.get(p)? == b'-';
    let p = p + usize::from(neg);
    let (mut w, mut p_end) = digits16(b, p, 0)?;
    let mut digits = p_end;
    p_end += p;
    let mut e = 0i32;
    if b.get(p_end) == Some(&b'.') {
        let (wf, f) = digits16(b, p_end + 1, w)?;
        w = wf;
        digits += f;
        e = -(f as i32);
        p_end += 1 + f;
    }
    if digits == 0 || digits > 19 || w > 1 << 53 {
        return None;
    }
    if b.get(p_end).is_some_and(|c| c | 0x20 == b'e') {
        let (x, end) = plain_exponent(b, p_end + 1)?;
        e += x;
        p_end = end;
        if !(-22..=22).contains(&e) {
            return None;
        }
    }
    let v = w as f64;
    Some((if neg { -v } else { v }, e, p_end))
}

/// The exponent after the `e` at `b[p]`: an optional sign and one to three digits; its
/// value and the index after it.
#[inline(always)]
fn plain_exponent(b: &[u8], p: usize) -> Option<(i32, usize)> {
    let (neg, start) = match b.get(p) {
        Some(b'-') => (true, p + 1),
        Some(b'+') => (false, p + 1),
        _ => (false, p),
    };
    let mut x = 0i32;
    let mut j = start;
    while let Some(d) = b.get(j).filter(|d| d.is_ascii_digit()) {
        if j - start == 3 {
            return None;
        }
        x = 10 * x + i32::from(d - b'0');
        j += 1;
    }
    if j == start {
        return None;
    }
    Some((if neg { -x } else { x }, j))
}

/// A number at `b[p]` that is not a plain decimal of [`plain_number`]'s (more digits, an
/// exponent beyond 22): `fast-float2`'s value, which [`parse_line`] gives too, and the
/// index after it.
#[inline(never)]
fn long_number(b: &[u8], p: usize) -> Option<(f64, usize)> {
    let (x, k) = fast_float2::parse_partial::<f64, _>(b.get(p..)?).ok()?;
    Some((x, p + k))
}

/// Reads the line at `b[i]` when it holds one plain decimal ([`plain_number`]) per field,
/// separated by single commas and ended by `\n` or `\r\n` (`cols.plain`: every field is
/// read): the values into `row`, and the index after the line end. `None` for any other
/// line, which the caller reads with [`parse_line`] (the same values where both read it).
#[inline]
fn parse_line_plain(
    b: &[u8],
    mut i: usize,
    cols: &Cols,
    row: &mut [f64; MAX_COLS],
) -> Option<usize> {
    let last = cols.slot_of.len().checked_sub(1)?;
    for (field, &slot) in cols.slot_of.iter().enumerate() {
        let (x, end) = match plain_number(b, i) {
            Some((v, e, end)) => (scaled(v, e), end),
            // (A longer number: a time printed at f64 precision, `0.0013000000000000002`.)
            None => long_number(b, i)?,
        };
        *row.get_mut(slot)? = x;
        let c = *b.get(end)?;
        if field < last {
            if c != b',' {
                return None;
            }
            i = end + 1;
        } else {
            return match c {
                b'\n' => Some(end + 1),
                b'\r' if b.get(end + 1) == Some(&b'\n') => Some(end + 2),
                _ => None,
            };
        }
    }
    None
}

/// Parses a block of whole lines; the rows' first `cols.width` values are appended to
/// `out`. Empty lines are skipped. False at the first line the fast path does not accept.
#[cfg(test)]
fn parse_block(block: &[u8], cols: &Cols, out: &mut Vec<f64>) -> bool {
    parse_block_with(block, cols, |slots| out.extend_from_slice(slots)).is_some()
}

/// Parses a block of whole lines and hands each row's first `cols.width` values to
/// `on_row`. Empty lines are skipped and counted: returns their number, or `None` at the
/// first line the fast path does not accept.
pub(super) fn parse_block_with(
    block: &[u8],
    cols: &Cols,
    on_row: impl FnMut(&[f64]),
) -> Option<u64> {
    // The row width as a constant, so that handing a row over is a few moves.
    match cols.width {
        4 => parse_block_w::<4>(block, cols, on_row),
        5 => parse_block_w::<5>(block, cols, on_row),
        6 => parse_block_w::<6>(block, cols, on_row),
        7 => parse_block_w::<7>(block, cols, on_row),
        8 => parse_block_w::<8>(block, cols, on_row),
        9 => parse_block_w::<9>(block, cols, on_row),
        10 => parse_block_w::<10>(block, cols, on_row),
        _ => parse_block_w::<0>(block, cols, on_row),
    }
}

/// [`parse_block_with`] for rows of `W` values (`W` = 0: any width).
fn parse_block_w<const W: usize>(
    block: &[u8],
    cols: &Cols,
    mut on_row: impl FnMut(&[f64]),
) -> Option<u64> {
    let mut row = [0f64; MAX_COLS];
    let n = block.len();
    let mut i = 0;
    let mut blank = 0u64;
    while i < n {
        match block[i] {
            b'\n' => {
                i += 1;
                blank += 1;
                continue;
            }
            b'\r' if i + 1 >= n || block[i + 1] == b'\n' => {
                i += 2;
                blank += 1;
                continue;
            }
            _ => {}
        }
        let plain = if cols.plain {
            parse_line_plain(block, i, cols, &mut row)
        } else {
            None
        };
        i = match plain {
            Some(end) => end,
            None => parse_line(block, i, cols, &mut row)?,
        };
        if W > 0 {
            on_row(&row[..W]);
        } else {
            on_row(&row[..cols.width]);
        }
    }
    Some(blank)
}

#[cfg(test)]
#[path = "csv_line_tests.rs"]
mod tests;
