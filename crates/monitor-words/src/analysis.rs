//! The words the model-vs-measurement analyses (`compare`, `explain`, the ladder) share,
//! spelled from [`monitor_analysis`]'s typed values: why an effect was not fitted, why a
//! dynamics effect is not proposed, the unbalance analysis.

use crate::Spelling;
use monitor_analysis::effects::SetupError;
use monitor_analysis::explain::{SkipReason, Skipped};
use monitor_analysis::transients::{NotProposed, SPEED_CHANGE_MIN, STEP_MIN};
use monitor_analysis::unbalance::{CannotJudgeUnbalance, UnbalanceAnalysis, UnbalanceFinding};
use monitor_analysis::EffectId;
use monitor_replay::OptionField;
use serde::Serialize;

/// Effect names, comma separated.
pub fn effect_names(kinds: &[EffectId]) -> String {
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
        NotProposed::NoTransient { tau_s, settling_s } => format!(
            "no start, supply step or fast speed change in the analysed span (voltage and frequency within {:.0} %, the speed within {:.0} % of synchronous over {:.0} ms): its {:.1} ms dynamics have nothing to act on",
            100.0 * STEP_MIN,
            100.0 * SPEED_CHANGE_MIN,
            1000.0 * settling_s,
            1000.0 * tau_s
        ),
    }
}

/// The unbalance analysis in one sentence (JSON `unbalance.summary`); `spell` names the
/// option a healthy baseline is given by.
pub fn unbalance(u: &UnbalanceAnalysis, spell: &dyn Spelling) -> String {
    let baseline = || spell.command_with("diagnose", OptionField::Baseline);
    match &u.finding {
        UnbalanceFinding::CannotJudge { ratio, why } => format!(
            "cannot judge the unbalance (negative sequence {:.1} %): {}",
            100.0 * ratio,
            cannot_judge(why)
        ),
        UnbalanceFinding::Winding {
            ratio,
            voltages,
            phase,
            shorted_fraction,
            deviation,
        } => format!(
            "negative-sequence current {:.1} % of positive sequence{}: phase {} winding differs (shorted turns: at least {:.1} % of its turns, as a bolted short; its current is {:.1} % {} the mean)",
            100.0 * ratio,
            if *voltages { "" } else { " (current-only log: supply assumed balanced, from the parameter file)" },
            phase.name(),
            100.0 * shorted_fraction,
            100.0 * deviation.abs(),
            if *deviation > 0.0 { "above" } else { "below" },
        ),
        UnbalanceFinding::Supply {
            ratio,
            voltage_ratio,
        } => format!(
            "negative-sequence current {:.1} %, caused by the supply's {:.1} % voltage unbalance (no winding suspected)",
            100.0 * ratio,
            100.0 * voltage_ratio
        ),
        UnbalanceFinding::WithinHealthy {
            ratio,
            winding_ratio,
            healthy,
        } => format!(
            "negative-sequence current {:.1} % of positive sequence, the winding's part of it {:.1} % (the supply's taken out): within a healthy machine's own asymmetry of {:.0} %, so no winding is named ({} with a healthy run of this motor judges a smaller change)",
            100.0 * ratio,
            100.0 * winding_ratio,
            100.0 * healthy,
            baseline()
        ),
        UnbalanceFinding::CurrentOnly { ratio, healthy } => format!(
            "negative sequence {:.1} %: cannot judge the phase (a current-only log: below a healthy machine's own asymmetry of {:.0} % a winding cannot be told from the supply's unbalance or the machine's build; {} with a healthy log judges it)",
            100.0 * ratio,
            100.0 * healthy,
            baseline()
        ),
        UnbalanceFinding::Balanced { ratio } => {
            format!("currents balanced (negative sequence {:.2} %)", 100.0 * ratio)
        }
    }
}

/// Why a log cannot carry an unbalance claim (JSON `unbalance.cannot_judge_because`).
pub fn cannot_judge(why: &CannotJudgeUnbalance) -> String {
    match why {
        CannotJudgeUnbalance::FewPeriods { periods, needed } => format!(
            "{periods:.1} supply periods analysed, {needed} needed (give a longer log or window)"
        ),
        CannotJudgeUnbalance::CurrentVaries { variation, max } => format!(
            "the current varies by {:.0} % RMS over the stretch analysed (a start or a load change; {:.0} % at most): its decaying terms look like a negative sequence",
            100.0 * variation,
            100.0 * max
        ),
        CannotJudgeUnbalance::InNoise {
            mean_a,
            noise_a,
            factor,
        } => format!("the current ({mean_a:.3} A) is within {factor}x its noise ({noise_a:.3} A)"),
    }
}

/// The unbalance analysis as its JSON documents carry it (`compare`'s and `explain`'s
/// `unbalance`): the typed analysis, and beside its `finding` the sentences spelled from it.
#[derive(Debug, Clone, Serialize)]
pub struct UnbalanceDoc<'a> {
    /// The analysis' typed values (its ratios, suspect phase, phase currents and finding).
    #[serde(flatten)]
    pub analysis: &'a UnbalanceAnalysis,
    /// The analysis in one sentence ([`unbalance`]).
    pub summary: String,
    /// Why the log cannot carry an unbalance claim ([`cannot_judge`]); `None` (JSON null)
    /// where it was judged.
    pub cannot_judge_because: Option<String>,
}

impl<'a> UnbalanceDoc<'a> {
    /// The document of `u`, its sentences in `spell`'s words.
    pub fn new(u: &'a UnbalanceAnalysis, spell: &dyn Spelling) -> Self {
        UnbalanceDoc {
            analysis: u,
            summary: unbalance(u, spell),
            cannot_judge_because: u.finding.cannot_judge().map(cannot_judge),
        }
    }
}
