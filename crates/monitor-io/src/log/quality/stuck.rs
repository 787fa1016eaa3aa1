//! Stuck and dead channels ([`StuckTracker`]): an alternating channel whose reading does not
//! change.
//!
//! A phase voltage or current of a running machine alternates at the supply frequency: with
//! sensor noise it changes every sample, and even a noise-free, quantised reading stays on
//! one value only near a peak, for a small fraction of a period. A run of identical readings
//! lasting [`STUCK_PERIODS`] of a supply period (and at least [`STUCK_MIN_SAMPLES`] rows) is
//! a frozen sensor, a held DAQ channel or a disconnected input. It is judged per set (the
//! three voltages, the three currents):
//! - one or two channels of a set frozen while another channel of the set alternates: the
//!   frozen channels' cells are bad from then on until they move again;
//! - a whole set frozen while the other set alternates (currents flat with the supply on,
//!   voltages flat with current flowing): the frozen set's cells are bad — a dead sensor
//!   set, a channel in the wrong unit or a disconnected motor, never a perfect fit;
//! - both sets frozen: the machine is off, nothing is marked.
//!
//! The first [`STUCK_PERIODS`] of a run pass before the run is known; the count of bad cells
//! says how many were marked.

use super::BadCells;
use crate::log::{Column, Row};

/// A run of identical readings this long (in supply periods) is stuck.
pub const STUCK_PERIODS: f64 = 0.25;
/// ... and at least this many rows.
pub const STUCK_MIN_SAMPLES: u32 = 8;

/// The six phase channels, voltages then currents.
const PHASES: [Column; 6] = [
    Column::Va,
    Column::Vb,
    Column::Vc,
    Column::Ia,
    Column::Ib,
    Column::Ic,
];

/// Runs of identical readings of the six phase channels; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct StuckTracker {
    /// Rows a run must last to be stuck.
    run_min: u32,
    /// Per channel (va, vb, vc, ia, ib, ic): last reading (NaN after a bad cell) ...
    last: [f64; 6],
    /// ... and the length of its run (0 after a bad cell).
    runs: [u64; 6],
}

impl StuckTracker {
    /// A tracker for rows `period_s` apart on a supply of `supply_hz`.
    pub fn new(period_s: f64, supply_hz: f64) -> Self {
        let per_period = 1.0 / (period_s * supply_hz).max(f64::MIN_POSITIVE);
        let run = (STUCK_PERIODS * per_period)
            .ceil()
            .min(f64::from(u32::MAX / 2)) as u32;
        StuckTracker {
            run_min: run.max(STUCK_MIN_SAMPLES),
            last: [f64::NAN; 6],
            runs: [0; 6],
        }
    }

    /// The readings of `row` the tracker follows (va, vb, vc, ia, ib, ic; NaN for absent
    /// voltages, which never repeat).
    #[inline(always)]
    pub(super) fn readings(row: &Row) -> [f64; 6] {
        let v = row.v_abc.unwrap_or([f64::NAN; 3]);
        [v[0], v[1], v[2], row.i_abc[0], row.i_abc[1], row.i_abc[2]]
    }

    /// Follows a row with no bad phase cell when no run of its reaches the length of a
    /// stuck channel (true); else leaves the state as it was (false: the row is for
    /// [`StuckTracker::check_flagged`], which may mark it). The same runs as
    /// [`StuckTracker::check_flagged`] of the row when it marks nothing.
    #[inline(always)]
    pub(super) fn follow_unmarked(&mut self, row: &Row) -> bool {
        let x = Self::readings(row);
        let v_on = 0u64.wrapping_sub(u64::from(row.v_abc.is_some()));
        let mut runs = [0u64; 6];
        let mut long = false;
        for (k, run) in runs.iter_mut().enumerate() {
            let same = 0u64.wrapping_sub(u64::from(x[k] == self.last[k]));
            // (Without voltages their runs stay at 0.)
            let on = if k < 3 { v_on } else { u64::MAX };
            *run = ((self.runs[k] & same).wrapping_add(1)) & on;
            long |= *run >= u64::from(self.run_min);
        }
        if long {
            return false;
        }
        self.last = x;
        self.runs = runs;
        true
    }

