//! The ladder's words (`explain --ladder`), spelled from
//! [`monitor_analysis::explain::ladder`]'s typed values: why it stopped, why a candidate was
//! not kept, each step, the base changes, what was found, and the JSON document that
//! carries each sentence beside the typed reason it is spelled from ([`LadderDoc`],
//! [`document`]).

use crate::analysis::effect_names;
use crate::Spelling;
use monitor_analysis::effects::sig;
use monitor_analysis::explain::ladder::{
    Alike, AsOne, FinalFit, LadderReport, LadderStep, Refusal, StopReason, TestRule, Tried,
    WhatIsLeft, WhyNotPhysical, BAND_PERIODS, FLOOR_BAND,
};
use monitor_analysis::EffectId;
use serde_json::Value;

mod base;
mod doc;
use base::apart;
pub use base::{base_change, base_changes};
pub use doc::{LadderDoc, StepDoc, TriedDoc};

/// `explain --ladder --json`'s document: [`LadderDoc`], the report's typed values with
/// the sentences a crew reads beside them (`summary`, `stopped_because` beside
/// `stopped_reason`, `skipped` beside `skipped_reasons`, `test` beside `test_rule`, each
/// step's `summary`, each candidate's `because` beside its `refusal`, and where the error
/// lives when the ladder stops above the floor, `leftover.summary`); `spell` names the
/// options advice refers to. As a JSON value, so that its keys print sorted at every level
/// as the document always has (the workspace's `serde_json` keeps no insertion order).
pub fn document(r: &LadderReport, spell: &dyn Spelling) -> Value {
    serde_json::to_value(LadderDoc::new(r, spell)).unwrap_or_default()
}

/// Why the ladder stopped, naming the numbers that decided (JSON `stopped_because`).
pub fn stopped(r: &LadderReport) -> String {
    match &r.stopped_reason {
        StopReason::NoiseFloor {
            error,
            noise_floor,
            heldback_error,
            heldback_noise_floor,
            band,
        } => format!(
            "at the noise floor: the whole-log error {} is {:.2}x its noise floor {} and the held-back error {} is {:.2}x its floor {} (both within {band:.2}x): nothing is left to explain",
            sig(*error),
            error / noise_floor,
            sig(*noise_floor),
            sig(*heldback_error),
            heldback_error / heldback_noise_floor,
            sig(*heldback_noise_floor)
        ),
        StopReason::NothingHelps {
            error,
            noise_floor,
            heldback_error,
            heldback_noise_floor,
            best,
            left,
        } => format!(
            "no plausible candidate passes the step's test: the whole-log error {} is {:.2}x its noise floor and the held-back error {} is {:.2}x its floor; the best candidate was {}. {}",
            sig(*error),
            error / noise_floor,
            sig(*heldback_error),
            heldback_error / heldback_noise_floor,
            best.as_ref().map_or_else(
                || "no candidate could be fitted".to_string(),
                |t| format!("{} ({})", tried_name(t), refusal(&t.refusal))
            ),
            what_is_left(left)
        ),
        StopReason::LibraryExhausted => {
            "no effect of the library is left to add on this log".to_string()
        }
        StopReason::NoVoltages => "the log has no voltages: the model cannot run, so no effect can be added (the unbalance analysis needs only the currents: explain without the ladder gives it)".to_string(),
        StopReason::Untrusted => format!(
            "could not judge: the data-quality stage does not trust the log ({})",
            r.data_quality.not_trusted_because.join("; ")
        ),
    }
}

/// What the error the ladder could not explain further is, as far as it can tell.
fn what_is_left(left: &WhatIsLeft) -> String {
    match left {
        WhatIsLeft::BeyondLibrary => {
            "What is left is beyond the effect library (or below what the log can show)".into()
        }
        WhatIsLeft::NotTried { effects } => format!(
            "What is left is not explained by the effects that could be fitted on this log; not tried: {}",
            effect_names(effects)
        ),
        WhatIsLeft::OnTheFileBase => {
            "What is left is not explained by the effects of the library on the file's base parameters"
                .into()
        }
    }
}

