//! The trend's computation (the statistics in [`super::stats`], the rules in the module's
//! documentation).

use super::reference::{latched, normalisation_note, reference_stats};
use super::stats::{least_squares, mad_sigma, median, theil_sen};
use super::{
    reference_rows, Direction, FaultLevel, Indicator, IndicatorTrend, MotorTrend, TrendOptions,
    TrendPoint, INDICATORS, RISE,
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
        .map(|ind| {
            let judge = |r: &[&StoredRow]| indicator_trend(ind, r, opts);
            latched(judge(&rows), &rows, opts, &judge)
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
        normalisation,
        operating_point_fitted: fit.is_some(),
        reference_centre,
        reference_scatter,
        from_reference_scatters: None,
        sentence: String::new(),
        series,
    };
    judge(&mut t, ind, opts, end_s / DAY_S, floor);
    if let (Some(l), Some(c), Some(s)) = (t.last, reference_centre, reference_scatter) {
        t.from_reference_scatters = Some((l - c) / s);
    }
    if fit.is_none() && !covs.is_empty() && usable < needed {
        hold_for_fit(&mut t, usable, needed);
    }
    finish(&mut t, ind, covs);
    t
}

/// The last words of `t`: a residual without a temperature channel is not alarmed
/// ([`hold_without_probe`]); an alarm says what it means.
fn finish(t: &mut IndicatorTrend, ind: &Indicator, covs: &[&str]) {
    if covs.contains(&RISE) {
        hold_without_probe(t);
    }
    if t.alarm && !ind.alarm_means.is_empty() {
        t.sentence = format!("{}; {}", t.sentence, ind.alarm_means);
    }
}

/// Too few logs (`n` of the `needed`) to tell a trend from the operating point's moves: no
/// alarm, and the sentence says so (it never says TREND ALARM where the alarm is not
/// raised).
fn hold_for_fit(t: &mut IndicatorTrend, n: usize, needed: usize) {
    if t.alarm {
        t.alarm = false;
        t.sentence = t.sentence.replace(
            ": TREND ALARM",
            &format!(": no alarm yet ({n} logs; the operating-point fit needs {needed})"),
        );
    }
}

/// A residual normalised on the rise the isolation read (no temperature channel): shown,
/// not alarmed. The rise is read from Rs and Rr against the parameter file, so with a file
/// 10 % off it follows the file's error as much as the season: on a held-out month judged
/// against such a file every healthy motor's residuals alarmed on the first day the fit
/// was allowed. The stator's resistance beyond the rotor's (`stator_excess_pct`) needs no
/// temperature and alarms a loosening connection instead.
fn hold_without_probe(t: &mut IndicatorTrend) {
    if t.alarm {
        t.alarm = false;
        t.sentence = t.sentence.replace(
            ": TREND ALARM",
            ": shown, not alarmed (no temperature channel: normalised on the rise the isolation read)",
        );
    }
}

/// The indicator's points, normalised with `fit` where there is one: those from `start_s`
/// on in the window, those of the reference mask (over `rows`) in the reference.
fn series_of(
    ind: &Indicator,
    covs: &[&str],
    fit: Option<&OperatingFit>,
    (rows, reference): (&[&StoredRow], &[bool]),
    start_s: f64,
) -> Vec<TrendPoint> {
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
                in_reference: *in_reference,
            })
        })
        .collect()
}

/// The indicator's FAULT level for these rows, where it has one.
fn fault_level_of(ind: &Indicator, rows: &[&StoredRow]) -> Option<f64> {
    match ind.fault_level {
        FaultLevel::None => None,
        FaultLevel::Fixed(x) => Some(x),
        FaultLevel::Column(c) => {
            let mut v: Vec<f64> = rows.iter().filter_map(|r| r.f64(c)).collect();
            median(&mut v).filter(|x| *x > 0.0)
        }
    }
}

