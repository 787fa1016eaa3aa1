//! The trend's computation (the statistics in [`super::stats`], the rules in the module's
//! documentation).

use super::stats::{least_squares, mad_sigma, median, theil_sen};
use super::{
    Direction, FaultLevel, Indicator, IndicatorTrend, MotorTrend, TrendOptions, TrendPoint,
    INDICATORS,
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
    let indicators: Vec<IndicatorTrend> = INDICATORS
        .iter()
        .map(|ind| indicator_trend(ind, &rows, opts))
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
        indicators,
    }
}

/// The operating-point fit of `ind` on the motor's rows: least squares of the indicator
/// on its covariates and a linear time term together (so that the covariates' part does
/// not take up a trend in time), the covariates' coefficients and their median values, or
/// `None` where it cannot be fitted (too few logs, a covariate that does not vary).
fn fit_operating_point(ind: &Indicator, rows: &[&StoredRow]) -> Option<(Vec<f64>, Vec<f64>)> {
    let usable: Vec<(Vec<f64>, f64)> = rows
        .iter()
        .filter_map(|r| {
            let y = r.f64(ind.column)?;
            let t = r.f64("log_time_s")? / DAY_S;
            let x: Option<Vec<f64>> = ind.covariates.iter().map(|c| r.f64(c)).collect();
            let mut x = x?;
            x.push(t);
            Some((x, y))
        })
        .collect();
    if usable.len() < fit_logs(ind) {
        return None;
    }
    let xs: Vec<Vec<f64>> = usable.iter().map(|(x, _)| x.clone()).collect();
    let ys: Vec<f64> = usable.iter().map(|(_, y)| *y).collect();
    let coef = least_squares(&xs, &ys)?;
    let centre: Option<Vec<f64>> = (0..ind.covariates.len())
        .map(|k| {
            let mut col: Vec<f64> = xs.iter().filter_map(|x| x.get(k).copied()).collect();
            median(&mut col)
        })
        .collect();
    Some((coef, centre?))
}

/// The fewest logs the operating-point fit is made on: four per coefficient (the
/// intercept, each covariate, time). With fewer, an indicator that has covariates gives no
/// alarm: a trend cannot yet be told from the operating point's moves.
pub fn fit_logs(ind: &Indicator) -> usize {
    4 * (ind.covariates.len() + 2)
}

/// One indicator's trend over the window ending at the motor's last row (`rows` by time).
pub fn indicator_trend(
    ind: &Indicator,
    rows: &[&StoredRow],
    opts: &TrendOptions,
) -> IndicatorTrend {
    let fit = fit_operating_point(ind, rows);
    let normalisation = match &fit {
        Some(_) => format!(
            "brought to the median {} (least squares on them and time over the motor's {} logs)",
            ind.covariates.join(" and "),
            rows.len()
        ),
        None => "raw values (too few logs, or an operating point that does not vary, to fit)"
            .to_string(),
    };
    let end_s = rows
        .last()
        .and_then(|r| r.f64("log_time_s"))
        .unwrap_or_default();
    let start_s = end_s - opts.window_days * DAY_S;
    let series: Vec<TrendPoint> = rows
        .iter()
        .filter_map(|r| {
            let t = r.f64("log_time_s")?;
            let value = r.f64(ind.column)?;
            let normalised = match &fit {
                Some((coef, centre)) => {
                    let mut v = value;
                    for (k, c) in ind.covariates.iter().enumerate() {
                        v -= coef.get(k + 1)? * (r.f64(c)? - centre.get(k)?);
                    }
                    v
                }
                None => value,
            };
            (t >= start_s - 1.0).then_some(TrendPoint {
                t_days: t / DAY_S,
                value,
                normalised,
            })
        })
        .collect();
    let level = match ind.fault_level {
        FaultLevel::None => None,
        FaultLevel::Fixed(x) => Some(x),
        FaultLevel::Column(c) => {
            let mut v: Vec<f64> = rows.iter().filter_map(|r| r.f64(c)).collect();
            median(&mut v).filter(|x| *x > 0.0)
        }
    };
    let mut t = IndicatorTrend {
        indicator: ind.column.to_string(),
        label: ind.label.to_string(),
        unit: ind.unit.to_string(),
        direction: ind.direction,
        logs: series.len(),
        slope_per_day: None,
        slope_low: None,
        slope_high: None,
        scatter: None,
        moves_scatters: None,
        last: None,
        fault_level: level,
        days_to_fault: None,
        alarm: false,
        normalisation,
        sentence: String::new(),
        series,
    };
    judge(&mut t, ind, opts, end_s / DAY_S);
    if fit.is_none() && !ind.covariates.is_empty() && rows.len() < fit_logs(ind) {
        t.alarm = false;
        t.normalisation = format!(
            "not yet: {} logs, the operating-point fit needs {}; no alarm until then",
            rows.len(),
            fit_logs(ind)
        );
    }
    t
}

