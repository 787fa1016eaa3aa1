//! The machine fitted to the log against the parameter file ([`StartFit`]): where nothing
//! was commissioned, a fault present from the first sample moves the residuals as the
//! file's own error does, and thresholds on the file's values cannot tell them apart. A log
//! with a start or a load change can: the full-order machine fitted to it (the API runs
//! `identify` on the log's first seconds) gives each electrical parameter's change from the
//! file with its interval. One parameter beyond the file's own uncertainty while the others
//! stay on the file is a fault present from the start ([`StartFit::finding`]); all of them
//! on the file is the reach a "healthy" carries.

use super::{Detail, FindingReport};
use monitor_core::isolation::NOMINAL_UNCERTAINTY;
use monitor_core::verdict::{Against, FaultName, FindingSource, NamedFault, Size, State};
use monitor_core::Fault;
use serde::Serialize;

/// The electrical parameters the fit gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitParameter {
    /// The stator resistance Rs.
    Rs,
    /// The rotor resistance Rr.
    Rr,
    /// The leakage Lls + Llr.
    Leakage,
    /// The magnetising inductance Lm.
    Lm,
}

impl FitParameter {
    /// Table 1's fault that scales this parameter alone, where one does (the leakage and
    /// Lm are not one fault's: Ls and Lr scale them together, differently per machine).
    pub fn fault(self) -> Option<Fault> {
        match self {
            FitParameter::Rs => Some(Fault::Rs),
            FitParameter::Rr => Some(Fault::Rr),
            FitParameter::Leakage | FitParameter::Lm => None,
        }
    }
}

/// One parameter's change from the file: the fit's value over the file's, less one, with
/// its 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FittedChange {
    /// The parameter.
    pub parameter: FitParameter,
    /// Its relative change from the file's value (0.5: +50 %).
    pub change: f32,
    /// The 95 % interval's low end.
    pub low: f32,
    /// Its high end.
    pub high: f32,
}

impl FittedChange {
    /// The interval's largest distance from the file's value.
    pub fn reach(&self) -> f32 {
        self.low.abs().max(self.high.abs())
    }
}

/// The full-order machine fitted to the log's first seconds against the parameter file
/// (JSON `findings[].reason` of the parameter fit, `kind` `machine_fit`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StartFit {
    /// The window fitted [s].
    pub from_s: f64,
    /// Its end [s].
    pub to_s: f64,
    /// The current the fitted model leaves unexplained, over the current's RMS.
    pub relative_rms_error: f64,
    /// The parameters the log identified (a parameter the log does not excite is left
    /// out).
    pub changes: Vec<FittedChange>,
}

/// Largest change of the other parameters beside a named one: a fault present from the
/// start changes one; a file off the machine (a nameplate's estimate) all of them.
pub const FIT_OTHERS_WITHIN: f32 = 0.08;
/// Largest current error of a fit that names a fault: a model that leaves more misses
/// something of the motor, and its values carry it.
pub const FIT_MAX_ERROR: f64 = 0.05;
/// Largest change of every parameter for the fit to say that the machine is the file's
/// (the reach a "healthy" against the file then carries).
pub const FIT_ON_FILE: f32 = 0.1;

impl StartFit {
    /// The change of `p`, where the log identified it.
    pub fn change(&self, p: FitParameter) -> Option<&FittedChange> {
        self.changes.iter().find(|c| c.parameter == p)
    }

    /// Whether the four electrical parameters were all identified.
    fn complete(&self) -> bool {
        self.changes.len() == 4
    }