/// The slope, scatter, alarm, projection and sentence of `t` from its series.
fn judge(t: &mut IndicatorTrend, ind: &Indicator, opts: &TrendOptions, end_days: f64, floor: f64) {
    let name = ind.column;
    let window: Vec<&TrendPoint> = t.series.iter().filter(|p| p.in_window).collect();
    if window.len() < opts.min_logs.max(3) {
        t.sentence = format!(
            "{name}: {} logs in the last {} days, too few for a trend or a scatter (at least {}){}",
            window.len(),
            opts.window_days,
            opts.min_logs.max(3),
            stored_values(&window, ind),
        );
        return;
    }
    // Days from the window's first point (the slope's scale does not depend on it).
    let t0 = window.first().map_or(0.0, |p| p.t_days);
    let x: Vec<f64> = window.iter().map(|p| p.t_days - t0).collect();
    let y: Vec<f64> = window.iter().map(|p| p.normalised).collect();
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
    project(t, &line, (&x, &y), end_days - t0, opts);
    // With a FAULT level, a slope that would take longer than the horizon to reach it is
    // not worth a visit, however significant.
    let soon = t.fault_level.is_none() || t.days_to_fault.is_some_and(|d| d <= opts.horizon_days);
    t.alarm = ind.alarms && significant && big && soon;
    t.sentence = sentence(t, ind, &line, span);
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

/// "; the stored values 0.0001 to 0.026 pu (first 0.0001, last 0.026)", in the shown unit:
/// what there is where there is no trend.
fn stored_values(window: &[&TrendPoint], ind: &Indicator) -> String {
    let v: Vec<f64> = window.iter().map(|p| p.value * ind.scale).collect();
    let (Some(first), Some(last)) = (v.first(), v.last()) else {
        return String::new();
    };
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    format!(
        "; the stored values {} to {} {} (first {}, last {})",
        sig3(lo),
        sig3(hi),
        ind.shown_unit,
        sig3(*first),
        sig3(*last)
    )
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

/// "i2_over_i1 rising 0.36 % of I1/week (0.14 to 0.68), 3.3 scatters over 14 days: TREND
/// ALARM, FAULT level in about 38 days", in the indicator's shown unit.
fn sentence(
    t: &IndicatorTrend,
    ind: &Indicator,
    line: &super::stats::SenLine,
    span: f64,
) -> String {
    let week = |v: f64| 7.0 * v * ind.scale;
    let dir = if line.slope >= 0.0 {
        "rising"
    } else {
        "falling"
    };
    let mut s = format!(
        "{} {dir} {} {}/week ({} to {}), {:.1} scatters over {span:.0} days",
        ind.column,
        sig3(week(line.slope)),
        ind.shown_unit,
        sig3(week(line.low)),
        sig3(week(line.high)),
        t.moves_scatters.unwrap_or_default(),
    );
    match (t.alarm, t.days_to_fault) {
        (true, Some(d)) if d < 0.5 => s.push_str(": TREND ALARM, at the FAULT level already"),
        (true, Some(d)) => {
            s.push_str(&format!(": TREND ALARM, FAULT level in about {d:.0} days"));
            s.push_str(&sooner(t.days_to_fault_recent, d, span));
        }
        (true, None) => s.push_str(": TREND ALARM"),
        (false, Some(d)) if d < 365.0 => s.push_str(&format!(
            ": no alarm (FAULT level in about {d:.0} days at this slope)"
        )),
        (false, _) if !ind.alarms => s.push_str(": shown, not alarmed"),
        (false, _) => s.push_str(": no alarm"),
    }
    s
}

/// " (about 7 at the last 7 days' slope)" where the window's second half projects the FAULT
/// level well sooner (under 0.8 of) the whole window's `d` days; else nothing.
fn sooner(recent: Option<f64>, d: f64, span: f64) -> String {
    match recent {
        Some(r) if r < 0.8 * d => format!(
            " (about {:.0} at the last {:.0} days' slope)",
            r.max(0.0),
            0.5 * span
        ),
        _ => String::new(),
    }
}

/// `v` with three significant digits, in plain notation where that is short.
fn sig3(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !(1e-3..1e4).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// The UTC day of `t_days` days since 1970-01-01.
pub fn day_of(t_days: f64) -> String {
    utc_day((t_days * DAY_S).floor() as i64)
}