    /// [`StuckTracker::follow_unmarked`] of rows given channel by channel (`x`: the six
    /// channels' readings of at least `*n` rows, the voltages' left out when `has_v` is
    /// false): `*n` cut to the rows before the first whose run reaches a stuck one's; the
    /// tracker after them.
    pub(super) fn follow_columns(&self, x: [&[f64]; 6], has_v: bool, n: &mut usize) -> Self {
        let run_min = u64::from(self.run_min);
        let first = if has_v { 0 } else { 3 };
        let reach = (self.run_min as usize).saturating_sub(1);
        for (k, xs) in x.iter().enumerate().skip(first) {
            let (mut run, mut last) = (self.runs[k], self.last[k]);
            let xs = xs.get(..*n).unwrap_or(xs);
            // A run as long as a stuck one's either goes on from the last row followed or
            // has equal readings `run_min - 1` rows apart: without either (a live
            // channel), no run is looked for.
            let far = xs.iter().zip(xs.get(reach..).unwrap_or_default());
            if xs.first() != Some(&last) && !far.fold(false, |any, (a, b)| any | (a == b)) {
                continue;
            }
            for (j, &v) in xs.iter().enumerate() {
                if v == last {
                    run += 1;
                    if run >= run_min {
                        *n = j;
                        break;
                    }
                } else {
                    run = 1;
                }
                last = v;
            }
        }
        let mut out = self.clone();
        let Some(end) = n.checked_sub(1) else {
            return out;
        };
        for (k, xs) in x.iter().enumerate() {
            if k < first {
                (out.last[k], out.runs[k]) = (f64::NAN, 0);
                continue;
            }
            // The run the last row ends: equal readings back from it, and the run before
            // the first row when they reach it.
            let xs = &xs[..=end];
            let back = xs.iter().rev().take_while(|&&v| v == xs[end]).count();
            let before = if back == xs.len() && xs[end] == self.last[k] {
                self.runs[k]
            } else {
                0
            };
            (out.last[k], out.runs[k]) = (xs[end], back as u64 + before);
        }
        out
    }

    /// Follows `row` and marks its stuck cells in `bad` (cells already bad are left out of
    /// the runs).
    #[inline]
    pub fn check(&mut self, row: &Row, bad: &mut BadCells) {
        let v = row.v_abc.unwrap_or([f64::NAN; 3]);
        let values = [v[0], v[1], v[2], row.i_abc[0], row.i_abc[1], row.i_abc[2]];
        // Branch-free (every channel of a live log changes nearly every row): per channel
        // a mask of ones where the cell counts (not bad, finite) and one where it repeats
        // the last reading; a run goes on, starts at one, or is 0 for a cell left out.
        let mask = |b: bool| 0u64.wrapping_sub(u64::from(b));
        let limit = u64::from(self.run_min).wrapping_sub(1);
        let mut over = 0u64;
        for (k, (&x, c)) in values.iter().zip(&PHASES).enumerate() {
            let ok = mask(!bad.has(*c) & (x.abs() <= f64::MAX));
            let same = mask(x == self.last[k]);
            let run = ((self.runs[k] & same).wrapping_add(1)) & ok;
            self.runs[k] = run;
            self.last[k] = f64::from_bits((x.to_bits() & ok) | (f64::NAN.to_bits() & !ok));
            // The top bit set when the run is at least `run_min` long.
            over |= limit.wrapping_sub(run);
        }
        // (Every row of a live log ends here: no run is long.)
        if over >> 63 != 0 {
            self.mark(row.v_abc.is_some(), bad);
        }
    }

    /// [`StuckTracker::check`] of a row whose non-finite phase cells `bad` already flags
    /// (as [`BadCells::of`] does): the common row, with no phase cell bad, is followed
    /// without judging each cell again; the same runs, the same marks.
    #[inline]
    pub(super) fn check_flagged(&mut self, row: &Row, bad: &mut BadCells) {
        if PHASES.iter().any(|c| bad.has(*c)) {
            return self.check(row, bad);
        }
        let v = row.v_abc.unwrap_or([f64::NAN; 3]);
        let values = [v[0], v[1], v[2], row.i_abc[0], row.i_abc[1], row.i_abc[2]];
        // The row of a live log: every channel moved (a NaN never repeats), every run
        // starts again at one (none without voltages), none is long (`run_min` >= 8).
        let eq = |k: usize| u8::from(values[k] == self.last[k]);
        if eq(0) | eq(1) | eq(2) | eq(3) | eq(4) | eq(5) == 0 {
            self.last = values;
            let v_runs = u64::from(row.v_abc.is_some());
            self.runs = [v_runs, v_runs, v_runs, 1, 1, 1];
            return;
        }
        let limit = u64::from(self.run_min).wrapping_sub(1);
        let mut over = 0u64;
        for (k, &x) in values.iter().enumerate() {
            let same = 0u64.wrapping_sub(u64::from(x == self.last[k]));
            let run = (self.runs[k] & same).wrapping_add(1);
            self.runs[k] = run;
            over |= limit.wrapping_sub(run);
        }
        self.last = values;
        if row.v_abc.is_none() {
            // No voltages: no runs (their NaN never repeats, and is the mark of a cell
            // left out).
            self.runs[..3].fill(0);
            over = limit.wrapping_sub(self.runs[3]) | limit.wrapping_sub(self.runs[4]);
            over |= limit.wrapping_sub(self.runs[5]);
        }
        // The top bit set when a run is at least `run_min` long. (Every row of a live
        // log ends here: no run is long.)
        if over >> 63 != 0 {
            self.mark(row.v_abc.is_some(), bad);
        }
    }

