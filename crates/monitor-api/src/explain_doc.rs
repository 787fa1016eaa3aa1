//! `explain`'s document: the one verdict's headline, `explain`'s own answer (the ranking of
//! the library's effects by the model error they remove), how the two relate, and the
//! motor current signature analysis.
//!
//! The verdict and the ranking answer two questions. The verdict judges the motor: each
//! analysis of `diagnose` against what a healthy motor does (a fault's residuals, the
//! winding's negative sequence stretch by stretch, the rotor's current sidebands). The
//! ranking explains the error of the paper's model over the whole log: which effect the
//! model is missing. A fault can be plain to its own analysis and a small part of the
//! model's error (a broken bar's sidebands are tens of dB below the supply line); a missing
//! effect (a load step, heating) is no fault. [`beside_verdict`] says which of these holds
//! for the log, so that a ranking never reads as if it contradicted the verdict.

use super::{
    diagnose, load_analysis, load_params_for, AnalysisRequest, ApiError, DiagnoseRequest,
    LogSource, ParamsSource,
};
use monitor_analysis::explain::{EffectCandidate, ExplainReport, Standing};
use monitor_analysis::rotor_asymmetry::{self, McsaReport};
use monitor_analysis::Analysis;
use monitor_analysis::EffectId;
use monitor_core::verdict::FaultName;
use monitor_replay::{DiagnoseReport, FindingReport, Verdict};
use monitor_words::diagnose::fault_text;
use monitor_words::Spelling;

/// `explain`'s JSON document: the one verdict's headline, the report, how the ranking
/// relates to the verdict's finding, and the motor current signature analysis.
#[derive(Debug, serde::Serialize)]
pub struct ExplainDocument {
    /// The one verdict `diagnose` gives on the same log and parameter file, as its line
    /// (`explain` opens with it: the model's discrepancy is read beside what the motor was
    /// judged to have).
    pub headline: String,
    /// That verdict (`fault`, `watching`, `healthy`, `could_not_judge`).
    pub motor_verdict: Verdict,
    /// The finding that verdict rests on (null for healthy and nothing judged).
    pub verdict_finding: Option<FindingReport>,
    /// How the effect ranking reads beside the verdict's named fault ([`beside_verdict`]);
    /// null when the verdict names no fault.
    pub beside_verdict: Option<String>,
    /// The ranking and its verdict.
    #[serde(flatten)]
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
    Ok(doc.json(judged.as_ref().ok(), sp))
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
    /// The document as JSON, the report's sentences spelled at the door beside its typed
    /// values ([`monitor_words::explain::report_into`]) in the words of `spell`.
    /// The document of an `explain` report beside the verdict `diagnose` gave the same log
    /// (`judged`; its error where it gave none), its headline in `sp`'s words.
    pub fn new(
        judged: Result<&DiagnoseReport, &ApiError>,
        report: ExplainReport,
        rotor_asymmetry: McsaReport,
        sp: &dyn Spelling,
    ) -> Self {
        let (headline, motor_verdict, verdict_finding) = match judged {
            Ok(j) => (
                format!("verdict: {}", monitor_words::diagnose::verdict_line(j, sp)),
                j.verdict,
                j.verdict_finding.clone(),
            ),
            Err(e) => (
                format!("verdict: could not judge: {}", e.spelled(sp)),
                Verdict::CouldNotJudge,
                None,
            ),
        };
        let beside = verdict_finding
            .as_ref()
            .and_then(|f| beside_verdict(f, &report, &rotor_asymmetry, sp));
        ExplainDocument {
            headline,
            motor_verdict,
            verdict_finding,
            beside_verdict: beside,
            report,
            rotor_asymmetry,
        }
    }
}

impl ExplainDocument {
    /// The JSON document, the verdict's finding with its sentence (`judged`: the report it
    /// comes from).
    pub fn json(&self, judged: Option<&DiagnoseReport>, sp: &dyn Spelling) -> serde_json::Value {
        let mut v = serde_json::to_value(self).unwrap_or_default();
        monitor_words::explain::report_into(&mut v, &self.report, sp);
        if let (Some(j), Some(f), Some(vf)) = (
            judged,
            self.verdict_finding.as_ref(),
            v.get_mut("verdict_finding").and_then(|x| x.as_object_mut()),
        ) {
            vf.insert(
                "summary".into(),
                monitor_words::diagnose::summary(f, j, sp).into(),
            );
        }
        v
    }
}