/// Why a candidate was not kept (JSON `last_round[].because`).
pub fn refusal(r: &Refusal) -> String {
    match r {
        Refusal::Diverged => {
            "the model with it could not be run through the log (it diverged)".into()
        }
        Refusal::NotPhysical { why } => format!(
            "not physical: {}",
            why.iter().map(not_physical).collect::<Vec<_>>().join("; ")
        ),
        Refusal::BelowTest { share, asks } => format!(
            "removes {:.0} % of the held-back error beyond the noise floor (the test asks {:.0} %)",
            100.0 * share,
            100.0 * asks
        ),
        Refusal::DivergedOnWholeLog => {
            "the model with it could not be run through the whole log (it diverged)".into()
        }
        Refusal::WholeLogRises { from, to } => format!(
            "the whole-log error would rise {} -> {} (held-back windows only improved)",
            sig(*from),
            sig(*to)
        ),
        Refusal::BetterKept => "a better candidate was kept".into(),
    }
}

/// Why a fitted step is not physical, one value.
pub fn not_physical(w: &WhyNotPhysical) -> String {
    match w {
        WhyNotPhysical::Effect { effect, why } => format!("{effect}: {why}"),
        WhyNotPhysical::AtBound {
            effect,
            parameter,
            value,
            unit,
            low,
            high,
        } => format!(
            "{effect}: {parameter} = {} is at the bound of its fit ({}..{}), not a value the log shows",
            monitor_analysis::effects::with_unit(&sig(*value), unit),
            sig(*low),
            sig(*high)
        ),
        WhyNotPhysical::Contradicted { why, .. } | WhyNotPhysical::Base { why } => why.clone(),
        WhyNotPhysical::BaseFactor {
            parameter,
            factor,
            low,
            high,
            basis,
        } => format!(
            "base: {parameter} x{} is outside the physical range x{}..x{} ({basis})",
            sig(*factor),
            sig(*low),
            sig(*high)
        ),
    }
}

/// A tried candidate's name: its effects joined with `+`, or `the base parameters
/// refitted`.
pub fn tried_name(t: &Tried) -> String {
    // An effect fitted with the base parameters refitted beside it is named by its effects.
    if t.added.is_empty() {
        return "the base parameters refitted".to_string();
    }
    t.added
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join("+")
}

/// The rule each step passed and the ladder stops by (JSON `test`).
pub fn test(rule: &TestRule) -> String {
    format!(
        "a step is kept when it removes at least {:.0} % of the held-back error beyond the noise floor (each parameter costing {:.0} % of the held-back error) and lowers the whole-log error; the ladder stops within {:.2}x the noise floor on the whole log and the held-back part{}",
        100.0 * rule.step_min,
        100.0 * rule.param_penalty,
        rule.floor_band,
        if rule.floor_band < FLOOR_BAND - 1e-9 {
            format!(
                " ({FLOOR_BAND:.2}x on a log of up to {BAND_PERIODS:.0} supply periods; this log's periods show a smaller model error)"
            )
        } else {
            String::new()
        }
    )
}

/// One step in words (JSON `ladder[].summary`): the base rung's changes, or the added
/// effects' values (and the base refitted beside them where it changed); then each
/// effect the step removed and why.
pub fn step(s: &LadderStep) -> String {
    let mut out = if s.effect.is_none() {
        base_changes(&s.base)
    } else if s.base.is_empty() {
        s.described.join("; ")
    } else {
        format!(
            "{}; on the refitted base: {}",
            s.described.join("; "),
            base_changes(&s.base)
        )
    };
    for d in &s.dropped_because {
        out = format!(
            "{out}; {} removed: the model without it loses {:.0} % of the held-back error beyond the noise floor (a step must earn {:.0} %), this step explains what it stood in for",
            d.effect,
            100.0 * d.loses.max(0.0),
            100.0 * d.asks
        );
    }
    out
}

/// What the ladder found, then why it stopped (JSON `summary`): the base changes and the
/// effects the steps added, with their sizes, where the chosen model ends on the whole log;
/// where the ladder could not start, only why.
pub fn summary(r: &LadderReport) -> String {
    if matches!(
        r.stopped_reason,
        StopReason::NoVoltages | StopReason::Untrusted
    ) {
        return stopped(r);
    }
    let fin = r.final_fit.as_ref();
    let found = match fin {
        Some(f) => found(r, f),
        None => r
            .ladder
            .iter()
            .filter_map(|s| s.effect.map(|e| e.name().to_string()))
            .collect(),
    };
    let dropped: Vec<String> = r
        .ladder
        .iter()
        .flat_map(|s| s.dropped.iter().map(|k| k.name().to_string()))
        .collect();
    let mut out = if found.is_empty() {
        "found: nothing the model lacks on this log".to_string()
    } else {
        format!("found: {}", found.join("; "))
    };
    if !dropped.is_empty() {
        out.push_str(&format!(
            " (removed on the way: {}, explained better by a later step)",
            dropped.join(", ")
        ));
    }
    if let Some(f) = fin {
        out.push_str(&format!(
            ". The chosen model refitted on the whole log: error {} = {:.2}x its noise floor {}, {:.1}x below the start",
            sig(f.error),
            f.ratio_to_floor,
            sig(f.noise_floor),
            f.below_start
        ));
    }
    out.push_str(&format!(". Stopped: {}", stopped(r)));
    out
}

