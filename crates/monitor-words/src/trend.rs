//! The trend's words: the alarm, each indicator's line and the reference, spelled from
//! [`monitor_store::trend`]'s typed values.
//!
//! - [`sentence`]: an indicator's one sentence, from its [`TrendReason`] and its line
//!   ("i2_over_i1 rising 0.518 % of I1/week (0.213 to 0.789), 3.3 scatters over 14 days:
//!   TREND ALARM, FAULT level in about 38 days (about 13 at the last 7 days' slope); a short
//!   between turns growing in one phase").
//! - [`normalisation`]: how it was brought to the motor's operating point, or why not.
//! - [`reference_how`]: which logs are the motor's reference.
//! - [`spelled`]: `sim-host trend --json`'s and Python's `motors`: the engine's values with
//!   each sentence beside its typed reason (`sentence` and `reason`, `normalisation` and
//!   `normalisation_reason`, `reference.how` and `reference.basis`).

use monitor_store::trend::{
    CovariateRange, Indicator, IndicatorTrend, MotorTrend, Normalisation, ReferenceBasis,
    TrendReason, TrendReference, ValueRange, INDICATORS,
};
use serde::Serialize;

/// The indicator of store column `column`, where it is one of [`INDICATORS`].
fn indicator(column: &str) -> Option<&'static Indicator> {
    INDICATORS.iter().find(|i| i.column == column)
}

