//! The trend of a motor's indicators across its stored logs, and the alarm on it: typed
//! values and typed reasons ([`TrendReason`], [`Normalisation`], [`ReferenceBasis`]), no
//! sentence (`monitor_words::trend` spells them).
//!
//! Per indicator, over the last [`TrendOptions::window_days`] of the motor's logs:
//!
//! 1. **Like operating points.** The indicator is brought to the motor's median operating
//!    point: a least-squares fit of it on the covariates it depends on (the load, as the
//!    positive-sequence current `i1_peak_a`; the windings' rise `winding_rise_k` the
//!    isolation read) and on time together, over all the motor's logs, and the covariates'
//!    part removed (the time term is fitted with them so that they do not take up a trend).
//!    A season that warms the windings or a load that moves from day to day is then not a
//!    trend. Where the logs cannot fit the covariates (too few, or a covariate that does
//!    not vary) the raw values are used; the report says which
//!    ([`IndicatorTrend::normalisation`]).
//! 2. **A robust slope.** Theil-Sen's slope per day with Sen's interval
//!    ([`stats::theil_sen`]), and the indicator's own scatter, 1.4826 x the median absolute
//!    deviation of the values about the line ([`stats::mad_sigma`]).
//! 3. **The alarm.** On [`TrendOptions::confirm_logs`] logs in a row (each judged on the
//!    logs up to it), either of:
//!    - **the FAULT level**: the log's stored value is at or beyond the indicator's FAULT
//!      level (the log's own level where the level is a column, as its verdict used it).
//!      What the logs show raises the alarm whatever the operating-point fit still needs:
//!      the fit refines the slope, it never silences the logs
//!      ([`TrendReason::FaultLevelInARow`]); one log at the level alone does not
//!      ([`TrendReason::FaultLevelNotConfirmed`]);
//!    - **the slope**: the interval lies wholly on the indicator's bad side of zero (above
//!      it for a rising indicator; either side for a two-sided one) *and* the line moves
//!      the indicator by more than [`TrendOptions::k_scatter`] scatters over the window.
//!      Either alone is not enough: a significant slope far inside the noise is not worth
//!      a visit, and one large scatter is not a trend ([`TrendReason::Slope`]).
//!
//!    An indicator none of the motor's logs measured (a log without voltages has no parity
//!    residual and no Rs beyond Rr: null in the store) is absent from
//!    [`MotorTrend::indicators`], not a flat line at zero.
//! 4. **The alarm holds once raised** (a hysteresis): it stays raised on the later logs,
//!    whatever their slope, until the indicator is back at the motor's reference: on
//!    [`TrendOptions::confirm_logs`] logs in a row, the trend as of the log does not alarm,
//!    and both the line at the log and the log's own value lie within
//!    [`TrendOptions::k_scatter`] reference scatters of the reference's centre
//!    ([`IndicatorTrend::alarm_since`]). Raising and clearing are different tests (a slope,
//!    a level), so a fault that stops growing stays alarmed, and a repaired motor clears.
//! 5. **The reference.** Each motor's own healthy start
//!    ([`MotorTrend::reference`]): its logs up to [`TrendOptions::reference_until_s`]
//!    where the user marks the baseline, else those of its first
//!    [`TrendOptions::window_days`] whose stored verdict is not `fault` (at least
//!    [`TrendOptions::min_logs`] of them). Per indicator its centre (the median of their
//!    normalised values) and its scatter (1.4826 MAD about it, at least the
//!    operating-point fit's); the plot's bands and [`IndicatorTrend::from_reference_scatters`]
//!    are relative to it, and the alarm clears against it.
//! 6. **The projection.** Where the indicator has a FAULT level (the level at which a
//!    single log's verdict names the fault), the days until the line reaches it, only where
//!    Sen's interval lies wholly on the fault's side of zero (a slope that may be zero
//!    projects nothing) and within [`TrendOptions::horizon_days`]; for such an indicator
//!    the alarm also needs that projection (a significant drift far below the level is not
//!    worth a visit).

pub mod stats;

use serde::Serialize;

/// Which way an indicator moves when a fault grows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Up (the negative sequence, the sideband).
    Rising,
    /// Either way (a parity residual).
    Either,
}

