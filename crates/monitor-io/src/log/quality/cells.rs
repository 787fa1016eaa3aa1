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
        let mut b = BadCells::default();
        let bad = |x: f64, max: f64| !x.is_finite() || x.abs() > max;
        if let Some(v) = row.v_abc {
            for (x, c) in v.iter().zip([Column::Va, Column::Vb, Column::Vc]) {
                if bad(*x, lim.v_max) {
                    b.set(c);
                }
            }
        }
        for (x, c) in row.i_abc.iter().zip([Column::Ia, Column::Ib, Column::Ic]) {
            if bad(*x, lim.i_max) {
                b.set(c);
            }
        }
        if row.wm_rad_s.is_some_and(|w| bad(w, lim.wm_max)) {
            b.set(Column::Speed);
        }
        if row.enc_count == Some(crate::log::ENC_COUNT_UNREADABLE) {
            b.set(Column::Encoder);
        }
        b
    }
}
