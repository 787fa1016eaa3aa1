//! The motor's reference (its first healthy logs, or the baseline the user marks), what the
//! normalisation did and why, and the alarm's hysteresis: raised on the trend, held until
//! the indicator is back at the reference (the module's documentation, items 4 and 5).

use super::level::fault_level_run;
use super::stats::{mad_sigma, median};
use super::{
    CovariateRange, Indicator, IndicatorTrend, Normalisation, ReferenceBasis, TrendOptions,
    TrendPoint, TrendReason, TrendReference,
};
use crate::row::{utc_day, StoredRow};

/// Seconds per day.
const DAY_S: f64 = 86_400.0;

/// The motor's reference among `rows` (one motor's, by time): a mask over `rows` and what
/// it is. With [`TrendOptions::reference_until_s`], the logs before it (all of them: the
/// user marked them healthy); else the logs of the motor's first
/// [`TrendOptions::window_days`] whose stored verdict is `healthy` or `watching` (neither a
/// FAULT nor a log that could not judge), or its first [`TrendOptions::min_logs`] such logs
/// where the first days hold fewer; where no log's verdict is either, its first days' logs
/// whatever their verdict (and [`TrendReference::basis`] says so). Per indicator, a log at
/// the indicator's FAULT level is left out of its reference whatever its verdict.
pub fn reference_rows(rows: &[&StoredRow], opts: &TrendOptions) -> (Vec<bool>, TrendReference) {
    let time = |r: &StoredRow| r.f64("log_time_s").unwrap_or_default();
    // A log that judged the motor and found no fault: healthy, or watching a change below
    // a FAULT. Neither a FAULT nor a log that could not judge (a file that does not fit, a
    // wiring mix-up, a supply off the file's) is a healthy reference.
    let healthy = |r: &StoredRow| matches!(r.str("verdict"), Some("healthy" | "watching"));
    let marked = opts.reference_until_s.map(|u| u as f64);
    let marked_day = |u: f64| utc_day(u as i64 - 1);
    let (mask, basis, is_marked, mark_without_logs) = match marked {
        Some(u) if rows.iter().any(|r| time(r) < u) => (
            rows.iter().map(|r| time(r) < u).collect::<Vec<bool>>(),
            ReferenceBasis::Marked {
                until_day: marked_day(u),
            },
            true,
            None,
        ),
        _ => {
            let (mask, basis) = first_healthy(rows, opts, &time, &healthy);
            (mask, basis, false, marked.map(marked_day))
        }
    };
    let picked: Vec<&&StoredRow> = rows
        .iter()
        .zip(&mask)
        .filter(|(_, m)| **m)
        .map(|(r, _)| r)
        .collect();
    let day = |r: Option<&&&StoredRow>| r.and_then(|r| r.str("day")).map(str::to_string);
    let reference = TrendReference {
        logs: picked.len(),
        first_day: day(picked.first()),
        last_day: day(picked.last()),
        marked: is_marked,
        basis,
        mark_without_logs,
    };
    (mask, reference)
}

/// The default reference: the first days' logs whose verdict is not `fault` (see
/// [`reference_rows`]).
fn first_healthy(
    rows: &[&StoredRow],
    opts: &TrendOptions,
    time: &dyn Fn(&StoredRow) -> f64,
    healthy: &dyn Fn(&StoredRow) -> bool,
) -> (Vec<bool>, ReferenceBasis) {
    let t0 = rows.first().map_or(0.0, |r| time(r));
    let early = |r: &StoredRow| time(r) < t0 + opts.window_days * DAY_S;
    let days = opts.window_days;
    let mut mask: Vec<bool> = rows.iter().map(|r| early(r) && healthy(r)).collect();
    if mask.iter().filter(|m| **m).count() >= opts.min_logs {
        return (mask, ReferenceBasis::FirstHealthyDays { days });
    }
    let mut taken = 0;
    for (m, r) in mask.iter_mut().zip(rows) {
        *m = taken < opts.min_logs && healthy(r);
        taken += usize::from(*m);
    }
    if taken > 0 {
        return (mask, ReferenceBasis::FirstHealthyLogs { logs: taken });
    }
    (
        rows.iter().map(|r| early(r)).collect(),
        ReferenceBasis::FirstDaysAllFault { days },
    )
}