/// One trended indicator: a store column and what it means.
#[derive(Debug, Clone, Copy)]
pub struct Indicator {
    /// The store column ([`crate::COLUMNS`]).
    pub column: &'static str,
    /// A short label for tables and plots.
    pub label: &'static str,
    /// Its unit (the store's and the JSON's).
    pub unit: &'static str,
    /// The factor from `unit` to the unit sentences show it in.
    pub scale: f64,
    /// The unit sentences show it in.
    pub shown_unit: &'static str,
    /// Which way a fault moves it.
    pub direction: Direction,
    /// Whether its trend raises the alarm (else it is trended and shown only).
    pub alarms: bool,
    /// The covariates it is normalised on (store columns): sets in order of preference,
    /// the first one the motor's logs have used.
    pub covariates: &'static [&'static [&'static str]],
    /// The least scatter it is judged with [unit]: what one log can resolve at best, so
    /// that a line moving by a few hundredths of a per cent on clean simulated data is not
    /// a trend (0 where the scatter itself is the floor).
    pub min_scatter: f64,
    /// The store column holding its FAULT level per log (each log is at the FAULT level
    /// against its own; the trend's line against their median over the motor's logs), or a
    /// fixed level, or none.
    pub fault_level: FaultLevel,
}

/// Where an indicator's FAULT level comes from.
#[derive(Debug, Clone, Copy)]
pub enum FaultLevel {
    /// No level: the trend alarms, nothing is projected.
    None,
    /// A store column's value per log (a log against its own, the line against the median
    /// over the motor's logs).
    Column(&'static str),
    /// A fixed level in the indicator's unit.
    Fixed(f64),
}

/// The load covariate.
const LOAD: &str = "i1_peak_a";
/// The temperature covariate where the log has a temperature channel: measured, so it
/// does not take up a resistance change as the isolation's own reading of the rise does.
const TEMPERATURE: &str = "winding_temperature_c";
/// The temperature covariate without a channel: the rise the isolation read from Rs and Rr
/// together (a loosening connection's Rs partly reads as heating in it).
pub(crate) const RISE: &str = "winding_rise_k";

/// A parity residual as an indicator: either way, per unit, normalised on load and the
/// windings' temperature (measured, else the isolation's rise), no FAULT level.
const fn residual(column: &'static str, label: &'static str) -> Indicator {
    Indicator {
        column,
        label,
        unit: "pu",
        scale: 1.0,
        shown_unit: "pu",
        direction: Direction::Either,
        alarms: true,
        covariates: &[&[LOAD, TEMPERATURE], &[LOAD, RISE]],
        min_scatter: 0.0,
        fault_level: FaultLevel::None,
    }
}

/// The indicators trended, in the tables' order.
///
/// - `i2_over_i1`: the winding's negative-sequence change (a short grows it); its FAULT
///   level is the change that names a phase at the winding's FAULT probability
///   (`unbalance.least_change`, the level `diagnose`'s verdict uses), normalised on load.
/// - `residual_d`, `residual_q`, `residual_t`: the isolation's parity residuals against the
///   parameter file (a resistance, inductance or load change moves them), normalised on
///   load and the windings' rise; trended and shown, **not alarmed**: in the simulated
///   month their dependence on the season's heating and the load is not linear enough for
///   this fit, and healthy motors' residuals moved by 4 to 19 scatters in two weeks
///   (docs/trend.md, "Limits"). No FAULT level (the isolation names a fault from their
///   direction, not from one level).
/// - `sideband_db`: the rotor's lower sideband (broken bars grow it), normalised on load;
///   its FAULT level is -50 dB below the line ... (the usual MCSA rule of thumb for one
///   broken bar, not a project threshold: docs/trend.md).
/// - `stator_excess_pct`: Rs's change beyond Rr's, read apart at the log's steady points
///   (`monitor_core::isolation::resistance_split`): a warm winding raises both alike and
///   leaves it, a loosening connection raises Rs alone. Normalised on load (an inductance
///   of the file that is off moves it with the operating point, not with the
///   temperature); FAULT level [`STATOR_EXCESS_FAULT_PCT`], judged with at least
///   [`STATOR_EXCESS_MIN_SCATTER_PCT`] of scatter.
pub const INDICATORS: [Indicator; 6] = [
    Indicator {
        column: "i2_over_i1",
        label: "|I2w|/|I1|",
        unit: "of I1",
        scale: 100.0,
        shown_unit: "% of I1",
        direction: Direction::Rising,
        alarms: true,
        covariates: &[&[LOAD]],
        min_scatter: 0.0,
        fault_level: FaultLevel::Column("i2_least_change"),
    },
    residual("residual_d", "e_d"),
    residual("residual_q", "e_q"),
    residual("residual_t", "e_T"),
    Indicator {
        column: "sideband_db",
        label: "sideband",
        unit: "dB",
        scale: 1.0,
        shown_unit: "dB",
        direction: Direction::Rising,
        alarms: true,
        covariates: &[&[LOAD]],
        min_scatter: 0.0,
        fault_level: FaultLevel::Fixed(-50.0),
    },
    Indicator {
        column: "stator_excess_pct",
        label: "Rs beyond Rr",
        unit: "%",
        scale: 1.0,
        shown_unit: "%",
        direction: Direction::Rising,
        alarms: true,
        covariates: &[&[LOAD]],
        min_scatter: STATOR_EXCESS_MIN_SCATTER_PCT,
        fault_level: FaultLevel::Fixed(STATOR_EXCESS_FAULT_PCT),
    },
];

/// The FAULT level of the stator's resistance change beyond the rotor's [%]: the least
/// change one commissioned log's verdict calls a FAULT (the core's `MIN_FAULT_CHANGE`,
/// 5 %: what 13 K of heating does to a winding, here with no heating to explain it).
pub const STATOR_EXCESS_FAULT_PCT: f64 = 5.0;

/// The least scatter of the stator's excess [%]: Rs is read from the part of the voltage in
/// phase with the current, Rs I being 1-3 % of V, so a DAQ whose voltage-to-current phase
/// drifts by 0.03 mrad, or whose channels' gain ratio drifts by 0.005 %, from one day to the
/// next moves it by about 0.2 %; the simulator's logs scatter by 0.01 %.
pub const STATOR_EXCESS_MIN_SCATTER_PCT: f64 = 0.2;

/// The trend's settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrendOptions {
    /// The window the slope is taken over, ending at the motor's last log [days].
    pub window_days: f64,
    /// The interval's two-sided confidence.
    pub confidence: f64,
    /// How many scatters the line must move the indicator over the window to alarm.
    pub k_scatter: f64,
    /// The fewest logs in the window for a slope.
    pub min_logs: usize,
    /// For an indicator with a FAULT level: the alarm needs the line to reach it within
    /// this many days of the last log.
    pub horizon_days: f64,
    /// How many logs in a row (the last and those before it, each judged on the logs up
    /// to it) must alarm before the alarm is raised, and must be back at the reference
    /// before a raised alarm clears.
    pub confirm_logs: usize,
    /// The baseline the user marks: the motor's logs before this time (s since 1970-01-01
    /// UTC; the command line's `--reference-until DAY` gives the end of that day) are its
    /// reference. `None`: the motor's first healthy logs ([`MotorTrend::reference`]).
    pub reference_until_s: Option<i64>,
}

impl Default for TrendOptions {
    fn default() -> Self {
        TrendOptions {
            window_days: 14.0,
            confidence: 0.95,
            k_scatter: 3.0,
            min_logs: 6,
            horizon_days: 90.0,
            confirm_logs: 2,
            reference_until_s: None,
        }
    }
}

/// One point of an indicator's series.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TrendPoint {
    /// Days since 1970-01-01 UTC (fractional).
    pub t_days: f64,
    /// The stored value.
    pub value: f64,
    /// The value at the reference operating point (the value itself where not normalised).
    pub normalised: f64,
    /// In the window the slope is taken over.
    pub in_window: bool,
    /// One of the motor's reference logs ([`MotorTrend::reference`]).
    pub in_reference: bool,
}

