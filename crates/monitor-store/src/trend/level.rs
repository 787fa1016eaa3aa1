//! The FAULT level of an indicator and the run of logs at it: what the trend's alarm on
//! consecutive FAULT logs reads ([`super::TrendReason::FaultLevelInARow`]), apart from the
//! trend's fit and its reference so that both may use it.

use super::stats::median;
use super::{FaultLevel, Indicator};
use crate::row::StoredRow;

/// The motor's last logs in a row at an indicator's FAULT level
/// ([`TrendReason::FaultLevelInARow`]).
pub(super) struct LevelRun {
    /// How many (at least 1).
    pub logs: usize,
    /// The first one's UTC day.
    pub first_day: String,
    /// The last log's stored value.
    pub value: f64,
    /// Its FAULT level.
    pub level: f64,
}

/// The run of logs at the FAULT level of `ind` that ends at the last of `rows` (by time):
/// each log's stored value at or beyond its own level (a level column's value in the log,
/// else the indicator's level over `rows`); a log without the value, or below its level,
/// ends the run. `None` where the last log is not at the level or `ind` has none.
pub(super) fn fault_level_run(ind: &Indicator, rows: &[&StoredRow]) -> Option<LevelRun> {
    let common = fault_level_of(ind, rows);
    let level_of = |r: &StoredRow| match ind.fault_level {
        FaultLevel::Column(c) => r.f64(c).filter(|x| *x > 0.0).or(common),
        _ => common,
    };
    let at = |r: &StoredRow| match (r.f64(ind.column), level_of(r)) {
        (Some(v), Some(l)) if v.is_finite() && v >= l => Some((v, l)),
        _ => None,
    };
    let last = rows.last()?;
    let (value, level) = at(last)?;
    let logs = rows.iter().rev().take_while(|r| at(r).is_some()).count();
    let first = rows.get(rows.len() - logs)?;
    Some(LevelRun {
        logs,
        first_day: first.str("day").unwrap_or_default().to_string(),
        value,
        level,
    })
}

/// Whether the log `r` stands at the FAULT level of `ind` (its own level column's value,
/// else `common`, the indicator's level over the motor's logs): such a log is no healthy
/// reference for that indicator, whatever its verdict said.
pub(super) fn at_fault_level(ind: &Indicator, r: &StoredRow, common: Option<f64>) -> bool {
    let level = match ind.fault_level {
        FaultLevel::Column(c) => r.f64(c).filter(|x| *x > 0.0).or(common),
        _ => common,
    };
    matches!((r.f64(ind.column), level), (Some(v), Some(l)) if v.is_finite() && v >= l)
}

/// The indicator's FAULT level for these rows, where it has one.
pub(super) fn fault_level_of(ind: &Indicator, rows: &[&StoredRow]) -> Option<f64> {
    match ind.fault_level {
        FaultLevel::None => None,
        FaultLevel::Fixed(x) => Some(x),
        FaultLevel::Column(c) => {
            let mut v: Vec<f64> = rows.iter().filter_map(|r| r.f64(c)).collect();
            median(&mut v).filter(|x| *x > 0.0)
        }
    }
}
