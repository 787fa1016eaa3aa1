//! `diagnose` in words: every line a crew reads of one log's report (the text, the HTML
//! report, the JSON document, the HMI, Python) spelled from the report's typed findings, in
//! one place, so that no two lines disagree.
//!
//! [`Story`] spells a report once; [`DiagnoseDoc`] ([`document`]) is `diagnose --json`'s
//! document: the report's typed values (the findings with their `reason`, the isolation's `said`, the
//! winding's `phase_not_judged_reason`, the rotor's `cannot_judge_reason`, ...) and beside
//! each its sentence under the key it has always had (`summary`, `verdict`,
//! `phase_not_judged`, `cannot_judge_because`, ...).

mod beside_explain;
mod commissioning;
mod doc;
mod doc_parts;
mod findings;
mod isolation;
pub mod machine_fit;
mod named;
mod rotor;
mod verdict;
mod winding;

pub use beside_explain::{beside_verdict, explain_headline, ExplainDoc};
pub use commissioning::{
    advice, first_point_misfit, not_learned, not_learned_why, note, quantity, range_note, skipped,
    thresholds,
};
pub use doc::{CommissioningDoc, DiagnoseDoc, RangeNoteDoc, TimelinePointDoc, UnbalanceReportDoc};
pub use doc_parts::{GroupDoc, IsolationDoc, RotorDoc, RotorLoadDoc};
pub use findings::{brief, summary, FindingDoc};
pub use isolation::{channel_dropped, channel_use, event_line, group_reason, moved_note, said};
pub use rotor::{band_words, load_unknown, load_words};
pub use verdict::{
    against_text, fault_text, judged, line as verdict_line, not_judged, pct, why_watched,
    withheld_because,
};
pub use winding::{
    describe_against, line as winding_line, operating_point_source, phase_not_judged, reach,
    sequence_ratio, shorted_turns, summary as winding_summary, suspect, widened, CREW_SHORT,
};

use monitor_replay::{DiagnoseReport, MonitorState, MovedWhy};
use serde_json::Value;

use crate::spelling::Spelling;

/// Every sentence of one report, spelled once from its findings.
#[derive(Debug, Clone, PartialEq)]
pub struct Story {
    /// The verdict's line, after `verdict: `.
    pub verdict_line: String,
    /// What was judged, against what (`residuals against commissioning`).
    pub judged: Vec<String>,
    /// What could not be judged, and why.
    pub not_judged: Vec<String>,
    /// Why the verdict is not a FAULT or healthy (empty for those).
    pub withheld_because: Vec<String>,
    /// Each finding's sentence and brief phrase, in the report's order.
    pub findings: Vec<(String, String)>,
    /// The analyses the log could not feed.
    pub skipped: Vec<String>,
    /// The thresholds in force and the advice on commissioning.
    pub thresholds: String,
    /// See `thresholds`.
    pub advice: Option<String>,
    /// Where a lit lamp met the operating point outside the commissioned range.
    pub outside_range: Vec<String>,
    /// The isolation's verdict.
    pub isolation: String,
    /// Why each group of candidates cannot be separated.
    pub groups: Vec<String>,
    /// The temperature channel's use, for a log with the column.
    pub temperature_channel: Option<String>,
    /// Why the winding names no phase, and a baseline at another operating point.
    pub phase_not_judged: Option<String>,
    /// See `phase_not_judged`.
    pub least_change_widened: Option<String>,
    /// The rotor's one sentence, and why it was not judged.
    pub rotor: String,
    /// See `rotor`.
    pub rotor_cannot: Option<String>,
    /// The rotor band's meaning.
    pub rotor_band: Option<String>,
    /// Why the rotor's load is unknown.
    pub rotor_load_unknown: Option<String>,
    /// The timeline's notes, one per point (`None` where a point has none).
    pub timeline_notes: Vec<Option<String>>,
    /// The events, one line each.
    pub events: Vec<String>,
}

impl Story {
    /// The rotor's one sentence (the report's `rotor.sentence`).
    pub fn rotor_sentence(r: &monitor_replay::RotorReport) -> String {
        rotor::sentence(r)
    }