/// What the chosen model refitted on the whole log (`f`) holds that the start did not: the
/// base changes, the machine's own dynamics, each other effect with the values of the step
/// that added it ([`as_stepped`]; the whole log's refit's where no step describes it).
fn found(r: &LadderReport, f: &FinalFit) -> Vec<String> {
    let mut found = Vec::new();
    if f.base.iter().any(|c| c.changed || c.questioned()) {
        let beside = if f.far_from_floor && f.base.iter().any(|c| c.changed) {
            format!(
                " (read beside a model that ends at {:.2}x its noise floor: a law of the model that \
                 is not the machine's can move them)",
                f.ratio_to_floor
            )
        } else {
            String::new()
        };
        found.push(format!(
            "base parameters{beside}: {}",
            base_changes(&f.base)
        ));
    }
    let dynamics: Vec<&str> = f
        .fitted
        .iter()
        .filter(|e| e.effect.is_dynamics())
        .map(|e| e.effect.name())
        .filter(|k| !r.start.effects.iter().any(|s| s.name() == *k))
        .collect();
    if !dynamics.is_empty() {
        found.push(format!(
            "the machine's own dynamics ({})",
            dynamics.join(", ")
        ));
    }
    let as_one = |id| f.as_one.iter().any(|a| a.effects.contains(&id));
    for e in f
        .fitted
        .iter()
        .filter(|e| !e.effect.is_dynamics() && !r.start.effects.contains(&e.effect))
        .filter(|e| !as_one(e.effect))
    {
        found.push(format!(
            "{}: {}",
            e.effect,
            as_stepped(r, e.effect).unwrap_or(&e.summary)
        ));
        found.extend(f.alike.iter().filter(|a| a.effect == e.effect).map(alike));
    }
    found.extend(f.as_one.iter().map(one_load));
    found
}

/// Effect `id`'s values as the last step that added it describes them (`None` where no
/// step describes it one by one). The found line states these: the step's values are the
/// ones the held-back test judged, and its list reads the same; the final refit frees the
/// base parameters beside every value, where an effect can trade its size with them (a
/// load torque of -17.75 N m beside its step's +2.36 N m), and stays in the JSON's
/// `final_fit.fitted`.
fn as_stepped(r: &LadderReport, id: EffectId) -> Option<&str> {
    r.ladder.iter().rev().find_map(|s| {
        let i = s.added.iter().position(|a| *a == id)?;
        (s.described.len() == s.added.len()).then(|| s.described[i].as_str())
    })
}

/// `load_torque and coulomb_friction fit this log alike (1.01x and 1.02x its noise floor):
/// ...`: a confusable effect of the library fits as well in the place of one of the chosen
/// model's ([`Alike`]), with why and what would tell them apart.
pub fn alike(a: &Alike) -> String {
    format!(
        "{} and {} fit this log alike ({:.2}x and {:.2}x its noise floor): {}",
        a.effect,
        a.other,
        a.ratio,
        a.ratio_other,
        apart(a.apart_by)
    )
}

/// `windage and load_torque are one load on this log, not two: ...`: two load laws of the
/// chosen model that one law of speed fits as well ([`AsOne`]), with that law.
pub fn one_load(a: &AsOne) -> String {
    format!(
        "{} and {} are one load on this log, not two: one torque of speed fits it as well          ({:.2}x its noise floor, the two {:.2}x), {} N m at synchronous speed going as |w|^{:.1};          neither is a finding alone (the library has no such law: write it as your own)",
        a.effects[0],
        a.effects[1],
        a.ratio_as_one,
        a.ratio_as_one * a.error_apart / a.error_as_one,
        sig(a.torque_at_sync_nm),
        a.exponent
    )
}
