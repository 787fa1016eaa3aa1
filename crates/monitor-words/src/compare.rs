//! `compare`'s words, spelled from [`monitor_analysis::compare`]'s typed values: the advice
//! on transients, what could not run, what the log does not identify, why the fit is not
//! plausible, and the JSON document that carries each sentence beside its typed value
//! ([`CompareDoc`], [`document`]).

use crate::analysis::{not_proposed, UnbalanceDoc};
use crate::leftover::LeftoverDoc;
use crate::Spelling;
use monitor_analysis::compare::{CompareReport, CompareSkip, NotIdentifiedBase, NotIdentifiedWhy};
use monitor_analysis::fit::Jacobian;
use monitor_analysis::metrics::{ChannelError, WorstWindow, DIVERGED_CURRENT_RATIO};
use monitor_analysis::transients::{Advice, Cover};
use monitor_analysis::{DataInfo, EffectId, FittedEffect, ParamValue};
use monitor_io::log::quality::DataQuality;
use monitor_replay::OptionField;
use serde::Serialize;
use serde_json::Value;
use std::collections::BTreeMap;

/// `compare --json`'s document: [`CompareDoc`], the report's typed values with the
/// sentences beside them (`advice` beside `advice_values`, `skipped` beside
/// `skipped_reasons`, `not_identified` beside `not_identified_values`,
/// `implausible_because` with a diverged prediction first, the unbalance's `summary` and
/// `cannot_judge_because`, and where the error lives, `leftover.summary`); `spell` names
/// the options the advice refers to. As a JSON value, so that its keys print sorted at
/// every level as the document always has (the workspace's `serde_json` keeps no insertion
/// order).
pub fn document(r: &CompareReport, spell: &dyn Spelling) -> Value {
    serde_json::to_value(CompareDoc::new(r, spell)).unwrap_or_default()
}

/// `compare`'s report as its JSON document carries it: each of [`CompareReport`]'s values
/// under its own key (by reference; a field added to the report is a compile error in
/// [`CompareDoc::new`] until the document carries it), with the sentences spelled from
/// them beside them.
#[derive(Debug, Clone, Serialize)]
pub struct CompareDoc<'a> {
    /// Effects in the model.
    pub effects: &'a [EffectId],
    /// Mean normalised RMS error over the channels.
    pub normalized_rms_error: f64,
    /// Where the model's prediction diverged [s] (absent when it did not).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diverged_at_s: Option<f64>,
    /// The error a perfect model would show (sensor noise) on the same measure.
    pub noise_floor: f64,
    /// Per-channel errors.
    pub channels: &'a [ChannelError],
    /// Where the model fails most.
    pub worst_windows: &'a [WorstWindow],
    /// What to do when the worst windows are transients, typed.
    pub advice_values: &'a [Advice],
    /// The same in words ([`advice`]).
    pub advice: Vec<String>,
    /// Fitted base parameters.
    pub base_parameters: &'a BTreeMap<String, ParamValue>,
    /// Fitted effects.
    pub fitted_effects: &'a [FittedEffect],
    /// False when a fitted value is outside its physical range.
    pub plausible: bool,
    /// Why not, in words ([`implausible`]: a diverged prediction first, then each value
    /// out of range); absent when there is nothing to say.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub implausible_because: Vec<String>,
    /// What the log identifies (null when the base parameters were not refitted).
    pub identifiability: Option<&'a Jacobian>,
    /// The base parameters the log does not identify, typed.
    pub not_identified_values: &'a [NotIdentifiedBase],
    /// The same in words ([`not_identified`]).
    pub not_identified: Vec<String>,
    /// Analyses that could not run, typed.
    pub skipped_reasons: &'a [CompareSkip],
    /// The same in words ([`skipped`]).
    pub skipped: Vec<String>,
    /// The unbalance analysis with its sentences.
    pub unbalance: UnbalanceDoc<'a>,
    /// Rows read, working rate, frame.
    pub data: &'a DataInfo,
    /// What the data-quality stage found and what the analysis did about it.
    pub data_quality: &'a DataQuality,
    /// Where the model's error lives, with its lines (null where the model could not run
    /// or diverged).
    pub leftover: Option<LeftoverDoc<'a>>,
}

impl<'a> CompareDoc<'a> {
    /// The document of `r`, its sentences in `spell`'s words (the options advice refers to).
    pub fn new(r: &'a CompareReport, spell: &dyn Spelling) -> Self {
        let CompareReport {
            effects,
            normalized_rms_error,
            diverged_at_s,
            noise_floor,
            channels,
            worst_windows,
            advice: advice_values,
            base_parameters,
            fitted_effects,
            plausible,
            implausible_because: _,
            identifiability,
            not_identified: not_identified_values,
            skipped: skipped_reasons,
            unbalance,
            data,
            data_quality,
            leftover,
        } = r;
        CompareDoc {
            effects,
            normalized_rms_error: *normalized_rms_error,
            diverged_at_s: *diverged_at_s,
            noise_floor: *noise_floor,
            channels,
            worst_windows,
            advice_values,
            advice: advice_values.iter().map(|a| advice(a, spell)).collect(),
            base_parameters,
            fitted_effects,
            plausible: *plausible,
            // The typed list's values, with a diverged prediction said before them.
            implausible_because: implausible(r, spell),
            identifiability: identifiability.as_ref(),
            not_identified_values,
            not_identified: not_identified_values.iter().map(not_identified).collect(),
            skipped_reasons,
            skipped: skipped_reasons.iter().map(|s| skipped(*s)).collect(),
            unbalance: UnbalanceDoc::new(unbalance, spell),
            data,
            data_quality,
            leftover: leftover.as_ref().map(LeftoverDoc::new),
        }
    }
}