    /// Marks the stuck cells of the row just followed.
    fn mark(&self, has_v: bool, bad: &mut BadCells) {
        let stuck: [bool; 6] = std::array::from_fn(|k| self.runs[k] >= u64::from(self.run_min));
        let alive = |set: &[bool]| set.iter().any(|s| !s);
        let (sv, si) = (&stuck[..3], &stuck[3..]);
        for (k, c) in PHASES.iter().enumerate() {
            let (own, other) = if k < 3 { (sv, si) } else { (si, sv) };
            let other_alive = if k < 3 {
                alive(other)
            } else {
                has_v && alive(other)
            };
            if stuck[k] && (alive(own) || other_alive) {
                bad.set(*c);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 50 Hz three-phase row at `t`, noise-free (the hardest case for the detector).
    fn row(t: f64) -> Row {
        let w = std::f64::consts::TAU * 50.0 * t;
        let ph = |a: f64, k: f64| a * (w - k * std::f64::consts::TAU / 3.0).cos();
        Row {
            t_s: t,
            v_abc: Some([ph(300.0, 0.0), ph(300.0, 1.0), ph(300.0, 2.0)]),
            i_abc: [ph(10.0, 0.0), ph(10.0, 1.0), ph(10.0, 2.0)],
            wm_rad_s: Some(150.0),
            enc_count: None,
            t_winding_c: None,
        }
    }

    /// The cells marked stuck in `rows` (their bad cells those of [`BadCells::of`]), the
    /// same by [`StuckTracker::check`] and [`StuckTracker::check_flagged`].
    fn marked(rows: &[Row]) -> [u32; 6] {
        let lim = super::super::CellLimits {
            v_max: 1000.0,
            i_max: 100.0,
            wm_max: 1000.0,
            supply_hz: 50.0,
            sync_rad_s: 157.0,
            pole_pairs: 2.0,
        };
        let (mut tr, mut flagged) = (StuckTracker::new(1e-4, 50.0), StuckTracker::new(1e-4, 50.0));
        let mut n = [0u32; 6];
        for r in rows {
            let before = BadCells::of(r, &lim);
            let (mut b, mut f) = (before, before);
            tr.check(r, &mut b);
            flagged.check_flagged(r, &mut f);
            assert_eq!(b, f, "{r:?}");
            for (k, c) in PHASES.iter().enumerate() {
                n[k] += u32::from(b.has(*c) && !before.has(*c));
            }
        }
        n
    }

    #[test]
    fn without_voltages_or_with_missing_cells_the_currents_are_judged_alone() {
        let rows: Vec<Row> = (0..20_000)
            .map(|k| {
                let mut r = row(k as f64 * 1e-4);
                r.v_abc = None;
                if (5000..10_000).contains(&k) {
                    r.i_abc[1] = -2.0;
                }
                if k % 997 == 0 {
                    r.i_abc[2] = f64::NAN;
                }
                r
            })
            .collect();
        let n = marked(&rows);
        assert_eq!(n[..3], [0, 0, 0]);
        assert!(n[4] >= 4940 && n[4] <= 4952, "{n:?}");
        assert_eq!([n[3], n[5]], [0, 0]);
    }

    #[test]
    fn live_channels_pass_even_quantised_at_their_peaks() {
        // 10 kHz, readings on a coarse 12-bit grid of a 1000 V / 100 A range.
        let rows: Vec<Row> = (0..20_000)
            .map(|k| {
                let mut r = row(k as f64 * 1e-4);
                let q = |x: f64, lsb: f64| (x / lsb).round() * lsb;
                r.v_abc = r.v_abc.map(|v| v.map(|x| q(x, 2000.0 / 4096.0)));
                r.i_abc = r.i_abc.map(|x| q(x, 200.0 / 4096.0));
                r
            })
            .collect();
        assert_eq!(marked(&rows), [0; 6]);
    }

    #[test]
    fn a_frozen_phase_is_marked_and_a_dead_set_too_but_not_a_machine_at_rest() {
        let mut rows: Vec<Row> = (0..20_000).map(|k| row(k as f64 * 1e-4)).collect();
        for r in &mut rows[5000..10_000] {
            r.i_abc[0] = 3.0;
        }
        let n = marked(&rows);
        // 5000 rows frozen; the first 50 (a quarter period) pass before the run is known.
        assert!(n[3] >= 4940 && n[3] <= 4952, "{n:?}");
        assert_eq!(n[..3], [0, 0, 0]);
        assert_eq!(n[4..], [0, 0]);

        let mut dead: Vec<Row> = (0..20_000).map(|k| row(k as f64 * 1e-4)).collect();
        for r in &mut dead {
            r.i_abc = [0.0; 3];
        }
        let n = marked(&dead);
        assert!(n[3..].iter().all(|&x| x >= 19_900), "{n:?}");
        assert_eq!(n[..3], [0, 0, 0]);

        let rest: Vec<Row> = (0..20_000)
            .map(|k| Row {
                v_abc: Some([0.0; 3]),
                i_abc: [0.0; 3],
                ..row(k as f64 * 1e-4)
            })
            .collect();
        assert_eq!(marked(&rest), [0; 6]);
    }
}
