//! Duplicated and swapped channels ([`WiringCheck`]): what a DAQ's wiring or a spreadsheet
//! does to a log.
//!
//! - **Duplicated.** Two phase channels of one set (two currents, two voltages) that hold
//!   the same reading on more than [`DUPLICATE_SHARE`] of the rows where they alternate: one
//!   column was copied over another, or two inputs read the same sensor. A balanced
//!   three-phase set never has two phases equal for more than an instant per period.
//! - **Swapped.** The direction in which the space vector turns (the sign of the cross
//!   product of consecutive Clarke vectors, `alpha_k beta_{k+1} - beta_k alpha_{k+1}`) is
//!   the phase order. Currents turning the other way than the voltages on more than
//!   [`SWAPPED_SHARE`] of the rows where both turn is two phases swapped in one set: the
//!   machine cannot draw a negative-sequence current from a positive-sequence supply.
//!
//! Either finding withholds the verdict (the report's `wiring` lines say which).

use crate::log::Row;

/// Share of the alternating rows on which two channels must be equal to be duplicates.
pub const DUPLICATE_SHARE: f64 = 0.5;
/// Share of the turning rows on which the currents must turn against the voltages to be
/// swapped.
pub const SWAPPED_SHARE: f64 = 0.8;
/// Rows a finding needs before it is said.
const MIN_ROWS: u64 = 1000;

/// The counts of the checks; see the module documentation.
#[derive(Debug, Clone, Default)]
pub struct WiringCheck {
    /// Rows seen, and rows on which each pair (ab, bc, ca) of currents, then of voltages,
    /// read the same non-zero value.
    rows: u64,
    equal: [u64; 6],
    /// Rows on which both vectors turned, and on which they turned opposite ways.
    turning: u64,
    opposite: u64,
    last: Option<([f64; 2], [f64; 2])>,
}

/// Clarke's alpha and beta of a phase set.
#[inline(always)]
fn clarke(x: [f64; 3]) -> [f64; 2] {
    let alpha = (2.0 * x[0] - x[1] - x[2]) / 3.0;
    let beta = (x[1] - x[2]) / 3f64.sqrt();
    [alpha, beta]
}

/// Rows whose Clarke vectors [`WiringCheck::push_block`] computes at a time.
const CHUNK: usize = 64;

/// Alpha and beta of up to [`CHUNK`] rows.
type Clarke = [[f64; CHUNK]; 2];

/// [`clarke`] of each row of a phase set given channel by channel (at most [`CHUNK`] rows).
fn clarke_all(x: [&[f64]; 3]) -> Clarke {
    let mut out = [[0.0; CHUNK]; 2];
    let [a, b] = &mut out;
    for ((((alpha, beta), x0), x1), x2) in
        a.iter_mut().zip(b.iter_mut()).zip(x[0]).zip(x[1]).zip(x[2])
    {
        [*alpha, *beta] = clarke([*x0, *x1, *x2]);
    }
    out
}

/// Whether both vectors turned (the cross products of consecutive Clarke vectors), and
/// whether they turned opposite ways, as counts.
#[inline(always)]
fn turn_counts(turn_i: f64, turn_v: f64) -> (u64, u64) {
    let both = (turn_i != 0.0) & (turn_v != 0.0);
    (
        u64::from(both),
        u64::from(both & ((turn_i > 0.0) != (turn_v > 0.0))),
    )
}

/// The turns between consecutive rows of the first `m` rows of one chunk: rows on which
/// both vectors turned, and on which they turned opposite ways.
fn count_turns(ci: &Clarke, cv: &Clarke, m: usize) -> (u64, u64) {
    let m = m.min(CHUNK);
    let (ai, bi, av, bv) = (&ci[0][..m], &ci[1][..m], &cv[0][..m], &cv[1][..m]);
    let (mut turning, mut opposite) = (0, 0);
    for k in 1..m {
        let turn_i = ai[k - 1] * bi[k] - bi[k - 1] * ai[k];
        let turn_v = av[k - 1] * bv[k] - bv[k - 1] * av[k];
        let (t, o) = turn_counts(turn_i, turn_v);
        turning += t;
        opposite += o;
    }
    (turning, opposite)
}

/// Adds to `equal` the rows on which each pair (ab, bc, ca) of `x` read the same non-zero
/// value.
fn count_equal(equal: &mut [u64], x: [&[f64]; 3]) {
    let same = |p: f64, q: f64| u64::from((p == q) & (p != 0.0));
    let mut n = [0u64; 3];
    for ((&a, &b), &c) in x[0].iter().zip(x[1]).zip(x[2]) {
        n[0] += same(a, b);
        n[1] += same(b, c);
        n[2] += same(c, a);
    }
    for (e, n) in equal.iter_mut().zip(n) {
        *e += n;
    }
}

