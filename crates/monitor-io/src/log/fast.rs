//! The fast path of [`super::LogFile::for_each_row`]: a parallel, bounded-memory CSV number
//! reader for long logs.
//!
//! The header was parsed by [`super::LogFile::open`] (one column map for both paths).
//! Data are read in 4 MiB blocks cut at line ends (`memchr`); the numbers are
//! parsed correctly rounded, the same values as `str::parse::<f64>` ([`super::csv_line`]);
//! the blocks of a batch are parsed into rows in
//! parallel (rayon), and the rows are handed over in file order. Reading
//! the next batch, parsing the current one and handing over the previous one overlap, and
//! the buffers are reused, so memory stays at a few tens of MB whatever the log's length.
//!
//! Any cell the fast path does not accept (quotes, tabs, text) or a wrong field count makes
//! [`for_each_row`] return `Ok(false)`: the caller then re-reads with the exact reader,
//! whose message names the line and column. Numbers that are not finite ("NaN", "inf") and
//! times that do not increase are handed over: the data-quality stage judges them.

use super::csv_line::{parse_block_with, Cols};
use super::source::row_from_values;
use super::source::{ColumnMap, Opened};
use super::{Column, LogError, Row};
use rayon::prelude::*;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes per block (one parallel work item).
pub(super) const BLOCK_BYTES: usize = 4 << 20;
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
    /// Bytes of the file read so far, the header's included.
    read: u64,
}

impl BlockReader {
    /// A reader of `log`'s data lines (from the end of its header), `block` bytes per block.
    fn open(log: &Opened<'_>, block: usize) -> std::io::Result<Self> {
        let mut f = File::open(log.path())?;
        f.seek(SeekFrom::Start(log.header_bytes()))?;
        Ok(BlockReader {
            f,
            block: block.max(1),
            carry: Vec::new(),
            pool: Vec::new(),
            eof: false,
            read: log.header_bytes(),
        })
    }

    /// Reads up to `count` blocks; an empty result at the end of the file.
    fn batch(&mut self, count: usize) -> std::io::Result<Vec<Vec<u8>>> {
        let mut blocks = Vec::with_capacity(count);
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
            self.read += k as u64;
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
        Ok(blocks)
    }
}

/// Streams the data rows of `log` in file order, parsing in parallel, `block` bytes per
/// work item, handed to `on_rows` [`HAND_ROWS`] at a time (a sink that judges a block of
/// rows at once, as the data-quality stage does); it returns [`ControlFlow::Break`] with
/// the index of the row that asked to stop. `progress` gets the fraction of the file read.
/// Returns the number of blank lines skipped, or `Ok(None)` when the fast path gave up
/// (see the module documentation; a time column of ISO 8601 text is the exact reader's).
///
/// # Errors
/// I/O errors.
pub(super) fn for_each_row(
    log: &Opened<'_>,
    block: usize,
    progress: &mut dyn FnMut(f64),
    on_rows: &mut dyn FnMut(&[Row]) -> ControlFlow<usize>,
) -> Result<Option<u64>, LogError> {
    if log.columns().time.is_text() {
        return Ok(None);
    }
    let io = |source| LogError::Io {
        path: log.shown().to_string(),
        source,
    };
    let total = log.len_bytes().max(1) as f64;
    let columns = log.columns();
    let (present, cols) = slot_layout(columns);
    // (Run by the parsing workers: the reading thread only hands the rows over.)
    let to_row = |slots: &[f64]| row_of_slots(&present, slots, columns);
    let mut reader = BlockReader::open(log, block).map_err(io)?;
    let per_batch = rayon::current_num_threads().max(1) * 2;
    // Pipeline: read batch k+1 | parse batch k | hand over batch k-1 (one [`turn`]).
    let mut to_parse = reader.batch(per_batch).map_err(io)?;
    let mut to_hand: Option<Vec<Option<Parsed>>> = None;
    let mut outs: Vec<Parsed> = Vec::new();
    let blank = AtomicU64::new(0);
    loop {
        if to_parse.is_empty() && to_hand.is_none() {
            return Ok(Some(blank.into_inner()));
        }
        let read_bytes = reader.read;
        let parse = (&cols, &to_row, &blank);
        let t = turn(
            &mut reader,
            per_batch,
            &to_parse,
            to_hand.take(),
            parse,
            &mut outs,
            on_rows,
        );
        match t.verdict {
            Some(true) => return Ok(Some(blank.into_inner())),
            Some(false) => return Ok(None),
            None => {}
        }
        progress((read_bytes as f64 / total).min(1.0));
        reader.pool.append(&mut to_parse);
        to_hand = t.parsed;
        to_parse = match t.next {
            Some(r) => r.map_err(io)?,
            None => Vec::new(),
        };
    }
}

/// The row of a parsed line: slot j of `slots` is column `present[j]` ([`slot_layout`]),
/// the absent columns 0 before [`row_from_values`].
#[inline]
fn row_of_slots(present: &[usize], slots: &[f64], columns: &ColumnMap) -> Row {
    let mut v = [0.0f64; Column::COUNT];
    for (&c, &x) in present.iter().zip(slots) {
        v[c] = x;
    }
    row_from_values(&v, columns)
}

