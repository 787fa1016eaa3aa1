//! The one verdict of a replay: every analysis yields a finding ([`FindingReport`]), and one
//! function, the core's decision table (`monitor_core::verdict::decide`, the same code the
//! board's FAULT lamp runs), turns them into the verdict every output shows ([`decide_report`]):
//! `diagnose`'s last line and its JSON (`verdict`, `verdict_line`, `verdict_finding`,
//! `findings`, `judged`, `not_judged`), `explain`'s headline, the Python result, the fleet's
//! row and the HMI. The table itself, row by row, is in `docs/isolation.md` ("One verdict").
//!
//! The findings (built by the replay, [`findings`]):
//! - **residuals**: the lamps r1..r4 and their isolation (Table 1's fault with its size, the
//!   isolation's probability as the confidence), against commissioning or the file;
//! - **winding**: the negative sequence's change (shorted turns, with the phase and its
//!   confidence);
//! - **rotor**: the current spectrum's (1 - 2s) f sideband (broken bars, with the MCSA band);
//! - **operating point**: load moves and heating (they explain lamps; never a fault);
//! - **data quality**: what the data-quality stage does not trust, and the sensors' readings
//!   no machine gives;
//! - **parameter fit**: whether the parameter file fits the log where nothing was
//!   commissioned.

pub(super) mod findings;
pub mod machine_fit;
pub(super) mod measured;

use monitor_core::verdict::{decide, Finding, NamedFault, Size, State};
pub use monitor_core::verdict::{Against, FindingSource, Rule, Verdict};
use monitor_core::Phase;
use serde::{Serialize, Serializer};

pub use findings::FileMisfit;

/// One finding as the report gives it (JSON `findings[]`, `verdict_finding`): the core's
/// [`Finding`] and what it rests on ([`Detail`]), from which the door (`monitor_words`)
/// spells its sentence (`summary`) and its brief phrase.
#[derive(Debug, Clone, PartialEq)]
pub struct FindingReport {
    /// What the decision table reads.
    pub finding: Finding,
    /// What was found, or why nothing could be judged, with its numbers.
    pub detail: Detail,
}

pub use crate::lamps::SkippedAnalysis;

/// What a finding rests on, with its numbers (JSON `findings[].reason`, `{"kind": ..}`).
/// The winding's, the rotor's and the isolation's own reports carry theirs (the report's
/// `unbalance`, `rotor` and `isolation`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Detail {
    /// The residuals were skipped: the log lacks a column (`None`: the voltages and the
    /// speed both).
    ResidualsSkipped {
        /// Which column.
        need: Option<SkippedAnalysis>,
    },
    /// The commissioning window asked for was not learned.
    ResidualsNotLearned(crate::lamps::commission::NotLearned),
    /// The lamps were never evaluated: the motor never ran settled and quasi-steady with
    /// voltage.
    ResidualsNeverEvaluated,
    /// The lamps were judged on too little settled, quasi-steady running.
    ResidualsTooLittle {
        /// Seconds judged.
        judged_s: f64,
        /// Seconds needed ([`MIN_JUDGED_S`]).
        needed_s: f64,
    },
    /// The log ended inside a held, unsettled stretch with a residual far outside its band.
    ResidualsUnsettled(crate::lamps::HeldUnsettled),
    /// The isolation's conclusion (the report's `isolation.said`).
    Isolation,
    /// The lamps lit for the windings' heating (the tracked rise [K], where known).
    LampsForHeating {
        /// The rise [K].
        rise_k: Option<f32>,
    },
    /// The lamps lit for a load move (to the paper's model a load change is a Bl change).
    LampsForLoadMove,
    /// The lamps lit only while the load or the voltage was outside the commissioned range.
    LampsOutOfRange {
        /// First lit [s].
        first_s: f64,
    },
    /// The winding's negative sequence (the report's `unbalance`).
    Winding,
    /// The rotor's sidebands (the report's `rotor`).
    Rotor,
    /// The load and the heating need the voltages and the speed.
    OperatingPointUnavailable,
    /// Steady: no load move, no heating.
    Steady,
    /// No load move; the heating not judged: the isolation never judged a steady
    /// operating point with voltage, so the windings' temperature was not read.
    NoLoadMoveHeatingUnread,
    /// The operating point moved.
    OperatingPointMoved {
        /// Outside the commissioned range at the end: what left it.
        outside: Option<Vec<crate::lamps::commission::RangeDeparture>>,
        /// How many times the load moved.
        load_moves: usize,
        /// How much the windings warmed since commissioning [K].
        rise_k: Option<f32>,
    },
    /// Commissioned: the residuals are judged against the healthy motor learned.
    Commissioned,
    /// The residuals against the file need the voltages and the speed.
    ParameterFitUnavailable,
    /// The residuals against the file's nominal values stay within their fixed thresholds.
    FileFits,
    /// The parameter file does not fit this log, and why.
    FileMisfit(FileMisfit),
    /// The full-order machine fitted to the log against the file: a fault present from the
    /// start named, or the machine on the file (the reach of a "healthy").
    MachineFit(machine_fit::StartFit),
    /// The data-quality stage does not trust the data (the report's
    /// `data_quality.not_trusted_because`).
    DataNotTrusted,
    /// Too much of the log could not be judged (the report's `data_quality.not_judged`).
    DataNotJudged {
        /// Seconds not judged.
        unjudged_s: f64,
        /// The log's length [s].
        duration_s: f64,
    },
    /// The data are clean (the report's `data_quality`).
    DataClean,
    /// Sensor readings no machine gives at the end of the log.
    ImpossibleReadings {
        /// The current sensors.
        current: bool,
        /// The voltage sensors.
        voltage: bool,
        /// The speed sensor (encoder).
        speed: bool,
    },
    /// The data-quality stage does not trust the data: nothing is judged, and what the
    /// analysis read.
    Distrusted {
        /// Why the data are not trusted: the data-quality finding's own detail.
        why: Box<Detail>,
        /// What the analysis read.
        read: Box<Detail>,
    },
}