impl WiringCheck {
    /// Follows a row whose cells are all good.
    pub fn push(&mut self, r: &Row) {
        self.rows += 1;
        let i = r.i_abc;
        let pairs = |x: [f64; 3]| [(x[0], x[1]), (x[1], x[2]), (x[2], x[0])];
        for (k, (a, b)) in pairs(i).into_iter().enumerate() {
            self.equal[k] += u64::from(a == b && a != 0.0);
        }
        if let Some(v) = r.v_abc {
            for (k, (a, b)) in pairs(v).into_iter().enumerate() {
                self.equal[3 + k] += u64::from(a == b && a != 0.0);
            }
            let (ci, cv) = (clarke(i), clarke(v));
            if let Some((pi, pv)) = self.last {
                let turn_i = pi[0] * ci[1] - pi[1] * ci[0];
                let turn_v = pv[0] * cv[1] - pv[1] * cv[0];
                if turn_i != 0.0 && turn_v != 0.0 {
                    self.turning += 1;
                    self.opposite += u64::from((turn_i > 0.0) != (turn_v > 0.0));
                }
            }
            self.last = Some((ci, cv));
        }
    }

    /// Follows a block of rows whose cells are all good, channel by channel (`v`: the
    /// voltages a, b, c when the rows have them; `i`: the currents, as long): the same
    /// counts as [`WiringCheck::push`] row by row, in loops the compiler vectorises.
    pub fn push_block(&mut self, v: Option<[&[f64]; 3]>, i: [&[f64]; 3]) {
        let n = i[0].len();
        self.rows += n as u64;
        count_equal(&mut self.equal[..3], i);
        let Some(v) = v else {
            return;
        };
        count_equal(&mut self.equal[3..], v);
        let mut start = 0;
        while start < n {
            let m = (n - start).min(CHUNK);
            let (ci, cv) = (
                clarke_all(i.map(|c| c.get(start..start + m).unwrap_or_default())),
                clarke_all(v.map(|c| c.get(start..start + m).unwrap_or_default())),
            );
            let first = |c: &Clarke| [c[0][0], c[1][0]];
            if let Some((pi, pv)) = self.last {
                let turn_i = pi[0] * first(&ci)[1] - pi[1] * first(&ci)[0];
                let turn_v = pv[0] * first(&cv)[1] - pv[1] * first(&cv)[0];
                let (t, o) = turn_counts(turn_i, turn_v);
                self.turning += t;
                self.opposite += o;
            }
            let (t, o) = count_turns(&ci, &cv, m);
            self.turning += t;
            self.opposite += o;
            let last = |c: &Clarke| [c[0][m - 1], c[1][m - 1]];
            self.last = Some((last(&ci), last(&cv)));
            start += m;
        }
    }

    /// A row that breaks the sequence (a bad cell, a gap): the next turn starts afresh.
    pub fn interrupt(&mut self) {
        self.last = None;
    }

    /// What was found, one line each (empty when nothing).
    pub fn findings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.rows < MIN_ROWS {
            return out;
        }
        const NAMES: [(&str, &str); 6] = [
            ("ia_A", "ib_A"),
            ("ib_A", "ic_A"),
            ("ic_A", "ia_A"),
            ("va_V", "vb_V"),
            ("vb_V", "vc_V"),
            ("vc_V", "va_V"),
        ];
        for (n, (a, b)) in self.equal.iter().zip(NAMES) {
            let share = *n as f64 / self.rows as f64;
            if share > DUPLICATE_SHARE {
                out.push(format!(
                    "{a} and {b} read the same value on {:.0} % of the rows: one channel duplicates the other (a copied column, or two inputs on one sensor)",
                    100.0 * share
                ));
            }
        }
        if self.turning >= MIN_ROWS {
            let share = self.opposite as f64 / self.turning as f64;
            if share > SWAPPED_SHARE {
                out.push(format!(
                    "the currents' phase order is reversed against the voltages' on {:.0} % of the rows: two current (or two voltage) channels are swapped",
                    100.0 * share
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: f64, order: [usize; 3], dup: bool) -> Row {
        let w = std::f64::consts::TAU * 50.0 * t;
        let ph = |a: f64, lag: f64, k: usize| {
            a * (w - lag - k as f64 * std::f64::consts::TAU / 3.0).cos()
        };
        let mut i = [0, 1, 2].map(|k| ph(10.0, 0.5, order[k]));
        if dup {
            i[1] = i[0];
        }
        Row {
            t_s: t,
            v_abc: Some([0, 1, 2].map(|k| ph(300.0, 0.0, k))),
            i_abc: i,
            wm_rad_s: None,
            enc_count: None,
            t_winding_c: None,
        }
    }

    fn check(order: [usize; 3], dup: bool) -> Vec<String> {
        let mut c = WiringCheck::default();
        for k in 0..10_000 {
            c.push(&row(k as f64 * 1e-4, order, dup));
        }
        c.findings()
    }

    #[test]
    fn a_clean_set_passes_and_swapped_or_duplicated_channels_are_named() {
        assert!(check([0, 1, 2], false).is_empty());
        let swapped = check([0, 2, 1], false);
        assert_eq!(swapped.len(), 1, "{swapped:?}");
        assert!(swapped[0].contains("reversed"), "{swapped:?}");
        let dup = check([0, 1, 2], true);
        assert!(
            dup.iter().any(|f| f.starts_with("ia_A and ib_A")),
            "{dup:?}"
        );
    }
}
