//! What a replay reports ([`DiagnoseReport`]): the stages' findings side by side, the
//! timeline, and the verdict decided once from the findings ([`DiagnoseReport::conclude`]),
//! built by [`crate::Replay::finish`].

use crate::isolation::{FaultCandidate, IsolationFinding, IsolationReport};
use crate::lamps::commission::CommissioningReport;
use crate::lamps::{Detection, LampsFinding};
use crate::options::{serialize_angle_source, CommissionWindow};
use crate::rotor::RotorReport;
use crate::timeline::TimelinePoint;
use crate::verdict::findings::Stages;
use crate::verdict::{conclude, put, FindingReport};
use crate::winding::UnbalanceReport;
use monitor_core::{AngleSource, Fault, MonitorOutput};
use monitor_io::log::quality::DataQuality;
use serde::Serialize;

pub use crate::verdict::{Rule, Verdict};

/// What `diagnose` reports (the JSON keys of `docs/design.md`, plus `verdict`, `data_quality` and
/// `commissioning`).
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseReport {
    /// The one verdict (`fault`, `watching`, `healthy`, `could_not_judge`): the decision
    /// table over `findings` ([`crate::verdict`]).
    pub verdict: Verdict,
    /// The row of the decision table that decided (`named`, `data_untrusted`, `file_misfit`,
    /// `watching`, `unexplained`, `out_of_range`, `healthy`, `nothing_judged`).
    pub verdict_rule: Rule,
    /// The finding the verdict rests on (null for healthy and for nothing judged).
    pub verdict_finding: Option<FindingReport>,
    /// Every analysis' finding: residuals, winding, rotor, operating point, data quality,
    /// parameter fit. (The door, `monitor_words`, spells the verdict's line and the lists
    /// of what was and was not judged from them: JSON `verdict_line`, `judged`,
    /// `not_judged`, `verdict_withheld_because`.)
    pub findings: Vec<FindingReport>,
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
    /// The rotor: broken bars from the current's sidebands (`crate::rotor`).
    pub rotor: RotorReport,
    /// Faults ever named while the lamps were lit, with the time first named.
    pub detections: Vec<Detection>,
    /// Analyses skipped for lack of a column, with the column (JSON `skipped_reasons`; the
    /// door spells them as `skipped`).
    #[serde(rename = "skipped_reasons")]
    pub skipped: Vec<crate::verdict::SkippedAnalysis>,
    /// Angle source used (JSON: its command-line name, [`crate::angle_source_name`]).
    #[serde(serialize_with = "serialize_angle_source")]
    pub angle_source: AngleSource,
    /// Commissioning window asked for, if any [s].
    pub commission: Option<CommissionWindow>,
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
    /// The threshold band of each normalised residual r1..r4 in force at the log's end,
    /// `[centre, half-width]` (the learned mean and `k_sigma` spreads once commissioned
    /// (in force from the commissioning window's end), else 0 and the fixed threshold): a
    /// residual outside its band lights its lamp. Null for a log without the residuals.
    pub threshold_bands: Option<[[f32; 2]; 4]>,
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
    /// The report of the stages' findings (`lamps` with the isolation's, the winding's
    /// `unbalance` with the `rotor`'s), `rows` replayed, the lamps' own candidates
    /// `signature` and the `timeline`: every analysis' finding drawn, the verdict not
    /// decided yet ([`DiagnoseReport::conclude`] decides it once).
    pub(crate) fn undecided(
        rows: u64,
        (lamps, isolation): (LampsFinding, IsolationFinding),
        (unbalance, rotor): (UnbalanceReport, RotorReport),
        signature_candidates: Vec<FaultCandidate>,
        timeline: Vec<TimelinePoint>,
    ) -> Self {
        let stages = Stages {
            lamps: &lamps,
            isolation: &isolation,
        };
        let findings = stages.findings(&unbalance, &rotor);
        DiagnoseReport {
            verdict: Verdict::CouldNotJudge,
            verdict_rule: Rule::NothingJudged,
            verdict_finding: None,
            findings,
            lamps: final_lamps(&lamps.out),
            candidates: isolation.candidates,
            isolation: isolation.report,
            signature_candidates,
            first_detection_s: lamps.first_detection,
            unbalance,
            rotor,
            detections: lamps.detections,
            skipped: lamps.skipped,
            angle_source: lamps.angle_source,
            commission: lamps.commission.requested(),
            commissioning: lamps.commission.report(lamps.k_sigma, lamps.monitor),
            data_quality: DataQuality::default(),
            rows,
            max_abs_residual: lamps.max_abs,
            timeline,
            threshold_bands: None,
        }
    }

    /// Decides the verdict from the report's `findings` by the decision table
    /// ([`conclude`], `monitor_core::verdict::decide`) and writes it into the verdict's
    /// keys: once per report, after every finding is in.
    pub fn conclude(&mut self) {
        let c = conclude(&self.findings);
        self.verdict = c.verdict;
        self.verdict_rule = c.rule;
        self.verdict_finding = c.finding;
    }

    /// The parameter fit's finding from the machine fitted to the log (`f`,
    /// [`crate::verdict::machine_fit::StartFit::finding`]), where the residuals were judged against the file:
    /// a fault it names replaces the residuals' parameter-fit finding; the machine on the
    /// file replaces only a clear one (a misfit the residuals saw stands).
    pub(crate) fn put_machine_fit(&mut self, f: FindingReport) {
        use monitor_core::verdict::{Against, FindingSource, State};
        let Some(old) = self
            .findings
            .iter()
            .find(|g| g.source() == FindingSource::ParameterFit)
        else {
            return;
        };
        let replaces = old.finding.against == Against::ParameterFile
            && (matches!(f.finding.state, State::Named(_)) || old.finding.state == State::Clear);
        if replaces {
            put(&mut self.findings, f);
        }
    }

    /// Data that cannot carry a verdict (`why`): every fault-judging finding that judged
    /// something becomes "not judged", with what it would have said (the verdict is decided
    /// after, [`DiagnoseReport::conclude`]).
    pub(crate) fn distrust(&mut self, why: &crate::verdict::Detail) {
        for f in &mut self.findings {
            if f.source().judges_faults()
                && f.finding.state != monitor_core::verdict::State::NotJudged
            {
                let read = std::mem::replace(&mut f.detail, crate::verdict::Detail::DataClean);
                f.detail = crate::verdict::Detail::Distrusted {
                    why: Box::new(why.clone()),
                    read: Box::new(read),
                };
                f.finding.state = monitor_core::verdict::State::NotJudged;
            }
        }
    }

    /// Replaces (or adds) the finding of its source (the verdict is decided after,
    /// [`DiagnoseReport::conclude`]).
    pub(crate) fn put_finding(&mut self, f: FindingReport) {
        put(&mut self.findings, f);
    }
}