/// What to do about transients among the worst windows, one piece of advice (JSON
/// `advice[]`).
pub fn advice(a: &Advice, spell: &dyn Spelling) -> String {
    match a {
        Advice::Transients { windows, cover: c } => {
            let spans: Vec<String> = windows
                .iter()
                .map(|w| {
                    format!(
                        "{:.2}-{:.2} s: {}",
                        w.t_start_s, w.t_end_s, w.transient.description
                    )
                })
                .collect();
            format!(
                "the worst windows are transients ({}); {}",
                spans.join("; "),
                cover(c, spell)
            )
        }
        Advice::NotProposed { effect, why } => format!("{effect}: {}", not_proposed(why, spell)),
        Advice::LeaveStartOut {
            from_s,
            start_end_s,
        } => format!(
            "or leave the start out: {} (the start ends at about {start_end_s:.2} s, plus five rotor time constants)",
            spell.hint(OptionField::From, &format!("{from_s:.1}"))
        ),
    }
}

/// What the model's dynamics effects do for the transients.
fn cover(c: &Cover, spell: &dyn Spelling) -> String {
    match c {
        Cover::AllInModel => "every dynamics effect is already in the model; what remains there is another effect or a parameter error".to_string(),
        Cover::NoneProposed => "the dynamics effects are not proposed on this span (why below, as explain skips them)".to_string(),
        Cover::Add { proposed, effects } => {
            let names = |k: &[monitor_analysis::EffectId], sep: &str| {
                k.iter().map(|e| e.name()).collect::<Vec<_>>().join(sep)
            };
            format!(
                "the model's dynamics effects cover a start or a supply step: add {} ({})",
                names(proposed, ", "),
                spell.hint(OptionField::Effects, &names(effects, ","))
            )
        }
    }
}

/// What `compare` could not run (JSON `skipped[]`).
pub fn skipped(s: CompareSkip) -> String {
    match s {
        CompareSkip::NoSpeed => "omega_r not compared: the log has no wm_rad_s column (the model still predicts it)".to_string(),
        CompareSkip::NoVoltages => "model prediction (I_qs, omega_r, phase currents) skipped: the log has no voltage columns va_V, vb_V, vc_V, and the model is driven by V_qs; the unbalance analysis ran on the currents".to_string(),
    }
}

/// A base parameter the log does not identify, with why (JSON `not_identified[]`).
pub fn not_identified(n: &NotIdentifiedBase) -> String {
    format!(
        "{} is not identified: {} (a 10 % change moves the error by {:.4}, below {})",
        n.parameter,
        why_not_identified(&n.because),
        n.error_change_per_10_percent,
        n.identified_min
    )
}

/// Why a log does not identify a base parameter.
fn why_not_identified(w: &NotIdentifiedWhy) -> String {
    match w {
        NotIdentifiedWhy::SpeedConstant { span } => format!(
            "the speed never changes in this log (it spans {:.1} % of its largest value)",
            100.0 * span
        ),
        NotIdentifiedWhy::SpeedSlow => "the speed changes too little or too slowly for the inertia torque to matter next to the other torques".into(),
        NotIdentifiedWhy::NoSpeed => "the log has no speed column, and the currents alone hardly depend on it".into(),
        NotIdentifiedWhy::ViscousAtOneSpeed { span, sync_rpm } => format!(
            "the speed never changes in this log (spans {:.1} %, synchronous {sync_rpm:.0} rpm): a viscous torque cannot be told from a constant one",
            100.0 * span
        ),
        NotIdentifiedWhy::ViscousSmall => "the speed-dependent load torque is too small next to the other torques".into(),
        NotIdentifiedWhy::FluxConstant { span } => format!(
            "the flux current hardly changes (spans {:.1} %), so Ls trades off against Ra at one operating point",
            100.0 * span
        ),
        NotIdentifiedWhy::LoadConstant { span } => format!(
            "the load current hardly changes (spans {:.1} %), so Ra trades off against Ls at one operating point",
            100.0 * span
        ),
        NotIdentifiedWhy::Compensated => "the other fitted parameters compensate its change".into(),
    }
}

/// Why `compare`'s fit is not plausible (JSON `implausible_because`): a prediction that
/// diverged first, then each value out of its physical range.
pub fn implausible(r: &CompareReport, spell: &dyn Spelling) -> Vec<String> {
    let diverged = r.diverged_at_s.map(|t| {
        format!(
            "the model diverged at {t:.3} s (its predicted current left {DIVERGED_CURRENT_RATIO}x the largest measured): the error {:.4} measures nothing; add the effects the advice names, or leave the start out ({})",
            r.normalized_rms_error,
            spell.hint(OptionField::From, "")
        )
    });
    diverged
        .into_iter()
        .chain(r.implausible_because.iter().cloned())
        .collect()
}
