//! The replay's findings, one per analysis, as the decision table reads them
//! ([`super::FindingReport`]). Each says what it found and what it was judged against, or
//! why it could not judge.

use super::measured::{rotor_finding, sensor_flag_finding, winding_finding};
use super::MIN_JUDGED_S;
use super::{Detail, FindingReport, SkippedAnalysis};
use crate::isolation::IsolationFinding;
use crate::isolation::{FaultCandidate, IsolationBaseline, IsolationName, IsolationReport};
use crate::lamps::commission::FirstPointMisfit;
use crate::lamps::LampsFinding;
use crate::winding::UnbalanceReport;
use monitor_core::verdict::{Against, FaultName, FindingSource, NamedFault, Size, State};
use monitor_core::MonitorOutput;

/// What the residual finding is drawn from: the lamps' final output, the isolation's report
/// and candidates, whether a fault was detected, and the analyses the log could not feed.
pub(crate) struct ResidualInputs<'a> {
    /// The monitor's last output.
    pub out: &'a MonitorOutput,
    /// The isolation's report.
    pub isolation: &'a IsolationReport,
    /// Its candidates (sizes and phases of one phase's sensors).
    pub candidates: &'a [FaultCandidate],
    /// A lamp or the isolation detected a fault (after heating and load moves).
    pub detected: bool,
    /// The analyses the log could not feed (the report's `skipped`).
    pub skipped: &'a [SkippedAnalysis],
}

/// What the isolation names, as the verdict reads it: a Table 1 fault with its candidate's
/// size, phase and probability, or (with the paper's viscous load) the friction class with
/// Bl's size and the probability of B and Bl together; `None` when it names nothing.
pub(crate) fn isolation_name(
    iso: &IsolationReport,
    candidates: &[FaultCandidate],
) -> Option<NamedFault> {
    let p = |f: monitor_core::Fault| {
        candidates
            .iter()
            .find(|c| c.fault == f)
            .map_or(0.0, |c| c.probability)
    };
    match iso.named? {
        IsolationName::Fault(f) => {
            let c = candidates.iter().find(|c| c.fault == f);
            Some(NamedFault {
                fault: FaultName::Table1(f),
                size: Size::Relative(c.and_then(|c| c.change).or(iso.named_change)?),
                phase: c.and_then(|c| c.phase),
                confidence: p(f),
            })
        }
        IsolationName::Friction => Some(NamedFault {
            fault: FaultName::Friction,
            size: Size::Relative(iso.named_change?),
            phase: None,
            confidence: (p(monitor_core::Fault::B) + p(monitor_core::Fault::Bl)).min(1.0),
        }),
    }
}

/// Whether the isolation's equations departed from its baseline in a way it names no fault
/// for and heating does not explain.
fn deviates_unexplained(iso: &IsolationReport) -> bool {
    use monitor_core::IsolationState;
    matches!(
        iso.state,
        IsolationState::Isolated | IsolationState::Unknown
    ) && iso.named.is_none()
        && !iso.heating_explains
}

/// Why the parameter file does not fit the log (JSON `{"kind": ..}`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FileMisfit {
    /// The nearest single fault is within the file's own uncertainty.
    NearestWithinFile {
        /// The fault, with its size.
        #[serde(serialize_with = "super::serialize_named")]
        named: NamedFault,
    },
    /// What the isolation concluded (the report's `isolation.said`).
    Isolation,
    /// The first quasi-steady point already passes a fixed threshold.
    FirstPoint(FirstPointMisfit),
}

/// What the findings read of a replay's stages at its end: the lamps' and the isolation's
/// findings.
pub(crate) struct Stages<'a> {
    /// The lamps' finding.
    pub lamps: &'a LampsFinding,
    /// The isolation's finding.
    pub isolation: &'a IsolationFinding,
}