/// The reference's centre and scatter of a series (its points `in_reference`): the median
/// and 1.4826 MAD about it, the scatter at least `floor` (the operating-point fit's) and
/// only with at least `min` values.
pub(super) fn reference_stats(
    series: &[TrendPoint],
    floor: f64,
    min: usize,
) -> (Option<f64>, Option<f64>) {
    let mut v: Vec<f64> = series
        .iter()
        .filter(|p| p.in_reference)
        .map(|p| p.normalised)
        .collect();
    let scatter = if v.len() >= min.max(3) {
        let top = v.iter().map(|x| x.abs()).fold(0.0, f64::max);
        mad_sigma(&v).map(|s| s.max(floor).max(1e-9 * top).max(f64::MIN_POSITIVE))
    } else {
        None
    };
    (median(&mut v), scatter)
}

/// A spread negligible against the covariate's size: below 0.1 % of its largest value
/// (and below 1e-9 in absolute terms for a covariate about zero).
fn negligible(lo: f64, hi: f64) -> bool {
    hi - lo <= 1e-3 * lo.abs().max(hi.abs()).max(1e-6)
}

/// The operating-point normalisation of `ind` on `covs` over `rows`, `fitted` or not: the
/// fit made, or the actual reason it was not (too few logs with the covariates, N of M
/// needed; a covariate that does not vary; covariates that cannot be told apart), with
/// each covariate's range where it is not taken out. Also the logs the fit could use.
pub(super) fn normalisation_note(
    ind: &Indicator,
    covs: &[&str],
    rows: &[&StoredRow],
    fitted: bool,
    needed: usize,
) -> (Normalisation, usize) {
    let n = rows
        .iter()
        .filter(|r| r.f64(ind.column).is_some() && covs.iter().all(|c| r.f64(c).is_some()))
        .count();
    let covariates = || covs.iter().map(|c| c.to_string()).collect();
    if fitted {
        let covariates = covariates();
        return (
            Normalisation::Fitted {
                covariates,
                logs: n,
            },
            n,
        );
    }
    if covs.is_empty() {
        return (Normalisation::NoCovariates, n);
    }
    let (moved, flat) = covariate_ranges(covs, rows);
    let note = if n < needed {
        Normalisation::TooFewLogs {
            logs: n,
            needed,
            lacking: rows.len().saturating_sub(n),
            total: rows.len(),
            moved,
        }
    } else if flat.is_empty() {
        Normalisation::Collinear {
            covariates: covariates(),
            logs: n,
            moved,
        }
    } else {
        Normalisation::Flat { flat, moved }
    };
    (note, n)
}

/// The covariates' ranges over `rows`: those that moved, and those whose spread is
/// negligible.
fn covariate_ranges(
    covs: &[&str],
    rows: &[&StoredRow],
) -> (Vec<CovariateRange>, Vec<CovariateRange>) {
    let (mut moved, mut flat) = (Vec::new(), Vec::new());
    for c in covs {
        let v: Vec<f64> = rows.iter().filter_map(|r| r.f64(c)).collect();
        let low = v.iter().copied().fold(f64::INFINITY, f64::min);
        let high = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !low.is_finite() {
            continue;
        }
        let range = CovariateRange {
            column: c.to_string(),
            low,
            high,
        };
        if negligible(low, high) {
            flat.push(range);
        } else {
            moved.push(range);
        }
    }
    (moved, flat)
}

/// The state of one log in the alarm's history: the trend as of it (on the logs up to it)
/// alarms or the log is at the FAULT level, or it is back at the reference (neither, and
/// the line at it and its value within [`TrendOptions::k_scatter`] reference scatters of
/// the reference's centre).
#[derive(Clone, Copy)]
struct LogState {
    /// The trend as of the log alarms, or the log's value is at the FAULT level.
    alarm: bool,
    /// The indicator is back at the reference at the log.
    back: bool,
}

