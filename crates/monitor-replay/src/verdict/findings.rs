//! The replay's findings, one per analysis, as the decision table reads them
//! ([`super::FindingReport`]). Each says what it found and what it was judged against, or
//! why it could not judge.

use super::words::fault_text;
use super::FindingReport;
use crate::isolation::{FaultCandidate, IsolationBaseline, IsolationName, IsolationReport};
use super::MIN_JUDGED_S;
use crate::replay::Replay;
use crate::winding::{BaselineSource, UnbalanceReport};
use monitor_core::verdict::{Against, FaultName, FindingSource, NamedFault, Size, State};
use monitor_core::{MonitorOutput, SensorFlags};
use monitor_io::log::quality::{DataQuality, MAX_NOT_JUDGED_FRACTION};

/// What the residual finding is drawn from, besides the replay's own state: the final output,
/// the isolation's report and candidates, whether a fault was detected, and the analyses the
/// log could not feed.
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

impl Replay {
    /// What the residuals are judged against: commissioning where a window was learned (the
    /// lamps' thresholds) or the isolation learned its baseline, else the parameter file.
    fn residuals_against(&self, iso: &IsolationReport) -> Against {
        if self.commission.learned() || iso.baseline == IsolationBaseline::Learned {
            Against::Commissioning
        } else {
            Against::ParameterFile
        }
    }