impl Stages<'_> {
    /// Every analysis' finding at the end of the replay (the data quality's is added by the
    /// caller that ran the data-quality stage, `diagnose`): the residuals, the winding, the
    /// rotor, the operating point, the parameter file's fit, and the sensors' impossible
    /// readings.
    pub(crate) fn findings(
        &self,
        unbalance: &UnbalanceReport,
        rotor: &crate::rotor::RotorReport,
    ) -> Vec<FindingReport> {
        let inp = &ResidualInputs {
            out: &self.lamps.out,
            isolation: &self.isolation.report,
            candidates: &self.isolation.candidates,
            detected: self.isolation.detected,
            skipped: &self.lamps.skipped,
        };
        let residual = self.residual_finding(inp);
        let mut found = vec![
            residual.clone(),
            winding_finding(unbalance),
            rotor_finding(rotor),
            self.operating_point_finding(inp.out, inp.isolation),
            self.parameter_fit_finding(&residual, inp.isolation),
        ];
        found.extend(sensor_flag_finding(inp.out.sensor_fault));
        found
    }

    /// What the residuals are judged against: commissioning where a window was learned (the
    /// lamps' thresholds) or the isolation learned its baseline, else the parameter file.
    fn residuals_against(&self, iso: &IsolationReport) -> Against {
        if self.lamps.commission.learned() || iso.baseline == IsolationBaseline::Learned {
            Against::Commissioning
        } else {
            Against::ParameterFile
        }
    }

    /// Why the residuals could not be judged at all, where they could not.
    fn residuals_not_judged(&self, inp: &ResidualInputs<'_>) -> Option<Detail> {
        if !self.lamps.monitor {
            return Some(Detail::ResidualsSkipped {
                need: inp.skipped.first().copied(),
            });
        }
        if let Some(n) = self.lamps.commission.not_learned() {
            return Some(Detail::ResidualsNotLearned(n));
        }
        if !self.lamps.evaluated && self.lamps.first_detection.is_none() {
            return Some(Detail::ResidualsNeverEvaluated);
        }
        if inp.detected {
            return None;
        }
        if self.lamps.judged_s < MIN_JUDGED_S {
            return Some(Detail::ResidualsTooLittle {
                judged_s: self.lamps.judged_s,
                needed_s: MIN_JUDGED_S,
            });
        }
        self.lamps.withheld.map(Detail::ResidualsUnsettled)
    }

    /// The residual lamps' and the isolation's finding.
    pub(crate) fn residual_finding(&self, inp: &ResidualInputs<'_>) -> FindingReport {
        let against = self.residuals_against(inp.isolation);
        let of =
            |state, detail| FindingReport::new(FindingSource::Residuals, state, against, detail);
        if let Some(why) = self.residuals_not_judged(inp) {
            let state = if !self.lamps.monitor {
                State::Unavailable
            } else {
                State::NotJudged
            };
            return of(state, why);
        }
        let iso = inp.isolation;
        if let Some(named) = isolation_name(iso, inp.candidates).filter(|_| inp.detected) {
            // Against the file's nominal values a name within the file's own uncertainty is
            // no name: the change is the file's as much as a fault's (the parameter fit
            // says so).
            let in_file_error = against == Against::ParameterFile
                && matches!(named.fault, FaultName::Table1(_))
                && !named.stands_clear(against);
            let state = if in_file_error {
                State::Unexplained
            } else {
                State::Named(named)
            };
            return of(state, Detail::Isolation);
        }
        let lit_end = inp.out.lamps.iter().any(|l| *l);
        if let Some(why) = self.operating_point_explains(inp, lit_end) {
            return of(State::Explained, why);
        }
        if against == Against::ParameterFile && deviates_unexplained(iso) {
            // Against the file's nominal values, a change the isolation's steady-state
            // equations saw beyond the healthy spread, that names no fault and that heating
            // does not explain, is no "clear": a fault present from the first sample and a
            // file off the machine look the same there (the parameter fit says which it
            // cannot tell).
            return of(State::Unexplained, Detail::Isolation);
        }
        if !inp.detected && !lit_end {
            return of(State::Clear, Detail::Isolation);
        }
        if let (Some(t), false) = (self.lamps.first_detection, self.lamps.detected_in_range) {
            return of(State::OutOfRange, Detail::LampsOutOfRange { first_s: t });
        }
        of(State::Unexplained, Detail::Isolation)
    }

    /// Why the lamps that lit are the operating point's (heating, a load move), where they
    /// are; `lit_end` whether a lamp is lit at the end.
    fn operating_point_explains(&self, inp: &ResidualInputs<'_>, lit_end: bool) -> Option<Detail> {
        let iso = inp.isolation;
        let ever_lit = self.lamps.first_detection.is_some() || lit_end;
        if ever_lit && self.isolation.heating_explains_lamps {
            return Some(Detail::LampsForHeating {
                rise_k: iso.winding_rise_k,
            });
        }
        // The lamps' matching read only the load term: a load move, unless the isolation's
        // steady-state equations find a change no single fault (nor the load) explains.
        let lamps_read_load =
            self.lamps.only_load_named && iso.state != monitor_core::IsolationState::Unknown;
        if ever_lit && (self.isolation.load_explains_lamps || lamps_read_load) {
            return Some(Detail::LampsForLoadMove);
        }
        None
    }

    /// Whether the parameter file fits the log where nothing was commissioned: judged from
    /// the residual finding `residual` and the first quasi-steady point against the file.
    pub(crate) fn parameter_fit_finding(
        &self,
        residual: &FindingReport,
        iso: &IsolationReport,
    ) -> FindingReport {
        let of = |state, against, detail| {
            FindingReport::new(FindingSource::ParameterFit, state, against, detail)
        };
        if self.residuals_against(iso) == Against::Commissioning {
            return of(State::Clear, Against::Commissioning, Detail::Commissioned);
        }
        if !self.lamps.monitor {
            return of(
                State::Unavailable,
                Against::ParameterFile,
                Detail::ParameterFitUnavailable,
            );
        }
        if let Some(why) = self.file_misfit(residual, iso) {
            return of(
                State::Unexplained,
                Against::ParameterFile,
                Detail::FileMisfit(why),
            );
        }
        of(State::Clear, Against::ParameterFile, Detail::FileFits)
    }

    /// Why the parameter file does not fit the log, judged against its nominal values from
    /// the residual finding: a change no single fault explains, a name within the file's own
    /// uncertainty, or the first quasi-steady point already past the fixed thresholds.
    fn file_misfit(&self, residual: &FindingReport, iso: &IsolationReport) -> Option<FileMisfit> {
        match residual.finding.state {
            State::Unexplained => Some(match (iso.named, iso.named_change) {
                (Some(IsolationName::Fault(f)), Some(c)) => FileMisfit::NearestWithinFile {
                    named: NamedFault {
                        fault: FaultName::Table1(f),
                        size: Size::Relative(c),
                        phase: None,
                        confidence: iso.named_probability.unwrap_or(0.0),
                    },
                },
                _ => FileMisfit::Isolation,
            }),
            State::OutOfRange => Some(FileMisfit::Isolation),
            State::Named(n) if !n.stands_clear(Against::ParameterFile) => {
                Some(FileMisfit::NearestWithinFile { named: n })
            }
            State::Named(_) => None,
            _ => self
                .lamps
                .commission
                .nominal_misfit()
                .map(FileMisfit::FirstPoint),
        }
    }

    /// The operating point's finding: load moves and heating (they explain lamps; never a
    /// fault).
    pub(crate) fn operating_point_finding(
        &self,
        out: &MonitorOutput,
        iso: &IsolationReport,
    ) -> FindingReport {
        let against = self.residuals_against(iso);
        let of = |state, detail| {
            FindingReport::new(FindingSource::OperatingPoint, state, against, detail)
        };
        if !self.lamps.monitor {
            return of(State::Unavailable, Detail::OperatingPointUnavailable);
        }
        let load_moves = iso
            .events
            .iter()
            .filter(|e| matches!(e, crate::events::IsolationEvent::LoadMoved { .. }))
            .count();
        let outside = self.lamps.commission.moved_note(out);
        let rise_k = iso.winding_rise_k;
        if outside.is_none() && load_moves == 0 && rise_k.is_none() {
            // "No heating" only where the isolation read the windings at a steady point.
            let detail = if iso.state == monitor_core::IsolationState::NotJudged {
                Detail::NoLoadMoveHeatingUnread
            } else {
                Detail::Steady
            };
            return of(State::Clear, detail);
        }
        of(
            State::Explained,
            Detail::OperatingPointMoved {
                outside,
                load_moves,
                rise_k,
            },
        )
    }
}
