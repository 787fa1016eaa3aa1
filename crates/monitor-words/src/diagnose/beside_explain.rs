//! The one verdict beside `explain`'s ranking: `explain`'s headline (the verdict's line),
//! how the ranking reads beside the verdict's finding ([`beside_verdict`]), and
//! `explain --json`'s whole document, which opens with the verdict ([`ExplainDoc`]). Here,
//! among the report's words, because all three read the verdict's; the ranking's own words
//! are [`crate::explain`]'s.
//!
//! The verdict and the ranking answer two questions. The verdict judges the motor: each
//! analysis of `diagnose` against what a healthy motor does (a fault's residuals, the
//! winding's negative sequence stretch by stretch, the rotor's current sidebands). The
//! ranking explains the error of the paper's model over the whole log: which effect the
//! model is missing. A fault can be plain to its own analysis and a small part of the
//! model's error (a broken bar's sidebands are tens of dB below the supply line); a missing
//! effect (a load step, heating) is no fault. [`beside_verdict`] says which of these holds
//! for the log, so that a ranking never reads as if it contradicted the verdict.

use super::{fault_text, verdict_line, FindingDoc};
use crate::explain::ExplainReportDoc;
use crate::Spelling;
use monitor_analysis::explain::{EffectCandidate, ExplainReport, Standing};
use monitor_analysis::rotor_asymmetry::McsaReport;
use monitor_analysis::EffectId;
use monitor_core::verdict::FaultName;
use monitor_replay::{DiagnoseReport, FindingReport, Verdict};
use serde::Serialize;

/// `explain`'s headline: the verdict `diagnose` gives the same log (`judged`), as its
/// line in `sp`'s words, or where it could give none, why (`judged`'s error, spelled).
pub fn explain_headline(judged: Result<&DiagnoseReport, &str>, sp: &dyn Spelling) -> String {
    match judged {
        Ok(j) => format!("verdict: {}", verdict_line(j, sp)),
        Err(why) => format!("verdict: could not judge: {why}"),
    }
}

/// `explain --json`'s whole document: the verdict `diagnose` gives the same log beside
/// `explain`'s report (flattened: its keys are the document's own) and the motor current
/// signature analysis. The front end (`monitor_api::ExplainDocument`) holds the typed
/// values and the sentences spelled here for them, and lends them to this document.
#[derive(Debug, Clone, Serialize)]
pub struct ExplainDoc<'a> {
    /// The verdict's line ([`explain_headline`]).
    pub headline: &'a str,
    /// That verdict (`fault`, `watching`, `healthy`, `could_not_judge`).
    pub motor_verdict: Verdict,
    /// The finding that verdict rests on with its sentence (null for healthy and nothing
    /// judged).
    pub verdict_finding: Option<&'a FindingDoc<FindingReport>>,
    /// How the effect ranking reads beside the verdict's named fault
    /// ([`beside_verdict`]); null when the verdict names no fault.
    pub beside_verdict: Option<&'a str>,
    /// The report with its sentences.
    #[serde(flatten)]
    pub report: ExplainReportDoc<'a>,
    /// The motor current signature analysis (broken rotor bars).
    pub rotor_asymmetry: &'a McsaReport,
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
            crate::analysis::unbalance(&report.unbalance, spell)
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
            crate::analysis::skip_reason(&s.because, spell)
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
