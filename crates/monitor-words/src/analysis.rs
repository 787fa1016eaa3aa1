//! The words of the model-vs-measurement analyses (`compare`, `explain`), spelled from
//! [`monitor_analysis`]'s typed values: why an effect was not fitted, why a dynamics effect
//! is not proposed.

use monitor_analysis::effects::SetupError;
use monitor_analysis::explain::{SkipReason, Skipped};
use monitor_analysis::transients::{NotProposed, STEP_MIN};
use monitor_core::EffectKind;
use monitor_replay::{OptionField, Spelling};

/// Effect names, comma separated.
pub fn effect_names(kinds: &[EffectKind]) -> String {
    kinds
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// An effect not fitted on a log, as `name: why` (JSON `skipped[]`); `spell` names the
/// options the advice refers to.
pub fn skipped(s: &Skipped, spell: &dyn Spelling) -> String {
    format!("{}: {}", s.effect, skip_reason(&s.because, spell))
}

/// Why an effect was not fitted.
pub fn skip_reason(r: &SkipReason, spell: &dyn Spelling) -> String {
    match r {
        SkipReason::NotProposed { why } => not_proposed(why, spell),
        SkipReason::Setup { why } => why.to_string(),
        SkipReason::NeedsFirst { effects } => format!(
            "needs {} first, which cannot be fitted on this log",
            effect_names(effects)
        ),
        SkipReason::NoVoltages => {
            format!("{}; see the unbalance analysis", SetupError::NoVoltages)
        }
    }
}

/// Why a dynamics effect is not proposed on a log (`explain`'s `skipped`, `compare`'s
/// advice: the one rule both print); `spell` names the window's options.
pub fn not_proposed(n: &NotProposed, spell: &dyn Spelling) -> String {
    match n {
        NotProposed::Requires(k) => format!("needs {} in the model first", effect_names(k)),
        NotProposed::Unresolved { dt_s, tau_s } => format!(
            "the fit series of this long log ({:.0} Hz) cannot resolve a {:.1} ms time constant; analyse a shorter window with {}/{}",
            1.0 / dt_s,
            1000.0 * tau_s,
            spell.hint(OptionField::From, ""),
            spell.hint(OptionField::To, "")
        ),
        NotProposed::NoTransient { tau_s } => format!(
            "no start or supply step in the analysed span (voltage and frequency within {:.0} %): its {:.1} ms dynamics have nothing to act on",
            100.0 * STEP_MIN,
            1000.0 * tau_s
        ),
    }
}
