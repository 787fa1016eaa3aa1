//! The replay's findings, one per analysis, as the decision table reads them
//! ([`super::FindingReport`]). Each says what it found and what it was judged against, or
//! why it could not judge.

use super::measured::{rotor_finding, sensor_flag_finding, winding_finding};
use super::words::fault_text;
use super::FindingReport;
use super::MIN_JUDGED_S;
use crate::isolation::IsolationFinding;
use crate::isolation::{FaultCandidate, IsolationBaseline, IsolationName, IsolationReport};
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
    pub skipped: &'a [String],
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

/// The residuals' brief phrase (`residuals against commissioning`).
fn residual_brief(against: Against) -> String {
    format!(
        "residuals {}",
        super::words::against_text(FindingSource::Residuals, against)
    )
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
    fn residuals_not_judged(&self, inp: &ResidualInputs<'_>) -> Option<String> {
        if !self.lamps.monitor {
            return Some(inp.skipped.first().cloned().unwrap_or_else(|| {
                "residuals r1..r4: need the voltages and the speed".to_string()
            }));
        }
        if let Some(why) = self.lamps.commission.why_incomplete() {
            return Some(why);
        }
        if !self.lamps.evaluated && self.lamps.first_detection.is_none() {
            return Some(
                "the lamps were never evaluated (the motor never ran settled and quasi-steady with voltage)"
                    .to_string(),
            );
        }
        if inp.detected {
            return None;
        }
        if self.lamps.judged_s < MIN_JUDGED_S {
            return Some(format!(
                "the lamps were judged on only {:.2} s of settled, quasi-steady running ({MIN_JUDGED_S:.1} s needed): the log is all start or transient, or ends too soon after commissioning",
                self.lamps.judged_s
            ));
        }
        self.lamps.withheld.clone()
    }

    /// The residual lamps' and the isolation's finding.
    pub(crate) fn residual_finding(&self, inp: &ResidualInputs<'_>) -> FindingReport {
        let against = self.residuals_against(inp.isolation);
        let brief = residual_brief(against);
        let of = |state, summary: String| {
            FindingReport::new(
                FindingSource::Residuals,
                state,
                against,
                summary,
                brief.clone(),
            )
        };
        if let Some(why) = self.residuals_not_judged(inp) {
            return self.residuals_unjudged(against, why);
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
            return of(state, iso.verdict.clone());
        }
        let lit_end = inp.out.lamps.iter().any(|l| *l);
        if let Some((why, what)) = self.operating_point_explains(inp, lit_end) {
            let mut f = of(State::Explained, why);
            f.brief = format!("{brief} (the lamps lit for {what}, not a fault)");
            return f;
        }
        if !inp.detected && !lit_end {
            return of(State::Clear, iso.verdict.clone());
        }
        if let (Some(t), false) = (self.lamps.first_detection, self.lamps.detected_in_range) {
            return of(
                State::OutOfRange,
                format!(
                    "the lamps lit (first at {t:.2} s) only while the load or the voltage was outside the range commissioned: the learned means hold only where they were learned; commission over the whole load and voltage range ({})",
                    iso.verdict
                ),
            );
        }
        of(State::Unexplained, iso.verdict.clone())
    }

    /// The residual finding where they could not be judged (`why`): a log without the
    /// voltages or the speed lacks what they need (unavailable); else the log kept them
    /// from judging (not judged).
    fn residuals_unjudged(&self, against: Against, why: String) -> FindingReport {
        let state = if !self.lamps.monitor {
            State::Unavailable
        } else {
            State::NotJudged
        };
        let brief = format!("residuals: {why}");
        FindingReport::new(FindingSource::Residuals, state, against, why, brief)
    }

    /// Why the lamps that lit are the operating point's (heating, a load move), where they
    /// are: the sentence, and a short phrase
    /// (`62 K of heating`); `lit_end` whether a lamp is lit at the end.
    fn operating_point_explains(
        &self,
        inp: &ResidualInputs<'_>,
        lit_end: bool,
    ) -> Option<(String, String)> {
        let iso = inp.isolation;
        let ever_lit = self.lamps.first_detection.is_some() || lit_end;
        if ever_lit && self.isolation.heating_explains_lamps {
            let rise = iso
                .winding_rise_k
                .map_or("heating".to_string(), |k| format!("{k:.0} K of heating"));
            return Some((iso.verdict.clone(), rise));
        }
        // The lamps' matching read only the load term: a load move, unless the isolation's
        // steady-state equations find a change no single fault (nor the load) explains.
        let lamps_read_load =
            self.lamps.only_load_named && iso.state != monitor_core::IsolationState::Unknown;
        if ever_lit && (self.isolation.load_explains_lamps || lamps_read_load) {
            return Some((
                format!(
                    "the lamps lit for a load move (to the paper's model a load change is a Bl change): {}",
                    iso.verdict
                ),
                "a load move".to_string(),
            ));
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
        let brief = "parameter file".to_string();
        let of = |state, against, summary: String| {
            FindingReport::new(
                FindingSource::ParameterFit,
                state,
                against,
                summary,
                brief.clone(),
            )
        };
        if self.residuals_against(iso) == Against::Commissioning {
            return of(
                State::Clear,
                Against::Commissioning,
                "commissioned: the residuals are judged against the healthy motor learned in commissioning, not the file's values".to_string(),
            );
        }
        if !self.lamps.monitor {
            return of(
                State::Unavailable,
                Against::ParameterFile,
                "the residuals against the file need the voltages and the speed".to_string(),
            );
        }
        let misfit = |why: String| {
            of(
                State::Unexplained,
                Against::ParameterFile,
                format!(
                    "the parameter file does not fit this log (commission on the healthy motor, or identify it: sim-host identify): {why}"
                ),
            )
        };
        if let Some(why) = self.file_misfit(residual, iso) {
            return misfit(why);
        }
        of(
            State::Clear,
            Against::ParameterFile,
            "the residuals against the file's nominal values stay within their fixed thresholds"
                .to_string(),
        )
    }

    /// Why the parameter file does not fit the log, judged against its nominal values from
    /// the residual finding: a change no single fault explains, a name within the file's own
    /// uncertainty, or the first quasi-steady point already past the fixed thresholds.
    fn file_misfit(&self, residual: &FindingReport, iso: &IsolationReport) -> Option<String> {
        let within = |what: String| {
            format!(
                "the nearest single fault, {what}, is within the file's own uncertainty (+/-{:.0} %); a file 10-30 % off the machine, or windings 60 K warmer than the file assumes, move the residuals this much",
                100.0 * monitor_core::isolation::NOMINAL_UNCERTAINTY
            )
        };
        match residual.finding.state {
            State::Unexplained => Some(match (iso.named, iso.named_change) {
                (Some(IsolationName::Fault(f)), Some(c)) => {
                    within(format!("{} {}", f.name(), super::words::pct(c)))
                }
                _ => iso.verdict.clone(),
            }),
            State::OutOfRange => Some(iso.verdict.clone()),
            State::Named(n) if !n.stands_clear(Against::ParameterFile) => {
                Some(within(fault_text(&n)))
            }
            State::Named(_) => None,
            _ => self.lamps.commission.nominal_misfit(),
        }
    }

    /// The operating point's finding: load moves and heating (they explain lamps; never a
    /// fault).
    pub(crate) fn operating_point_finding(
        &self,
        out: &MonitorOutput,
        iso: &IsolationReport,
    ) -> FindingReport {
        let brief = "operating point".to_string();
        let against = self.residuals_against(iso);
        let of = |state, summary: String| {
            FindingReport::new(
                FindingSource::OperatingPoint,
                state,
                against,
                summary,
                brief.clone(),
            )
        };
        if !self.lamps.monitor {
            return of(
                State::Unavailable,
                "the load and the heating need the voltages and the speed".to_string(),
            );
        }
        let moves = iso
            .events
            .iter()
            .filter(|e| matches!(e, crate::events::IsolationEvent::LoadMoved { .. }))
            .count();
        let mut said = Vec::new();
        if let Some(note) = self.lamps.commission.moved_note(out) {
            said.push(format!("outside the commissioned range at the end: {note}"));
        }
        if moves > 0 {
            said.push(format!(
                "the load moved {moves} time{}",
                if moves == 1 { "" } else { "s" }
            ));
        }
        if let Some(rise) = iso.winding_rise_k {
            said.push(format!(
                "the windings warmed by {rise:.0} K since commissioning"
            ));
        }
        if said.is_empty() {
            return of(State::Clear, "steady: no load move, no heating".to_string());
        }
        of(State::Explained, said.join("; "))
    }
}
