//! `diagnose --report R.html`: the one page a crew prints and a planner files.
//!
//! What it holds, top to bottom: the verdict's banner (at most two lines: the verdict with
//! the fault it names, then which analyses were judged and which could not be); the
//! findings table right below it (one row per analysis, its state and sentence: each
//! reason once, the row the verdict rests on marked); the residuals and the lamps over
//! time with the events marked (load moves, faults named, first detections); the negative
//! sequence over time with the named phase; the rotor's sidebands against the severity
//! bands; the data quality. Charts are inline SVG drawn with plotters ([`super::plot`]),
//! so the page is one self-contained file; tables wrap their text, and the page is laid
//! out for an A4 sheet and a phone's width alike (the charts scale to the page's width).
//! The file is written atomically ([`monitor_api::files::write_atomic`]).

use super::plot::{self, Chart, Series};
use crate::cli::words::CliWords;
use monitor_api::replay::Verdict;
use monitor_api::replay::{DiagnoseReport, Diagnosed, FindingReport, IsolationEvent, RotorBand};
use monitor_api::words::diagnose::{self as words, Story};
use monitor_core::verdict::State;
use std::fmt::Write as _;
use std::path::Path;

/// Writes the report of `d` (the log `log`) to `path`, atomically.
///
/// # Errors
/// A chart that cannot be drawn, or a file that cannot be written (naming it).
pub fn write(path: &Path, log: &Path, d: &Diagnosed) -> anyhow::Result<()> {
    let mut svgs = Vec::new();
    for c in charts(&d.report) {
        let body = match &c.omitted {
            Some(why) => format!("<p><i>{}</i></p>", esc(why)),
            None => plot::svg_string(&c).map_err(anyhow::Error::msg)?,
        };
        svgs.push((c.title.to_string(), body));
    }
    let html = page(&log.display().to_string(), d, &svgs);
    monitor_api::files::write_atomic(path, html.as_bytes())
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    // Not eprintln!: a closed stderr must not panic after the report is written.
    let _ = std::io::Write::write_all(
        &mut std::io::stderr(),
        format!("report: {}\n", path.display()).as_bytes(),
    );
    Ok(())
}