    /// Why the residuals could not be judged at all, where they could not.
    fn residuals_not_judged(&self, inp: &ResidualInputs<'_>) -> Option<String> {
        if self.monitor.is_none() {
            return Some(inp.skipped.first().cloned().unwrap_or_else(|| {
                "residuals r1..r4: need the voltages and the speed".to_string()
            }));
        }
        if let Some(why) = self.commission.why_incomplete() {
            return Some(why);
        }
        if !self.evaluated && self.first_detection.is_none() {
            return Some(
                "the lamps were never evaluated (the motor never ran settled and quasi-steady with voltage)"
                    .to_string(),
            );
        }
        if inp.detected {
            return None;
        }
        if self.judged_s < MIN_JUDGED_S {
            return Some(format!(
                "the lamps were judged on only {:.2} s of settled, quasi-steady running ({MIN_JUDGED_S:.1} s needed): the log is all start or transient, or ends too soon after commissioning",
                self.judged_s
            ));
        }
        self.unsettled.withheld()
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
        if let (Some(t), false) = (self.first_detection, self.detected_in_range) {
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
        let state = if self.monitor.is_none() {
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
        let ever_lit = self.first_detection.is_some() || lit_end;
        if ever_lit && self.isolation.heating_explains_lamps() {
            let rise = iso
                .winding_rise_k
                .map_or("heating".to_string(), |k| format!("{k:.0} K of heating"));
            return Some((iso.verdict.clone(), rise));
        }
        // The lamps' matching read only the load term: a load move, unless the isolation's
        // steady-state equations find a change no single fault (nor the load) explains.
        let lamps_read_load =
            self.only_load_named() && iso.state != monitor_core::IsolationState::Unknown;
        if ever_lit && (self.isolation.load_explains_lamps() || lamps_read_load) {
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

    /// With the load an unknown input, the lamps' matching only ever named the friction
    /// class (the load term): a load move.
    fn only_load_named(&self) -> bool {
        self.opts.load == crate::options::LoadModel::Unknown
            && !self.detections.is_empty()
            && self
                .detections
                .iter()
                .all(|d| matches!(d.fault, monitor_core::Fault::B | monitor_core::Fault::Bl))
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
        if self.monitor.is_none() {
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
            _ => self.commission.nominal_misfit(),
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
        if self.monitor.is_none() {
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
        if let Some(note) = self.commission.moved_note(out) {
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

/// What the winding was judged against, and the brief phrase (`winding against 2 healthy
/// runs`).
fn winding_against(u: &UnbalanceReport) -> (Against, String) {
    let against = u.judged_against.unwrap_or(match u.baseline {
        Some(BaselineSource::File) => Against::HealthyRuns,
        Some(BaselineSource::Commissioning) => Against::Commissioning,
        None => Against::Nothing,
    });
    let brief = if u.baseline_runs > 0 && against == Against::HealthyRuns {
        format!(
            "winding against {} healthy run{}",
            u.baseline_runs,
            if u.baseline_runs == 1 { "" } else { "s" }
        )
    } else {
        format!(
            "winding {}",
            super::words::against_text(FindingSource::Winding, against)
        )
    };
    (against, brief)
}

/// The winding's finding from the negative-sequence report: shorted turns named with the
/// phase's calibrated probability where a phase is more probable than no short (a FAULT
/// from 0.5 on), clear where no short is the more probable, unavailable without a steady
/// stretch.
pub(crate) fn winding_finding(u: &UnbalanceReport) -> FindingReport {
    let (against, brief) = winding_against(u);
    let of = |state, summary: String| {
        FindingReport::new(
            FindingSource::Winding,
            state,
            against,
            summary,
            brief.clone(),
        )
    };
    let widened = u
        .least_change_widened
        .as_ref()
        .map_or(String::new(), |w| format!("; {w}"));
    let change = format!(
        "the negative sequence changed by {:.1} % of I1 (least change {:.1} %){widened}",
        100.0 * u.winding_ratio,
        100.0 * u.least_change
    );
    let short = |phase, confidence| {
        State::Named(NamedFault {
            fault: FaultName::ShortedTurns,
            size: winding_size(u),
            phase: Some(phase),
            confidence,
        })
    };
    if let Some(p) = u.suspect_phase {
        // With the level where one was sized: "shorted turns in phase c: about 30 % of the
        // phase's turns (22-38 %), from ...; the negative sequence changed by ...".
        let said = u.shorted_turns.map_or_else(
            || format!("shorted turns in phase {}: {change}", p.name()),
            |t| format!("{}; {change}", t.sentence()),
        );
        return of(short(p, u.phase_confidence), said);
    }
    if u.judged_segment.is_none() {
        return winding_unavailable(u, against);
    }
    let why = u
        .phase_not_judged
        .as_ref()
        .map_or(String::new(), |w| format!(" ({w})"));
    if let Some((p, prob)) = watched_phase(&u.phase_probabilities) {
        // Not named (no short is the most probable), but a short too probable to call the
        // winding clear: watched, never healthy.
        return of(
            short(p, prob),
            format!(
                "a short in phase {} is not ruled out (probability {prob:.2}, no short {:.2}): {change}{why}",
                p.name(),
                u.phase_probabilities.no_short
            ),
        );
    }
    of(State::Clear, format!("no shorted turns: {change}{why}"))
}

/// The winding finding's size: the shorted fraction of the phase's turns where one was
/// sized (`unbalance.shorted_turns`), else the change of the negative sequence.
fn winding_size(u: &UnbalanceReport) -> Size {
    u.shorted_turns
        .map_or(Size::OfPositiveSequence(u.winding_ratio), |t| {
            Size::TurnsFraction(t.fraction)
        })
}

/// The winding's finding where no steady stretch was judged: unavailable, with the reason.
fn winding_unavailable(u: &UnbalanceReport, against: Against) -> FindingReport {
    let why = u
        .phase_not_judged
        .clone()
        .unwrap_or_else(|| "no steady stretch".to_string());
    let brief = format!("winding: {why}");
    FindingReport::new(
        FindingSource::Winding,
        State::Unavailable,
        against,
        why,
        brief,
    )
}

/// The least probability of a short in one phase at which the winding is not clear
/// ([`winding_finding`]): a short in a phase at 1 in 5 is worth watching.
pub const WINDING_WATCH_PROBABILITY: f32 = 0.2;

/// The most probable shorted phase and its probability, where it has
/// [`WINDING_WATCH_PROBABILITY`] or more.
fn watched_phase(pp: &crate::winding::PhaseProbabilities) -> Option<(monitor_core::Phase, f32)> {
    use monitor_core::Phase;
    [(Phase::A, pp.a), (Phase::B, pp.b), (Phase::C, pp.c)]
        .into_iter()
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .filter(|(_, p)| *p >= WINDING_WATCH_PROBABILITY)
}

/// The rotor's finding from the current spectrum (MCSA): broken bars named from the band "a
/// cracked bar or a high-resistance joint likely" on (48 dB or less below the supply line,
/// `monitor_core::verdict::ROTOR_FAULT_DB`), with the spectrum's confidence; quieter
/// sidebands ("no sign", and the "watch" band, which practice trends rather than acts on)
/// are judged clear, with their level; a record the spectrum could not read is unavailable.
pub(crate) fn rotor_finding(r: &crate::rotor::RotorReport) -> FindingReport {
    use crate::rotor::RotorBand;
    let of = |state, summary: String, brief: String| {
        FindingReport::new(
            FindingSource::Rotor,
            state,
            Against::Nothing,
            summary,
            brief,
        )
    };
    let (Some(level), Some(band), true) = (r.level_db, r.band, r.judged) else {
        let why = r
            .cannot_judge_because
            .clone()
            .unwrap_or_else(|| "the sidebands were not read".to_string());
        return of(State::Unavailable, why.clone(), format!("rotor: {why}"));
    };
    let below = -level as f32;
    let brief = format!("rotor sidebands {below:.0} dB below the supply line");
    match band {
        RotorBand::NoSign | RotorBand::Watch => {
            let brief = if band == RotorBand::Watch {
                format!("{brief} (the watch band: trend it)")
            } else {
                brief
            };
            of(State::Clear, r.sentence.clone(), brief)
        }
        _ => {
            let named = NamedFault {
                fault: FaultName::BrokenBars,
                size: Size::DbBelowLine(below),
                phase: None,
                confidence: r.confidence.unwrap_or(0.0) as f32,
            };
            of(State::Named(named), r.sentence.clone(), brief)
        }
    }
}

/// The data-quality finding: what the stage does not trust, the stretches not judged, and
/// the sensors' readings no machine gives at the end (`sensors`, the core's flags).
pub(crate) fn data_quality_finding(q: &DataQuality, sensors: SensorFlags) -> FindingReport {
    let of = |state, summary: String| {
        FindingReport::new(
            FindingSource::DataQuality,
            state,
            Against::Nothing,
            summary,
            "data quality".to_string(),
        )
    };
    if !q.trusted {
        return of(
            State::Unexplained,
            format!("data quality: {}", q.not_trusted_because.join("; ")),
        );
    }
    let unjudged: f64 = q.not_judged.iter().map(|n| n.to_s - n.from_s).sum();
    if unjudged > MAX_NOT_JUDGED_FRACTION * q.duration_s.max(f64::MIN_POSITIVE) {
        return of(
            State::Unexplained,
            format!(
                "{unjudged:.2} s of the {:.2} s log could not be judged (over {:.0} %): {}",
                q.duration_s,
                100.0 * MAX_NOT_JUDGED_FRACTION,
                q.not_judged
                    .iter()
                    .map(|n| format!("{:.2}..{:.2} s, {}", n.from_s, n.to_s, n.why))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        );
    }
    if let Some(s) = sensor_flag_finding(sensors) {
        return s;
    }
    of(State::Clear, format!("data quality: {}", q.summary()))
}

/// The core's sensor flags at the end of a replay as a data-quality finding (readings no
/// machine gives: a sensor or its wiring, not the motor); `None` with no flag set.
pub(crate) fn sensor_flag_finding(s: SensorFlags) -> Option<FindingReport> {
    let which: Vec<&str> = [
        (s.current, "current"),
        (s.voltage, "voltage"),
        (s.speed, "speed (encoder)"),
    ]
    .into_iter()
    .filter_map(|(on, w)| on.then_some(w))
    .collect();
    (!which.is_empty()).then(|| {
        FindingReport::new(
            FindingSource::DataQuality,
            State::Unexplained,
            Against::Nothing,
            format!(
                "the {} sensor readings at the end of the log are impossible for any machine (not a number, saturated, phases not summing to zero, or an encoder jump): check the sensors and their wiring; the motor cannot be judged from them",
                which.join(" and ")
            ),
            "data quality".to_string(),
        )
    })
}
