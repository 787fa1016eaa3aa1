//! The HTML renderer: the one-page report of `compare` and `explain`, and the chart files
//! of `--plot` and `--report`.
//!
//! The report embeds the SVG charts inline, so `report.html` is one self-contained file;
//! the PNG copies sit beside it for slides and tickets. Every file is written atomically.

use super::{charts, plot};
use monitor_api::analysis::Analysis;
use monitor_api::analysis::Prediction;
use monitor_api::analysis::{CompareOutput, CompareReport};
use monitor_api::analysis::{FinalFit, LadderReport, LadderStep};
use monitor_api::files::DataQuality;
use monitor_api::words;
use monitor_api::ExplainDocument;

/// The command line's words for the options advice names (`--from`, `--effects`).
const CLI: &crate::cli::words::CliWords = &crate::cli::words::CliWords;
use monitor_api::analysis::EffectId;
use plot::Chart;
use std::fmt::Write as _;
use std::path::Path;

/// The report page's file name in `--report DIR`.
pub const REPORT_FILE: &str = "report.html";

/// Writes the charts into `dir` (created if needed); returns (title, HTML) pairs: the SVG,
/// or for a chart not drawn the sentence why.
fn write_charts(dir: &Path, charts: &[Chart]) -> anyhow::Result<Vec<(String, String)>> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    let mut v = Vec::new();
    for c in charts {
        let body = match &c.omitted {
            Some(why) => format!("<p><i>{}</i></p>", esc(why)),
            None => plot::write(dir, c).map_err(anyhow::Error::msg)?.0,
        };
        v.push((c.title.to_string(), body));
    }
    Ok(v)
}

/// Writes the chart files into `plot` and the report (its own copy of the charts) into
/// `report`, each when given. Charts are only built when something is written (they thin
/// copies of the full series).
fn write_outputs(
    plot: Option<&Path>,
    report: Option<&Path>,
    charts: impl FnOnce() -> Vec<Chart<'static>>,
    page: impl FnOnce(&[(String, String)]) -> String,
) -> anyhow::Result<()> {
    if plot.is_none() && report.is_none() {
        return Ok(());
    }
    let charts = charts();
    if let Some(dir) = plot {
        write_charts(dir, &charts)?;
    }
    if let Some(dir) = report {
        let svgs = write_charts(dir, &charts)?;
        let path = dir.join(REPORT_FILE);
        monitor_api::files::write_atomic(&path, page(&svgs).as_bytes())
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        // Not eprintln!: a closed stderr must not panic after the report is written.
        let _ = std::io::Write::write_all(
            &mut std::io::stderr(),
            format!("report: {}\n", path.display()).as_bytes(),
        );
    }
    Ok(())
}

/// `compare --plot DIR --report DIR`.
pub fn write_compare(
    plot: Option<&Path>,
    report: Option<&Path>,
    log: &Path,
    a: &Analysis,
    out: &CompareOutput,
) -> anyhow::Result<()> {
    let log = log.display().to_string();
    write_outputs(
        plot,
        report,
        || charts::compare_charts(&a.data, out),
        |svgs| compare_html(&log, out, svgs),
    )
}

/// `explain --plot DIR --report DIR`, with the motor current signature analysis (its
/// spectrum among the charts, its text in the report).
pub fn write_explain(
    plot: Option<&Path>,
    report: Option<&Path>,
    log: &Path,
    a: &Analysis,
    (before, after): (&Prediction, Option<&(EffectId, Prediction)>),
    doc: &ExplainDocument,
) -> anyhow::Result<()> {
    let log = log.display().to_string();
    write_outputs(
        plot,
        report,
        || {
            let mut v = charts::explain_charts(&a.data, before, after);
            v.extend(super::mcsa::chart(&doc.rotor_asymmetry));
            v
        },
        |svgs| explain_html(&log, doc, svgs),
    )
}

/// `explain --ladder --plot DIR --report DIR`: the chart of the error falling step by step
/// onto the floor band, and the page with the steps' table.
pub fn write_ladder(
    plot: Option<&Path>,
    report: Option<&Path>,
    log: &Path,
    r: &LadderReport,
) -> anyhow::Result<()> {
    let log = log.display().to_string();
    write_outputs(
        plot,
        report,
        || {
            vec![
                super::ladder_charts::ladder_chart(r),
                super::ladder_charts::ladder_time_chart(r),
            ]
        },
        |svgs| ladder_html(&log, r, svgs),
    )
}

