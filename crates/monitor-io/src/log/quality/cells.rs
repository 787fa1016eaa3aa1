//! Bad cells: values no sensor of the machine should report ([`CellLimits`], [`BadCells`]),
//! and missing ones (NaN, and an encoder count that was not a number,
//! [`crate::log::ENC_COUNT_UNREADABLE`]).

use crate::log::{Column, Row};
use crate::params::ParamFile;

/// Limits beyond which a cell is bad: magnitudes no sensor of this machine should report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellLimits {
    /// Largest |phase voltage| [V].
    pub v_max: f64,
    /// Largest |phase current| [A].
    pub i_max: f64,
    /// Largest |mechanical speed| [rad/s].
    pub wm_max: f64,
    /// Supply frequency of the parameter file [Hz].
    pub supply_hz: f64,
    /// The machine's mechanical synchronous speed [rad/s] (0: not known).
    pub sync_rad_s: f64,
    /// Its pole pairs.
    pub pole_pairs: f64,
}

impl CellLimits {
    /// The limits of a log of the parameter file's machine ([`ParamFile::log_limits`]:
    /// twice the sensor ranges, twice the supply's angular frequency), the replay's
    /// monitor's too.
    pub fn for_params(p: &ParamFile) -> Self {
        let limits = p.log_limits();
        CellLimits {
            v_max: f64::from(limits.v_max_v),
            i_max: f64::from(limits.i_max_a),
            wm_max: f64::from(limits.wm_max_rad_s),
            supply_hz: p.supply.f_hz,
            sync_rad_s: p.supply.omega_rad_s() / f64::from((p.motor.poles / 2).max(1)),
            pole_pairs: f64::from((p.motor.poles / 2).max(1)),
        }
    }
}

impl CellLimits {
    /// True when `x`, a cell of column `c`, lies beyond its limit (voltages, currents,
    /// speed; never for the time and the encoder count).
    pub fn beyond(&self, c: Column, x: f64) -> bool {
        let max = match c {
            Column::Va | Column::Vb | Column::Vc => self.v_max,
            Column::Ia | Column::Ib | Column::Ic => self.i_max,
            Column::Speed => self.wm_max,
            Column::Time | Column::Encoder | Column::Temperature => return false,
        };
        x.abs() > max
    }
}

/// The bad cells of a row: one bit per [`Column`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BadCells(u16);

impl BadCells {
    /// True when any cell is bad.
    pub fn any(self) -> bool {
        self.0 != 0
    }
    /// True when the cell of `c` is bad.
    pub fn has(self, c: Column) -> bool {
        self.0 & (1 << c as u16) != 0
    }
    /// Marks the cell of `c` good.
    pub fn clear(&mut self, c: Column) {
        self.0 &= !(1 << c as u16);
    }
    /// Marks the cell of `c` bad.
    pub fn set(&mut self, c: Column) {
        self.0 |= 1 << c as u16;
    }

    /// The bad cells of `row` against `lim`.
    #[inline]
    pub fn of(row: &Row, lim: &CellLimits) -> Self {
        // (Every row of a clean log ends here.)
        if Self::none_of(row, lim) {
            return BadCells(0);
        }
        Self::of_each(row, lim)
    }

    /// True when `row` has no bad cell against `lim` ([`BadCells::of`] is empty).
    #[inline(always)]
    pub(super) fn none_of(row: &Row, lim: &CellLimits) -> bool {
        // `|x| <= max` with `max` made finite: false for NaN and the infinities too.
        let within = |x: f64, max: f64| x.abs() <= max.min(f64::MAX);
        let i = row.i_abc;
        let mut good = within(i[0], lim.i_max) & within(i[1], lim.i_max) & within(i[2], lim.i_max);
        if let Some(v) = row.v_abc {
            good &= within(v[0], lim.v_max) & within(v[1], lim.v_max) & within(v[2], lim.v_max);
        }
        if let Some(w) = row.wm_rad_s {
            good &= within(w, lim.wm_max);
        }
        good & (row.enc_count != Some(crate::log::ENC_COUNT_UNREADABLE))
    }

    /// [`BadCells::of`] cell by cell.
    #[cold]
    fn of_each(row: &Row, lim: &CellLimits) -> Self {
        let within = |x: f64, max: f64| x.abs() <= max.min(f64::MAX);
        let out = |x: f64, max: f64| u16::from(!within(x, max));
        let bit = |c: Column| c as u16;
        let mut b = 0u16;
        if let Some(v) = row.v_abc {
            b |= out(v[0], lim.v_max) << bit(Column::Va)
                | out(v[1], lim.v_max) << bit(Column::Vb)
                | out(v[2], lim.v_max) << bit(Column::Vc);
        }
        let i = row.i_abc;
        b |= out(i[0], lim.i_max) << bit(Column::Ia)
            | out(i[1], lim.i_max) << bit(Column::Ib)
            | out(i[2], lim.i_max) << bit(Column::Ic);
        if let Some(w) = row.wm_rad_s {
            b |= out(w, lim.wm_max) << bit(Column::Speed);
        }
        b |= u16::from(row.enc_count == Some(crate::log::ENC_COUNT_UNREADABLE))
            << bit(Column::Encoder);
        BadCells(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cells against the rule as the module states it: not finite, or beyond the limit.
    #[test]
    fn bad_cells_are_the_non_finite_and_those_beyond_the_limits() {
        let lim = |v_max: f64| CellLimits {
            v_max,
            i_max: 100.0,
            wm_max: 1000.0,
            supply_hz: 50.0,
            sync_rad_s: 157.0,
            pole_pairs: 2.0,
        };
        let xs = [
            0.0,
            -5.0,
            99.9,
            100.0,
            -100.0,
            100.1,
            1e308,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for v_max in [100.0, f64::INFINITY, f64::NAN] {
            let lim = lim(v_max);
            for (k, &x) in xs.iter().enumerate() {
                let y = xs[(k * 7 + 3) % xs.len()];
                let row = Row {
                    t_s: 0.0,
                    v_abc: Some([x, 1.0, y]),
                    i_abc: [1.0, y, x],
                    wm_rad_s: Some(x * 10.0),
                    enc_count: Some(k as i64),
                    t_winding_c: None,
                };
                let rule = |x: f64, max: f64| !x.is_finite() || x.abs() > max;
                let b = BadCells::of(&row, &lim);
                assert_eq!(b.has(Column::Va), rule(x, v_max), "{x} {v_max}");
                assert!(!b.has(Column::Vb));
                assert_eq!(b.has(Column::Vc), rule(y, v_max), "{y} {v_max}");
                assert!(!b.has(Column::Ia));
                assert_eq!(b.has(Column::Ib), rule(y, 100.0), "{y}");
                assert_eq!(b.has(Column::Ic), rule(x, 100.0), "{x}");
                assert_eq!(b.has(Column::Speed), rule(x * 10.0, 1000.0), "{x}");
                assert!(!b.has(Column::Encoder));
            }
        }
        let unreadable = Row {
            t_s: 0.0,
            v_abc: None,
            i_abc: [1.0; 3],
            wm_rad_s: None,
            enc_count: Some(crate::log::ENC_COUNT_UNREADABLE),
            t_winding_c: None,
        };
        let b = BadCells::of(&unreadable, &lim(100.0));
        assert!(b.has(Column::Encoder) && b.any());
    }
}