/// The present columns of `columns` in [`Column::ALL`] order (slot j of a parsed row is
/// column `present[j]`) and the fields the parser picks for them.
fn slot_layout(columns: &ColumnMap) -> (Vec<usize>, Cols) {
    let present: Vec<usize> = (0..Column::ALL.len())
        .filter(|&c| columns.field[c].is_some())
        .collect();
    let idx: Vec<usize> = present.iter().filter_map(|&c| columns.field[c]).collect();
    let cols = Cols::new(&idx, columns.n_fields);
    (present, cols)
}

/// What one turn of the pipeline gives.
struct Turn {
    /// The next batch's blocks (`None`: the file was read to its end).
    next: Option<std::io::Result<Vec<Vec<u8>>>>,
    /// The current batch's rows per block ([`parse_blocks`]; `None`: nothing to parse).
    parsed: Option<Vec<Option<Parsed>>>,
    /// [`hand_over`]'s verdict on the previous batch (`None`: go on).
    verdict: Option<bool>,
}

/// One turn of the pipeline, the three stages overlapping: reads the next batch (one
/// task) | parses `to_parse` (parallel, into buffers from `outs`) | hands `to_hand` over to
/// `on_rows` (this thread, so `on_rows` need not be Send; its emptied buffers go back to
/// `outs`). `parse`: the parser's columns, the row builder and the blank-line count.
fn turn(
    reader: &mut BlockReader,
    per_batch: usize,
    to_parse: &[Vec<u8>],
    to_hand: Option<Vec<Option<Parsed>>>,
    parse: (&Cols, &(impl Fn(&[f64]) -> Row + Sync), &AtomicU64),
    outs: &mut Vec<Parsed>,
    on_rows: &mut dyn FnMut(&[Row]) -> ControlFlow<usize>,
) -> Turn {
    let mut next: Option<std::io::Result<Vec<Vec<u8>>>> = None;
    let mut parsed: Option<Vec<Option<Parsed>>> = None;
    let mut verdict: Option<bool> = None;
    let mut free_outs: Vec<Parsed> = Vec::new();
    rayon::in_place_scope(|s| {
        if !reader.eof {
            let (rd, nx) = (&mut *reader, &mut next);
            s.spawn(move |_| *nx = Some(rd.batch(per_batch)));
        }
        if !to_parse.is_empty() {
            let bufs: Vec<Parsed> = (0..to_parse.len())
                .map(|_| outs.pop().unwrap_or_default())
                .collect();
            let ((cols, to_row, blank), pr) = (parse, &mut parsed);
            s.spawn(move |_| *pr = Some(parse_blocks(to_parse, bufs, cols, to_row, blank)));
        }
        if let Some(batch) = to_hand {
            verdict = hand_over(batch, on_rows, &mut free_outs);
        }
    });
    outs.append(&mut free_outs);
    Turn {
        next,
        parsed,
        verdict,
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

/// Rows handed over at a time (what the data-quality stage judges as one block).
const HAND_ROWS: usize = 256;

/// Hands a parsed batch's rows to `on_rows` in order, [`HAND_ROWS`] at a time, returning
/// each emptied buffer to `free`. `Some(false)`: a block was not for the fast path (give
/// up); `Some(true)`: `on_rows` asked to stop; `None`: go on.
fn hand_over(
    batch: Vec<Option<Parsed>>,
    on_rows: &mut dyn FnMut(&[Row]) -> ControlFlow<usize>,
    free: &mut Vec<Parsed>,
) -> Option<bool> {
    for p in batch {
        let Some(v) = p else {
            return Some(false);
        };
        for rows in v.chunks(HAND_ROWS) {
            if on_rows(rows).is_break() {
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
    use crate::log::LogFile;
    use std::path::Path;

    /// The rows of a log through the exact reader.
    fn exact(path: &Path) -> Vec<Row> {
        let log = LogFile::open(path).unwrap();
        let mut r = super::super::exact::ExactRows::new(&log.opened()).unwrap();
        let mut v = vec![];
        while let Some(row) = r.next_row().unwrap() {
            v.push(row);
        }
        v
    }

    fn fast(path: &Path, block: usize) -> (bool, Vec<Row>) {
        let log = LogFile::open(path).unwrap();
        let mut v = vec![];
        let ok = for_each_row(&log.opened(), block, &mut |_| {}, &mut |r| {
            v.extend_from_slice(r);
            ControlFlow::Continue(())
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
        let ok = for_each_row(&log.opened(), 64, &mut |_| {}, &mut |rows| {
            for k in 0..rows.len() {
                n += 1;
                if n == 10 {
                    return ControlFlow::Break(k);
                }
            }
            ControlFlow::Continue(())
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
            // ... where the exact reader (behind `LogFile::for_each_row`) names the line of
            // a wrong field count; it accepts the quotes, and reads text in a measured
            // column as a bad cell (NaN, for the data-quality stage).
            let log = LogFile::open(&path).unwrap();
            let mut rows: Vec<Row> = Vec::new();
            let res = log.for_each_row(&mut |_| {}, &mut rows);
            if bad.contains('"') || bad.contains('x') || bad.contains("zz") {
                assert_eq!(res.unwrap(), 502);
                assert_eq!(rows.len(), 502, "the sink was restarted");
                let r = &rows[500];
                if bad.contains('x') {
                    assert!(r.v_abc.is_some_and(|v| v[0].is_nan()), "{bad}: {r:?}");
                }
                if bad.contains("zz") {
                    assert_eq!(r.enc_count, Some(crate::log::ENC_COUNT_UNREADABLE), "{bad}");
                }
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
}