/// What an alarm on the indicator of store column `column` means to a planner (added to
/// its alarmed sentence), where it says more than the indicator's name.
pub fn alarm_means(column: &str) -> Option<&'static str> {
    match column {
        "i2_over_i1" => Some("a short between turns growing in one phase"),
        "sideband_db" => Some("rotor bars cracking or breaking"),
        "stator_excess_pct" => Some(
            "Rs beyond Rr: the stator circuit's resistance rises and the rotor's does not, so \
             not heating (a warm winding raises both together): a loosening connection, or, \
             with |I2w|/|I1| rising too, turns shorting in one phase",
        ),
        _ => None,
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

/// The scale and the unit sentences show the indicator of `t` in (the store's where it is
/// not one of [`INDICATORS`]).
fn shown(t: &IndicatorTrend) -> (f64, &str) {
    indicator(&t.indicator).map_or((1.0, t.unit.as_str()), |i| (i.scale, i.shown_unit))
}

/// "i2_over_i1 rising 0.518 % of I1/week (0.213 to 0.789), 3.3 scatters over 14 days": the
/// window's line, in the indicator's shown unit; the indicator's name alone without a line.
fn head(t: &IndicatorTrend) -> String {
    let (Some(slope), Some(low), Some(high), Some(span)) =
        (t.slope_per_day, t.slope_low, t.slope_high, t.span_days)
    else {
        return t.indicator.clone();
    };
    let (scale, unit) = shown(t);
    let week = |v: f64| sig3(7.0 * v * scale);
    let dir = if slope >= 0.0 { "rising" } else { "falling" };
    format!(
        "{} {dir} {} {unit}/week ({} to {}), {:.1} scatters over {span:.0} days",
        t.indicator,
        week(slope),
        week(low),
        week(high),
        t.moves_scatters.unwrap_or_default(),
    )
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

/// "; the stored values 0.0001 to 0.026 pu (first 0.0001, last 0.026)": what there is
/// where there is no trend.
fn stored_values(v: Option<&ValueRange>, scale: f64, unit: &str) -> String {
    v.map_or(String::new(), |v| {
        format!(
            "; the stored values {} to {} {unit} (first {}, last {})",
            sig3(v.low * scale),
            sig3(v.high * scale),
            sig3(v.first * scale),
            sig3(v.last * scale)
        )
    })
}

/// An indicator's one sentence: its line (or its name) and what its [`TrendReason`] says,
/// with what an alarm means ([`alarm_means`]) after a raised one.
pub fn sentence(t: &IndicatorTrend) -> String {
    let (scale, unit) = shown(t);
    let name = &t.indicator;
    let level = |v: f64, l: f64| {
        format!(
            "the last log {} {unit} against its level {}",
            sig3(v * scale),
            sig3(l * scale)
        )
    };
    let tail = match &t.reason {
        TrendReason::TooFewLogs {
            logs,
            needed,
            window_days,
            values,
        } => {
            return format!(
                "{name}: {logs} logs in the last {window_days} days, too few for a trend or a \
                 scatter (at least {needed}){}",
                stored_values(values.as_ref(), scale, unit)
            )
        }
        TrendReason::OneTime => return format!("{name}: all logs at one time, no slope"),
        TrendReason::FaultLevelInARow {
            logs,
            first_day,
            value,
            level: l,
        } => format!(
            ": TREND ALARM, at the FAULT level on the last {logs} logs in a row, since \
             {first_day} ({})",
            level(*value, *l)
        ),
        TrendReason::Slope {
            days_to_fault,
            days_to_fault_recent,
        } => match days_to_fault {
            Some(d) if *d < 0.5 => ": TREND ALARM, at the FAULT level already".to_string(),
            Some(d) => format!(
                ": TREND ALARM, FAULT level in about {d:.0} days{}",
                sooner(*days_to_fault_recent, *d, t.span_days.unwrap_or_default())
            ),
            None => ": TREND ALARM".to_string(),
        },
        TrendReason::Held {
            since,
            from_reference_scatters,
            k_scatter,
            confirm_logs,
        } => {
            let now = from_reference_scatters.map_or(String::new(), |x| {
                format!(", the line {x:+.1} reference scatters from the reference")
            });
            return format!(
                "{}: TREND ALARM held, raised on {since}{now}; it clears when back within \
                 {k_scatter} reference scatters on {confirm_logs} logs in a row",
                head(t)
            );
        }
        TrendReason::NotConfirmed { confirm_logs } => {
            format!(": alarm not yet confirmed ({confirm_logs} logs in a row needed)")
        }
        TrendReason::FaultLevelNotConfirmed {
            logs,
            confirm_logs,
            value,
            level: l,
        } => format!(
            ": no alarm yet, at the FAULT level on the last {logs} of the {confirm_logs} logs \
             in a row needed ({})",
            level(*value, *l)
        ),
        TrendReason::NotYet { logs, needed } => {
            format!(": no alarm yet ({logs} logs; the operating-point fit needs {needed})")
        }
        TrendReason::NoTemperatureChannel => ": shown, not alarmed (no temperature channel: \
             normalised on the rise the isolation read)"
            .to_string(),
        TrendReason::ShownOnly => ": shown, not alarmed".to_string(),
        TrendReason::NoAlarm {
            days_to_fault: Some(d),
        } if *d < 365.0 => format!(": no alarm (FAULT level in about {d:.0} days at this slope)"),
        TrendReason::NoAlarm { .. } => ": no alarm".to_string(),
    };
    let means = alarm_means(name)
        .filter(|_| t.alarm)
        .map_or(String::new(), |m| format!("; {m}"));
    format!("{}{tail}{means}", head(t))
}

/// A covariate's name and unit in the report's words.
fn covariate_words(c: &str) -> (&'static str, &'static str) {
    match c {
        "i1_peak_a" => ("the load (I1)", "A"),
        "winding_temperature_c" => ("the windings' temperature", "°C"),
        "winding_rise_k" => ("the windings' rise", "K"),
        _ => ("a covariate", ""),
    }
}

/// "; the load (I1) varied 6.400-7.600 A (i1_peak_a) and is not taken out" for the
/// covariates that moved (nothing where none did).
fn not_taken_out(moved: &[CovariateRange]) -> String {
    let said: Vec<String> = moved
        .iter()
        .map(|r| {
            let (name, unit) = covariate_words(&r.column);
            format!(
                "{name} varied {:.3}-{:.3} {unit} ({})",
                r.low, r.high, r.column
            )
        })
        .collect();
    match said.len() {
        0 => String::new(),
        1 => format!("; {} and is not taken out", said.join("")),
        _ => format!("; {} and are not taken out", said.join(", ")),
    }
}

/// How an indicator was brought to the motor's operating point, or the actual reason it was
/// not ("not yet: raw values, too few logs for the operating-point fit (4 of the 28
/// needed); the load (I1) varied 6.400-7.600 A (i1_peak_a) and is not taken out; its slope
/// does not alarm until then").
pub fn normalisation(n: &Normalisation) -> String {
    match n {
        Normalisation::Fitted { covariates, logs } => format!(
            "brought to the median {} (least squares, second order in them, with time, over \
             the motor's {logs} logs)",
            covariates.join(" and ")
        ),
        Normalisation::NoCovariates => "raw values (the indicator has no covariates)".to_string(),
        Normalisation::TooFewLogs {
            logs,
            needed,
            lacking,
            total,
            moved,
        } => {
            let lack = if *lacking > 0 {
                format!(", {lacking} of the {total} logs lack a covariate or the value")
            } else {
                String::new()
            };
            format!(
                "not yet: raw values, too few logs for the operating-point fit ({logs} of the \
                 {needed} needed{lack}){}; its slope does not alarm until then",
                not_taken_out(moved)
            )
        }
        Normalisation::Collinear {
            covariates,
            logs,
            moved,
        } => format!(
            "raw values: the fit on {} could not be made over {logs} logs (they move \
             together){}",
            covariates.join(" and "),
            not_taken_out(moved)
        ),
        Normalisation::Flat { flat, moved } => {
            let flat: Vec<String> = flat
                .iter()
                .map(|r| {
                    let (name, unit) = covariate_words(&r.column);
                    format!("{name} ({}) stays at {:.3} {unit}", r.column, r.low)
                })
                .collect();
            format!(
                "raw values: the operating point does not vary ({}){}",
                flat.join(", "),
                not_taken_out(moved)
            )
        }
    }
}

/// Which logs are the motor's reference ("the motor's first 14 days of logs whose verdict
/// is healthy or watching").
pub fn reference_how(r: &TrendReference) -> String {
    let how = match &r.basis {
        ReferenceBasis::Marked { until_day } => format!("the logs up to {until_day} (marked)"),
        ReferenceBasis::FirstHealthyDays { days } => {
            format!("the motor's first {days} days of logs whose verdict is healthy or watching")
        }
        ReferenceBasis::FirstHealthyLogs { logs } => {
            format!("the motor's first {logs} logs whose verdict is healthy or watching")
        }
        ReferenceBasis::FirstDaysAllFault { days } => {
            format!(
                "the motor's first {days} days of logs (no log's verdict is healthy or watching)"
            )
        }
    };
    match &r.mark_without_logs {
        Some(day) => format!("no log up to the marked {day}: {how}"),
        None => how,
    }
}

/// One indicator's trend with its words (JSON: the engine's keys, `sentence` beside
/// `reason`, `normalisation` beside `normalisation_reason`).
#[derive(Debug, Serialize)]
pub struct SpelledIndicator<'a> {
    /// The engine's values.
    #[serde(flatten)]
    pub trend: &'a IndicatorTrend,
    /// [`sentence`].
    pub sentence: String,
    /// [`normalisation`].
    pub normalisation: String,
}

/// A motor's reference with its words (JSON: `how` beside `basis`).
#[derive(Debug, Serialize)]
pub struct SpelledReference<'a> {
    /// The engine's values.
    #[serde(flatten)]
    pub reference: &'a TrendReference,
    /// [`reference_how`].
    pub how: String,
}

