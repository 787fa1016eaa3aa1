//! `diagnose --json`'s document ([`DiagnoseDoc`]): the report's typed values, and beside
//! each its sentence under the key the document has always had. The isolation's and the
//! rotor's parts are in [`super::doc_parts`].

use super::doc_parts::{IsolationDoc, RotorDoc};
use super::{
    commissioning, detection_line, judged, not_judged, note, phase_not_judged, range_note, skipped,
    verdict_line, widened, withheld_because, FindingDoc,
};
use crate::Spelling;
use monitor_io::log::quality::DataQuality;
use monitor_replay::verdict::SkippedAnalysis;
use monitor_replay::{
    angle_source_name, CommissionAdvice, CommissionWindow, CommissioningOutcome,
    CommissioningReport, Detection, DiagnoseReport, FaultCandidate, FindingReport,
    QuasiSteadyPoint, RangeNote, Rule, Thresholds, TimelinePoint, UnbalanceReport, Verdict,
};
use serde::Serialize;
use std::collections::BTreeMap;

/// `diagnose`'s report as its JSON document carries it: each of [`DiagnoseReport`]'s values
/// under its own key (by reference; a field added to the report is a compile error in
/// [`DiagnoseDoc::new`] until the document carries it), the parts that have sentences as
/// their own documents, and the report's sentences.
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseDoc<'a> {
    /// The one verdict.
    pub verdict: Verdict,
    /// The row of the decision table that decided.
    pub verdict_rule: Rule,
    /// The finding the verdict rests on, with its sentence (null for healthy and for
    /// nothing judged).
    pub verdict_finding: Option<FindingDoc<&'a FindingReport>>,
    /// Every analysis' finding, each with its sentence (`summary`).
    pub findings: Vec<FindingDoc<&'a FindingReport>>,
    /// Final lamps `{"r1":bool,..}`.
    pub lamps: &'a BTreeMap<String, bool>,
    /// Final fault candidates, most probable first.
    pub candidates: &'a [FaultCandidate],
    /// What the isolation concluded, with its sentences.
    pub isolation: IsolationDoc<'a>,
    /// The lamps' own candidates, most probable first.
    pub signature_candidates: &'a [FaultCandidate],
    /// First time a lamp lit or a sensor fault was seen [s], or null.
    pub first_detection_s: Option<f64>,
    /// The negative-sequence analysis of the currents, with its sentences.
    pub unbalance: UnbalanceReportDoc<'a>,
    /// The rotor, with its sentences.
    pub rotor: RotorDoc<'a>,
    /// Faults ever named while the lamps were lit, with the time first named.
    pub detections: &'a [Detection],
    /// Analyses skipped for lack of a column, typed.
    pub skipped_reasons: &'a [SkippedAnalysis],
    /// The angle source used, by its command-line name ([`angle_source_name`]).
    pub angle_source: &'static str,
    /// Commissioning window asked for, if any [s].
    pub commission: Option<&'a CommissionWindow>,
    /// What commissioning did, with its sentences.
    pub commissioning: CommissioningDoc<'a>,
    /// What the data-quality stage found and did.
    pub data_quality: &'a DataQuality,
    /// Rows replayed.
    pub rows: u64,
    /// Largest |normalised residual| while evaluating, r1..r4.
    pub max_abs_residual: [f32; 4],
    /// The timeline, each point with its note where it has one.
    pub timeline: Vec<TimelinePointDoc<'a>>,
    /// The threshold band of each normalised residual at the log's end (null without the
    /// residuals).
    pub threshold_bands: Option<[[f32; 2]; 4]>,
    /// The verdict's line, after `verdict: ` ([`verdict_line`]).
    pub verdict_line: String,
    /// What was judged, against what ([`judged`]).
    pub judged: Vec<String>,
    /// What could not be judged, and why ([`not_judged`]).
    pub not_judged: Vec<String>,
    /// Why the verdict is not a FAULT or healthy ([`withheld_because`]).
    pub verdict_withheld_because: Vec<String>,
    /// The analyses the log could not feed, in words.
    pub skipped: Vec<String>,
    /// Each of `detections` beside the verdict ([`detection_line`]).
    pub detections_said: Vec<String>,
}

impl<'a> DiagnoseDoc<'a> {
    /// The document of `rep`, its sentences in `sp`'s words (the options advice names).
    pub fn new(rep: &'a DiagnoseReport, sp: &dyn Spelling) -> Self {
        let DiagnoseReport {
            verdict,
            verdict_rule,
            verdict_finding,
            findings,
            lamps,
            candidates,
            isolation,
            signature_candidates,
            first_detection_s,
            unbalance,
            rotor,
            detections,
            skipped: skipped_reasons,
            angle_source,
            commission,
            commissioning,
            data_quality,
            rows,
            max_abs_residual,
            timeline,
            threshold_bands,
        } = rep;
        let finding = |f| FindingDoc::new(f, rep, sp);
        DiagnoseDoc {
            verdict: *verdict,
            verdict_rule: *verdict_rule,
            verdict_finding: verdict_finding.as_ref().map(finding),
            findings: findings.iter().map(finding).collect(),
            lamps,
            candidates,
            isolation: IsolationDoc::new(isolation, sp),
            signature_candidates,
            first_detection_s: *first_detection_s,
            unbalance: UnbalanceReportDoc::new(unbalance, sp),
            rotor: RotorDoc::new(rotor),
            detections,
            skipped_reasons,
            angle_source: angle_source_name(*angle_source),
            commission: commission.as_ref(),
            commissioning: CommissioningDoc::new(commissioning, sp),
            data_quality,
            rows: *rows,
            max_abs_residual: *max_abs_residual,
            timeline: timeline.iter().map(TimelinePointDoc::new).collect(),
            threshold_bands: *threshold_bands,
            verdict_line: verdict_line(rep, sp),
            judged: judged(rep, sp),
            not_judged: not_judged(rep, sp),
            verdict_withheld_because: withheld_because(rep, sp),
            skipped: skipped_reasons
                .iter()
                .map(|s| skipped(*s).to_string())
                .collect(),
            detections_said: detections.iter().map(|d| detection_line(d, rep)).collect(),
        }
    }
}