/// The slope, scatter, alarm, projection and sentence of `t` from its series.
fn judge(t: &mut IndicatorTrend, ind: &Indicator, opts: &TrendOptions, end_days: f64) {
    let name = ind.column;
    if t.series.len() < opts.min_logs.max(3) {
        t.sentence = format!(
            "{name}: {} logs in the last {} days, too few for a trend (at least {})",
            t.series.len(),
            opts.window_days,
            opts.min_logs.max(3)
        );
        return;
    }
    // Days from the window's first point (the slope's scale does not depend on it).
    let t0 = t.series.first().map_or(0.0, |p| p.t_days);
    let x: Vec<f64> = t.series.iter().map(|p| p.t_days - t0).collect();
    let y: Vec<f64> = t.series.iter().map(|p| p.normalised).collect();
    let Some(line) = theil_sen(&x, &y, opts.confidence) else {
        t.sentence = format!("{name}: all logs at one time, no slope");
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
        .max(1e-9 * y.iter().map(|v| v.abs()).fold(0.0, f64::max))
        .max(f64::MIN_POSITIVE);
    let span = x.last().copied().unwrap_or_default();
    let moves = line.slope * span / scatter;
    let last = line.intercept + line.slope * (end_days - t0);
    let significant = match ind.direction {
        Direction::Rising => line.low > 0.0,
        Direction::Either => line.low > 0.0 || line.high < 0.0,
    };
    let big = match ind.direction {
        Direction::Rising => moves > opts.k_scatter,
        Direction::Either => moves.abs() > opts.k_scatter,
    };
    t.slope_per_day = Some(line.slope);
    t.slope_low = Some(line.low);
    t.slope_high = Some(line.high);
    t.scatter = Some(scatter);
    t.moves_scatters = Some(moves);
    t.last = Some(last);
    t.days_to_fault = t.fault_level.and_then(|lvl| {
        let d = (lvl - last) / line.slope;
        (d.is_finite() && d >= 0.0 && line.slope > 0.0).then_some(d)
    });
    // With a FAULT level, a slope that would take longer than the horizon to reach it is
    // not worth a visit, however significant.
    let soon = t.fault_level.is_none() || t.days_to_fault.is_some_and(|d| d <= opts.horizon_days);
    t.alarm = ind.alarms && significant && big && soon;
    let week = |v: f64| 7.0 * v;
    let dir = if line.slope >= 0.0 {
        "rising"
    } else {
        "falling"
    };
    let mut s = format!(
        "{name} {dir} {:.3e} {}/week ({:.3e} to {:.3e}), {:.1} scatters over {:.0} days",
        week(line.slope),
        ind.unit,
        week(line.low),
        week(line.high),
        moves,
        span
    );
    match (t.alarm, t.days_to_fault) {
        (true, Some(d)) => s.push_str(&format!(": TREND ALARM, FAULT level in about {d:.0} days")),
        (true, None) => s.push_str(": TREND ALARM"),
        (false, Some(d)) if d < 365.0 => s.push_str(&format!(
            ": no alarm (FAULT level in about {d:.0} days at this slope)"
        )),
        (false, _) if !ind.alarms => s.push_str(": shown, not alarmed"),
        (false, _) => s.push_str(": no alarm"),
    }
    t.sentence = s;
}

/// The UTC day of `t_days` days since 1970-01-01.
pub fn day_of(t_days: f64) -> String {
    utc_day((t_days * DAY_S).floor() as i64)
}