/// One indicator's trend for one motor (JSON: `sim-host trend --json`'s `indicators`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct IndicatorTrend {
    /// The store column.
    pub indicator: String,
    /// Its label.
    pub label: String,
    /// Its unit.
    pub unit: String,
    /// Which way a fault moves it.
    pub direction: Direction,
    /// Logs in the window (with a value of the indicator).
    pub logs: usize,
    /// Theil-Sen's slope [unit/day] (null with too few logs).
    pub slope_per_day: Option<f64>,
    /// Sen's interval, low end [unit/day].
    pub slope_low: Option<f64>,
    /// Its high end [unit/day].
    pub slope_high: Option<f64>,
    /// The scatter about the line (1.4826 MAD) [unit].
    pub scatter: Option<f64>,
    /// The line's change over the window in scatters (signed): how fast it moves.
    pub moves_scatters: Option<f64>,
    /// The line's value at the last log [unit].
    pub last: Option<f64>,
    /// The FAULT level [unit], where the indicator has one.
    pub fault_level: Option<f64>,
    /// Days from the last log until the line reaches the FAULT level, where it heads there.
    pub days_to_fault: Option<f64>,
    /// The same at the slope of the window's second half alone (Theil-Sen over its logs,
    /// at least [`RECENT_MIN_LOGS`]), where that heads there: a fault that began inside the
    /// window, or grows faster as it grows, reaches the level sooner than the whole
    /// window's line says.
    pub days_to_fault_recent: Option<f64>,
    /// The trend alarm (raised, or held since it was raised: [`Self::alarm_since`]).
    pub alarm: bool,
    /// The day of the log on which the alarm now raised was raised (it holds until the
    /// indicator is back at the reference; the module's documentation, item 4).
    pub alarm_since: Option<String>,
    /// The days the window's line spans, from its first log to its last (null without a
    /// line).
    pub span_days: Option<f64>,
    /// How the indicator was normalised for the operating point, and why not where not
    /// (JSON `normalisation_reason`; its words, `normalisation`, are the front end's).
    #[serde(rename = "normalisation_reason")]
    pub normalisation: Normalisation,
    /// Whether the operating-point fit was made (else `normalised` is the stored value).
    pub operating_point_fitted: bool,
    /// The reference's centre: the median of the reference logs' normalised values [unit].
    pub reference_centre: Option<f64>,
    /// The reference's scatter: 1.4826 MAD of those values about their median, at least the
    /// operating-point fit's [unit]; none with fewer than [`TrendOptions::min_logs`] values.
    pub reference_scatter: Option<f64>,
    /// The line at the last log from the reference's centre, in reference scatters (signed).
    pub from_reference_scatters: Option<f64>,
    /// Why it alarms or does not, with the numbers that decided (its words, the JSON's
    /// `sentence`, are the front end's: `monitor_words::trend`).
    pub reason: TrendReason,
    /// The logs in a row, ending at the last log with a value, whose stored value is at the
    /// indicator's FAULT level (0 without a level).
    pub fault_level_logs: usize,
    /// The motor's points, the window's marked.
    pub series: Vec<TrendPoint>,
}