/// How the effect ranking of `report` reads beside the verdict's `finding`, when it names
/// a fault (`None` otherwise): the library effect that models the named fault (shorted
/// turns: `phase_asymmetry`; broken bars: `rotor_asymmetry`) and where the ranking puts it,
/// what the verdict judged from, and why a ranking that does not name the fault does not
/// contradict it (module doc). A Table 1 fault (a parameter's or a sensor's change) is
/// absorbed by the base parameters `explain` refits before it ranks, so it shows in the
/// refit, not in the ranking. On a log without voltages the model does not run: the sentence
/// says so and points at the unbalance line.
pub fn beside_verdict(
    finding: &FindingReport,
    report: &ExplainReport,
    mcsa: &McsaReport,
    spell: &dyn Spelling,
) -> Option<String> {
    let named = finding.named()?;
    let fault = fault_text(named);
    let effect = match named.fault {
        FaultName::BrokenBars => EffectId::ROTOR_ASYMMETRY,
        FaultName::ShortedTurns => EffectId::PHASE_ASYMMETRY,
        FaultName::Table1(_) | FaultName::Friction => {
            return Some(format!(
                "beside the verdict ({fault}): a change of the machine's parameters or of a sensor, judged from the paper's residuals; explain refits the model's base parameters (Ra, Ls, B+Bl, J) to the log before it ranks effects, so such a change shows in the refit (below), and the ranking says what the refitted model still misses: the two do not contradict each other"
            ));
        }
    };
    if !report.baseline_normalized_rms_error.is_finite() {
        return Some(format!(
            "beside the verdict ({fault}): the model could not run on this log (no voltages), so explain ranks no effect; the verdict's analysis judged the motor, and the unbalance line below is the whole log's average ({})",
            monitor_words::analysis::unbalance(&report.unbalance, spell)
        ));
    }
    let place = place_of(effect, report, spell);
    if place.agrees {
        return Some(format!(
            "beside the verdict ({fault}): the ranking agrees: {}",
            place.words
        ));
    }
    let (judged, part) = if effect == EffectId::ROTOR_ASYMMETRY {
        (
            "the current spectrum's (1 - 2s) f sideband",
            sideband_share(mcsa),
        )
    } else {
        (
            "the negative-sequence current, stretch by stretch",
            format!(
                "the negative sequence is {:.1} % of the current on average{}",
                100.0 * report.unbalance.negative_sequence_ratio,
                match (&report.unbalance.suspect_phase, named.phase) {
                    (Some(p), Some(q)) if p.as_str() == q.name() => String::new(),
                    (Some(p), _) => format!(" (the unbalance line's average points at phase {p})"),
                    (None, _) => " (the unbalance line's average names no phase)".into(),
                }
            ),
        )
    };
    Some(format!(
        "beside the verdict ({fault}): the verdict judges the motor from {judged}; the ranking explains the paper's model's error over the whole log, where {part}, and {}. The two answer different questions and do not contradict each other: a missing effect is no fault, and a fault need not be the model's largest error",
        place.words
    ))
}

/// Where the ranking puts `effect`: in words, and whether that agrees with a verdict naming
/// its fault (ranked as a candidate).
struct Place {
    words: String,
    agrees: bool,
}

/// [`Place`] of `effect` in `report`: ranked, without effect, not plausible, skipped, in the
/// model already, or not fitted (a log without voltages).
fn place_of(effect: EffectId, report: &ExplainReport, spell: &dyn Spelling) -> Place {
    let said = |words: String| Place {
        words,
        agrees: false,
    };
    if report.effects.contains(&effect) {
        return said(format!("{effect} is in the model already"));
    }
    if let Some(c) = report.ranking.iter().find(|c| c.effect == effect) {
        return placed(c);
    }
    match report.skipped.iter().find(|s| s.effect == effect) {
        Some(s) => said(format!(
            "{effect} is not fitted on this log ({})",
            monitor_words::analysis::skip_reason(&s.because, spell)
        )),
        None => said(format!("{effect} was not fitted")),
    }
}

/// [`Place`] of a fitted candidate `c`.
fn placed(c: &EffectCandidate) -> Place {
    let (whole, held) = (
        100.0 * c.whole_log_explained_fraction,
        100.0 * c.explained_fraction,
    );
    match (c.standing, c.rank) {
        (Standing::Candidate, Some(k)) => Place {
            words: format!(
                "{} is rank {k}, explaining {whole:.0} % / {held:.0} % of the model's error beyond the noise floor (whole log / held-back windows)",
                c.effect
            ),
            agrees: true,
        },
        (Standing::NotPlausible, _) => Place {
            words: format!(
                "{}'s fit there is not physical ({})",
                c.effect,
                c.implausible_because
                    .first()
                    .map(String::as_str)
                    .unwrap_or("a value out of range")
            ),
            agrees: false,
        },
        _ => Place {
            words: format!(
                "{} explains {whole:.0} % / {held:.0} % of the error beyond the noise floor (whole log / held-back windows; no effect on the ranking)",
                c.effect
            ),
            agrees: false,
        },
    }
}

/// The (1 - 2s) f sideband's share of the current, in words, where the spectrum was judged.
fn sideband_share(mcsa: &McsaReport) -> String {
    match mcsa.lower_sideband_db {
        Some(db) => format!(
            "a sideband {:.1} dB below the supply line is {:.2} % of the current",
            -db,
            100.0 * 10f64.powf(db / 20.0)
        ),
        None => "a broken bar's sidebands are a small part of the current (tens of dB below the supply line)".to_string(),
    }
}
