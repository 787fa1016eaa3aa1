//! Tests of the data-quality stage ([`super::QualityStage`]).

use super::*;

/// Collects what the stage passes on.
#[derive(Default)]
struct Collect {
    base: Option<TimeBase>,
    rows: Vec<(Row, BadCells)>,
    breaks: Vec<(usize, SegmentBreak)>,
}

impl CleanSink for Collect {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.base = Some(*base);
        true
    }
    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        self.rows.push((*row, bad));
        true
    }
    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        self.breaks.push((self.rows.len(), why));
        true
    }
    fn restart(&mut self) {
        *self = Collect::default();
    }
}

const LIMITS: CellLimits = CellLimits {
    v_max: 1000.0,
    i_max: 100.0,
    wm_max: 1000.0,
    supply_hz: 50.0,
    sync_rad_s: 157.08,
    pole_pairs: 2.0,
};

/// A 50 Hz three-phase row at time `t` (10 A peak).
fn row(t: f64) -> Row {
    let w = std::f64::consts::TAU * 50.0 * t;
    let ph = |k: f64| 10.0 * (w - k * std::f64::consts::TAU / 3.0).cos();
    Row {
        t_s: t,
        v_abc: Some([30.0 * ph(0.0), 30.0 * ph(1.0), 30.0 * ph(2.0)]),
        i_abc: [ph(0.0), ph(1.0), ph(2.0)],
        wm_rad_s: Some(150.0),
        enc_count: None,
        t_winding_c: None,
    }
}

/// Runs `times` (in the file's unit, rows built at `times * unit`) through the stage.
fn run(times: &[f64], unit: f64) -> (Collect, DataQuality) {
    let mut sink = Collect::default();
    let mut stage = QualityStage::new(&mut sink, LIMITS, "t.csv");
    for &t in times {
        let mut r = row(t * unit);
        r.t_s = t;
        assert!(stage.row(&r));
    }
    let q = stage.finish().unwrap();
    (sink, q)
}

fn grid(n: usize, fs: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 / fs).collect()
}

#[test]
fn a_clean_log_passes_unchanged() {
    let t = grid(20_000, 10_000.0);
    let (c, q) = run(&t, 1.0);
    assert_eq!(c.rows.len(), t.len());
    assert!(c
        .rows
        .iter()
        .zip(&t)
        .all(|((r, _), t)| (r.t_s - t).abs() < 1e-12));
    assert!(q.trusted && q.warnings.is_empty(), "{q:?}");
    assert!((q.sample_rate_hz - 10_000.0).abs() < 1e-6);
    assert!((q.current_frequency_hz.unwrap() - 50.0).abs() < 0.5);
}

#[test]
fn jittered_timestamps_go_onto_the_sample_clock() {
    // +/- 20 % of a period, uniform (a software timestamp), deterministic.
    let mut x = 1u64;
    let t: Vec<f64> = grid(50_000, 10_000.0)
        .into_iter()
        .map(|t| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            t + 2e-5 * ((x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0)
        })
        .collect();
    let (c, q) = run(&t, 1.0);
    assert_eq!(c.rows.len(), t.len());
    assert_eq!(q.irregular_intervals + q.timestamp_glitches, 0, "{q:?}");
    // The clock's distance from the true sample times: a fifth of the raw jitter's.
    let err: Vec<f64> = c
        .rows
        .iter()
        .enumerate()
        .skip(200)
        .map(|(k, (r, _))| r.t_s - k as f64 * 1e-4)
        .collect();
    let rms = (err.iter().map(|e| e * e).sum::<f64>() / err.len() as f64).sqrt();
    assert!(rms < 0.2 * 11.5e-6, "clock error {rms} s RMS");
    assert!(q.timestamp_jitter_rms_s > 1e-5 && q.trusted);
}

/// Rows handed over in blocks ([`RowSink::rows`]) pass as they do one by one: the same
/// rows, flags, breaks and report, through gaps, glitches, bad cells, a frozen channel,
/// quantised readings, jitter, a stretch without voltages and a time in milliseconds.
#[test]
fn blocks_of_rows_pass_as_rows_one_by_one() {
    let mut x = 7u64;
    let mut noise = move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut rows = Vec::new();
    for k in 0..60_000usize {
        let mut t = k as f64 * 1e-4;
        if (20_000..21_000).contains(&k) {
            t += 2e-5 * noise();
        }
        let mut r = row(t);
        // Quantised (readings repeat), a gap, a glitch, bad cells, a frozen phase.
        r.i_abc = r.i_abc.map(|i| (i * 8.0).round() / 8.0);
        if k % 5000 == 17 {
            r.t_s += 3.3e-5;
        }
        if (30_000..30_010).contains(&k) {
            r.i_abc[1] = f64::NAN;
        }
        if (40_000..41_000).contains(&k) {
            r.i_abc[2] = 1.0;
        }
        if (45_000..46_000).contains(&k) {
            r.v_abc = None;
        }
        if !(50_000..50_300).contains(&k) && k != 12_345 {
            rows.push(r);
        }
    }
    rows.push(rows[rows.len() - 3]);
    for unit in [1.0, 1e3] {
        let rows: Vec<Row> = rows
            .iter()
            .map(|r| Row {
                t_s: r.t_s * unit,
                ..*r
            })
            .collect();
        let mut one = Collect::default();
        let mut stage = QualityStage::new(&mut one, LIMITS, "t.csv");
        assert!(rows.iter().all(|r| stage.row(r)));
        let q_one = stage.finish().unwrap();
        for block in [1, 7, 256, 4096] {
            let mut blocks = Collect::default();
            let mut stage = QualityStage::new(&mut blocks, LIMITS, "t.csv");
            for b in rows.chunks(block) {
                assert_eq!(stage.rows(b), ControlFlow::Continue(()));
            }
            let q = stage.finish().unwrap();
            assert_eq!(format!("{q:?}"), format!("{q_one:?}"), "block {block}");
            assert_eq!(blocks.breaks.len(), one.breaks.len());
            assert_eq!(blocks.rows.len(), one.rows.len());
            for (a, b) in blocks.rows.iter().zip(&one.rows) {
                assert_eq!(format!("{a:?}"), format!("{b:?}"), "block {block}");
            }
        }
        assert!(
            q_one.glitch_bursts > 0 && q_one.gaps_bridged > 0,
            "{q_one:?}"
        );
        assert!(!q_one.stuck_cells.is_empty(), "{q_one:?}");
    }
}
