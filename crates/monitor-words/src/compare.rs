//! `compare`'s words, spelled from [`monitor_analysis::compare`]'s typed values: the advice
//! on transients, what could not run, what the log does not identify, why the fit is not
//! plausible, and the JSON document that carries each sentence beside its typed value
//! ([`document`]).

use crate::analysis::{not_proposed, unbalance_into};
use crate::Spelling;
use monitor_analysis::compare::{CompareReport, CompareSkip, NotIdentifiedBase, NotIdentifiedWhy};
use monitor_analysis::metrics::DIVERGED_CURRENT_RATIO;
use monitor_analysis::transients::{Advice, Cover};
use monitor_replay::OptionField;
use serde_json::Value;

/// `compare --json`'s document: the report's typed values with the sentences beside them
/// (`advice` beside `advice_values`, `skipped` beside `skipped_reasons`, `not_identified`
/// beside `not_identified_values`, `implausible_because` with a diverged prediction first,
/// the unbalance's `summary` and `cannot_judge_because`, and where the error lives,
/// `leftover.summary`); `spell` names the options the advice refers to.
pub fn document(r: &CompareReport, spell: &dyn Spelling) -> Value {
    let mut doc = serde_json::to_value(r).unwrap_or_default();
    let Some(obj) = doc.as_object_mut() else {
        return doc;
    };
    let strings = |v: Vec<String>| Value::from(v);
    obj.insert(
        "advice".into(),
        strings(r.advice.iter().map(|a| advice(a, spell)).collect()),
    );
    obj.insert(
        "skipped".into(),
        strings(r.skipped.iter().map(|s| skipped(*s)).collect()),
    );
    obj.insert(
        "not_identified".into(),
        strings(r.not_identified.iter().map(not_identified).collect()),
    );
    let why = implausible(r, spell);
    if !why.is_empty() {
        obj.insert("implausible_because".into(), strings(why));
    }
    if let Some(u) = obj.get_mut("unbalance") {
        unbalance_into(u, &r.unbalance, spell);
    }
    if let (Some(v), Some(l)) = (obj.get_mut("leftover"), &r.leftover) {
        crate::leftover::into_json(v, l);
    }
    doc
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
