//! The trend's computation (the statistics in [`super::stats`], the rules in the module's
//! documentation).

use super::level::{fault_level_of, fault_level_run};
use super::reference::{latched, normalisation_note, reference_stats};
use super::stats::{least_squares, mad_sigma, median, theil_sen};
use super::{
    reference_rows, Direction, Indicator, IndicatorTrend, MotorTrend, TrendOptions, TrendPoint,
    TrendReason, ValueRange, INDICATORS, RISE,
};
use crate::row::{utc_day, StoredRow};

/// Seconds per day.
const DAY_S: f64 = 86_400.0;

/// The trend of every motor in `rows`, the fastest-moving first (alarmed motors before the
/// others, then by [`MotorTrend::fastest_scatters`]).
pub fn trend(rows: &[StoredRow], opts: &TrendOptions) -> Vec<MotorTrend> {
    let mut motors: Vec<&str> = rows.iter().filter_map(|r| r.str("motor")).collect();
    motors.sort_unstable();
    motors.dedup();
    let mut out: Vec<MotorTrend> = motors
        .into_iter()
        .map(|m| {
            let mine: Vec<&StoredRow> = rows.iter().filter(|r| r.str("motor") == Some(m)).collect();
            motor_trend(m, &mine, opts)
        })
        .collect();
    out.sort_by(|a, b| {
        b.alarm
            .cmp(&a.alarm)
            .then(b.fastest_scatters.total_cmp(&a.fastest_scatters))
            .then(a.motor.cmp(&b.motor))
    });
    out
}

/// One motor's trend from its rows (any order; rows without a verdict are left out).
pub fn motor_trend(motor: &str, rows: &[&StoredRow], opts: &TrendOptions) -> MotorTrend {
    let mut rows: Vec<&StoredRow> = rows
        .iter()
        .copied()
        .filter(|r| r.str("verdict").is_some())
        .collect();
    rows.sort_by(|a, b| {
        a.f64("log_time_s")
            .unwrap_or_default()
            .total_cmp(&b.f64("log_time_s").unwrap_or_default())
    });
    // An indicator none of the motor's logs measured (a log without voltages has no parity
    // residual, no Rs beyond Rr) is absent, not a flat line at zero.
    let indicators: Vec<IndicatorTrend> = INDICATORS
        .iter()
        .filter(|ind| rows.iter().any(|r| r.f64(ind.column).is_some()))
        .map(|ind| {
            let judge = |r: &[&StoredRow]| indicator_trend(ind, r, opts);
            latched(judge(&rows), ind, &rows, opts, &judge)
        })
        .collect();
    let fastest = indicators
        .iter()
        .filter_map(|t| t.moves_scatters.map(f64::abs))
        .fold(0.0, f64::max);
    let day = |r: Option<&&StoredRow>| r.and_then(|r| r.str("day")).unwrap_or_default().to_string();
    MotorTrend {
        motor: motor.to_string(),
        logs: rows.len(),
        first_day: day(rows.first()),
        last_day: day(rows.last()),
        alarm: indicators.iter().any(|t| t.alarm),
        fastest_scatters: fastest,
        reference: reference_rows(&rows, opts).1,
        indicators,
    }
}

/// The operating point's fit of one indicator: least-squares coefficients of its
/// second-order features ([`features`]) of the covariates taken from their medians.
struct OperatingFit {
    /// The covariates' medians over the motor's logs.
    centre: Vec<f64>,
    /// The coefficients of [`features`] (the intercept and time's left out).
    coef: Vec<f64>,
    /// The scatter of the fit's residuals over all the motor's logs (1.4826 MAD).
    scatter: f64,
}

impl OperatingFit {
    /// The operating point's part of the indicator at covariates `x`.
    fn part(&self, x: &[f64]) -> Option<f64> {
        let c: Option<Vec<f64>> = x
            .iter()
            .zip(&self.centre)
            .map(|(v, m)| Some(v - m))
            .collect();
        let f = features(&c?);
        Some(f.iter().zip(&self.coef).map(|(a, b)| a * b).sum())
    }
}

/// The second-order features of the centred covariates `c`: each one, each product of
/// two and each square (load and temperature: L, T, L T, L^2, T^2). Second order because a
/// parity residual of a resistance change is the change times a current: a product of the
/// temperature's and the load's parts, and the load's own part is not linear in the
/// current (measured on the simulated month: the linear fit left 0.0012 pu of e_d's
/// scatter where the second-order one left 0.0002-0.0003).
fn features(c: &[f64]) -> Vec<f64> {
    let mut f: Vec<f64> = c.to_vec();
    for i in 0..c.len() {
        for j in i..c.len() {
            if let (Some(a), Some(b)) = (c.get(i), c.get(j)) {
                f.push(a * b);
            }
        }
    }
    f
}