/// The page's style: readable on paper (A4, 12 mm margins) and on a phone; charts scale to
/// the width; long words and numbers in tables wrap instead of running off the page.
const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:1em auto;padding:0 .6em;color:#222;line-height:1.35}\
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.4em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:.6em 0;width:100%;table-layout:auto}\
td,th{border:1px solid #bbb;padding:3px 6px;text-align:left;vertical-align:top;overflow-wrap:anywhere}\
td.k{overflow-wrap:normal;white-space:nowrap;font-size:.9em}\
th{background:#eee}svg{max-width:100%;height:auto;display:block}\
.v{font-size:1.15em;padding:.6em;border-left:6px solid #888;background:#f4f4f4}\
.fault{border-color:#c22;background:#fbeaea}.watching{border-color:#c90;background:#fbf4e0}\
.healthy{border-color:#2a2;background:#eaf6ea}.could_not_judge{border-color:#888}\
.v small{display:block;font-size:.75em;margin-top:.2em}tr.by td{font-weight:bold;background:#f4f4f4}td.k small{display:block;white-space:normal}\
code{overflow-wrap:anywhere}ul{padding-left:1.2em}\
@media print{body{max-width:none;margin:0}h2{break-after:avoid}svg,table,tr{break-inside:avoid}}\
@page{size:A4;margin:12mm}";

/// The page (module docs), with the charts as (title, inline SVG or why not drawn).
fn page(log: &str, d: &Diagnosed, charts: &[(String, String)]) -> String {
    let rep = &d.report;
    let story = Story::of(rep, &CliWords);
    let mut h = String::new();
    let _ = write!(h, "<!doctype html><html lang=en><head><meta charset=utf-8><meta name=viewport content=\"width=device-width,initial-scale=1\"><title>diagnose: {}</title><style>{STYLE}</style></head><body>", esc(log));
    let _ = write!(
        h,
        "<h1>Drive monitor: diagnosis</h1><p>Log <code>{}</code>: {} rows at {:.0} Hz; frame angle: {}.</p>",
        esc(log),
        rep.rows,
        d.sample_rate_hz,
        monitor_api::replay::angle_source_name(rep.angle_source)
    );
    verdict(&mut h, rep);
    findings_table(&mut h, rep, &story);
    for (title, svg) in charts {
        let _ = write!(h, "<h2>{}</h2>{svg}", esc(title));
    }
    events_list(&mut h, rep);
    // The rotor's sentence is its finding's, in the table above: said once.
    winding(&mut h, rep);
    quality(&mut h, rep);
    h.push_str("<p><small>Written by <code>sim-host diagnose --report</code>; the same verdict as <code>diagnose</code>'s text and <code>--json</code>.</small></p></body></html>");
    h
}

/// Whether a finding judged nothing (not judged, or unavailable on this log).
fn judged_nothing(f: &FindingReport) -> bool {
    matches!(f.finding.state, State::NotJudged | State::Unavailable)
}

/// The verdict with the fault it names, as the banner's first line (`FAULT shorted turns in
/// phase c: about 10 % of the phase's turns`, `healthy`); its confidence is the second
/// line's, why and against what the findings table's (its marked row).
fn verdict_head(rep: &DiagnoseReport) -> String {
    let named = rep.verdict_finding.as_ref().and_then(FindingReport::named);
    match (rep.verdict, named) {
        (Verdict::Fault, Some(n)) => format!("FAULT {}", words::fault_text(n)),
        (Verdict::Watching, Some(n)) => format!("WATCHING {}", words::fault_text(n)),
        (Verdict::Fault, None) => "FAULT".to_string(),
        (Verdict::Watching, None) => "WATCHING".to_string(),
        (Verdict::Healthy, _) => "healthy".to_string(),
        (Verdict::CouldNotJudge, _) => "could not judge".to_string(),
    }
}

/// The verdict's banner, at most two lines: the verdict ([`verdict_head`]), then the named
/// fault's confidence (a watched one's with why it is watched rather than a FAULT, in the
/// verdict line's words) and the analyses judged and those that could not judge, by name.
/// Each one's reason is said once, in the findings table right below.
fn verdict(h: &mut String, rep: &DiagnoseReport) {
    let class = serde_json::to_value(rep.verdict)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    let names = |nothing: bool| {
        let v: Vec<&str> = rep
            .findings
            .iter()
            .filter(|f| f.source().judges_faults() && judged_nothing(f) == nothing)
            .map(|f| f.source().name())
            .collect();
        if v.is_empty() {
            "none".to_string()
        } else {
            v.join(", ")
        }
    };
    // A FAULT's confidence; a watched name's, with why it is watched, not a FAULT.
    let by = rep.verdict_finding.as_ref();
    let confidence = match (rep.verdict, by.and_then(|f| f.named().map(|n| (f, n)))) {
        (Verdict::Watching, Some((f, n))) => {
            format!("{}; ", words::why_watched(n, f.finding.against))
        }
        (_, Some((_, n))) => format!("confidence {:.2}; ", n.confidence),
        (_, None) => String::new(),
    };
    let _ = write!(
        h,
        "<p class=\"v {}\"><b>verdict: {}</b><small>{confidence}judged: {}; not judged: {}. Why, for each, in the findings below.</small></p>",
        esc(&class),
        esc(&verdict_head(rep)),
        esc(&names(false)),
        esc(&names(true))
    );
}

/// A titled list of sentences (nothing when empty).
fn list(h: &mut String, title: &str, items: &[String]) {
    if items.is_empty() {
        return;
    }
    let _ = write!(h, "<p><b>{}</b></p><ul>", esc(title));
    for s in items {
        let _ = write!(h, "<li>{}</li>", esc(s));
    }
    h.push_str("</ul>");
}

/// One row per analysis: its name, state and sentence, with what a judged analysis was
/// judged against (and a named fault's confidence); the row the verdict rests on is marked.
fn findings_table(h: &mut String, rep: &DiagnoseReport, story: &Story) {
    h.push_str("<h2>Findings</h2><table><tr><th>analysis</th><th>state</th><th>finding</th></tr>");
    let by = rep.verdict_finding.as_ref().map(FindingReport::source);
    for (f, (summary, _)) in rep.findings.iter().zip(&story.findings) {
        let against = words::against_text(f.source(), f.finding.against);
        let judged = match f.named() {
            Some(n) => format!(" (confidence {:.2}; {against})", n.confidence),
            None if f.source().judges_faults() && !judged_nothing(f) => format!(" ({against})"),
            None => String::new(),
        };
        let (row, mark) = if by == Some(f.source()) {
            (" class=by", "<br><small>the verdict rests on it</small>")
        } else {
            ("", "")
        };
        let _ = write!(
            h,
            "<tr{row}><td class=k>{}</td><td class=k>{}{mark}</td><td>{}{}</td></tr>",
            esc(f.source().name()),
            esc(f.state_name()),
            esc(summary),
            esc(&judged)
        );
    }
    h.push_str("</table>");
}

/// The isolation's events and the first detections, with their times.
fn events_list(h: &mut String, rep: &DiagnoseReport) {
    let mut lines: Vec<(f64, String)> = rep
        .isolation
        .events
        .iter()
        .map(|e| (e.t_s(), words::event_line(e).trim().to_string()))
        .collect();
    lines.extend(
        rep.detections
            .iter()
            .map(|d| (d.t_s, words::detection_line(d, rep))),
    );
    lines.sort_by(|a, b| a.0.total_cmp(&b.0));
    let lines: Vec<String> = lines.into_iter().map(|(_, l)| l).collect();
    list(h, "Events (marked on the charts above)", &lines);
}

/// A negative-sequence ratio in per cent where it is a measurement (at most 100 %: above
/// it the phase order is reversed, `words::sequence_ratio`), else not drawn (NaN).
fn measured_pct(ratio: f32) -> f64 {
    if ratio <= 1.0 {
        100.0 * f64::from(ratio)
    } else {
        f64::NAN
    }
}

/// The negative sequence: the whole log's ratio, the named phase and its confidence.
fn winding(h: &mut String, rep: &DiagnoseReport) {
    let u = &rep.unbalance;
    let phase = words::suspect(u);
    let _ = write!(
        h,
        "<h2>Winding</h2><p>Negative sequence |I2|/|I1| = {} (least change that names a phase {:.1} %); suspect phase: {}.</p>",
        esc(&words::sequence_ratio(u.negative_sequence_ratio)),
        100.0 * u.least_change,
        esc(&phase)
    );
    // Why no phase was judged is the winding finding's sentence, in the table above.
    let p = &u.phase_probabilities;
    let _ = write!(
        h,
        "<table><tr><th>no short</th><th>short in phase a</th><th>in b</th><th>in c</th></tr><tr><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td></tr></table>",
        p.no_short, p.a, p.b, p.c
    );
}

/// What the data-quality stage did (what it found, and what it does not trust, is its
/// finding's, in the table above: said once).
fn quality(h: &mut String, rep: &DiagnoseReport) {
    let q = &rep.data_quality;
    h.push_str("<h2>Data quality</h2>");
    if q.actions.is_empty() {
        h.push_str(
            "<p>The data-quality stage changed nothing; its finding is in the table above.</p>",
        );
    }
    let done: Vec<String> = q.actions.iter().map(|a| format!("done: {a}")).collect();
    list(h, "What the data-quality stage did", &done);
}

/// The page's charts (module docs). Without a timeline the residuals and the lamps are one
/// place that says, once, why neither is drawn.
fn charts(rep: &DiagnoseReport) -> Vec<Chart<'static>> {
    let mut v = vec![residuals_chart(rep)];
    if rep.timeline.is_empty() {
        v[0].title = "Residuals r1..r4 and the lamps over time";
    } else {
        v.push(lamps_chart(rep));
    }
    v.extend([sequence_chart(rep), rotor_chart(rep)]);
    v
}

/// The times to mark on the time charts: load moves, faults named, first detections.
fn event_times(rep: &DiagnoseReport) -> Vec<(f64, bool)> {
    let mut t: Vec<(f64, bool)> = rep
        .isolation
        .events
        .iter()
        .map(|e| (e.t_s(), matches!(e, IsolationEvent::LoadMoved { .. })))
        .collect();
    t.extend(rep.detections.iter().map(|d| (d.t_s, false)));
    t
}

/// Vertical markers at the events between `lo` and `hi` on the y axis: load moves in one
/// colour, faults named and detections in another.
fn markers(rep: &DiagnoseReport, lo: f64, hi: f64) -> Vec<Series> {
    let (moves, named): (Vec<_>, Vec<_>) = event_times(rep).into_iter().partition(|e| e.1);
    let mut v = Vec::new();
    // Colours of their own (the palette's brown and pink): not a residual's or a lamp's.
    for (label, times, color) in [
        ("load moved", moves, 6),
        ("fault named or signature matched", named, 7),
    ] {
        let mut pts = Vec::new();
        for (t, _) in times {
            // A vertical stroke per event; a NaN point lifts the pen between strokes.
            pts.extend([(t, lo), (t, hi), (f64::NAN, f64::NAN)]);
        }
        if !pts.is_empty() {
            v.push(line(label, pts, color, true));
        }
    }
    v
}

/// One line series.
fn line(label: &str, points: Vec<(f64, f64)>, color: usize, dashed: bool) -> Series {
    Series {
        label: label.to_string(),
        points,
        color,
        scatter: false,
        dashed,
    }
}

/// A time chart, or why it is not drawn when the timeline is empty.
fn time_chart(
    rep: &DiagnoseReport,
    (stem, title, y_label): (&'static str, &'static str, &'static str),
    series: Vec<Series>,
) -> Chart<'static> {
    let omitted = rep.timeline.is_empty().then(|| no_timeline(rep));
    Chart {
        stem,
        title,
        x_label: "time [s]",
        y_label,
        series,
        log_y: false,
        omitted,
        x_names: Vec::new(),
    }
}

/// Why the log has no timeline: the core's monitor did not run (what was missing is the
/// residuals' finding, in the table: not said again), or the log is shorter than one step.
fn no_timeline(rep: &DiagnoseReport) -> String {
    if rep.skipped.is_empty() {
        "Not drawn: the log is shorter than one timeline step.".to_string()
    } else {
        "Not drawn: the monitor did not run on this log (the residuals' finding above says why)."
            .to_string()
    }
}

/// The normalised residuals r1..r4 over time, in per cent, with the events marked.
fn residuals_chart(rep: &DiagnoseReport) -> Chart<'static> {
    let mut series: Vec<Series> = (0..4)
        .map(|k| {
            let pts = rep
                .timeline
                .iter()
                .map(|p| {
                    (
                        p.t_s,
                        100.0 * f64::from(p.residuals.get(k).copied().unwrap_or(0.0)),
                    )
                })
                .collect();
            line(&format!("r{}", k + 1), pts, k, false)
        })
        .collect();
    series.extend(threshold_lines(rep));
    let hi = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1.abs()))
        .filter(|y| y.is_finite())
        .fold(1.0, f64::max);
    series.extend(markers(rep, -hi, hi));
    time_chart(
        rep,
        (
            "residuals",
            "Residuals r1..r4 over time with their threshold bands (dashed), events marked",
            "residual [% of nominal]",
        ),
        series,
    )
}

/// The residuals' threshold bands in force at the log's end (`threshold_bands`), dashed in
/// grey (one legend entry, a colour of its own): each band's two edges from where it came
/// into force (the commissioning window's end, else the log's first point) to the log's
/// end. A residual outside its band lights its lamp: the chart shows why r1 lit and r2 did
/// not (the fixed bands are one, +/-3 %; the learned ones each residual's own).
fn threshold_lines(rep: &DiagnoseReport) -> Vec<Series> {
    let (Some(bands), Some(first), Some(last)) = (
        rep.threshold_bands,
        rep.timeline.first(),
        rep.timeline.last(),
    ) else {
        return Vec::new();
    };
    let from = rep
        .commissioning
        .window
        .filter(|_| {
            matches!(
                rep.commissioning.thresholds,
                monitor_api::replay::Thresholds::Learned { .. }
            )
        })
        .map_or(first.t_s, |w| w[1].max(first.t_s));
    let mut pts = Vec::new();
    for [c, w] in bands {
        for edge in [c - w, c + w] {
            let y = 100.0 * f64::from(edge);
            pts.extend([(from, y), (last.t_s, y), (f64::NAN, f64::NAN)]);
        }
    }
    vec![line("threshold bands r1..r4", pts, 5, true)]
}

/// The lamps r1..r4 and the monitor's state over time: one row each, high where lit.
fn lamps_chart(rep: &DiagnoseReport) -> Chart<'static> {
    let row = |k: usize, on: &dyn Fn(&monitor_api::replay::TimelinePoint) -> bool| {
        rep.timeline
            .iter()
            .map(|p| (p.t_s, k as f64 + if on(p) { 0.7 } else { 0.0 }))
            .collect::<Vec<_>>()
    };
    let mut series: Vec<Series> = (0..4)
        .map(|k| {
            let on = move |p: &monitor_api::replay::TimelinePoint| p.lamps.get(k) == Some(&true);
            line(&format!("r{} lit", k + 1), row(k, &on), k, false)
        })
        .collect();
    series.push(line("evaluating", row(4, &|p| p.evaluating), 4, false));
    series.push(line(
        "commissioning",
        row(5, &|p| p.commissioning),
        5,
        false,
    ));
    series.extend(markers(rep, 0.0, 6.0));
    time_chart(
        rep,
        (
            "lamps",
            "Lamps and state over time (rows from the bottom: r1..r4, evaluating, commissioning; high = on)",
            "row",
        ),
        series,
    )
}

/// The negative-sequence ratio over time, with the steady stretches' values: the monitor's
/// timeline where it ran, else (a log with the currents only) the least-squares windows'
/// ratio (`unbalance.ratio_over_time`, the legend says each window's length). Drawn
/// whenever either has a point; a series without one is left out, so every legend entry
/// is a curve.
fn sequence_chart(rep: &DiagnoseReport) -> Chart<'static> {
    let (pts, label): (Vec<(f64, f64)>, String) = if rep.timeline.is_empty() {
        let w = &rep.unbalance.ratio_over_time;
        let pts = w.iter().map(|&(t, r)| (t, 100.0 * f64::from(r))).collect();
        let mut steps: Vec<f64> = w.windows(2).map(|p| p[1].0 - p[0].0).collect();
        steps.sort_by(f64::total_cmp);
        let label = match steps.get(steps.len() / 2) {
            Some(dt) => format!("|I2|/|I1| (each {dt:.2} s window)"),
            None => "|I2|/|I1| (one window)".to_string(),
        };
        (pts, label)
    } else {
        let pts = rep
            .timeline
            .iter()
            .map(|p| (p.t_s, measured_pct(p.negative_sequence_ratio)))
            .collect();
        (pts, "|I2|/|I1|".to_string())
    };
    let mut seg = Vec::new();
    for s in &rep.unbalance.segments {
        let y = measured_pct(s.negative_sequence_ratio);
        seg.extend([(s.from_s, y), (s.to_s, y), (f64::NAN, f64::NAN)]);
    }
    let drawn = !pts.is_empty() || !seg.is_empty();
    let mut series = Vec::new();
    if !pts.is_empty() {
        series.push(line(&label, pts, 0, false));
    }
    if !seg.is_empty() {
        series.push(line("steady stretches", seg, 1, true));
    }
    let mut chart = time_chart(
        rep,
        (
            "negative_sequence",
            "Negative sequence of the currents over time",
            "|I2|/|I1| [%]",
        ),
        series,
    );
    if drawn {
        chart.omitted = None;
    }
    chart
}

