//! `explain`'s document: the one verdict's headline, `explain`'s own answer (the ranking of
//! the library's effects by the model error they remove), how the two relate
//! ([`beside_verdict`], which says why a ranking does not contradict the verdict), and the
//! motor current signature analysis. Every sentence is spelled at the door
//! ([`monitor_words::explain`], [`monitor_words::diagnose`]); this module only gathers the
//! values.

use super::{
    diagnose, load_analysis, load_params_for, AnalysisRequest, ApiError, DiagnoseRequest,
    LogSource, ParamsSource,
};
use monitor_analysis::explain::ExplainReport;
use monitor_analysis::rotor_asymmetry::{self, McsaReport};
use monitor_analysis::Analysis;
use monitor_analysis::EffectId;
use monitor_replay::{DiagnoseReport, FindingReport, Verdict};
use monitor_words::diagnose::{explain_headline, ExplainDoc, FindingDoc};
use monitor_words::explain::ExplainReportDoc;
use monitor_words::Spelling;

pub use monitor_words::diagnose::beside_verdict;

/// `explain`'s document: the one verdict's headline, the report, how the ranking relates to
/// the verdict's finding, and the motor current signature analysis; its JSON is
/// [`ExplainDocument::json`] (the door's [`ExplainDoc`], each sentence beside its value).
#[derive(Debug)]
pub struct ExplainDocument {
    /// The one verdict `diagnose` gives on the same log and parameter file, as its line
    /// (`explain` opens with it: the model's discrepancy is read beside what the motor was
    /// judged to have).
    pub headline: String,
    /// That verdict (`fault`, `watching`, `healthy`, `could_not_judge`).
    pub motor_verdict: Verdict,
    /// The finding that verdict rests on, with its sentence (`None`, JSON null, for
    /// healthy and nothing judged).
    pub verdict_finding: Option<FindingDoc<FindingReport>>,
    /// How the effect ranking reads beside the verdict's named fault ([`beside_verdict`]);
    /// null when the verdict names no fault.
    pub beside_verdict: Option<String>,
    /// The ranking and its verdict.
    pub report: ExplainReport,
    /// The motor current signature analysis (broken rotor bars).
    pub rotor_asymmetry: McsaReport,
}

/// The motor current signature analysis beside `explain`'s ranking: the fitted
/// `rotor_asymmetry`'s delta (where it was fitted), and the rotor's bar count from the one
/// place that gives it ([`rotor_asymmetry::rotor_bar_count`]: `--rotor-bars`, or the
/// parameter file).
pub fn mcsa_beside(a: &Analysis, report: &ExplainReport, rotor_bars: Option<u32>) -> McsaReport {
    let delta = report
        .ranking
        .iter()
        .find(|r| r.effect == EffectId::ROTOR_ASYMMETRY)
        .and_then(|r| r.parameters.get("delta"))
        .map(|p| p.value);
    rotor_asymmetry::mcsa(
        &a.data,
        a.constants.np,
        rotor_asymmetry::rotor_bar_count(&a.params, rotor_bars),
        delta,
    )
}

/// `explain --json`'s document, its sentences in the words of `spell` (the front end's).
///
/// # Errors
/// As [`super::compare`].
pub fn explain(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    req: &AnalysisRequest,
    sp: &dyn Spelling,
) -> Result<serde_json::Value, ApiError> {
    let log = &log.into();
    // The parameter file read once for both calls.
    let (params, columns) = load_params_for(params, log)?;
    let read = ParamsSource::Read {
        params: &params,
        columns: &columns,
    };
    let a = load_analysis(read, log, req, &mut |_| {})?;
    let judged = verdict_for_explain(read, log, req.group.clone());
    let out = a.explain(&req.options(&a)?, &|_| {})?;
    let rotor_asymmetry = mcsa_beside(&a, &out.report, req.rotor_bars);
    let doc = ExplainDocument::new(judged.as_ref(), out.report, rotor_asymmetry, sp);
    Ok(doc.json(sp))
}

/// `explain --ladder --json`'s document ([`monitor_analysis::explain::ladder`]): the
/// ladder's steps from the configured model to the noise floor, and why it stopped, each
/// sentence spelled at the door beside its typed reason ([`monitor_words::ladder::document`]).
///
/// # Errors
/// As [`super::compare`].
pub fn ladder(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    req: &AnalysisRequest,
    spell: &dyn Spelling,
) -> Result<serde_json::Value, ApiError> {
    let log = &log.into();
    let a = load_analysis(params, log, req, &mut |_| {})?;
    let report = a.ladder(&req.options(&a)?, &|_| {})?;
    Ok(monitor_words::ladder::document(&report, spell))
}

/// The verdict `diagnose` gives `log` with its defaults (no commissioning, no baseline; the
/// TDMS `group`), which `explain` opens with; the error where `diagnose` cannot judge the
/// log at all.
///
/// # Errors
/// As [`super::diagnose`].
pub fn verdict_for_explain(
    params: ParamsSource<'_>,
    log: impl Into<LogSource>,
    group: Option<String>,
) -> Result<DiagnoseReport, ApiError> {
    let req = DiagnoseRequest {
        group,
        ..DiagnoseRequest::default()
    };
    diagnose(params, log, &req, &mut |_| {}).map(|d| d.report)
}

impl ExplainDocument {
    /// The document of an `explain` report beside the verdict `diagnose` gave the same log
    /// (`judged`; its error where it gave none), its sentences spelled at the door in `sp`'s
    /// words (the headline, the finding's sentence, [`beside_verdict`]).
    pub fn new(
        judged: Result<&DiagnoseReport, &ApiError>,
        report: ExplainReport,
        rotor_asymmetry: McsaReport,
        sp: &dyn Spelling,
    ) -> Self {
        let (headline, motor_verdict, verdict_finding) = match judged {
            Ok(j) => (
                explain_headline(Ok(j), sp),
                j.verdict,
                j.verdict_finding
                    .as_ref()
                    .map(|f| FindingDoc::new(f.clone(), j, sp)),
            ),
            Err(e) => (
                explain_headline(Err(&e.spelled(sp)), sp),
                Verdict::CouldNotJudge,
                None,
            ),
        };
        let beside = verdict_finding
            .as_ref()
            .and_then(|f| beside_verdict(&f.finding, &report, &rotor_asymmetry, sp));
        ExplainDocument {
            headline,
            motor_verdict,
            verdict_finding,
            beside_verdict: beside,
            report,
            rotor_asymmetry,
        }
    }

    /// The JSON document: the door's [`ExplainDoc`] of these values, the report's sentences
    /// spelled beside its typed values ([`ExplainReportDoc`]) in the words of `sp`. As a
    /// JSON value, so that its keys print sorted at every level as the document always has
    /// (the workspace's `serde_json` keeps no insertion order).
    pub fn json(&self, sp: &dyn Spelling) -> serde_json::Value {
        let doc = ExplainDoc {
            headline: &self.headline,
            motor_verdict: self.motor_verdict,
            verdict_finding: self.verdict_finding.as_ref(),
            beside_verdict: self.beside_verdict.as_deref(),
            report: ExplainReportDoc::new(&self.report, sp),
            rotor_asymmetry: &self.rotor_asymmetry,
        };
        serde_json::to_value(doc).unwrap_or_default()
    }
}