/// [`LogState`] of a trend as of its last log.
fn state_of(t: &IndicatorTrend, opts: &TrendOptions) -> LogState {
    let within = |x: Option<f64>| x.is_some_and(|x| x.abs() <= opts.k_scatter);
    let value = match (t.series.last(), t.reference_centre, t.reference_scatter) {
        (Some(p), Some(c), Some(s)) => Some((p.normalised - c) / s),
        _ => None,
    };
    let alarm = t.alarm || t.fault_level_logs > 0;
    LogState {
        alarm,
        back: !alarm && within(t.from_reference_scatters) && within(value),
    }
}

/// `t` (the trend of `ind` as of the last of `rows`) with the alarm's hysteresis applied:
/// raised where the last [`TrendOptions::confirm_logs`] logs all alarm (the trend as of
/// each, or its value at the FAULT level), and held from the log it was raised on until the
/// indicator is back at the reference on `confirm_logs` logs in a row. The history is
/// walked back from the last log, each log judged on the logs up to it by `judge`, until
/// a clearing run or the first log. The reason: the FAULT level on the last logs in a row
/// first (what the logs show, whatever the operating-point fit needs), then the slope,
/// then the alarm held.
pub(super) fn latched(
    mut t: IndicatorTrend,
    ind: &Indicator,
    rows: &[&StoredRow],
    opts: &TrendOptions,
    judge: &dyn Fn(&[&StoredRow]) -> IndicatorTrend,
) -> IndicatorTrend {
    let c = opts.confirm_logs.max(1);
    let run = fault_level_run(ind, rows);
    let since = raised_at(rows, opts, state_of(&t, opts), judge);
    let Some(since) = since else {
        if t.alarm {
            t.alarm = false;
            t.reason = TrendReason::NotConfirmed { confirm_logs: c };
        } else if let Some(r) = run {
            t.reason = TrendReason::FaultLevelNotConfirmed {
                logs: r.logs,
                confirm_logs: c,
                value: r.value,
                level: r.level,
            };
        }
        return t;
    };
    let day = rows
        .get(since - 1)
        .and_then(|r| r.str("day"))
        .unwrap_or_default()
        .to_string();
    match run.filter(|r| r.logs >= c) {
        Some(r) => {
            t.reason = TrendReason::FaultLevelInARow {
                logs: r.logs,
                first_day: r.first_day,
                value: r.value,
                level: r.level,
            };
        }
        None if !t.alarm => {
            t.reason = TrendReason::Held {
                since: day.clone(),
                from_reference_scatters: t.from_reference_scatters,
                k_scatter: opts.k_scatter,
                confirm_logs: c,
            };
        }
        None => {}
    }
    t.alarm = true;
    t.alarm_since = Some(day);
    t
}

/// The log (1-based, over `rows`) the alarm now standing was raised on, if one stands:
/// the history walked back from the last log (whose state is `last`), each log judged on
/// the logs up to it, until [`TrendOptions::confirm_logs`] logs in a row back at the
/// reference (a clearing: an alarm raised before it no longer stands) or the first log.
fn raised_at(
    rows: &[&StoredRow],
    opts: &TrendOptions,
    last: LogState,
    judge: &dyn Fn(&[&StoredRow]) -> IndicatorTrend,
) -> Option<usize> {
    let c = opts.confirm_logs.max(1);
    let n = rows.len();
    let mut memo: Vec<Option<LogState>> = vec![None; n + 1];
    if let Some(m) = memo.get_mut(n) {
        *m = Some(last);
    }
    let mut state = |m: usize| -> LogState {
        if let Some(Some(s)) = memo.get(m) {
            return *s;
        }
        let none = LogState {
            alarm: false,
            back: false,
        };
        let s = rows.get(..m).map_or(none, |r| state_of(&judge(r), opts));
        if let Some(slot) = memo.get_mut(m) {
            *slot = Some(s);
        }
        s
    };
    let (mut run, mut since) = (0, None);
    for m in (1..=n).rev() {
        if state(m).back {
            run += 1;
            if run >= c {
                break;
            }
            continue;
        }
        run = 0;
        if m >= c && (m + 1 - c..=m).all(|j| state(j).alarm) {
            since = Some(m);
        }
    }
    since
}