    /// The fault present from the start the fit names: one parameter of Table 1 (Rs or Rr)
    /// whose interval lies wholly beyond the file's own uncertainty
    /// ([`NOMINAL_UNCERTAINTY`]), every other within [`FIT_OTHERS_WITHIN`], the model's
    /// error under [`FIT_MAX_ERROR`]. The confidence is the share of the interval beyond
    /// the file's uncertainty (a normal in the log of the ratio).
    pub fn named(&self) -> Option<NamedFault> {
        if !self.complete() || self.relative_rms_error > FIT_MAX_ERROR {
            return None;
        }
        let beyond: Vec<&FittedChange> = self
            .changes
            .iter()
            .filter(|c| c.change.abs() > FIT_OTHERS_WITHIN)
            .collect();
        let [c] = beyond[..] else {
            return None;
        };
        let fault = c.parameter.fault()?;
        let clear = if c.change > 0.0 {
            c.low > NOMINAL_UNCERTAINTY
        } else {
            c.high < -NOMINAL_UNCERTAINTY
        };
        clear.then(|| NamedFault {
            fault: FaultName::Table1(fault),
            size: Size::Relative(c.change),
            phase: None,
            confidence: beyond_share(c),
        })
    }

    /// Whether the fitted machine is the file's: every parameter identified, within
    /// [`FIT_ON_FILE`], the model's error under [`FIT_MAX_ERROR`].
    pub fn on_file(&self) -> bool {
        self.complete()
            && self.relative_rms_error <= FIT_MAX_ERROR
            && self.changes.iter().all(|c| c.reach() <= FIT_ON_FILE)
    }

    /// The parameter fit's finding from the machine fitted, where it says something the
    /// residuals cannot: a fault present from the start (named against the file), or the
    /// machine on the file (clear, with the fit's reach); `None` otherwise (the residuals'
    /// own parameter-fit finding stands).
    pub fn finding(&self) -> Option<FindingReport> {
        let of = |state| {
            FindingReport::new(
                FindingSource::ParameterFit,
                state,
                Against::ParameterFile,
                Detail::MachineFit(self.clone()),
            )
        };
        if let Some(n) = self.named() {
            return Some(of(State::Named(n)));
        }
        self.on_file().then(|| of(State::Clear))
    }
}

/// The probability that the change lies beyond the file's uncertainty on its side, from
/// its interval (a normal in `ln(1 + change)`, the interval `+-1.96 sigma`).
fn beyond_share(c: &FittedChange) -> f32 {
    let ln = |x: f32| f64::from(1.0 + x).max(1e-9).ln();
    let sigma = ((ln(c.high) - ln(c.low)) / (2.0 * 1.96)).max(1e-9);
    let edge = if c.change > 0.0 {
        ln(NOMINAL_UNCERTAINTY)
    } else {
        ln(-NOMINAL_UNCERTAINTY)
    };
    let z = (ln(c.change) - edge).abs() / sigma;
    // The normal's CDF by the error function's Abramowitz-Stegun 7.1.26 (1.5e-7).
    let t = 1.0 / (1.0 + 0.327_591_1 * z / std::f64::consts::SQRT_2);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-(z * z) / 2.0).exp();
    (0.5 * (1.0 + erf)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(rs: f32, rr: f32, others: f32, width: f32) -> StartFit {
        let c = |parameter, change: f32| FittedChange {
            parameter,
            change,
            low: change - width,
            high: change + width,
        };
        StartFit {
            from_s: 0.0,
            to_s: 6.0,
            relative_rms_error: 0.004,
            changes: vec![
                c(FitParameter::Rs, rs),
                c(FitParameter::Rr, rr),
                c(FitParameter::Leakage, others),
                c(FitParameter::Lm, -others),
            ],
        }
    }

    #[test]
    fn one_resistance_beyond_the_file_is_named_a_file_off_everywhere_is_not() {
        let n = fit(0.5, 0.0, 0.0, 0.002).named().expect("rs named");
        assert_eq!(n.fault, FaultName::Table1(Fault::Rs));
        assert!(n.confidence > 0.99, "{n:?}");
        assert!(fit(0.0, -0.4, 0.01, 0.002).named().is_some());
        // Within the file's uncertainty, or its interval reaching into it: not named.
        assert!(fit(0.25, 0.0, 0.0, 0.002).named().is_none());
        assert!(fit(0.32, 0.0, 0.0, 0.05).named().is_none());
        // A nameplate's file: every parameter off.
        assert!(fit(0.5, 0.2, 0.15, 0.002).named().is_none());
        assert!(fit(0.01, -0.02, 0.03, 0.01).on_file());
        assert!(!fit(0.01, -0.02, 0.2, 0.01).on_file());
    }
}