/// The fewest logs in the window's second half for [`IndicatorTrend::days_to_fault_recent`].
pub const RECENT_MIN_LOGS: usize = 4;

/// One motor's trend (JSON: one element of `sim-host trend --json`'s `motors`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct MotorTrend {
    /// The motor.
    pub motor: String,
    /// Its logs (all, not only the window's).
    pub logs: usize,
    /// The first log's day.
    pub first_day: String,
    /// The last log's day.
    pub last_day: String,
    /// Any indicator's trend alarm.
    pub alarm: bool,
    /// The fastest indicator's |moves_scatters| (the fleet's ranking key; 0 where no
    /// indicator has a line).
    pub fastest_scatters: f64,
    /// The logs the indicators are judged against.
    pub reference: TrendReference,
    /// Per indicator the motor's logs measured (one none of them measured is absent).
    pub indicators: Vec<IndicatorTrend>,
}

/// A motor's reference: its logs the indicators are judged against (JSON: `reference`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TrendReference {
    /// How many logs.
    pub logs: usize,
    /// The first one's day.
    pub first_day: Option<String>,
    /// The last one's day.
    pub last_day: Option<String>,
    /// Whether the user marked it ([`TrendOptions::reference_until_s`]).
    pub marked: bool,
    /// Which logs (its words, the JSON's `how`, are the front end's).
    pub basis: ReferenceBasis,
    /// The day the user marked where no log lies up to it (the reference is then the
    /// default one, `basis`).
    pub mark_without_logs: Option<String>,
}

mod analyse;
mod level;
mod reason;
mod reference;

pub use analyse::{day_of, fit_logs, indicator_trend, motor_trend, trend};
pub use reason::{CovariateRange, Normalisation, ReferenceBasis, TrendReason, ValueRange};
pub use reference::reference_rows;