/// The ladder's report page.
fn ladder_html(log: &str, r: &LadderReport, charts: &[(String, String)]) -> String {
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html><head><meta charset=utf-8><meta name=viewport content=\"width=device-width\"><title>ladder: {}</title><style>{STYLE}svg{{max-width:100%;height:auto}}</style></head><body>", esc(log));
    let _ = write!(h, "<h1>The ladder: model vs measurement, step by step</h1><p>Log <code>{}</code>: {} rows at {:.0} Hz ({:.2} s), analysed at {:.0} Hz.</p>", esc(log), r.data.rows, r.data.log_rate_hz, r.data.duration_s, r.data.working_rate_hz);
    data_quality(&mut h, &r.data_quality);
    let start = if r.start.effects.is_empty() {
        "the paper's model (eqs. 28-29)".to_string()
    } else {
        effect_list(&r.start.effects)
    };
    let _ = write!(
        h,
        "<p class=v>{}</p>",
        esc(&monitor_api::words::ladder::summary(r))
    );
    for (title, svg) in charts {
        let _ = write!(h, "<h3>{}</h3>{svg}", esc(title));
    }
    h.push_str("<table><tr><th>step</th><th class=l>change</th><th>error</th><th>x floor</th><th>held-back</th><th>x floor</th><th>explained (whole / held-back)</th><th class=l>fitted (physical range)</th></tr>");
    let _ = write!(h, "<tr><td>0</td><td class=l>{}</td><td>{:.4}</td><td>{}</td><td>{:.4}</td><td>{}</td><td></td><td></td></tr>", esc(&start), r.start.error, super::times_floor(r.start.ratio_to_floor), r.start.heldback_error, super::times_floor(r.start.heldback_error / r.start.heldback_noise_floor));
    for (k, s) in r.ladder.iter().enumerate() {
        ladder_row(&mut h, k + 1, s);
    }
    if let Some(f) = &r.final_fit {
        ladder_end_row(&mut h, f);
    }
    h.push_str("</table>");
    let _ = write!(
        h,
        "<p>Stopped: {}</p>",
        esc(&monitor_api::words::ladder::stopped(r))
    );
    let _ = write!(
        h,
        "<p>The test: {}.</p>",
        esc(&monitor_api::words::ladder::test(&r.test_rule))
    );
    ladder_end_html(&mut h, r);
    h.push_str("</body></html>");
    h
}

/// The ladder page's end: the last round's other candidates, the effects not fitted on the
/// log, and where the error lives when the ladder stopped above the floor.
fn ladder_end_html(h: &mut String, r: &LadderReport) {
    if !r.last_round.is_empty() {
        h.push_str("<h2>The last round's other candidates</h2><ul>");
        for t in &r.last_round {
            let _ = write!(
                h,
                "<li>{}: {}</li>",
                esc(&monitor_api::words::ladder::tried_name(t)),
                esc(&monitor_api::words::ladder::refusal(&t.refusal))
            );
        }
        h.push_str("</ul>");
    }
    if !r.skipped_reasons.is_empty() {
        h.push_str("<h2>Not fitted on this log</h2><ul>");
        for s in &r.skipped_reasons {
            let s = words::analysis::skipped(s, CLI);
            let _ = write!(h, "<li>{}</li>", esc(&s));
        }
        h.push_str("</ul>");
    }
    leftover_html(h, r.leftover.as_ref());
}

/// Where the model's error lives ([`words::leftover::lines`]): its headline, then a list.
fn leftover_html(h: &mut String, l: Option<&monitor_api::analysis::Leftover>) {
    let Some(l) = l else {
        return;
    };
    let lines = words::leftover::lines(l);
    let Some((head, rest)) = lines.split_first() else {
        return;
    };
    let _ = write!(h, "<h2>Where the error lives</h2><p>{}</p>", esc(head));
    if !rest.is_empty() {
        h.push_str("<ul>");
        for x in rest {
            let _ = write!(h, "<li>{}</li>", esc(x.trim_start()));
        }
        h.push_str("</ul>");
    }
}

