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
fn clarke(x: [f64; 3]) -> [f64; 2] {
    let alpha = (2.0 * x[0] - x[1] - x[2]) / 3.0;
    let beta = (x[1] - x[2]) / 3f64.sqrt();
    [alpha, beta]
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
