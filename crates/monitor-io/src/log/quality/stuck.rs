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
    runs: [u32; 6],
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

    /// Follows `row` and marks its stuck cells in `bad` (cells already bad are left out of
    /// the runs).
    #[inline]
    pub fn check(&mut self, row: &Row, bad: &mut BadCells) {
        let v = row.v_abc.unwrap_or([f64::NAN; 3]);
        let values = [v[0], v[1], v[2], row.i_abc[0], row.i_abc[1], row.i_abc[2]];
        // The common row: no phase cell bad, every reading present, finite and changed
        // (a voltage absent counts as changed: it starts no run). Every run present is one
        // row long, too short to be stuck.
        let phase_bad = PHASES.iter().any(|c| bad.has(*c));
        let has_v = row.v_abc.is_some();
        let fresh = values
            .iter()
            .zip(&self.last)
            .enumerate()
            .fold(true, |all, (k, (x, last))| {
                all & ((k < 3 && !has_v) | ((x != last) & (x.abs() <= f64::MAX)))
            });
        if fresh && !phase_bad && self.run_min > 1 {
            self.last = values;
            self.runs = if has_v { [1; 6] } else { [0, 0, 0, 1, 1, 1] };
            return;
        }
        self.check_runs(values, row.v_abc.is_some(), bad);
    }

    /// [`StuckTracker::check`] channel by channel.
    #[cold]
    fn check_runs(&mut self, values: [f64; 6], has_v: bool, bad: &mut BadCells) {
        let mut longest = 0;
        // Selects, not jumps: every channel of a live log changes every row.
        for k in 0..6 {
            let x = values[k];
            let ok = !bad.has(PHASES[k]) && x.is_finite();
            let run = if ok && x == self.last[k] {
                self.runs[k].saturating_add(1)
            } else {
                u32::from(ok)
            };
            self.last[k] = if ok { x } else { f64::NAN };
            self.runs[k] = run;
            longest = longest.max(run);
        }
        // (Every row of a live log ends here: no run is long.)
        if longest >= self.run_min {
            self.mark(has_v, bad);
        }
    }

    /// Marks the stuck cells of the row just followed.
    fn mark(&self, has_v: bool, bad: &mut BadCells) {
        let stuck: [bool; 6] = std::array::from_fn(|k| self.runs[k] >= self.run_min);
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

    fn marked(rows: &[Row]) -> [u32; 6] {
        let mut tr = StuckTracker::new(1e-4, 50.0);
        let mut n = [0u32; 6];
        for r in rows {
            let mut b = BadCells::default();
            tr.check(r, &mut b);
            for (k, c) in PHASES.iter().enumerate() {
                n[k] += u32::from(b.has(*c));
            }
        }
        n
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