/// How many features [`features`] gives for `n` covariates.
fn feature_count(n: usize) -> usize {
    n + n * (n + 1) / 2
}

/// The operating-point fit of `ind` on the motor's rows: least squares of the indicator
/// on the covariates' second-order features and a linear time term together (so that the
/// covariates' part does not take up a trend in time), or `None` where it cannot be
/// fitted (too few logs, a covariate that does not vary).
fn fit_operating_point(
    ind: &Indicator,
    covs: &[&str],
    rows: &[&StoredRow],
) -> Option<OperatingFit> {
    let usable: Vec<(Vec<f64>, f64, f64)> = rows
        .iter()
        .filter_map(|r| {
            let y = r.f64(ind.column)?;
            let t = r.f64("log_time_s")? / DAY_S;
            let x: Option<Vec<f64>> = covs.iter().map(|c| r.f64(c)).collect();
            Some((x?, t, y))
        })
        .collect();
    if usable.len() < fit_logs(covs) {
        return None;
    }
    let centre: Option<Vec<f64>> = (0..covs.len())
        .map(|k| {
            let mut col: Vec<f64> = usable.iter().filter_map(|u| u.0.get(k).copied()).collect();
            median(&mut col)
        })
        .collect();
    let centre = centre?;
    let t0 = usable.first().map_or(0.0, |u| u.1);
    let xs: Vec<Vec<f64>> = usable
        .iter()
        .map(|(x, t, _)| {
            let c: Vec<f64> = x.iter().zip(&centre).map(|(v, m)| v - m).collect();
            let mut f = features(&c);
            f.push(t - t0);
            f
        })
        .collect();
    let ys: Vec<f64> = usable.iter().map(|u| u.2).collect();
    let all = least_squares(&xs, &ys)?;
    let n = feature_count(covs.len());
    let coef = all.get(1..=n)?.to_vec();
    let resid: Vec<f64> = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| {
            let fitted: f64 = all.first().copied().unwrap_or_default()
                + x.iter()
                    .zip(all.iter().skip(1))
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            y - fitted
        })
        .collect();
    let scatter = mad_sigma(&resid).unwrap_or_default();
    Some(OperatingFit {
        centre,
        coef,
        scatter,
    })
}

/// The fewest logs the operating-point fit is made on: four per coefficient (the
/// intercept, each feature, time). With fewer, an indicator that has covariates gives no
/// alarm: a trend cannot yet be told from the operating point's moves.
pub fn fit_logs(covs: &[&str]) -> usize {
    4 * (feature_count(covs.len()) + 2)
}

/// The covariate set `ind` is normalised on for these rows: the first of its sets that
/// enough of the rows have (all values present), else its last.
fn covariates_of(ind: &Indicator, rows: &[&StoredRow]) -> &'static [&'static str] {
    let have = |set: &[&str]| {
        rows.iter()
            .filter(|r| r.f64(ind.column).is_some() && set.iter().all(|c| r.f64(c).is_some()))
            .count()
            >= fit_logs(set)
    };
    ind.covariates
        .iter()
        .copied()
        .find(|set| have(set))
        .or(ind.covariates.last().copied())
        .unwrap_or_default()
}

