//! The JSON renderer: every command's `--json` document, printed the one way.

use monitor_api::replay::{FaultCandidate, TimelinePoint};
use monitor_api::sim::SimSummary;
use monitor_studies::bench::{BenchFigures, DetectionLimitCase};
use monitor_studies::demo::DemoRun;
use monitor_studies::fault_signatures::Table1Row;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Prints `v` as one pretty JSON document on stdout ([`crate::cli::out::stdout`]). The document is
/// serialised first, so a failed write is the stdout error `main` recognises.
///
/// # Errors
/// Serialisation or stdout errors.
pub fn print<T: Serialize + ?Sized>(out: &mut dyn std::io::Write, v: &T) -> anyhow::Result<()> {
    let mut doc = serde_json::to_vec_pretty(v)?;
    doc.push(b'\n');
    out.write_all(&doc)?;
    Ok(())
}

/// `demo --json`.
#[derive(Serialize)]
pub struct DemoReport<'a> {
    /// `service` (the default run) or `paper` (`--paper`).
    story: &'static str,
    fault_injected: &'static str,
    change: f64,
    fault_at_s: f64,
    first_detection_s: Option<f64>,
    /// Seconds from the fault to the first red FAULT state, null when none came.
    detected_after_s: Option<f64>,
    /// The isolation's events (load moves and names, with times).
    events: &'a [monitor_api::replay::IsolationEvent],
    verdict: monitor_api::replay::Verdict,
    /// The verdict's line, as `diagnose` prints it.
    verdict_line: String,
    /// The finding the verdict rests on (as `diagnose --json` gives it, with its sentence).
    verdict_finding: serde_json::Value,
    named: &'a [FaultCandidate],
    correct_fault_among_candidates: bool,
    lamps: &'a BTreeMap<String, bool>,
    timeline: &'a [TimelinePoint],
}

/// The `demo --json` document of a run.
pub fn demo(run: &DemoRun) -> DemoReport<'_> {
    let sp = &crate::cli::words::CliWords;
    let doc = monitor_api::words::diagnose::document(&run.report, sp);
    DemoReport {
        story: match run.story {
            monitor_studies::demo::DemoStory::Service { .. } => "service",
            monitor_studies::demo::DemoStory::Paper { .. } => "paper",
        },
        fault_injected: run.fault.name(),
        change: run.change,
        fault_at_s: run.fault_at_s,
        first_detection_s: run.report.first_detection_s,
        detected_after_s: run.detected_after_s(),
        events: &run.report.isolation.events,
        verdict: run.report.verdict,
        verdict_line: monitor_api::words::diagnose::verdict_line(&run.report, sp),
        verdict_finding: doc
            .get("verdict_finding")
            .cloned()
            .unwrap_or(serde_json::Value::Null),
        named: &run.report.candidates,
        correct_fault_among_candidates: run.correct_fault_named(),
        lamps: &run.report.lamps,
        timeline: &run.report.timeline,
    }
}

/// `simulate --json`: the summary with the output path and the wall time.
#[derive(Serialize)]
pub struct SimulateReport<'a> {
    out: String,
    wall_s: f64,
    #[serde(flatten)]
    summary: &'a SimSummary,
}

/// The `simulate --json` document.
pub fn simulate<'a>(out: &Path, wall_s: f64, summary: &'a SimSummary) -> SimulateReport<'a> {
    SimulateReport {
        out: out.display().to_string(),
        wall_s,
        summary,
    }
}

/// `table1`'s result (the JSON document; the text table is drawn from it too).
#[derive(Serialize)]
pub struct Table1Report {
    /// The motor.
    pub motor: String,
    /// The frame's CLI name.
    pub angle_source: String,
    /// The 18 rows.
    pub rows: Vec<Table1Row>,
    /// Rows equal to the paper's.
    pub matches_paper: usize,
}

impl Table1Report {
    /// The report of `rows` measured on `motor` in the frame of `angle`.
    pub fn new(motor: String, angle: monitor_core::AngleSource, rows: Vec<Table1Row>) -> Self {
        let matches_paper = rows.iter().filter(|r| r.signature == r.paper).count();
        Table1Report {
            motor,
            angle_source: monitor_api::replay::angle_source_name(angle).into(),
            rows,
            matches_paper,
        }
    }
}

/// What `convert` did (the JSON document; the text line is drawn from it too).
#[derive(Debug, Serialize)]
pub struct Converted {
    /// The input path.
    pub input: String,
    /// Its format.
    pub input_format: &'static str,
    /// The output path.
    pub output: String,
    /// Its format.
    pub output_format: &'static str,
    /// Rows copied.
    pub rows: u64,
    /// Size of the output [bytes].
    pub output_bytes: u64,
    /// Wall time [s].
    pub wall_s: f64,
}

/// `explain --compare --json`: both documents (each with its sentences spelled at the
/// door, `monitor_api::words`).
#[derive(Serialize)]
pub struct ExplainWithCompare<'a> {
    /// `compare`'s document.
    pub compare: &'a serde_json::Value,
    /// `explain`'s document.
    pub explain: &'a serde_json::Value,
}

/// `bench --json`.
#[derive(Serialize)]
pub struct BenchReport<'a> {
    /// The timings and accuracy.
    #[serde(flatten)]
    pub figures: &'a BenchFigures,
    /// With `--detection`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detection_limits: Option<&'a [DetectionLimitCase]>,
}