impl FindingReport {
    /// A finding of `source` in `state` against `against`, resting on `detail`.
    pub fn new(source: FindingSource, state: State, against: Against, detail: Detail) -> Self {
        FindingReport {
            finding: Finding::new(source, state, against),
            detail,
        }
    }

    /// Where it comes from.
    pub fn source(&self) -> FindingSource {
        self.finding.source
    }

    /// The named fault, where there is one.
    pub fn named(&self) -> Option<&NamedFault> {
        self.finding.named()
    }

    /// The state's name in the JSON: `unavailable` (the log lacks what the analysis
    /// needs), `not_judged` (the log kept it from judging), `clear`, `named`, `unexplained`,
    /// `explained`, `out_of_range`.
    pub fn state_name(&self) -> &'static str {
        match self.finding.state {
            State::Unavailable => "unavailable",
            State::NotJudged => "not_judged",
            State::Clear => "clear",
            State::Named(_) => "named",
            State::Unexplained => "unexplained",
            State::Explained => "explained",
            State::OutOfRange => "out_of_range",
        }
    }

    /// Whether the finding judged nothing: not judged, or unavailable.
    pub fn judged_nothing(&self) -> bool {
        matches!(self.finding.state, State::NotJudged | State::Unavailable)
    }
}

/// The JSON form of a [`FindingReport`]: `source`, `state`, `fault`, `size`, `size_unit`
/// (`relative`: 0.5 is +50 %; `of_i1`: a fraction of the positive-sequence current;
/// `turns_fraction`: of the phase's turns; `db_below_line`: dB below the supply line),
/// `phase`, `confidence` (null without a name), `against`, `reason` (the door adds
/// `summary`, its sentence).
#[derive(Serialize)]
struct FindingJson<'a> {
    source: FindingSource,
    state: &'static str,
    fault: Option<&'static str>,
    size: Option<f32>,
    size_unit: Option<&'static str>,
    phase: Option<Phase>,
    confidence: Option<f32>,
    against: Against,
    reason: &'a Detail,
}

/// A named fault as the JSON gives it: `{fault, size, size_unit, phase, confidence}`, for
/// `#[serde(serialize_with = "serialize_named")]`.
pub fn serialize_named<S: Serializer>(n: &NamedFault, s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct NamedJson {
        fault: &'static str,
        size: f32,
        size_unit: &'static str,
        phase: Option<Phase>,
        confidence: f32,
    }
    let (size, size_unit) = size_parts(n.size);
    NamedJson {
        fault: n.fault.name(),
        size,
        size_unit,
        phase: n.phase,
        confidence: n.confidence,
    }
    .serialize(s)
}

/// A size's value and the JSON name of its unit.
pub fn size_parts(size: Size) -> (f32, &'static str) {
    match size {
        Size::Relative(x) => (x, "relative"),
        Size::OfPositiveSequence(x) => (x, "of_i1"),
        Size::TurnsFraction(x) => (x, "turns_fraction"),
        Size::DbBelowLine(x) => (x, "db_below_line"),
    }
}

