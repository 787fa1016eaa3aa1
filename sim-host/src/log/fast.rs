//! The fast path of [`super::LogFile::for_each_row`]: a parallel, bounded-memory CSV number
//! reader for long logs.
//!
//! The header was parsed by [`super::LogFile::open`] (one column map for both paths).
//! Data are read in 4 MiB blocks cut at line ends (`memchr`); the numbers are
//! parsed correctly rounded, the same values as `str::parse::<f64>`: plain decimals of up
//! to 19 digits eight digits at a time with Clinger's exact path ([`parse_plain_parts`]),
//! everything else by `fast-float2`; the blocks of a batch are parsed into rows in
//! parallel (rayon), and the rows are handed over in file order. Reading
//! the next batch, parsing the current one and handing over the previous one overlap, and
//! the buffers are reused, so memory stays at a few tens of MB whatever the log's length.
//!
//! Any cell the fast path does not accept (quotes, tabs, text) or a wrong field count makes
//! [`for_each_row`] return `Ok(false)`: the caller then re-reads with the exact reader,
//! whose message names the line and column. Numbers that are not finite ("NaN", "inf") and
//! times that do not increase are handed over: the data-quality stage judges them.

use super::exact::row_from_values;
use super::mapping::TimeKind;
use super::reader::LogFile;
use super::{Column, LogError, Row};
use rayon::prelude::*;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes per block (one parallel work item).
pub(super) const BLOCK_BYTES: usize = 4 << 20;
/// Largest number of parsed columns (every column of the schema).
const MAX_COLS: usize = Column::COUNT;
/// Marker of a column that is not parsed.
const SKIP: usize = usize::MAX;

/// Which field of a line goes to which slot of the row.
#[derive(Debug, Clone)]
struct Cols {
    /// For each field of the line, its slot in the row or [`SKIP`].
    slot_of: Vec<usize>,
    /// Slots per row.
    width: usize,
}

