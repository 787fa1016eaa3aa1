//! The text reports of the model-vs-measurement commands, `compare` and `explain`.

use super::diagnose::data_quality;
use super::number;
use monitor_api::analysis::CompareReport;
use monitor_api::analysis::EffectId;
use monitor_api::analysis::LadderReport;
use monitor_api::analysis::{ExplainReport, Standing, EXPLAINS_MIN};
use monitor_api::words;

/// The command line's words for the options advice names (`--from`, `--effects`).
const CLI: &crate::cli::words::CliWords = &crate::cli::words::CliWords;
use monitor_api::ExplainDocument;
use std::io::Write;
use std::path::Path;

/// The effects of a model, as the text tables name it: `bare` without effects, else
/// `prefix` and the names joined by `sep`.
fn model_name(effects: &[EffectId], bare: &str, prefix: &str, sep: &str) -> String {
    if effects.is_empty() {
        bare.to_string()
    } else {
        let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
        format!("{prefix}{}", names.join(sep))
    }
}

/// `compare`'s errors, worst windows and fitted values.
pub fn compare(
    mut out: &mut dyn std::io::Write,
    log: &Path,
    r: &CompareReport,
) -> anyhow::Result<()> {
    writeln!(out, "compare {}", log.display())?;
    data_quality(&mut out, &r.data_quality)?;
    writeln!(
        out,
        "  model: {}",
        model_name(
            &r.effects,
            "paper's simplified model (eqs. 28-29)",
            "paper's model + ",
            " + "
        )
    )?;
    match r.diverged_at_s {
        Some(t) => writeln!(
            out,
            "  normalized_rms_error: not judged: the model diverged at {t:.3} s (see 'not plausible' below)"
        )?,
        None => writeln!(
            out,
            "  normalized_rms_error {}   (noise floor {})",
            number(r.normalized_rms_error),
            number(r.noise_floor)
        )?,
    }
    for ch in &r.channels {
        writeln!(
            out,
            "  {:<14} rms error {:>10.4}  of rms {:>10.4}  ({:.2} %)",
            ch.channel,
            ch.rms_error,
            ch.rms_measured,
            100.0 * ch.normalized
        )?;
    }
    worst_windows(&mut out, r)?;
    for a in &r.advice {
        writeln!(out, "  advice: {}", words::compare::advice(a, CLI))?;
    }
    fitted(&mut out, r)?;
    for s in &r.skipped {
        writeln!(out, "  skipped: {}", words::compare::skipped(*s))?;
    }
    writeln!(
        out,
        "  unbalance: {}",
        words::analysis::unbalance(&r.unbalance, CLI)
    )?;
    leftover(&mut out, r.leftover.as_ref(), "  ")
}

/// Where the model's error lives ([`words::leftover::lines`]), its first line indented by
/// `indent` and the others two more.
fn leftover(
    out: &mut dyn std::io::Write,
    l: Option<&monitor_api::analysis::Leftover>,
    indent: &str,
) -> anyhow::Result<()> {
    let Some(l) = l else {
        return Ok(());
    };
    for (k, line) in words::leftover::lines(l).iter().enumerate() {
        let more = if k == 0 { "" } else { "  " };
        writeln!(out, "{indent}{more}{line}")?;
    }
    Ok(())
}

/// The windows where the model fails most, with their conditions and transients.
fn worst_windows(out: &mut impl Write, r: &CompareReport) -> anyhow::Result<()> {
    if r.worst_windows.is_empty() {
        return Ok(());
    }
    writeln!(out, "  worst windows:")?;
    for w in &r.worst_windows {
        writeln!(
            out,
            "    {:>7.2}-{:<7.2} s  error {:.4}  speed {} rpm, I_qs {:.2} A, voltage {:.0} %, {:.1} Hz, {:.2} s after start; error mostly {}",
            w.t_start_s,
            w.t_end_s,
            w.normalized_rms_error,
            w.condition.speed_rpm.map(|s| format!("{s:.0}")).unwrap_or("-".into()),
            w.condition.load_current_a,
            w.condition.voltage_percent,
            w.condition.supply_hz,
            w.condition.time_since_start_s,
            w.error_kind
        )?;
        if let Some(t) = &w.transient {
            writeln!(out, "      transient ({}): {}", t.kind, t.description)?;
        }
    }
    Ok(())
}

/// The fitted effects and base parameters, what is not plausible and what the log does
/// not identify.
fn fitted(out: &mut impl Write, r: &CompareReport) -> anyhow::Result<()> {
    for e in &r.fitted_effects {
        writeln!(out, "  {}: {}", e.effect, e.summary)?;
    }
    for (k, v) in &r.base_parameters {
        writeln!(
            out,
            "  fitted {:<14} {:>12.5} {} (nominal {:.5}){}",
            k,
            v.value,
            v.unit,
            v.nominal.unwrap_or(f64::NAN),
            if v.plausible { "" } else { "  [not plausible]" }
        )?;
    }
    for w in words::compare::implausible(r, CLI) {
        writeln!(out, "  not plausible: {w}")?;
    }
    if let Some(j) = &r.identifiability {
        writeln!(
            out,
            "  identifiability: Jacobian rank {} of {}, condition number {:.3e}",
            j.rank, j.n_parameters, j.condition_number
        )?;
    }
    for w in &r.not_identified {
        writeln!(out, "  {}", words::compare::not_identified(w))?;
    }
    Ok(())
}