/// The table row of the ladder's step `s` (number `k`): what it added, changed or
/// dropped, its errors, the shares it explained and its fitted values.
fn ladder_row(h: &mut String, k: usize, s: &LadderStep) {
    let changed: Vec<String> = s
        .base
        .iter()
        .filter(|c| c.changed)
        .map(monitor_api::words::ladder::base_change)
        .collect();
    let mut fitted: Vec<String> = s
        .fitted
        .iter()
        .filter(|_| s.effect.is_some())
        .map(|(n, v)| {
            format!(
                "{n} {:.4} {} ({:.3}..{:.3})",
                v.value, v.unit, v.low, v.high
            )
        })
        .collect();
    if !changed.is_empty() {
        fitted.push(format!("base: {}", changed.join(", ")));
    }
    let mut name = match s.effect {
        None => "base parameters refitted".to_string(),
        Some(_) => effect_list(&s.added),
    };
    for d in &s.dropped {
        name.push_str(&format!(", {d} removed"));
    }
    let _ = write!(h, "<tr><td>{}</td><td class=l>{}</td><td>{:.4}</td><td>{}</td><td>{:.4}</td><td>{}</td><td>{:.0} % / {:.0} %</td><td class=l>{}</td></tr>", k, esc(&name), s.error, super::times_floor(s.ratio_to_floor), s.heldback_error, super::times_floor(s.heldback_ratio_to_floor), 100.0 * s.explained, 100.0 * s.heldback_explained, esc(&fitted.join("; ")));
}

