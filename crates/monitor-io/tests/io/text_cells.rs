//! Issue 65: a cell of text (`abc`) in a measured column of a CSV log is a bad cell, like
//! NaN: the file loads, the data-quality stage holds the cell out and counts it, and the
//! rest of the log is judged. Text in the time column, or a header that cannot be read,
//! still refuses the file with its line and column.

use monitor_io::log::quality::{BadCells, CellLimits, CleanSink, QualityStage, TimeBase};
use monitor_io::log::{LogError, LogFile, Row};
use monitor_io::params::ParamFile;
use std::path::Path;

/// Counts what the stage passes on.
#[derive(Default)]
struct Passed {
    rows: u64,
    rows_with_a_bad_cell: u64,
}

impl CleanSink for Passed {
    fn begin(&mut self, _base: &TimeBase) -> bool {
        true
    }
    fn row(&mut self, _row: &Row, bad: BadCells) -> bool {
        self.rows += 1;
        if bad != BadCells::default() {
            self.rows_with_a_bad_cell += 1;
        }
        true
    }
    fn new_segment(&mut self, _why: monitor_io::log::quality::SegmentBreak) -> bool {
        true
    }
    fn restart(&mut self) {
        *self = Passed::default();
    }
}

/// A 50 Hz, 10 A, 5 kHz log of 1 s (5000 rows), with `cell` in place of row `k`'s `ib_A`
/// (line `k + 2`), or its time when `in_time`.
fn log_with(dir: &Path, k: usize, cell: &str, in_time: bool) -> std::path::PathBuf {
    let mut text = String::from("t_s,ia_A,ib_A,ic_A\n");
    for n in 0..5000 {
        let t = n as f64 / 5000.0;
        let w = 2.0 * std::f64::consts::PI * 50.0 * t;
        let i = |ph: f64| 10.0 * (w - ph).cos();
        let tp = 2.0 * std::f64::consts::PI / 3.0;
        let (time, ib) = match (n == k, in_time) {
            (true, true) => (cell.to_string(), i(tp).to_string()),
            (true, false) => (t.to_string(), cell.to_string()),
            _ => (t.to_string(), i(tp).to_string()),
        };
        text += &format!("{time},{},{ib},{}\n", i(0.0), i(-tp));
    }
    let p = dir.join("log.csv");
    std::fs::write(&p, text).expect("write the log");
    p
}

/// The log read through the data-quality stage: its report and what was passed on.
fn judged(path: &Path) -> Result<(monitor_io::log::quality::DataQuality, Passed), LogError> {
    let log = LogFile::open(path)?;
    let mut passed = Passed::default();
    let limits = CellLimits::for_params(&ParamFile::reference_3hp());
    let mut stage = QualityStage::new(&mut passed, limits, log.shown());
    log.for_each_row(&mut |_| {}, &mut stage)?;
    let q = stage.finish()?;
    Ok((q, passed))
}

#[test]
fn a_text_cell_in_a_current_column_is_a_bad_cell_counted_like_nan() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (q, passed) = judged(&log_with(dir.path(), 2500, "abc", false)).expect("the file loads");
    assert_eq!(q.rows_read, 5000, "{q:?}");
    assert_eq!(q.bad_cells.get("ib_A"), Some(&1), "{:?}", q.bad_cells);
    assert_eq!(q.bad_cells.values().sum::<u64>(), 1, "{:?}", q.bad_cells);
    assert_eq!(q.bad_rows, 1, "{q:?}");
    // The rest is judged: every other row passed on clean.
    assert!(passed.rows >= 4999, "{}", passed.rows);
    assert!(passed.rows_with_a_bad_cell <= 1);
    // ... exactly as a NaN there is.
    let (nan, _) = judged(&log_with(dir.path(), 2500, "NaN", false)).expect("loads");
    assert_eq!(nan.bad_cells, q.bad_cells);
    assert_eq!(nan.bad_rows, q.bad_rows);
}

#[test]
fn text_in_the_time_column_or_an_unreadable_header_still_refuses_the_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let e = judged(&log_with(dir.path(), 2500, "abc", true))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("line 2502") && e.contains("'t_s'") && e.contains("'abc' is not a number"),
        "{e}"
    );
    let header = dir.path().join("semicolons.csv");
    std::fs::write(&header, "t_s;ia_A;ib_A;ic_A\n0;1;2;3\n").expect("write");
    assert!(judged(&header).is_err());
}
