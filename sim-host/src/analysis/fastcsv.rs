//! Parallel, bounded-memory CSV number reader for long logs.
//!
//! The header is checked by [`crate::log::LogReader::open`] (same column rules and
//! messages). Data are read in 8 MiB blocks cut at line ends; a batch of blocks is parsed in
//! parallel (rayon) by a plain decimal parser (`[-+]digits[.digits][e[-+]digits]`, also
//! `nan`/`inf` are rejected), and the rows are handed over in file order. Any cell the
//! fast path does not accept, a wrong field count, or time not increasing makes
//! [`for_each_row`] return `Ok(false)`: the caller then re-reads with the exact
//! [`crate::log::LogReader`], whose message names the line and column.
//!
//! Accuracy: the mantissa is accumulated exactly (up to 19 digits) and scaled by one
//! power of ten, so values are within 2 ulp of the correctly rounded result.

use crate::log::{LogError, LogReader};
use rayon::prelude::*;
use std::io::Read;
use std::path::Path;

const BLOCK: usize = 8 << 20;

/// Parses one decimal number; `None` if the text is not a plain decimal (spaces around
/// it and a trailing `\r` allowed). The same scanner as the block parser ([`parse_at`]),
/// required to consume the whole slice.
pub fn parse_f64(s: &[u8]) -> Option<f64> {
    match parse_at(s, 0)? {
        (v, end) if end == s.len() => Some(v),
        _ => None,
    }
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Column positions of the needed values: t, ia, ib, ic, [va, vb, vc], [wm].
#[derive(Debug, Clone)]
struct Cols {
    idx: Vec<usize>,
    nfields: usize,
}

/// Parses a decimal number starting at `i` (spaces allowed around it); returns the value
/// and the index of its terminator (',' or a line end or the end of the block), or `None`.
#[inline]
fn parse_at(b: &[u8], mut i: usize) -> Option<(f64, usize)> {
    let n = b.len();
    while i < n && b[i] == b' ' {
        i += 1;
    }
    let mut neg = false;
    if i < n && (b[i] == b'-' || b[i] == b'+') {
        neg = b[i] == b'-';
        i += 1;
    }
    let mut mant: u64 = 0;
    let mut digits = 0u32;
    let mut exp10: i32 = 0;
    let mut any = false;
    while i < n {
        let c = b[i].wrapping_sub(b'0');
        if c > 9 {
            break;
        }
        any = true;
        if digits < 19 {
            mant = mant * 10 + c as u64;
            if mant > 0 {
                digits += 1;
            }
        } else {
            exp10 += 1;
        }
        i += 1;
    }
    if i < n && b[i] == b'.' {
        i += 1;
        while i < n {
            let c = b[i].wrapping_sub(b'0');
            if c > 9 {
                break;
            }
            any = true;
            if digits < 19 {
                mant = mant * 10 + c as u64;
                if mant > 0 {
                    digits += 1;
                }
                exp10 -= 1;
            }
            i += 1;
        }
    }
    if !any {
        return None;
    }
    if i < n && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        let mut eneg = false;
        if i < n && (b[i] == b'-' || b[i] == b'+') {
            eneg = b[i] == b'-';
            i += 1;
        }
        let mut e: i32 = 0;
        let mut ed = false;
        while i < n {
            let c = b[i].wrapping_sub(b'0');
            if c > 9 {
                break;
            }
            e = e.saturating_mul(10).saturating_add(c as i32);
            ed = true;
            i += 1;
        }
        if !ed {
            return None;
        }
        exp10 += if eneg { -e } else { e };
    }
    while i < n && (b[i] == b' ' || b[i] == b'\r') {
        i += 1;
    }
    if i < n && b[i] != b',' && b[i] != b'\n' {
        return None;
    }
    let m = mant as f64;
    let v = if exp10 == 0 {
        m
    } else if (0..=22).contains(&exp10) {
        m * POW10[exp10 as usize]
    } else if (-22..0).contains(&exp10) {
        m / POW10[(-exp10) as usize]
    } else {
        m * 10f64.powi(exp10)
    };
    Some((if neg { -v } else { v }, i))
}

fn is_blank(line: &[u8]) -> bool {
    line.iter().all(|&b| b == b'\r' || b == b' ')
}

fn parse_block(block: &[u8], cols: &Cols, out: &mut Vec<f64>) -> bool {
    let k = cols.idx.len();
    let mut slot_of = vec![usize::MAX; cols.nfields];
    for (j, &c) in cols.idx.iter().enumerate() {
        if c < cols.nfields {
            slot_of[c] = j;
        }
    }
    let mut row = [0f64; 16];
    let n = block.len();
    let mut pos = 0;
    // One pass: wanted fields are parsed where they stand, others skipped to the next ','.
    while pos < n {
        let line_start = pos;
        let mut i = pos;
        let mut field = 0;
        let mut ok = true;
        loop {
            let sl = if field < cols.nfields {
                slot_of[field]
            } else {
                usize::MAX
            };
            if sl != usize::MAX {
                match parse_at(block, i) {
                    Some((v, e)) => {
                        row[sl] = v;
                        i = e;
                    }
                    None => {
                        ok = false;
                        while i < n && block[i] != b'\n' {
                            i += 1;
                        }
                    }
                }
            } else {
                while i < n && block[i] != b',' && block[i] != b'\n' {
                    i += 1;
                }
            }
            field += 1;
            if i >= n || block[i] == b'\n' {
                break;
            }
            i += 1; // past ','
        }
        let line_end = i.min(n);
        pos = line_end + 1;
        if !ok || field != cols.nfields {
            if is_blank(&block[line_start..line_end]) {
                continue;
            }
            return false;
        }
        out.extend_from_slice(&row[..k]);
    }
    true
}