/// One indicator's trend over the window ending at the motor's last row (`rows` by time),
/// judged on its own (without the alarm's history: [`motor_trend`] applies it).
pub fn indicator_trend(
    ind: &Indicator,
    rows: &[&StoredRow],
    opts: &TrendOptions,
) -> IndicatorTrend {
    let covs = covariates_of(ind, rows);
    let fit = fit_operating_point(ind, covs, rows);
    let needed = fit_logs(covs);
    let (normalisation, usable) = normalisation_note(ind, covs, rows, fit.is_some(), needed);
    let end_s = rows
        .last()
        .and_then(|r| r.f64("log_time_s"))
        .unwrap_or_default();
    let (mask, _) = reference_rows(rows, opts);
    let series = series_of(
        ind,
        covs,
        fit.as_ref(),
        (rows, &mask),
        end_s - opts.window_days * DAY_S,
    );
    let floor = fit.as_ref().map_or(0.0, |f| f.scatter).max(ind.min_scatter);
    let (reference_centre, reference_scatter) = reference_stats(&series, floor, opts.min_logs);
    let mut t = IndicatorTrend {
        indicator: ind.column.to_string(),
        label: ind.label.to_string(),
        unit: ind.unit.to_string(),
        direction: ind.direction,
        logs: series.iter().filter(|p| p.in_window).count(),
        slope_per_day: None,
        slope_low: None,
        slope_high: None,
        scatter: None,
        moves_scatters: None,
        last: None,
        fault_level: fault_level_of(ind, rows),
        days_to_fault: None,
        days_to_fault_recent: None,
        alarm: false,
        alarm_since: None,
        span_days: None,
        normalisation,
        operating_point_fitted: fit.is_some(),
        reference_centre,
        reference_scatter,
        from_reference_scatters: None,
        reason: TrendReason::OneTime,
        fault_level_logs: fault_level_run(ind, rows).map_or(0, |r| r.logs),
        series,
    };
    judge(&mut t, ind, opts, end_s / DAY_S, floor);
    if let (Some(l), Some(c), Some(s)) = (t.last, reference_centre, reference_scatter) {
        t.from_reference_scatters = Some((l - c) / s);
    }
    if t.alarm && fit.is_none() && !covs.is_empty() && usable < needed {
        // Too few logs to tell a trend from the operating point's moves: the slope does
        // not alarm yet (the FAULT level on logs in a row still does: [`latched`]).
        t.alarm = false;
        t.reason = TrendReason::NotYet {
            logs: usable,
            needed,
        };
    }
    if t.alarm && covs.contains(&RISE) {
        // A residual normalised on the rise the isolation read (no temperature channel):
        // shown, not alarmed. The rise is read from Rs and Rr against the parameter file,
        // so with a file 10 % off it follows the file's error as much as the season: on a
        // held-out month judged against such a file every healthy motor's residuals
        // alarmed on the first day the fit was allowed. The stator's resistance beyond the
        // rotor's (`stator_excess_pct`) needs no temperature and alarms a loosening
        // connection instead.
        t.alarm = false;
        t.reason = TrendReason::NoTemperatureChannel;
    }
    t
}

/// The indicator's points, normalised with `fit` where there is one: those from `start_s`
/// on in the window, those of the reference mask (over `rows`) in the reference unless
/// they stand at the indicator's FAULT level.
fn series_of(
    ind: &Indicator,
    covs: &[&str],
    fit: Option<&OperatingFit>,
    (rows, reference): (&[&StoredRow], &[bool]),
    start_s: f64,
) -> Vec<TrendPoint> {
    let common = super::level::fault_level_of(ind, rows);
    rows.iter()
        .zip(reference)
        .filter_map(|(r, in_reference)| {
            let t = r.f64("log_time_s")?;
            let value = r.f64(ind.column)?;
            let normalised = match fit {
                Some(f) => {
                    let x: Option<Vec<f64>> = covs.iter().map(|c| r.f64(c)).collect();
                    value - f.part(&x?)?
                }
                None => value,
            };
            Some(TrendPoint {
                t_days: t / DAY_S,
                value,
                normalised,
                in_window: t >= start_s - 1.0,
                // A log at the indicator's FAULT level is no healthy reference for it,
                // whatever its verdict said (a fault growing under the thresholds of a
                // log judged alone).
                in_reference: *in_reference && !super::level::at_fault_level(ind, r, common),
            })
        })
        .collect()
}