impl Serialize for FindingReport {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let n = self.named();
        let size = n.map(|n| size_parts(n.size));
        FindingJson {
            source: self.source(),
            state: self.state_name(),
            fault: n.map(|n| n.fault.name()),
            size: size.map(|s| s.0),
            size_unit: size.map(|s| s.1),
            phase: n.and_then(|n| n.phase),
            confidence: n.map(|n| n.confidence),
            against: self.finding.against,
            reason: &self.detail,
        }
        .serialize(s)
    }
}

/// What the decision table concluded.
#[derive(Debug, Clone, PartialEq)]
pub struct Conclusion {
    /// The verdict.
    pub verdict: Verdict,
    /// The row of the table that decided.
    pub rule: Rule,
    /// The finding it rests on, where one decided.
    pub finding: Option<FindingReport>,
}

/// The verdict of `findings` by the core's decision table.
pub fn conclude(findings: &[FindingReport]) -> Conclusion {
    #[cfg(test)]
    DECIDED.with(|d| d.set(d.get() + 1));
    let core: Vec<Finding> = findings.iter().map(|f| f.finding).collect();
    let d = decide(&core);
    Conclusion {
        verdict: d.verdict,
        rule: d.rule,
        finding: d.by.and_then(|k| findings.get(k)).cloned(),
    }
}

#[cfg(test)]
thread_local! {
    /// How many verdicts [`conclude`] decided on this thread (the test that a diagnosis
    /// decides once).
    static DECIDED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// How many verdicts [`conclude`] decided on this thread so far.
#[cfg(test)]
pub(crate) fn decided_on_this_thread() -> u32 {
    DECIDED.with(std::cell::Cell::get)
}

/// Replaces the finding of `source` in `findings` (or adds it).
pub fn put(findings: &mut Vec<FindingReport>, f: FindingReport) {
    match findings.iter_mut().find(|g| g.source() == f.source()) {
        Some(g) => *g = f,
        None => findings.push(f),
    }
}

use crate::isolation::IsolationReport;
use monitor_core::verdict::{FaultName, Glance};
use monitor_core::MonitorOutput;

/// The least running, in seconds, on which the lamps must have been judged (evaluated,
/// quasi-steady, on thresholds in force) for the verdict `healthy`: less is "could not
/// judge" with how much was judged. One rule for `diagnose`, the HMI's log replay and the
/// demo (all report through [`Replay::finish`]).
pub const MIN_JUDGED_S: f64 = 1.0;
/// The least relative change of a named fault for the verdict `fault`: the core's
/// ([`monitor_core::isolation::MIN_FAULT_CHANGE`], 5 %), read by the one verdict's decision
/// table (`monitor_core::verdict`) for `diagnose`, the HMI's log replay, the demo
/// ([`Replay::finish`]) and the board's FAULT lamp. Below it the verdict is `watching`, with
/// the name and its size.
pub const MIN_FAULT_CHANGE: f32 = monitor_core::isolation::MIN_FAULT_CHANGE;

/// The moment's evidence as the decision table reads it (the board's
/// `monitor_core::verdict::Glance`): the lamps, the sensor flags, the isolation's name with
/// its candidate's probability, its baseline, whether the operating point explains the
/// lamps (`moved`), and the core's winding phase.
pub(crate) fn glance(
    out: &MonitorOutput,
    report: Option<&(IsolationReport, Vec<crate::isolation::FaultCandidate>)>,
    moved: bool,
) -> Glance {
    let named = report.and_then(|(r, c)| findings::isolation_name(r, c));
    let friction =
        report.is_some_and(|(r, _)| r.named == Some(crate::isolation::IsolationName::Friction));
    Glance {
        lamps_lit: out.fault_detected,
        sensor_fault: out.sensor_fault.any(),
        named,
        commissioned: report
            .is_some_and(|(r, _)| r.baseline == crate::isolation::IsolationBaseline::Learned),
        moved: moved || friction,
        // The core's winding phase counts where the lamps are judged (settled, quasi-steady):
        // a start's or a step's transient unbalances the currents for a while.
        winding: steady_phase(out).map(|p| NamedFault {
            fault: FaultName::ShortedTurns,
            size: Size::OfPositiveSequence(out.unbalance.winding_ratio),
            phase: Some(p),
            confidence: out.unbalance.phase_confidence,
        }),
    }
}

/// The core's winding phase at `out` where the lamps are judged (evaluating, quasi-steady),
/// else `None`.
fn steady_phase(out: &MonitorOutput) -> Option<Phase> {
    out.unbalance
        .suspect_phase
        .filter(|_| out.evaluating && out.quasi_steady)
}
