//! What a replay reports ([`DiagnoseReport`]): the timeline, the negative-sequence
//! analysis, the verdict, built by [`Replay::finish`].

use super::commission::CommissioningReport;
use super::isolation::{FaultCandidate, IsolationReport};
use super::options::serialize_angle_source;
use super::step::Detection;
use super::verdict::{conclude, put, FindingReport};
use super::winding::UnbalanceReport;
use monitor_core::{AngleSource, CommissioningState, Fault, MonitorOutput};
use monitor_io::log::quality::DataQuality;
use monitor_io::log::Channels;
use serde::Serialize;

pub use super::verdict::{Rule, Verdict};

/// What the monitor is doing at a timeline point, as the panel would show it.
#[derive(Debug, Clone, PartialEq)]
pub enum MonitorState {
    /// Learning the healthy residuals; the fraction done.
    Commissioning(f32),
    /// The operating point is changing: the lamps hold.
    Transient,
    /// Settling after start (lamps not yet evaluated).
    Starting,
    /// Evaluating, no lamp lit.
    Healthy,
    /// Lamps lit: the candidates with their probabilities.
    Fault(Vec<(Fault, f32)>),
    /// The load or the voltage has left the commissioned range and no fault is named (the
    /// amber state): lamps may light, the FAULT lamp stays off; the note says where the
    /// operating point went ([`crate::Replay::operating_point_moved`]).
    Moved(String),
}

impl MonitorState {
    /// The state of a monitor output.
    pub fn of(o: &MonitorOutput) -> Self {
        match o.commissioning {
            CommissioningState::Learning(x) => MonitorState::Commissioning(x),
            _ if !o.quasi_steady => MonitorState::Transient,
            _ if !o.evaluating => MonitorState::Starting,
            _ if o.top().is_none() => MonitorState::Healthy,
            _ => MonitorState::Fault(MonitorState::signature(o)),
        }
    }

    /// The signature matching's candidates of `o` (probability above zero), most probable
    /// first.
    pub fn signature(o: &MonitorOutput) -> Vec<(Fault, f32)> {
        let mut c: Vec<(Fault, f32)> = Fault::ALL
            .iter()
            .zip(o.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| (*f, p))
            .collect();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        c
    }
}

/// The amber state's note where the lamps lit for a load that moved inside the commissioned
/// range, with the load an unknown input (`LoadModel::Unknown`).
pub const LOAD_MOVED_NOTE: &str =
    "load moved inside the commissioned range; the stator-voltage equations fit (the torque residuals read it as Bl)";

/// The amber state's note while lamps that lit for a load move go out after the load came
/// back into the commissioned range.
pub const LOAD_BACK_NOTE: &str =
    "the load came back; the lamps that lit while it had moved are going out";

/// One point of the diagnosis timeline.
#[derive(Debug, Clone, Serialize)]
pub struct TimelinePoint {
    /// Time [s].
    pub t_s: f64,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Lamps r1..r4.
    pub lamps: [bool; 4],
    /// Most probable fault, if any (JSON: its name).
    pub top: Option<Fault>,
    /// Its probability.
    pub top_probability: f32,
    /// Mechanical speed [rad/s].
    pub speed_rad_s: f32,
    /// Lamps are being evaluated (running, settled, commissioned or fixed).
    pub evaluating: bool,
    /// Learning healthy statistics.
    pub commissioning: bool,
    /// The operating point is quasi-steady (the steady-state residuals apply).
    pub quasi_steady: bool,
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// Beside a lit r2..r4 lamp: the operating point has left the commissioned range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_note: Option<String>,
    /// What the panel shows ([`Replay::panel`]; not in the JSON, whose keys above carry
    /// it).
    #[serde(skip)]
    pub panel: Panel,
}

/// What the panel shows at an output ([`Replay::panel`]): the HMI, the demo's and
/// `diagnose`'s timelines.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The state ([`Replay::state`]).
    pub state: MonitorState,
    /// The FAULT lamp: the decision table's FAULT ([`Panel::call`]), off in the amber
    /// state.
    pub fault_lamp: bool,
    /// The decision table's verdict at this output (`monitor_core::verdict::Glance`, the
    /// board's rule).
    pub call: Verdict,
    /// What the isolation concluded where the lamps are evaluated (the report and the
    /// candidates listed, [`Replay::isolation_now`]), else `None`.
    pub isolation: Option<(IsolationReport, Vec<FaultCandidate>)>,
}