/// `explain`'s report: the one verdict first, then explain's own answer on the model's error
/// and how it reads beside the verdict, the motor's own analyses (the unbalance, the rotor's
/// current signature), the ranked candidates, those with no effect in one line, those not
/// plausible apart with their reasons, what was skipped, and the refitted base parameters.
pub fn explain(
    mut out: &mut dyn std::io::Write,
    log: &Path,
    doc: &ExplainDocument,
) -> anyhow::Result<()> {
    let r = &doc.report;
    writeln!(out, "explain {}", log.display())?;
    // The one verdict first (what `diagnose` gives the same log), then the model's story.
    writeln!(out, "{}", doc.headline)?;
    data_quality(&mut out, &r.data_quality)?;
    writeln!(
        out,
        "  model as configured: {}; error {} (held-back {}), noise floor {}",
        model_name(&r.effects, "paper's model", "", ","),
        number(r.baseline_normalized_rms_error),
        number(r.baseline_validation_normalized_rms_error),
        number(r.noise_floor)
    )?;
    // Explain's own answer, then how it reads beside the verdict.
    writeln!(out, "model's error: {}", words::explain::verdict(r, CLI))?;
    if let Some(b) = &doc.beside_verdict {
        writeln!(out, "  {b}")?;
    }
    writeln!(
        out,
        "  unbalance: {}",
        words::analysis::unbalance(&r.unbalance, CLI)
    )?;
    write!(out, "{}", super::super::mcsa::text(&doc.rotor_asymmetry))?;
    ranking(&mut out, r)?;
    for s in &r.skipped {
        writeln!(out, "  skipped: {}", words::analysis::skipped(s, CLI))?;
    }
    if let Some(said) = r.base_refit.as_ref().map(words::explain::base_refit) {
        if !said.is_empty() {
            writeln!(out, "  {said}")?;
        }
    }
    Ok(())
}

/// The ranked candidates (plausible, explaining at least [`EXPLAINS_MIN`]) as a table, then
/// the fits without effect and those not plausible apart ([`apart`]).
fn ranking(out: &mut impl Write, r: &ExplainReport) -> anyhow::Result<()> {
    let of = |s: Standing| r.ranking.iter().filter(move |c| c.standing == s);
    let ranked: Vec<_> = of(Standing::Candidate).collect();
    if ranked.is_empty() {
        writeln!(
            out,
            "  ranking: no candidate (no plausible effect explains {:.0} % of the held-back error beyond the noise or more)",
            100.0 * EXPLAINS_MIN
        )?;
    } else {
        writeln!(
            out,
            "  ranking: the plausible effects that explain at least {:.0} % of the held-back error beyond the noise, by the error they leave on the held-back part of the log",
            100.0 * EXPLAINS_MIN
        )?;
        writeln!(
            out,
            "  {:<4} {:<18} {:>10} {:>10} {:>11}  fitted",
            "rank", "effect", "error", "held-back", "explained"
        )?;
    }
    for k in &ranked {
        writeln!(
            out,
            "  {:<4} {:<18} {:>10} {:>10} {:>4.0}% / {:>3.0}%  {}",
            k.rank.unwrap_or_default(),
            k.effect.name(),
            number(k.normalized_rms_error),
            number(k.validation_normalized_rms_error),
            100.0 * k.whole_log_explained_fraction,
            100.0 * k.explained_fraction,
            k.summary
        )?;
    }
    if !ranked.is_empty() {
        writeln!(
            out,
            "  (explained: the share of the error beyond the noise floor the effect removes, whole log / held-back windows)"
        )?;
    }
    apart(out, r)
}

/// The plausible fits with no effect, in one line, and those not plausible, each with its
/// reasons, under a heading of their own.
fn apart(out: &mut impl Write, r: &ExplainReport) -> anyhow::Result<()> {
    let of = |s: Standing| r.ranking.iter().filter(move |c| c.standing == s);
    let none: Vec<String> = of(Standing::NoEffect)
        .map(|c| format!("{} ({:.1} %)", c.effect, 100.0 * c.explained_fraction))
        .collect();
    if !none.is_empty() {
        writeln!(
            out,
            "  no effect (plausible, but explain under {:.0} %): {}",
            100.0 * EXPLAINS_MIN,
            none.join(", ")
        )?;
    }
    let mut implausible = of(Standing::NotPlausible).peekable();
    if implausible.peek().is_some() {
        writeln!(
            out,
            "  not plausible (fitted only with values no machine has: no explanation, whatever they would explain):"
        )?;
    }
    for c in implausible {
        writeln!(
            out,
            "    {} ({:.0} %): {}",
            c.effect,
            100.0 * c.explained_fraction,
            c.implausible_because.join("; ")
        )?;
    }
    Ok(())
}