/// The slope, scatter, alarm, projection and reason of `t` from its series.
fn judge(t: &mut IndicatorTrend, ind: &Indicator, opts: &TrendOptions, end_days: f64, floor: f64) {
    let window: Vec<&TrendPoint> = t.series.iter().filter(|p| p.in_window).collect();
    if window.len() < opts.min_logs.max(3) {
        t.reason = TrendReason::TooFewLogs {
            logs: window.len(),
            needed: opts.min_logs.max(3),
            window_days: opts.window_days,
            values: stored_values(&window),
        };
        return;
    }
    // Days from the window's first point (the slope's scale does not depend on it).
    let t0 = window.first().map_or(0.0, |p| p.t_days);
    let x: Vec<f64> = window.iter().map(|p| p.t_days - t0).collect();
    let y: Vec<f64> = window.iter().map(|p| p.normalised).collect();
    let Some(line) = theil_sen(&x, &y, opts.confidence) else {
        t.reason = TrendReason::OneTime;
        return;
    };
    let resid: Vec<f64> = x
        .iter()
        .zip(&y)
        .map(|(xi, yi)| yi - line.intercept - line.slope * xi)
        .collect();
    // A floor on the scatter: values identical to the stored precision would make any
    // slope infinitely many scatters.
    let scatter = mad_sigma(&resid)
        .unwrap_or_default()
        .max(floor)
        .max(1e-9 * y.iter().map(|v| v.abs()).fold(0.0, f64::max))
        .max(f64::MIN_POSITIVE);
    let span = x.last().copied().unwrap_or_default();
    let moves = line.slope * span / scatter;
    let last = line.intercept + line.slope * (end_days - t0);
    let (significant, big) = match ind.direction {
        Direction::Rising => (line.low > 0.0, moves > opts.k_scatter),
        Direction::Either => (
            line.low > 0.0 || line.high < 0.0,
            moves.abs() > opts.k_scatter,
        ),
    };
    t.slope_per_day = Some(line.slope);
    t.slope_low = Some(line.low);
    t.slope_high = Some(line.high);
    t.scatter = Some(scatter);
    t.moves_scatters = Some(moves);
    t.last = Some(last);
    t.span_days = Some(span);
    project(t, &line, (&x, &y), end_days - t0, opts);
    // With a FAULT level, a slope that would take longer than the horizon to reach it is
    // not worth a visit, however significant.
    let soon = t.fault_level.is_none() || t.days_to_fault.is_some_and(|d| d <= opts.horizon_days);
    t.alarm = ind.alarms && significant && big && soon;
    t.reason = if t.alarm {
        TrendReason::Slope {
            days_to_fault: t.days_to_fault,
            days_to_fault_recent: t.days_to_fault_recent,
        }
    } else if !ind.alarms {
        TrendReason::ShownOnly
    } else {
        TrendReason::NoAlarm {
            days_to_fault: t.days_to_fault,
        }
    };
}

/// The days to the FAULT level of `t` on the window's `line` and on its second half's
/// (the window's points `(x, y)`, `end` the last log's `x`): only on a slope whose interval
/// lies on the fault's side of zero (a level is reached by rising), and within the horizon.
fn project(
    t: &mut IndicatorTrend,
    line: &super::stats::SenLine,
    (x, y): (&[f64], &[f64]),
    end: f64,
    opts: &TrendOptions,
) {
    let within = |d: &f64| *d <= opts.horizon_days;
    let last = line.intercept + line.slope * end;
    t.days_to_fault = t
        .fault_level
        .and_then(|lvl| days_to(lvl, last, line.slope, line.low))
        .filter(within);
    t.days_to_fault_recent = t
        .fault_level
        .and_then(|lvl| recent_days_to(lvl, x, y, end, opts.confidence))
        .filter(within);
}

/// The stored values of the window's points (none without a point): what there is where
/// there is no trend.
fn stored_values(window: &[&TrendPoint]) -> Option<ValueRange> {
    let first = window.first()?.value;
    let last = window.last()?.value;
    let v = window.iter().map(|p| p.value);
    Some(ValueRange {
        low: v.clone().fold(f64::INFINITY, f64::min),
        high: v.fold(f64::NEG_INFINITY, f64::max),
        first,
        last,
    })
}

/// [`IndicatorTrend::days_to_fault_recent`]: the days to `level` on the Theil-Sen line of
/// the points `(x, y)` in the second half of the window (`x` from half of the last `x` on),
/// taken at `end` (same origin as `x`).
fn recent_days_to(level: f64, x: &[f64], y: &[f64], end: f64, confidence: f64) -> Option<f64> {
    let half = 0.5 * x.last().copied().unwrap_or_default();
    let (xr, yr): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(xi, _)| **xi >= half)
        .map(|(xi, yi)| (*xi, *yi))
        .unzip();
    if xr.len() < super::RECENT_MIN_LOGS {
        return None;
    }
    let line = theil_sen(&xr, &yr, confidence)?;
    days_to(
        level,
        line.intercept + line.slope * end,
        line.slope,
        line.low,
    )
}

/// The days until a line at `last` rising by `slope` a day reaches `level`: 0 at or past
/// it; none where it does not head there or where Sen's interval (its low end `low`) does
/// not exclude a flat line (a slope that may be zero projects nothing).
fn days_to(level: f64, last: f64, slope: f64, low: f64) -> Option<f64> {
    if last >= level {
        return Some(0.0);
    }
    let d = (level - last) / slope;
    (d.is_finite() && slope > 0.0 && low > 0.0).then_some(d)
}

/// The UTC day of `t_days` days since 1970-01-01.
pub fn day_of(t_days: f64) -> String {
    utc_day((t_days * DAY_S).floor() as i64)
}