/// What `diagnose` reports (the JSON keys of `docs/design.md`, plus `verdict`, `data_quality` and
/// `commissioning`).
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseReport {
    /// The one verdict (`fault`, `watching`, `healthy`, `could_not_judge`): the decision
    /// table over `findings` ([`super::verdict`]).
    pub verdict: Verdict,
    /// The verdict's line as `diagnose` prints it after `verdict: `.
    pub verdict_line: String,
    /// The row of the decision table that decided (`named`, `data_untrusted`, `file_misfit`,
    /// `watching`, `unexplained`, `out_of_range`, `healthy`, `nothing_judged`).
    pub verdict_rule: Rule,
    /// The finding the verdict rests on (null for healthy and for nothing judged).
    pub verdict_finding: Option<FindingReport>,
    /// Every analysis' finding: residuals, winding, rotor, operating point, data quality,
    /// parameter fit.
    pub findings: Vec<FindingReport>,
    /// What was judged, against what (`residuals against commissioning`, ...).
    pub judged: Vec<String>,
    /// What could not be judged, and why.
    pub not_judged: Vec<String>,
    /// Why the verdict is not a FAULT or healthy (empty for those): the deciding finding,
    /// then what could not be judged.
    pub verdict_withheld_because: Vec<String>,
    /// Final lamps `{"r1":bool,..}`.
    pub lamps: std::collections::BTreeMap<String, bool>,
    /// Final fault candidates, most probable first, with their estimated size: from the
    /// isolation ([`IsolationReport`]) when a fault was detected; an impossible sensor
    /// reading names its sensor outright (size null).
    pub candidates: Vec<FaultCandidate>,
    /// What the isolation concluded: the fault named, its size, the groups that cannot
    /// be separated, and one sentence.
    pub isolation: IsolationReport,
    /// The paper's matching of the final lamps against the fault signature matrix (Table
    /// 1 in voltage orientation), most probable first: the lamps' own candidates.
    pub signature_candidates: Vec<FaultCandidate>,
    /// First time a lamp lit or a sensor fault was seen [s], or null.
    pub first_detection_s: Option<f64>,
    /// Negative-sequence analysis of the currents.
    pub unbalance: UnbalanceReport,
    /// The rotor: broken bars from the current's sidebands (`super::rotor`).
    pub rotor: super::rotor::RotorReport,
    /// Faults ever named while the lamps were lit, with the time first named.
    pub detections: Vec<Detection>,
    /// Analyses skipped for lack of a column, with the reason.
    pub skipped: Vec<String>,
    /// Angle source used (JSON: its command-line name, [`super::options::angle_source_name`]).
    #[serde(serialize_with = "serialize_angle_source")]
    pub angle_source: AngleSource,
    /// Commissioning window asked for, if any [s].
    pub commission: Option<(f64, f64)>,
    /// What commissioning did (state, window used, range covered).
    pub commissioning: CommissioningReport,
    /// What the data-quality stage found and did.
    pub data_quality: DataQuality,
    /// Rows replayed.
    pub rows: u64,
    /// Largest |normalised residual| while evaluating, r1..r4.
    pub max_abs_residual: [f32; 4],
    /// Timeline (one point per `timeline_step_s`).
    pub timeline: Vec<TimelinePoint>,
}

/// The analyses a log with `channels` cannot feed, with the column they need (the report's
/// `skipped`).
pub(crate) fn skipped_analyses(channels: Channels) -> Vec<String> {
    let mut skipped = Vec::new();
    if !channels.voltages {
        skipped.push(
            "residuals r1..r4 and fault signatures: need the voltages va_V, vb_V, vc_V (Vqs)"
                .to_string(),
        );
    } else if !(channels.speed || channels.encoder) {
        skipped.push(
            "residuals r1..r4 and fault signatures: need the speed (wm_rad_s or enc_count)"
                .to_string(),
        );
    }
    skipped
}

/// The final lamps' matching against the signature matrix: the faults with a probability,
/// most probable first (the report's `signature_candidates`).
pub(crate) fn signature_candidates(out: &MonitorOutput) -> Vec<FaultCandidate> {
    let mut candidates: Vec<FaultCandidate> = Fault::ALL
        .iter()
        .zip(out.diagnosis.probabilities)
        .filter(|(_, p)| *p > 0.0)
        .map(|(f, p)| FaultCandidate {
            fault: *f,
            probability: p,
            change: None,
            phase: None,
        })
        .collect();
    candidates.sort_by(|a, b| b.probability.total_cmp(&a.probability));
    candidates
}

/// Outside the commissioned range at the end (`note`: where the point moved), a deviation no
/// single fault explains is the new operating point's, said calmly (the verdict withholds a
/// judgement).
pub(crate) fn note_moved_point(isolation: &mut IsolationReport, note: &str) {
    if isolation.state == monitor_core::IsolationState::Unknown {
        isolation.verdict = format!(
            "Not judged as a fault: the operating point moved outside the commissioned range ({note}), where the healthy baseline does not hold; the deviation there ({:.0} standard deviations) fits no single fault, as a new load would not. Commission over this load to judge it.",
            isolation.deviation_sigma
        );
    }
}

/// The final lamps, `{"r1": bool, ..}`.
pub(crate) fn final_lamps(out: &MonitorOutput) -> std::collections::BTreeMap<String, bool> {
    (0..4)
        .map(|k| {
            (
                format!("r{}", k + 1),
                out.lamps.get(k).copied().unwrap_or(false),
            )
        })
        .collect()
}

impl DiagnoseReport {
    /// Decides the verdict from the report's `findings` by the decision table
    /// ([`conclude`]) and writes it into the verdict's keys. Call again
    /// after adding or replacing a finding.
    pub fn conclude(&mut self) {
        let c = conclude(&self.findings);
        self.verdict = c.verdict;
        self.verdict_rule = c.rule;
        self.verdict_line = c.line;
        self.verdict_finding = c.finding;
        self.judged = c.judged;
        self.not_judged = c.not_judged;
        self.verdict_withheld_because = c.withheld_because;
    }

    /// Data that cannot carry a verdict (`why`): every fault-judging finding that judged
    /// something becomes "not judged", with what it would have said; decided again.
    pub fn distrust(&mut self, why: &str) {
        for f in &mut self.findings {
            if f.source().judges_faults()
                && f.finding.state != monitor_core::verdict::State::NotJudged
            {
                f.summary = format!("not judged ({why}); it read: {}", f.summary);
                f.brief = format!("{}: {why}", f.source().name());
                f.finding.state = monitor_core::verdict::State::NotJudged;
            }
        }
        self.conclude();
    }

    /// Replaces (or adds) the finding of its source and decides again.
    pub fn put_finding(&mut self, f: FindingReport) {
        put(&mut self.findings, f);
        self.conclude();
    }
}