/// `explain --ladder`'s page: first what was found (the summary: the base changes and the
/// effects with their sizes, the end, why it stopped), then the table: the model as
/// configured, one row per step (the effect added and what it dropped, or the base rung's
/// changes; the whole-log and held-back error each with its multiple of the noise floor,
/// the share of the error beyond the floor the step removed on each, the fitted values with
/// their physical ranges), the chosen model refitted on the whole log, then why it stopped,
/// the test, the last round's other candidates and what could not be fitted.
pub fn ladder(
    mut out: &mut dyn std::io::Write,
    log: &Path,
    r: &LadderReport,
) -> anyhow::Result<()> {
    writeln!(out, "explain --ladder {}", log.display())?;
    data_quality(&mut out, &r.data_quality)?;
    writeln!(out, "{}", words::ladder::summary(r))?;
    writeln!(
        out,
        "  {:<4} {:<34} {:>8} {:>7} {:>9} {:>7} {:>11}  fitted (physical range)",
        "step", "change", "error", "x floor", "held-back", "x floor", "explained"
    )?;
    writeln!(
        out,
        "  {:<4} {:<34} {:>8} {:>7} {:>9} {:>7} {:>11}  noise floor {} (held-back {})",
        0,
        model_name(&r.start.effects, "paper's model", "", ","),
        number(r.start.error),
        times(r.start.ratio_to_floor),
        number(r.start.heldback_error),
        times(r.start.heldback_error / r.start.heldback_noise_floor),
        "",
        number(r.start.noise_floor),
        number(r.start.heldback_noise_floor)
    )?;
    for (k, s) in r.ladder.iter().enumerate() {
        writeln!(out, "{}", ladder_row(k + 1, s))?;
    }
    if let Some(f) = &r.final_fit {
        writeln!(
            out,
            "  {:<4} {:<34} {:>8} {:>7} {:>9} {:>7} {:>11}  {}",
            "end",
            "refitted on the whole log",
            number(f.error),
            times(f.ratio_to_floor),
            "",
            "",
            "",
            super::super::end_base(f)
        )?;
    }
    writeln!(
        out,
        "  (explained: the share of the error beyond the noise floor the step removed, whole log / held-back windows)"
    )?;
    ladder_end(out, r)
}

/// The ladder page's end: why it stopped, the test, the last round's other candidates and
/// what could not be fitted.
fn ladder_end(out: &mut dyn std::io::Write, r: &LadderReport) -> anyhow::Result<()> {
    writeln!(out, "stopped: {}", words::ladder::stopped(r))?;
    writeln!(out, "  the test: {}", words::ladder::test(&r.test_rule))?;
    for t in &r.last_round {
        let (name, why) = (
            words::ladder::tried_name(t),
            words::ladder::refusal(&t.refusal),
        );
        writeln!(out, "  not kept: {name}: {why}")?;
    }
    for s in &r.skipped_reasons {
        let s = words::analysis::skipped(s, CLI);
        writeln!(out, "  not fitted: {s}")?;
    }
    leftover(out, r.leftover.as_ref(), "")
}

/// One step's row of the ladder's table (`k`: its number): `+ effect` (and `- dropped`), or
/// `base: Rs +20 % (±1 %), ...` for the base rung.
fn ladder_row(k: usize, s: &monitor_api::analysis::LadderStep) -> String {
    let changed: Vec<String> = s
        .base
        .iter()
        .filter(|c| c.changed)
        .map(words::ladder::base_change)
        .collect();
    let mut name = if s.effect.is_none() {
        "base parameters refitted".to_string()
    } else {
        model_name(&s.added, "", "+ ", " + ")
    };
    for d in &s.dropped {
        name.push_str(&format!(" - {d}"));
    }
    let fitted: Vec<String> = if s.effect.is_none() {
        changed.clone()
    } else {
        s.fitted
            .iter()
            .map(|(n, v)| {
                format!(
                    "{n} {} {} ({}..{})",
                    sig(v.value),
                    v.unit,
                    sig(v.low),
                    sig(v.high)
                )
            })
            .chain(
                (!changed.is_empty())
                    .then(|| format!("on the refitted base: {}", changed.join(", "))),
            )
            .collect()
    };
    format!(
        "  {:<4} {:<34} {:>8} {:>7} {:>9} {:>7} {:>4.0}% / {:>3.0}%  {}",
        k,
        name,
        number(s.error),
        times(s.ratio_to_floor),
        number(s.heldback_error),
        times(s.heldback_ratio_to_floor),
        100.0 * s.explained,
        100.0 * s.heldback_explained,
        fitted.join("; ")
    )
}

/// A multiple of the noise floor as the table prints it (`super::super::times_floor`).
fn times(r: f64) -> String {
    super::super::times_floor(r)
}

/// A value with four significant digits, in plain or scientific notation by its size.
fn sig(x: f64) -> String {
    monitor_api::analysis::sig(x)
}
