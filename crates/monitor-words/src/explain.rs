//! `explain`'s words, spelled from [`monitor_analysis::explain`]'s typed values: the
//! conclusion (JSON `verdict`), the base parameters refitted, and the report's part of the
//! JSON document, each sentence beside its typed value ([`ExplainReportDoc`]). What reads
//! the one verdict (the headline, how the ranking reads beside the verdict, the whole
//! document) is among the report's words ([`crate::diagnose`]: `explain_headline`,
//! `beside_verdict`, `ExplainDoc`).

use crate::analysis::unbalance;
use crate::Spelling;
use monitor_analysis::explain::{ExplainConclusion, ExplainReport};
use monitor_analysis::refit::BaseRefit;
use monitor_replay::OptionField;

mod doc;
pub use doc::ExplainReportDoc;

/// `explain`'s conclusion in words (JSON `verdict`), naming the numbers that decided, with
/// the notes on the candidates not named because their fits are not physical and on a
/// configured model whose own fit is not.
pub fn verdict(r: &ExplainReport, spell: &dyn Spelling) -> String {
    let mut v = match &r.conclusion {
        ExplainConclusion::Untrusted => {
            return format!(
                "could not judge: the data-quality stage does not trust this log ({}); the ranking below is not a verdict",
                r.data_quality.not_trusted_because.join("; ")
            );
        }
        ExplainConclusion::CurrentOnly => format!(
            "current-only log: only the unbalance analysis ran: {}",
            unbalance(&r.unbalance, spell)
        ),
        ExplainConclusion::NothingToExplain {
            error,
            noise_floor,
            heldback_error,
            heldback_noise_floor,
            margin,
        } => format!(
            "nothing to explain: the model's error {error:.4} is {:.2}x its noise floor {noise_floor:.4} and the held-back error {heldback_error:.4} is {:.2}x its floor {heldback_noise_floor:.4} (both within {margin}x)",
            error / noise_floor,
            heldback_error / heldback_noise_floor,
        ),
        ExplainConclusion::Missing {
            effect,
            explained,
            heldback_before,
            heldback_after,
            effects,
        } => format!(
            "missing effect: {effect} explains {:.0} % of the held-back error ({heldback_before:.4} -> {heldback_after:.4}); {}. Add it with {}",
            100.0 * explained,
            r.ranking
                .iter()
                .find(|c| c.effect == *effect)
                .map_or("", |c| c.summary.as_str()),
            spell.hint(
                OptionField::Effects,
                &effects.iter().map(|e| e.name()).collect::<Vec<_>>().join(",")
            )
        ),
        ExplainConclusion::TooLittle {
            effect,
            explained,
            asks,
        } => format!(
            "unexplained: the best candidate ({effect}) explains only {:.0} % of the held-back error (threshold {:.0} %); the error is not one of the library's effects",
            100.0 * explained,
            100.0 * asks
        ),
        ExplainConclusion::NoneExplains { asks } => format!(
            "unexplained: no plausible effect of the library explains {:.0} % of the held-back error or more; the error is not one of the library's effects",
            100.0 * asks
        ),
        ExplainConclusion::NothingPlausible => {
            "unexplained: no candidate could be fitted with physically plausible values".into()
        }
    };
    if !r.not_named.is_empty() {
        let listed: Vec<String> = r
            .not_named
            .iter()
            .map(|n| {
                format!(
                    "{} would explain {:.0} % but {}",
                    n.effect,
                    100.0 * n.explained,
                    n.because.as_deref().unwrap_or("a value is out of range")
                )
            })
            .collect();
        v.push_str(&format!(
            ". Not plausible, so not ranked and not named: {}",
            listed.join("; ")
        ));
    }
    if !r.model_implausible.is_empty() {
        v.push_str(&format!(
            ". The configured model's own fit is not plausible ({}): the base parameters absorb an error the model cannot follow; if the log has a start or steps, see compare's advice (dynamics effects or {})",
            r.model_implausible.join("; "),
            spell.hint(OptionField::From, "")
        ));
    }
    v
}

/// The base parameters `explain` refitted, for beside the verdict: those refitted by 2 %
/// or more with their values, whether the model was recentred on them and why, and those
/// the log does not identify; empty when there is nothing to say.
pub fn base_refit(b: &BaseRefit) -> String {
    let changed: Vec<String> = b
        .changed()
        .map(|r| {
            format!(
                "{} {} -> {} {} ({:+.0} %)",
                r.parameter,
                monitor_analysis::effects::sig(r.configured),
                monitor_analysis::effects::sig(r.refitted),
                r.unit,
                100.0 * r.change()
            )
        })
        .collect();
    let unidentified: Vec<&str> = b.unidentified().map(|r| r.parameter.key()).collect();
    let mut parts = Vec::new();
    if b.recentred {
        parts.push(format!(
            "the parameter file does not fit this log ({}): the effects were judged against the model refitted to it ({})",
            b.because.join("; "),
            if changed.is_empty() { "no identified change".to_string() } else { changed.join(", ") }
        ));
    } else if !changed.is_empty() {
        parts.push(format!(
            "base parameters refitted to the log: {}",
            changed.join(", ")
        ));
    }
    if !unidentified.is_empty() {
        parts.push(format!(
            "not identified by this log (kept near the file's value): {}",
            unidentified.join(", ")
        ));
    }
    parts.join("; ")
}