/// Streams the data rows of `path` as slices `[t, ia, ib, ic, (va, vb, vc), (wm)]` (voltages
/// and speed only when the log has them), in file order, parsing in parallel.
/// Returns `Ok(false)` when the fast path gave up (see the module documentation).
///
/// # Errors
/// I/O errors and header errors (from [`LogReader::open`]).
pub fn for_each_row(
    path: &Path,
    progress: &mut dyn FnMut(f64),
    on_row: &mut dyn FnMut(&[f64]) -> bool,
) -> Result<bool, LogError> {
    let io = |source| LogError::Io {
        path: path.display().to_string(),
        source,
    };
    let rdr = LogReader::open(path)?;
    let ch = rdr.channels();
    drop(rdr);
    let mut f = std::fs::File::open(path).map_err(io)?;
    let total = f.metadata().map_err(io)?.len().max(1) as f64;
    // Header line.
    let mut head = Vec::new();
    {
        let mut buf = [0u8; 4096];
        loop {
            let k = f.read(&mut buf).map_err(io)?;
            if k == 0 {
                break;
            }
            head.extend_from_slice(&buf[..k]);
            if head.contains(&b'\n') {
                break;
            }
        }
    }
    let nl = match head.iter().position(|&b| b == b'\n') {
        Some(p) => p,
        None => return Ok(false),
    };
    let header: Vec<String> = String::from_utf8_lossy(&head[..nl])
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let find = |n: &str| header.iter().position(|h| h == n);
    let mut idx = vec![];
    for n in ["t_s", "ia_A", "ib_A", "ic_A"] {
        match find(n) {
            Some(i) => idx.push(i),
            None => return Ok(false),
        }
    }
    if ch.voltages {
        for n in ["va_V", "vb_V", "vc_V"] {
            match find(n) {
                Some(i) => idx.push(i),
                None => return Ok(false),
            }
        }
    }
    if ch.speed {
        match find("wm_rad_s") {
            Some(i) => idx.push(i),
            None => return Ok(false),
        }
    }
    if idx.len() > 16 {
        return Ok(false);
    }
    let cols = Cols {
        idx,
        nfields: header.len(),
    };
    let width = cols.idx.len();
    let mut carry: Vec<u8> = head[nl + 1..].to_vec();
    let mut read_bytes = head.len() as f64;
    let mut prev_t = f64::NEG_INFINITY;
    let batch = rayon::current_num_threads().max(1) * 2;
    let mut eof = false;
    while !eof {
        // Gather a batch of line-aligned blocks.
        let mut blocks: Vec<Vec<u8>> = Vec::with_capacity(batch);
        while blocks.len() < batch {
            let mut buf = std::mem::take(&mut carry);
            let start = buf.len();
            buf.resize(start + BLOCK, 0);
            let mut filled = start;
            while filled < buf.len() {
                let k = f.read(&mut buf[filled..]).map_err(io)?;
                if k == 0 {
                    eof = true;
                    break;
                }
                filled += k;
            }
            read_bytes += (filled - start) as f64;
            buf.truncate(filled);
            if eof {
                if !buf.is_empty() {
                    blocks.push(buf);
                }
                break;
            }
            match buf.iter().rposition(|&b| b == b'\n') {
                Some(p) => {
                    carry = buf[p + 1..].to_vec();
                    buf.truncate(p + 1);
                    blocks.push(buf);
                }
                None => {
                    carry = buf;
                }
            }
        }
        let parsed: Vec<Option<Vec<f64>>> = blocks
            .par_iter()
            .map(|b| {
                let mut out = Vec::with_capacity(b.len() / 8);
                if parse_block(b, &cols, &mut out) {
                    Some(out)
                } else {
                    None
                }
            })
            .collect();
        for p in parsed {
            let Some(v) = p else { return Ok(false) };
            for row in v.chunks_exact(width) {
                let t = row[0];
                if t <= prev_t || !t.is_finite() {
                    return Ok(false);
                }
                prev_t = t;
                if !on_row(row) {
                    return Ok(true);
                }
            }
        }
        progress((read_bytes / total).min(1.0));
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_pick_columns_and_skip_blank_lines() {
        let cols = Cols {
            idx: vec![0, 2],
            nfields: 3,
        };
        let mut out = vec![];
        assert!(parse_block(b"1,2,3\n4, 5 ,6\r\n\n7,8,9", &cols, &mut out));
        assert_eq!(out, vec![1.0, 3.0, 4.0, 6.0, 7.0, 9.0]);
        let mut out = vec![];
        assert!(!parse_block(b"1,2\n", &cols, &mut out));
        assert!(!parse_block(b"1,x,y\n", &cols, &mut out));
    }

    #[test]
    fn parses_like_std() {
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
            "12345678901234567890",
        ] {
            let a = parse_f64(s.as_bytes()).unwrap();
            let b: f64 = s.parse().unwrap();
            assert!(
                (a - b).abs() <= 4.0 * f64::EPSILON * b.abs(),
                "{s}: {a} vs {b}"
            );
        }
        for s in ["", "-", "abc", "1.2.3", "1e", "nan", "1,2"] {
            assert!(parse_f64(s.as_bytes()).is_none(), "{s}");
        }
    }
}