/// The rotor's sidebands against the severity bands: the line at 0 dB, the `(1 -/+ 2s) f`
/// sidebands and the noise floor as read, and the upper edges of the severity bands
/// ([`RotorBand`]). Not drawn when the rotor was not judged.
fn rotor_chart(rep: &DiagnoseReport) -> Chart<'static> {
    let r = &rep.rotor;
    let f = r.supply_hz.unwrap_or(f64::NAN);
    let omitted = (!r.judged || !f.is_finite() || r.sideband_hz.len() < 2).then(|| {
        "Not drawn: the sidebands were not read (the rotor's finding above says why).".to_string()
    });
    let stem = |x: f64, y: f64| vec![(x, -90.0), (x, y)];
    let lo = r.sideband_hz.first().copied().unwrap_or(f);
    let hi = r.sideband_hz.get(1).copied().unwrap_or(f);
    let span = (lo.min(f) - 1.0, hi.max(f) + 1.0);
    let level = |l: Option<f64>| l.unwrap_or(-90.0);
    let mut series = vec![
        line("supply line (0 dB)", stem(f, 0.0), 0, false),
        line("(1-2s)f", stem(lo, level(r.level_db)), 3, false),
        line("(1+2s)f", stem(hi, level(r.upper_sideband_db)), 2, false),
    ];
    if let Some(n) = r.noise_floor_db {
        series.push(line("noise floor", vec![(span.0, n), (span.1, n)], 5, true));
    }
    // The bands' edges from the mildest up (cyan, olive, brown, red, purple): no colour
    // another entry of the chart has.
    const BAND_COLOURS: [usize; 5] = [9, 8, 6, 1, 4];
    for (band, color) in RotorBand::ALL.iter().zip(BAND_COLOURS) {
        let db = band.upper_db();
        if db.is_finite() {
            let label = format!("{} dB: below, {}", db, words::band_words(*band));
            series.push(line(&label, vec![(span.0, db), (span.1, db)], color, true));
        }
    }
    Chart {
        stem: "rotor_sidebands",
        title: "Rotor: the current's sidebands about the supply line against the severity bands",
        x_label: "frequency [Hz]",
        y_label: "level [dB re the line]",
        series,
        log_y: false,
        omitted,
        x_names: Vec::new(),
    }
}

/// HTML-escapes text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