/// The table row of the chosen model refitted on the whole log.
fn ladder_end_row(h: &mut String, f: &FinalFit) {
    let _ = write!(h, "<tr><td>end</td><td class=l>the chosen model refitted on the whole log</td><td>{:.4}</td><td>{}</td><td></td><td></td><td></td><td class=l>{}</td></tr>", f.error, super::times_floor(f.ratio_to_floor), esc(&super::end_base(f)));
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:4px 8px;text-align:right}th{background:#eee}td.l,th.l{text-align:left}.v{font-size:1.2em;background:#f4f4dc;padding:.6em;border-left:4px solid #cc4}";

/// The `compare` report page.
fn compare_html(log: &str, out: &CompareOutput, charts: &[(String, String)]) -> String {
    let r = &out.report;
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html><head><meta charset=utf-8><title>compare: {}</title><style>{STYLE}</style></head><body>", esc(log));
    let _ = write!(h, "<h1>Model vs measurement</h1><p>Log <code>{}</code>: {} rows at {:.0} Hz ({:.2} s), analysed at {:.0} Hz in the {}.</p>", esc(log), r.data.rows, r.data.log_rate_hz, r.data.duration_s, r.data.working_rate_hz, esc(r.data.frame.describe()));
    data_quality(&mut h, &r.data_quality);
    let eff = if r.effects.is_empty() {
        "none (the paper's model, eqs. 28-29)".to_string()
    } else {
        effect_list(&r.effects)
    };
    let _ = write!(h, "<p class=v>Effects in the model: <b>{}</b>. Normalized RMS error <b>{:.4}</b> (noise floor {:.4}: a perfect model would score about this).</p>", esc(&eff), r.normalized_rms_error, r.noise_floor);
    for s in &r.skipped {
        let _ = write!(h, "<p><i>{}</i></p>", esc(&words::compare::skipped(*s)));
    }
    channels_table(&mut h, r);
    worst_windows_table(&mut h, r);
    if !r.advice.is_empty() {
        h.push_str("<h2>Advice</h2><ul>");
        for a in &r.advice {
            let _ = write!(h, "<li>{}</li>", esc(&words::compare::advice(a, CLI)));
        }
        h.push_str("</ul>");
    }
    base_parameters_table(&mut h, r);
    for w in words::compare::implausible(r, CLI) {
        let _ = write!(h, "<p>not plausible: {}</p>", esc(&w));
    }
    if let Some(j) = &r.identifiability {
        let _ = write!(
            h,
            "<p>Identifiability: Jacobian rank {} of {}, condition number {:.3e}.</p>",
            j.rank, j.n_parameters, j.condition_number
        );
    }
    for w in &r.not_identified {
        let _ = write!(h, "<p>{}</p>", esc(&words::compare::not_identified(w)));
    }
    for e in &r.fitted_effects {
        let _ = write!(h, "<p><b>{}</b>: {}</p>", e.effect, esc(&e.summary));
    }
    let _ = write!(
        h,
        "<h2>Unbalance</h2><p>{}</p>",
        esc(&words::analysis::unbalance(&r.unbalance, CLI))
    );
    leftover_html(&mut h, r.leftover.as_ref());
    for (title, svg) in charts {
        let _ = write!(h, "<h3>{}</h3>{svg}", esc(title));
    }
    h.push_str("<p>Next step: <code>sim-host explain</code> ranks the physical effects that could remove this error.</p></body></html>");
    h
}

/// `compare`'s error per channel, as a table.
fn channels_table(h: &mut String, r: &CompareReport) {
    h.push_str("<h2>Error per channel</h2><table><tr><th class=l>channel</th><th>RMS error</th><th>RMS measured</th><th>normalized</th></tr>");
    for c in &r.channels {
        let _ = write!(
            h,
            "<tr><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td></tr>",
            c.channel, c.rms_error, c.rms_measured, c.normalized
        );
    }
    h.push_str("</table>");
}

/// `compare`'s worst windows with their conditions and transients, as a table.
fn worst_windows_table(h: &mut String, r: &CompareReport) {
    h.push_str("<h2>Where the model fails most</h2><table><tr><th>from [s]</th><th>to [s]</th><th>error</th><th>speed [rpm]</th><th>load I_qs [A]</th><th>voltage [%]</th><th>supply [Hz]</th><th>since start [s]</th><th class=l>error is mostly</th></tr>");
    for w in &r.worst_windows {
        let transient = w
            .transient
            .as_ref()
            .map(|t| format!("; transient ({}): {}", t.kind, t.description))
            .unwrap_or_default();
        let _ = write!(h, "<tr><td>{:.2}</td><td>{:.2}</td><td>{:.4}</td><td>{}</td><td>{:.2}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2}</td><td class=l>{}{}</td></tr>", w.t_start_s, w.t_end_s, w.normalized_rms_error, w.condition.speed_rpm.map(|s| format!("{s:.0}")).unwrap_or("-".into()), w.condition.load_current_a, w.condition.voltage_percent, w.condition.supply_hz, w.condition.time_since_start_s, esc(&w.error_kind), esc(&transient));
    }
    h.push_str("</table>");
}

/// `compare`'s refitted base parameters against their nominal values, as a table.
fn base_parameters_table(h: &mut String, r: &CompareReport) {
    h.push_str("<h2>Fitted parameters</h2><p>Nominal values are never exact; the parameters the data identify are refitted.</p><table><tr><th class=l>parameter</th><th>fitted</th><th>nominal</th><th class=l>unit</th><th class=l>plausible</th></tr>");
    for (k, v) in &r.base_parameters {
        let _ = write!(
            h,
            "<tr><td class=l>{}</td><td>{:.5}</td><td>{:.5}</td><td class=l>{}</td><td class=l>{}</td></tr>",
            k,
            v.value,
            v.nominal.unwrap_or(f64::NAN),
            esc(&v.unit),
            if v.plausible { "yes" } else { "[not plausible]" }
        );
    }
    h.push_str("</table>");
}

/// The `explain` report page.
fn explain_html(log: &str, doc: &ExplainDocument, charts: &[(String, String)]) -> String {
    let (r, mcsa) = (&doc.report, &doc.rotor_asymmetry);
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html><head><meta charset=utf-8><title>explain: {}</title><style>{STYLE}</style></head><body>", esc(log));
    let _ = write!(h, "<h1>Which physical effect is missing?</h1><p>Log <code>{}</code>. Effects already in the model: {}.</p>", esc(log), if r.effects.is_empty() { "none".into() } else { effect_list(&r.effects) });
    // The one verdict first, then explain's own answer and how the two relate.
    let _ = write!(h, "<p><b>{}</b></p>", esc(&doc.headline));
    let _ = write!(
        h,
        "<p class=v>The model's error: {}</p>",
        esc(&words::explain::verdict(r, CLI))
    );
    if let Some(b) = &doc.beside_verdict {
        let _ = write!(h, "<p>{}</p>", esc(b));
    }
    if let Some(said) = r.base_refit.as_ref().map(words::explain::base_refit) {
        if !said.is_empty() {
            let _ = write!(h, "<p>{}</p>", esc(&said));
        }
    }
    data_quality(&mut h, &r.data_quality);
    let _ = write!(h, "<p>Error of the model as configured: {:.4} (whole log), {:.4} on the held-back windows the fits never saw; noise floor {:.4}. Each candidate below was added to the model and fitted together with the base parameters; ranking is by the held-back error, so an effect that only fits noise does not win.</p>", r.baseline_normalized_rms_error, r.baseline_validation_normalized_rms_error, r.noise_floor);
    h.push_str("<table><tr><th>rank</th><th class=l>effect</th><th>error</th><th>held-back error</th><th>explained (whole / held-back)</th><th>params</th><th class=l>fitted, in words</th></tr>");
    // Ranked candidates, then those with no effect, then those not plausible (no rank).
    for c in &r.ranking {
        let rank = c.rank.map_or_else(
            || format!("[{}]", c.standing.name().replace('_', " ")),
            |k| k.to_string(),
        );
        let _ = write!(h, "<tr><td>{rank}</td><td class=l>{}</td><td>{:.4}</td><td>{:.4}</td><td>{:.0} % / {:.0} %</td><td>{}</td><td class=l>{}</td></tr>", c.effect, c.normalized_rms_error, c.validation_normalized_rms_error, 100.0 * c.whole_log_explained_fraction, 100.0 * c.explained_fraction, c.n_parameters, esc(&c.summary));
    }
    h.push_str("</table><p><i>explained: the share of the error beyond the noise floor the effect removes, whole log / held-back windows</i></p>");
    if let Some(c) = r.ranking.first().filter(|c| c.rank.is_some()) {
        let _ = write!(h, "<h2>Before / after</h2><table><tr><th class=l>model</th><th>held-back windows</th><th>whole log</th></tr><tr><td class=l>as configured</td><td>{:.4}</td><td>{:.4}</td></tr><tr><td class=l>+ {}</td><td>{:.4}</td><td>{:.4}</td></tr></table>", r.baseline_validation_normalized_rms_error, r.baseline_normalized_rms_error, c.effect, c.validation_normalized_rms_error, c.normalized_rms_error);
    }
    for s in &r.skipped {
        let _ = write!(
            h,
            "<p><i>skipped: {}</i></p>",
            esc(&words::analysis::skipped(s, CLI))
        );
    }
    let _ = write!(
        h,
        "<h2>Unbalance</h2><p>{}</p>",
        esc(&words::analysis::unbalance(&r.unbalance, CLI))
    );
    let _ = write!(
        h,
        "<h2>Rotor asymmetry (motor current signature analysis)</h2><pre>{}</pre>",
        esc(&super::mcsa::text(mcsa))
    );
    for (title, svg) in charts {
        let _ = write!(h, "<h3>{}</h3>{svg}", esc(title));
    }
    h.push_str("</body></html>");
    h
}

/// The data-quality stage's finding and what was done, as the text prints it.
fn data_quality(h: &mut String, q: &DataQuality) {
    let _ = write!(h, "<p>Data quality: {}</p>", esc(&q.summary()));
    if !q.actions.is_empty() {
        h.push_str("<ul>");
        for a in &q.actions {
            let _ = write!(h, "<li>done: {}</li>", esc(&a.to_string()));
        }
        h.push_str("</ul>");
    }
    if !q.trusted {
        let _ = write!(
            h,
            "<p><b>NOT TRUSTED</b>: {}</p>",
            esc(&q.not_trusted_because.join("; "))
        );
    }
}

fn effect_list(e: &[EffectId]) -> String {
    e.iter().map(|e| e.name()).collect::<Vec<_>>().join(", ")
}
