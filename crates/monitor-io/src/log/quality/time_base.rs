//! The time base of a log: its unit ([`TimeUnit`]) and nominal sample period, from the
//! first rows and the phase-a current's zero crossings.

use super::MIN_SAMPLES_PER_PERIOD;
use crate::log::{LogError, Row};
use serde::Serialize;

/// The unit of a log's `t_s` column as the stage reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeUnit {
    /// Seconds, as the schema says.
    #[default]
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
        }
    }

    /// "s", "ms" or "us".
    pub fn name(self) -> &'static str {
        match self {
            TimeUnit::S => "s",
            TimeUnit::Ms => "ms",
            TimeUnit::Us => "us",
        }
    }
}

/// The median of the positive finite values of `x` (reordered), `None` when there is none.
pub(in crate::log) fn median_positive(x: &mut Vec<f64>) -> Option<f64> {
    x.retain(|v| v.is_finite() && *v > 0.0);
    if x.is_empty() {
        return None;
    }
    x.sort_by(f64::total_cmp);
    Some(x[x.len() / 2])
}

/// Zero crossings of one signal with hysteresis (three tenths of its recent peak: a
/// no-load current on a grid carries a 5th harmonic of a quarter of its fundamental, whose
/// ripple crosses a tenth of the peak twice more per period): the
/// periods between positive-going crossings.
#[derive(Debug, Clone, Default)]
pub(super) struct CrossingCounter {
    state: Crossing,
    periods: Vec<f64>,
}

/// The counter's state between samples.
#[derive(Debug, Clone, Copy, Default)]
struct Crossing {
    peak: f64,
    positive: Option<bool>,
    last_rise: Option<f64>,
    last_t: Option<f64>,
}

impl Crossing {
    /// One sample; the period it ends, if it is a positive-going crossing after another.
    #[inline(always)]
    fn step(&mut self, t: f64, x: f64, decay_s: f64) -> Option<f64> {
        if !x.is_finite() {
            return None;
        }
        let dt = self.last_t.map_or(0.0, |l| (t - l).max(0.0));
        self.last_t = Some(t);
        self.peak = (self.peak * (1.0 - dt / decay_s).max(0.0)).max(x.abs());
        let h = 0.3 * self.peak;
        let now = if x > h {
            Some(true)
        } else if x < -h {
            Some(false)
        } else {
            self.positive
        };
        let mut period = None;
        if now == Some(true) && self.positive == Some(false) {
            period = self.last_rise.map(|r| t - r);
            self.last_rise = Some(t);
        }
        self.positive = now;
        period
    }
}

/// Periods kept for the median (a day at 50 Hz is 4.3 million).
const MAX_PERIODS: usize = 1 << 20;

impl CrossingCounter {
    pub(super) fn push(&mut self, t: f64, x: f64, decay_s: f64) {
        if let Some(p) = self.state.step(t, x, decay_s) {
            self.keep(p);
        }
    }

    /// [`CrossingCounter::push`] of each `(t[k], x[k])`, the state kept in registers.
    pub(super) fn push_all(&mut self, t: &[f64], x: &[f64], decay_s: f64) {
        let mut s = self.state;
        for (&t, &x) in t.iter().zip(x) {
            if let Some(p) = s.step(t, x, decay_s) {
                self.keep(p);
            }
        }
        self.state = s;
    }

    fn keep(&mut self, period: f64) {
        if self.periods.len() < MAX_PERIODS {
            self.periods.push(period);
        }
    }

    /// The median period (in the times' unit), from at least two whole periods.
    pub(super) fn median_period(&self) -> Option<f64> {
        if self.periods.len() < 2 {
            return None;
        }
        median_positive(&mut self.periods.clone())
    }
}

/// The time unit and the nominal period [s] of the first rows.
///
/// # Errors
/// [`LogError::NoTimeBase`] without two increasing finite times; [`LogError::RateTooLow`]
/// when the rate in the chosen unit gives fewer than [`MIN_SAMPLES_PER_PERIOD`] samples per
/// supply period.
pub(super) fn time_base(
    head: &[Row],
    supply_hz: f64,
    shown: &str,
) -> Result<(TimeUnit, f64), LogError> {
    let times: Vec<f64> = head.iter().map(|r| r.t_s).collect();
    let Some(period_file) = crate::log::sample_rate_hz(&times).map(|r| 1.0 / r) else {
        return Err(LogError::NoTimeBase {
            path: shown.to_string(),
        });
    };
    let mut cc = CrossingCounter::default();
    let span = head.last().map_or(0.0, |r| r.t_s) - head.first().map_or(0.0, |r| r.t_s);
    for r in head {
        cc.push(r.t_s, r.i_abc[0], span.abs().max(f64::MIN_POSITIVE));
    }
    let units = [TimeUnit::S, TimeUnit::Ms, TimeUnit::Us];
    let unit = match cc.median_period() {
        // The unit in which the current alternates nearest the supply frequency.
        Some(p) => units
            .into_iter()
            .min_by(|a, b| {
                let miss = |u: TimeUnit| (1.0 / (p * u.seconds()) / supply_hz).ln().abs();
                miss(*a).total_cmp(&miss(*b))
            })
            .unwrap_or_default(),
        // No alternating current: seconds, unless that is too slow to be a log.
        None => units
            .into_iter()
            .find(|u| 1.0 / (period_file * u.seconds()) >= MIN_SAMPLES_PER_PERIOD * supply_hz)
            .unwrap_or_default(),
    };
    let period = period_file * unit.seconds();
    let rate = 1.0 / period;
    if rate < MIN_SAMPLES_PER_PERIOD * supply_hz {
        return Err(LogError::RateTooLow {
            path: shown.to_string(),
            rate_hz: rate,
            supply_hz,
            needed_hz: MIN_SAMPLES_PER_PERIOD * supply_hz,
        });
    }
    Ok((unit, period))
}