impl Cols {
    /// Slot `j` holds field `idx[j]` of each line of `nfields` fields.
    fn new(idx: &[usize], nfields: usize) -> Self {
        let mut slot_of = vec![SKIP; nfields];
        for (j, &c) in idx.iter().enumerate() {
            if c < nfields {
                slot_of[c] = j;
            }
        }
        Cols {
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

/// Parses a block of whole lines; the rows' first `cols.width` values are appended to
/// `out`. Empty lines are skipped. False at the first line the fast path does not accept.
#[cfg(test)]
fn parse_block(block: &[u8], cols: &Cols, out: &mut Vec<f64>) -> bool {
    parse_block_with(block, cols, |slots| out.extend_from_slice(slots)).is_some()
}

/// Parses a block of whole lines and hands each row's first `cols.width` values to
/// `on_row`. Empty lines are skipped and counted: returns their number, or `None` at the
/// first line the fast path does not accept.
fn parse_block_with(block: &[u8], cols: &Cols, on_row: impl FnMut(&[f64])) -> Option<u64> {
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
        i = parse_line(block, i, cols, &mut row)?;
        if W > 0 {
            on_row(&row[..W]);
        } else {
            on_row(&row[..cols.width]);
        }
    }
    Some(blank)
}

/// A parsed block's rows (the buffer is reused for the next block).
type Parsed = Vec<Row>;

/// Sequential reader of line-aligned blocks, reusing its buffers.
struct BlockReader {
    f: File,
    /// Bytes per block.
    block: usize,
    /// Bytes after the last line end of the previous block.
    carry: Vec<u8>,
    /// Free buffers.
    pool: Vec<Vec<u8>>,
    eof: bool,
}

impl BlockReader {
    /// Reads up to `count` blocks; an empty result at the end of the file.
    fn batch(&mut self, count: usize) -> std::io::Result<(Vec<Vec<u8>>, u64)> {
        let mut blocks = Vec::with_capacity(count);
        let mut bytes = 0u64;
        while blocks.len() < count && !self.eof {
            let mut buf = self
                .pool
                .pop()
                .unwrap_or_else(|| Vec::with_capacity(self.block + 4096));
            buf.clear();
            buf.append(&mut self.carry);
            let k = (&mut self.f)
                .take(self.block as u64)
                .read_to_end(&mut buf)?;
            bytes += k as u64;
            if k < self.block {
                self.eof = true;
            }
            if self.eof {
                if buf.is_empty() {
                    self.pool.push(buf);
                } else {
                    blocks.push(buf);
                }
                break;
            }
            match memchr::memrchr(b'\n', &buf) {
                Some(p) => {
                    self.carry.extend_from_slice(&buf[p + 1..]);
                    buf.truncate(p + 1);
                    blocks.push(buf);
                }
                // A line longer than a block: keep reading it.
                None => self.carry = buf,
            }
        }
        Ok((blocks, bytes))
    }
}

/// Streams the data rows of `log` in file order, parsing in parallel, `block` bytes per
/// work item. `on_row` returns false to stop early. `progress` gets the fraction of the file read.
/// Returns the number of blank lines skipped, or `Ok(None)` when the fast path gave up
/// (see the module documentation; a time column of ISO 8601 text is the exact reader's).
///
/// # Errors
/// I/O errors.
pub(super) fn for_each_row(
    log: &LogFile,
    block: usize,
    progress: &mut dyn FnMut(f64),
    on_row: &mut dyn FnMut(&Row) -> bool,
) -> Result<Option<u64>, LogError> {
    if log.columns().time == TimeKind::Iso8601 {
        return Ok(None);
    }
    let io = |source| LogError::Io {
        path: log.shown().to_string(),
        source,
    };
    let mut f = File::open(log.path()).map_err(io)?;
    f.seek(SeekFrom::Start(log.header_bytes())).map_err(io)?;
    let total = log.len_bytes().max(1) as f64;
    // The present columns, in `Column::ALL` order: slot j of a parsed row is column
    // `present[j]`.
    let columns = log.columns();
    let present: Vec<usize> = (0..Column::ALL.len())
        .filter(|&c| columns.field[c].is_some())
        .collect();
    let idx: Vec<usize> = present.iter().filter_map(|&c| columns.field[c]).collect();
    let cols = Cols::new(&idx, columns.n_fields);
    // (Run by the parsing workers: the reading thread only hands the rows over.)
    let to_row = |slots: &[f64]| {
        let mut v = [0.0f64; Column::COUNT];
        for (&c, &x) in present.iter().zip(slots) {
            v[c] = x;
        }
        row_from_values(&v, columns)
    };
    let mut reader = BlockReader {
        f,
        block: block.max(1),
        carry: Vec::new(),
        pool: Vec::new(),
        eof: false,
    };
    let per_batch = rayon::current_num_threads().max(1) * 2;
    let mut read_bytes = log.header_bytes();
    // Pipeline: read batch k+1 (one task) | parse batch k (parallel) | hand over batch k-1
    // (this thread, so `on_row` need not be Send).
    let (mut to_parse, b) = reader.batch(per_batch).map_err(io)?;
    read_bytes += b;
    let mut to_hand: Option<Vec<Option<Parsed>>> = None;
    let mut outs: Vec<Parsed> = Vec::new();
    let blank = AtomicU64::new(0);
    loop {
        if to_parse.is_empty() && to_hand.is_none() {
            return Ok(Some(blank.into_inner()));
        }
        let mut next: Option<std::io::Result<(Vec<Vec<u8>>, u64)>> = None;
        let mut parsed: Option<Vec<Option<Parsed>>> = None;
        let mut verdict: Option<bool> = None;
        let mut free_outs: Vec<Parsed> = Vec::new();
        rayon::in_place_scope(|s| {
            if !reader.eof {
                let (rd, nx) = (&mut reader, &mut next);
                s.spawn(move |_| *nx = Some(rd.batch(per_batch)));
            }
            if !to_parse.is_empty() {
                let bufs: Vec<Parsed> = (0..to_parse.len())
                    .map(|_| outs.pop().unwrap_or_default())
                    .collect();
                let (blocks, cols, pr, to_row, blank) =
                    (&to_parse, &cols, &mut parsed, &to_row, &blank);
                s.spawn(move |_| *pr = Some(parse_blocks(blocks, bufs, cols, to_row, blank)));
            }
            if let Some(batch) = to_hand.take() {
                verdict = hand_over(batch, on_row, &mut free_outs);
            }
        });
        match verdict {
            Some(true) => return Ok(Some(blank.into_inner())),
            Some(false) => return Ok(None),
            None => {}
        }
        outs.append(&mut free_outs);
        progress((read_bytes as f64 / total).min(1.0));
        reader.pool.append(&mut to_parse);
        to_hand = parsed;
        match next {
            Some(r) => {
                let (blocks, b) = r.map_err(io)?;
                to_parse = blocks;
                read_bytes += b;
            }
            None => to_parse = Vec::new(),
        }
    }
}

/// Parses a batch of blocks in parallel into the row buffers `bufs` (reused), one result
/// per block: `None` where the block is not for the fast path. Adds the blank lines
/// skipped to `blank`.
fn parse_blocks(
    blocks: &[Vec<u8>],
    bufs: Vec<Parsed>,
    cols: &Cols,
    to_row: &(impl Fn(&[f64]) -> Row + Sync),
    blank: &AtomicU64,
) -> Vec<Option<Parsed>> {
    blocks
        .par_iter()
        .zip(bufs.into_par_iter())
        .map(|(b, mut rows)| {
            rows.clear();
            // (About 60 bytes a line in a typical log.)
            rows.reserve(b.len() / 60);
            let skipped = parse_block_with(b, cols, |slots| rows.push(to_row(slots)))?;
            blank.fetch_add(skipped, Ordering::Relaxed);
            Some(rows)
        })
        .collect()
}

/// Hands a parsed batch's rows to `on_row` in order, returning each emptied buffer to
/// `free`. `Some(false)`: a block was not for the fast path (give up); `Some(true)`:
/// `on_row` asked to stop; `None`: go on.
fn hand_over(
    batch: Vec<Option<Parsed>>,
    on_row: &mut dyn FnMut(&Row) -> bool,
    free: &mut Vec<Parsed>,
) -> Option<bool> {
    for p in batch {
        let Some(v) = p else {
            return Some(false);
        };
        for row in &v {
            if !on_row(row) {
                return Some(true);
            }
        }
        free.push(v);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn blocks_pick_columns_and_skip_empty_lines() {
        let cols = Cols::new(&[0, 2], 3);
        let mut out = vec![];
        assert!(parse_block(
            b"1,2,3\n4, 5 ,6\r\n\n\r\n7,8,9",
            &cols,
            &mut out
        ));
        assert_eq!(out, vec![1.0, 3.0, 4.0, 6.0, 7.0, 9.0]);
        let mut out = vec![];
        assert!(!parse_block(b"1,2\n", &cols, &mut out));
        assert!(!parse_block(b"1,2,3,4\n", &cols, &mut out));
        assert!(!parse_block(b"1,x,y\n", &cols, &mut out));
        assert!(!parse_block(b"1,2,3x\n", &cols, &mut out));
        assert!(!parse_block(b"1,2,\"3\"\n", &cols, &mut out));
    }

    #[test]
    fn line_ends_and_skipped_columns() {
        let cols = Cols::new(&[0, 1], 3);
        let mut out = vec![];
        assert!(parse_block(b"1,2,a\r\n3,4,b\n5,6,c\r", &cols, &mut out));
        assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let cols = Cols::new(&[1, 2], 3);
        let mut out = vec![];
        assert!(parse_block(
            b"x,1,2\r\ny,3, 4 \r\n\r\nz,5,6",
            &cols,
            &mut out
        ));
        assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert!(!parse_block(b"x,1,2\rz,5,6", &cols, &mut out));
        assert!(!parse_block(b"x,1,2 3\n", &cols, &mut out));
        assert!(!parse_block(b"   \n", &cols, &mut out));
    }

    /// The rows of a log through the exact reader.
    fn exact(path: &Path) -> Vec<Row> {
        let log = LogFile::open(path).unwrap();
        let mut r = super::super::exact::ExactRows::new(&log).unwrap();
        let mut v = vec![];
        while let Some(row) = r.next_row().unwrap() {
            v.push(row);
        }
        v
    }

    fn fast(path: &Path, block: usize) -> (bool, Vec<Row>) {
        let log = LogFile::open(path).unwrap();
        let mut v = vec![];
        let ok = for_each_row(&log, block, &mut |_| {}, &mut |r| {
            v.push(*r);
            true
        })
        .unwrap();
        (ok.is_some(), v)
    }

    #[test]
    fn same_rows_as_the_exact_reader_whatever_the_block_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.csv");
        let mut text = String::from("t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s,enc_count\n");
        for k in 0..500 {
            let t = k as f64 * 1e-4;
            text.push_str(&format!(
                "{t},{},{:e},-1.5e2,{},{},{},{},{}\n",
                300.0 * (t * 314.0).sin(),
                -2.5 * t,
                k % 7,
                0.1 * k as f64,
                -3.25,
                1e-9 * k as f64,
                k * 3
            ));
        }
        for t in [text.clone(), text.replace('\n', "\r\n")] {
            std::fs::write(&path, &t).unwrap();
            let want = exact(&path);
            assert_eq!(want.len(), 500);
            assert_eq!(want[499].enc_count, Some(1497));
            for block in [1, 7, 64, 1000, 1 << 20] {
                let (ok, got) = fast(&path, block);
                assert!(ok, "block {block}");
                assert_eq!(got, want, "block {block}");
            }
        }
        std::fs::write(&path, &text).unwrap();
        // Stopping early.
        let log = LogFile::open(&path).unwrap();
        let mut n = 0;
        let ok = for_each_row(&log, 64, &mut |_| {}, &mut |_| {
            n += 1;
            n < 10
        })
        .unwrap();
        assert!(ok.is_some());
        assert_eq!(n, 10);
        // Anything the fast path does not take: it gives up (the caller re-reads exactly).
        for bad in [
            "0.06,x,0,0,0,0,0,0,0",     // not a number
            "0.06,\"1\",0,0,0,0,0,0,0", // quoted
            "0.06,1,2",                 // too few fields
            "0.06,0,0,0,0,0,0,0,0,0",   // too many
            "0.06,0,0,0,0,0,0,0,zz",    // enc_count not a number
        ] {
            let t = format!("{text}{bad}\n0.07,0,0,0,0,0,0,0,0\n");
            std::fs::write(&path, &t).unwrap();
            for block in [64, 1 << 20] {
                assert!(!fast(&path, block).0, "{bad} block {block}");
            }
            // ... where the exact reader (behind `LogFile::for_each_row`) names the line,
            // except for the quotes, which it accepts.
            let log = LogFile::open(&path).unwrap();
            let mut rows: Vec<Row> = Vec::new();
            let res = log.for_each_row(&mut |_| {}, &mut rows);
            if bad.contains('"') {
                assert_eq!(res.unwrap(), 502);
                assert_eq!(rows.len(), 502, "the sink was restarted");
            } else {
                let e = res.unwrap_err().to_string();
                assert!(e.contains("line 502"), "{bad}: {e}");
            }
        }
    }

    #[test]
    fn times_that_do_not_increase_and_nan_cells_are_handed_over() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(
            &path,
            "t_s,ia_A,ib_A,ic_A\n0,1,2,3\n0,1,2,3\n-1,NaN,inf,3\nnan,1,2,3\n",
        )
        .unwrap();
        let (ok, rows) = fast(&path, 1 << 20);
        assert!(ok);
        assert_eq!(rows.len(), 4);
        assert_eq!(rows[2].t_s, -1.0);
        assert!(rows[2].i_abc[0].is_nan() && rows[2].i_abc[1].is_infinite());
        assert!(rows[3].t_s.is_nan());
        // (NaN is not equal to itself: compare the printed rows.)
        assert_eq!(format!("{rows:?}"), format!("{:?}", exact(&path)));
    }

    #[test]
    fn eight_digits_at_a_time() {
        let word = |s: &[u8]| {
            let mut a = [b'x'; 8];
            a[..s.len()].copy_from_slice(s);
            u64::from_le_bytes(a)
        };
        assert_eq!(leading_digits(word(b"12345678")), 8);
        assert_eq!(leading_digits(word(b"1234,678")), 4);
        assert_eq!(leading_digits(word(b",2345678")), 0);
        assert_eq!(leading_digits(word(b"9/:0")), 1);
        assert_eq!(leading_digits(word(b"09.1")), 2);
        assert_eq!(digits_value(word(b"12345678"), 8), 12_345_678);
        assert_eq!(digits_value(word(b"90210,5"), 5), 90_210);
        assert_eq!(digits_value(word(b"7"), 1), 7);
        assert_eq!(digits_value(word(b"00000009"), 8), 9);
        let (mut w, mut n) = (0, 0);
        let s = b"1234567890123,5";
        assert_eq!(digit_run(s, 0, &mut w, &mut n), 13);
        assert_eq!((w, n), (1_234_567_890_123, 13));
    }

    /// The plain-decimal path gives `fast_float2`'s value and length, or leaves the text
    /// to it: every printed f32 and f64 (shortest round trip, as the log writer prints),
    /// fixed and scientific forms, and text around the path's limits.
    #[test]
    fn plain_decimals_parse_like_fast_float() {
        let same = |s: &str| {
            let want = fast_float2::parse_partial::<f64, _>(s.as_bytes()).ok();
            let got = parse_number(s.as_bytes());
            assert_eq!(
                got.map(|(v, k)| (v.to_bits(), k)),
                want.map(|(v, k)| (v.to_bits(), k)),
                "{s}"
            );
            if let Some((v, k)) = parse_plain(s.as_bytes()) {
                assert_eq!(
                    (v.to_bits(), k),
                    want.map(|(v, k)| (v.to_bits(), k)).unwrap(),
                    "{s}"
                );
            }
        };
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut plain = 0;
        for k in 0..200_000 {
            // xorshift: bit patterns of every magnitude, then ordinary values.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = if k % 2 == 0 {
                f64::from_bits(x)
            } else {
                ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi(k % 13 - 6)
            };
            if !v.is_finite() {
                continue;
            }
            let f = v as f32;
            for s in [
                format!("{v}"),
                format!("{v:e}"),
                format!("{f}"),
                format!("{f:e}"),
                format!("{f:E}"),
                format!("{:.3}", f),
                format!("{}", (v * 1e4).round() / 1e4),
            ] {
                same(&s);
                plain += usize::from(parse_plain(s.as_bytes()).is_some());
            }
        }
        assert!(plain > 500_000, "the plain path took only {plain} numbers");
        for s in [
            "0",
            "-0",
            "+0",
            "-0.0",
            "1.",
            ".5",
            "-.5",
            "+.5e1",
            "1e22",
            "1e23",
            "1e-22",
            "1e-23",
            "9007199254740992",
            "9007199254740993",
            "9007199254740992e-3",
            "1234567890123456789",
            "12345678901234567890",
            "0.00030000000000000003",
            "1e",
            "1e+",
            "1e-",
            "1E5",
            "1e0005",
            "1e00005",
            "1e99999",
            "2.5e-308",
            "-",
            "+",
            ".",
            "-.",
            "e5",
            ".e5",
            "inf",
            "-infinity",
            "NaN",
            "1.5x",
            "1..5",
            "1.5e3,2",
            "326.5986,1",
            "0.0001\r\n",
            "1,2",
            "1 2",
            "000000000000000000001",
            "0000000000000000001.5",
            "4.9406564584124654e-324",
            "1.7976931348623157e308",
            "6.408294e-9",
            "0.0000012402029",
            "-163.67188",
        ] {
            same(s);
        }
    }

    #[test]
    fn parses_like_std() {
        let cols = Cols::new(&[0], 1);
        for s in [
            "0",
            "-0",
            "1.5",
            "326.5986",
            "-163.2993",
            "5.072449e-09",
            "1e3",
            "+2.5E+2",
            "0.0001",
            "0.00030000000000000003",
            "12345678901234567890",
            "1.",
            ".5",
            "inf",
            "-infinity",
            " 2.5 \r",
        ] {
            let mut out = vec![];
            assert!(parse_block(s.as_bytes(), &cols, &mut out), "{s}");
            let b: f64 = s.trim().parse().unwrap();
            assert_eq!(out[0].to_bits(), b.to_bits(), "{s}");
        }
        for s in ["-", "abc", "1.2.3", "1e", "1,2", "1 2"] {
            let mut out = vec![];
            assert!(!parse_block(s.as_bytes(), &cols, &mut out), "{s}");
            assert!(s.parse::<f64>().is_err(), "{s}");
        }
    }
}