    /// The report's sentences, in `sp`'s words for the options its advice names.
    pub fn of(rep: &DiagnoseReport, sp: &dyn Spelling) -> Self {
        let (thresholds, advice) = commissioning::report_words(&rep.commissioning, sp);
        Story {
            verdict_line: verdict::line(rep, sp),
            judged: verdict::judged(rep, sp),
            not_judged: verdict::not_judged(rep, sp),
            withheld_because: verdict::withheld_because(rep, sp),
            findings: rep
                .findings
                .iter()
                .map(|f| (summary(f, rep, sp), brief(f, rep, sp)))
                .collect(),
            skipped: rep
                .skipped
                .iter()
                .map(|s| skipped(*s).to_string())
                .collect(),
            thresholds,
            advice,
            outside_range: rep.commissioning.outside_range.iter().map(note).collect(),
            isolation: said(&rep.isolation.said, sp),
            groups: rep
                .isolation
                .groups
                .iter()
                .map(|g| group_reason(&g.reason))
                .collect(),
            temperature_channel: rep
                .isolation
                .temperature
                .temperature_channel
                .as_ref()
                .map(channel_use),
            phase_not_judged: rep
                .unbalance
                .phase_not_judged
                .as_ref()
                .map(|w| phase_not_judged(w, sp)),
            least_change_widened: rep.unbalance.least_change_widened.as_ref().map(widened),
            rotor: rotor::sentence(&rep.rotor),
            rotor_cannot: rotor::cannot_judge_because(&rep.rotor),
            rotor_band: rep.rotor.band.map(|b| band_words(b).to_string()),
            rotor_load_unknown: rep
                .rotor
                .load
                .as_ref()
                .and_then(|l| l.unknown_because.as_ref())
                .map(load_unknown),
            timeline_notes: rep
                .timeline
                .iter()
                .map(|p| p.range_note.as_deref().map(range_note))
                .collect(),
            events: rep.isolation.events.iter().map(event_line).collect(),
        }
    }
}

/// The amber state's note: why the operating point counts as moved.
pub fn moved_why(m: &MovedWhy) -> String {
    match m {
        MovedWhy::OutsideRange { departures } => moved_note(departures),
        MovedWhy::LoadMovedInside => "load moved inside the commissioned range; the stator-voltage equations fit (the torque residuals read it as Bl)".into(),
        MovedWhy::LoadCameBack => {
            "the load came back; the lamps that lit while it had moved are going out".into()
        }
        MovedWhy::BoardSays => {
            "the board says the load or the voltage left the commissioned range".into()
        }
    }
}

/// The note of a panel's state, where it has one (the amber state's).
pub fn state_note(s: &MonitorState) -> Option<String> {
    match s {
        MonitorState::Moved(m) => Some(moved_why(m)),
        _ => None,
    }
}

/// A first detection of the lamps' signature matching as the report's events list it,
/// beside the verdict: the fault the verdict names, or why the verdict does not name it
/// (the lamps' four residuals carry two equations' worth: Table 1 shares a row between
/// faults the isolation's equations tell apart). JSON `detections_said`.
pub fn detection_line(d: &monitor_replay::Detection, rep: &DiagnoseReport) -> String {
    use monitor_core::verdict::FaultName;
    let head = format!(
        "{:.2} s  the lamps' signature first matched {}",
        d.t_s,
        d.fault.name()
    );
    let named = rep.verdict_finding.as_ref().and_then(|f| f.named());
    match named.map(|n| n.fault) {
        Some(FaultName::Table1(f)) if f == d.fault => head,
        Some(_) => format!(
            "{head}; a candidate dropped: the lamps alone share it with other faults, the verdict names {}",
            named.map_or(String::new(), fault_text)
        ),
        None => format!("{head}; a candidate dropped: the verdict names no fault"),
    }
}

/// `diagnose --json`'s document of `rep`: [`DiagnoseDoc`], its typed values and beside
/// each its sentence under the key the document has always had, in `sp`'s words. As a JSON
/// value, so that its keys print sorted at every level as the document always has (the
/// workspace's `serde_json` keeps no insertion order).
pub fn document(rep: &DiagnoseReport, sp: &dyn Spelling) -> Value {
    serde_json::to_value(DiagnoseDoc::new(rep, sp)).unwrap_or_default()
}

#[cfg(test)]
mod tests;