/// The winding's negative-sequence analysis as the document carries it (`unbalance`): its
/// typed values and beside them its sentences.
#[derive(Debug, Clone, Serialize)]
pub struct UnbalanceReportDoc<'a> {
    /// The analysis' typed values.
    #[serde(flatten)]
    pub report: &'a UnbalanceReport,
    /// Why the winding names no phase ([`phase_not_judged`]; null where it names one or
    /// none was to be named).
    pub phase_not_judged: Option<String>,
    /// Why the least change it tells was widened ([`widened`]; null where it was not).
    pub least_change_widened: Option<String>,
}

impl<'a> UnbalanceReportDoc<'a> {
    /// The document of `u`, its sentences in `sp`'s words.
    pub fn new(u: &'a UnbalanceReport, sp: &dyn Spelling) -> Self {
        UnbalanceReportDoc {
            report: u,
            phase_not_judged: u.phase_not_judged.as_ref().map(|w| phase_not_judged(w, sp)),
            least_change_widened: u.least_change_widened.as_ref().map(widened),
        }
    }
}

/// What commissioning did as the document carries it (`commissioning`): each of
/// [`CommissioningReport`]'s values under its own key (by reference), each note of an
/// operating point outside the range with its sentence, and the thresholds and the advice
/// in words.
#[derive(Debug, Clone, Serialize)]
pub struct CommissioningDoc<'a> {
    /// `learned`, `incomplete` or `none`.
    pub state: &'a CommissioningOutcome,
    /// The window asked for, `[START, END]` [s], if any.
    pub requested: Option<&'a CommissionWindow>,
    /// The part of the log the run actually spanned [s]; null if it never started.
    pub window: Option<[f64; 2]>,
    /// Seconds of evaluated running learned.
    pub seconds_evaluated: f64,
    /// Seconds of evaluated running the window asked for.
    pub seconds_needed: f64,
    /// Span of the load current while learning, `[min, max]` [A peak].
    pub load_current_a: Option<[f32; 2]>,
    /// Span of the voltage magnitude while learning, `[min, max]` [V peak, phase].
    pub voltage_v: Option<[f32; 2]>,
    /// Which thresholds the lamps used, typed.
    pub thresholds_in_force: &'a Thresholds,
    /// Without commissioning: the first quasi-steady point and the residuals there.
    pub first_quasi_steady: Option<&'a QuasiSteadyPoint>,
    /// Times a lit r2/r3/r4 lamp met an operating point outside the learned range, each
    /// with its note.
    pub outside_range: Vec<RangeNoteDoc<'a>>,
    /// What the user should do, if anything, typed.
    pub advice_given: Option<&'a CommissionAdvice>,
    /// The thresholds in force, in words.
    pub thresholds: String,
    /// The advice in words (null where none is given).
    pub advice: Option<String>,
}

impl<'a> CommissioningDoc<'a> {
    /// The document of `c`, its sentences in `sp`'s words.
    pub fn new(c: &'a CommissioningReport, sp: &dyn Spelling) -> Self {
        let CommissioningReport {
            state,
            requested,
            window,
            seconds_evaluated,
            seconds_needed,
            load_current_a,
            voltage_v,
            thresholds: thresholds_in_force,
            first_quasi_steady,
            outside_range,
            advice: advice_given,
        } = c;
        let (thresholds, advice) = commissioning::report_words(c, sp);
        CommissioningDoc {
            state,
            requested: requested.as_ref(),
            window: *window,
            seconds_evaluated: *seconds_evaluated,
            seconds_needed: *seconds_needed,
            load_current_a: *load_current_a,
            voltage_v: *voltage_v,
            thresholds_in_force,
            first_quasi_steady: first_quasi_steady.as_ref(),
            outside_range: outside_range.iter().map(RangeNoteDoc::new).collect(),
            advice_given: advice_given.as_ref(),
            thresholds,
            advice,
        }
    }
}

/// A lit lamp met outside the commissioned range, as the document carries it
/// (`commissioning.outside_range[]`): its typed values and its note.
#[derive(Debug, Clone, Serialize)]
pub struct RangeNoteDoc<'a> {
    /// The note's typed values (when, what left the range).
    #[serde(flatten)]
    pub range: &'a RangeNote,
    /// The note in words ([`note`]).
    pub note: String,
}

impl<'a> RangeNoteDoc<'a> {
    /// The document of `n`.
    pub fn new(n: &'a RangeNote) -> Self {
        RangeNoteDoc {
            range: n,
            note: note(n),
        }
    }
}

/// A point of the timeline as the document carries it (`timeline[]`): its typed values and,
/// where the operating point left the commissioned range, its note.
#[derive(Debug, Clone, Serialize)]
pub struct TimelinePointDoc<'a> {
    /// The point's typed values.
    #[serde(flatten)]
    pub point: &'a TimelinePoint,
    /// What left the range, in words ([`range_note`]; absent where nothing did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_note: Option<String>,
}

impl<'a> TimelinePointDoc<'a> {
    /// The document of `p`.
    pub fn new(p: &'a TimelinePoint) -> Self {
        TimelinePointDoc {
            point: p,
            range_note: p.range_note.as_deref().map(range_note),
        }
    }
}