/// One motor's trend with its words (`sim-host trend --json`'s and Python's `motors`).
#[derive(Debug, Serialize)]
pub struct SpelledMotor<'a> {
    /// The motor.
    pub motor: &'a str,
    /// Its logs.
    pub logs: usize,
    /// The first log's day.
    pub first_day: &'a str,
    /// The last log's day.
    pub last_day: &'a str,
    /// Any indicator's trend alarm.
    pub alarm: bool,
    /// The fastest indicator's |moves_scatters|.
    pub fastest_scatters: f64,
    /// Its reference.
    pub reference: SpelledReference<'a>,
    /// Its indicators (those its logs measured).
    pub indicators: Vec<SpelledIndicator<'a>>,
}

/// The motors' trends with their words, in their order.
pub fn spelled(motors: &[MotorTrend]) -> Vec<SpelledMotor<'_>> {
    motors
        .iter()
        .map(|m| SpelledMotor {
            motor: &m.motor,
            logs: m.logs,
            first_day: &m.first_day,
            last_day: &m.last_day,
            alarm: m.alarm,
            fastest_scatters: m.fastest_scatters,
            reference: SpelledReference {
                reference: &m.reference,
                how: reference_how(&m.reference),
            },
            indicators: m
                .indicators
                .iter()
                .map(|t| SpelledIndicator {
                    trend: t,
                    sentence: sentence(t),
                    normalisation: normalisation(&t.normalisation),
                })
                .collect(),
        })
        .collect()
}
