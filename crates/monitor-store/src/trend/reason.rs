//! The trend's typed values: why an indicator alarms or does not ([`TrendReason`]), how it
//! was brought to the motor's operating point ([`Normalisation`]) and which logs are the
//! motor's reference ([`ReferenceBasis`]), each with the numbers that decided. The trend
//! builds no sentence; `monitor_words::trend` spells these.

use serde::Serialize;

/// Why an indicator's trend alarms or does not: the rule that decided, with its numbers
/// (JSON `reason`, tagged by `kind`, beside the indicator's `sentence`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TrendReason {
    /// **Alarm**: the indicator's stored value was at its FAULT level on the motor's last
    /// `logs` logs in a row (at least [`super::TrendOptions::confirm_logs`]), the first of
    /// them on `first_day`; what the logs themselves show, raised whatever the
    /// operating-point fit still needs (the fit refines the slope, it never silences this).
    FaultLevelInARow {
        /// The logs in a row at the FAULT level, ending at the last.
        logs: usize,
        /// The first one's UTC day.
        first_day: String,
        /// The last log's stored value [the indicator's unit].
        value: f64,
        /// Its FAULT level [the indicator's unit].
        level: f64,
    },
    /// **Alarm** on the slope: Sen's interval on the fault's side of zero, the line moving
    /// the indicator by more than [`super::TrendOptions::k_scatter`] scatters over the
    /// window (and, with a FAULT level, reaching it within the horizon), on
    /// [`super::TrendOptions::confirm_logs`] logs in a row.
    Slope {
        /// Days until the window's line reaches the FAULT level (0: there already).
        days_to_fault: Option<f64>,
        /// The same on the window's second half's line
        /// ([`super::IndicatorTrend::days_to_fault_recent`]).
        days_to_fault_recent: Option<f64>,
    },
    /// **Alarm held**: raised on `since` and not back at the reference since (the
    /// hysteresis: the module's documentation, item 4).
    Held {
        /// The UTC day of the log the alarm was raised on.
        since: String,
        /// The line at the last log from the reference's centre, in reference scatters.
        from_reference_scatters: Option<f64>,
        /// It clears within this many reference scatters ...
        k_scatter: f64,
        /// ... on this many logs in a row.
        confirm_logs: usize,
    },
    /// No alarm: the slope alarms as of the last log, not yet on `confirm_logs` logs in a
    /// row.
    NotConfirmed {
        /// The logs in a row needed.
        confirm_logs: usize,
    },
    /// No alarm: the stored value is at its FAULT level on the last `logs` logs in a row,
    /// fewer than `confirm_logs` (one spurious log does not alarm).
    FaultLevelNotConfirmed {
        /// The logs in a row at the FAULT level, ending at the last.
        logs: usize,
        /// The logs in a row needed.
        confirm_logs: usize,
        /// The last log's stored value [the indicator's unit].
        value: f64,
        /// Its FAULT level [the indicator's unit].
        level: f64,
    },
    /// No alarm yet: the slope would alarm, but the operating-point fit has `logs` of the
    /// `needed` logs, so a trend cannot yet be told from the operating point's moves.
    NotYet {
        /// The logs with the indicator and its covariates.
        logs: usize,
        /// The logs the fit needs ([`super::fit_logs`]).
        needed: usize,
    },
    /// Shown, not alarmed: a parity residual normalised on the rise the isolation read (the
    /// logs have no temperature channel).
    NoTemperatureChannel,
    /// Shown, not alarmed: the indicator never alarms ([`super::Indicator::alarms`]).
    ShownOnly,
    /// No alarm; where the line heads to the FAULT level within the horizon, in how many
    /// days.
    NoAlarm {
        /// Days until the line reaches the FAULT level at this slope.
        days_to_fault: Option<f64>,
    },
    /// No trend: `logs` logs in the last `window_days`, fewer than `needed`; `values`: the
    /// stored values there.
    TooFewLogs {
        /// The logs in the window with a value.
        logs: usize,
        /// The fewest for a slope and a scatter.
        needed: usize,
        /// The window [days].
        window_days: f64,
        /// The stored values in the window, where there is one.
        values: Option<ValueRange>,
    },
    /// No slope: every log of the window at one time.
    OneTime,
}

impl TrendReason {
    /// Whether the reason raises (or holds) the alarm.
    pub fn alarms(&self) -> bool {
        matches!(
            self,
            TrendReason::FaultLevelInARow { .. }
                | TrendReason::Slope { .. }
                | TrendReason::Held { .. }
        )
    }
}

/// Stored values of an indicator in its window [the indicator's unit].
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct ValueRange {
    /// The least.
    pub low: f64,
    /// The greatest.
    pub high: f64,
    /// The first log's.
    pub first: f64,
    /// The last log's.
    pub last: f64,
}

/// How an indicator was brought to the motor's median operating point, or why it was not
/// (JSON `normalisation_reason`, tagged by `kind`, beside the spelled `normalisation`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Normalisation {
    /// Brought to the median `covariates` (least squares, second order in them, with time,
    /// over the motor's `logs` logs).
    Fitted {
        /// The covariates (store columns).
        covariates: Vec<String>,
        /// The logs fitted.
        logs: usize,
    },
    /// Raw values: the indicator has no covariates.
    NoCovariates,
    /// Raw values: `logs` of the `needed` logs for the fit (`lacking` of the `total` logs
    /// lack a covariate or the value); no alarm on the slope until then.
    TooFewLogs {
        /// The logs with the indicator and its covariates.
        logs: usize,
        /// The logs the fit needs.
        needed: usize,
        /// The motor's logs that lack a covariate or the value.
        lacking: usize,
        /// The motor's logs.
        total: usize,
        /// The covariates that varied (not taken out).
        moved: Vec<CovariateRange>,
    },
    /// Raw values: the fit on `covariates` could not be made over `logs` logs (they move
    /// together).
    Collinear {
        /// The covariates.
        covariates: Vec<String>,
        /// The logs.
        logs: usize,
        /// The covariates that varied (not taken out).
        moved: Vec<CovariateRange>,
    },
    /// Raw values: the operating point does not vary (`flat`: the covariates whose spread is
    /// under 0.1 % of their value).
    Flat {
        /// The covariates that do not vary.
        flat: Vec<CovariateRange>,
        /// Those that varied (not taken out).
        moved: Vec<CovariateRange>,
    },
}

/// A covariate's range over the motor's logs.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct CovariateRange {
    /// The store column.
    pub column: String,
    /// Its least value [its unit].
    pub low: f64,
    /// Its greatest value [its unit].
    pub high: f64,
}

/// Which logs are a motor's reference (JSON `reference.basis`, tagged by `kind`, beside the
/// spelled `reference.how`).
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ReferenceBasis {
    /// The logs up to the end of the day the user marked.
    Marked {
        /// The marked UTC day.
        until_day: String,
    },
    /// The motor's first `days` days of logs whose verdict is healthy or watching.
    FirstHealthyDays {
        /// The days [days].
        days: f64,
    },
    /// Its first `logs` logs whose verdict is healthy or watching (its first days hold fewer).
    FirstHealthyLogs {
        /// The logs.
        logs: usize,
    },
    /// Its first `days` days of logs, every log's verdict being FAULT.
    FirstDaysAllFault {
        /// The days [days].
        days: f64,
    },
}
