//! `diagnose`'s text report: the timeline, what was found, the unbalance, the
//! commissioning, the data quality and the verdict (also the demo's).

use super::{candidate_list, lamp, panel_text};
use crate::cli::words::CliWords;
use monitor_api::files::DataQuality;
use monitor_api::replay::{angle_source_name, CommissioningReport, DiagnoseReport, Diagnosed};
use monitor_api::words::diagnose::{self as words, Story};
use monitor_studies::demo::MonitorState;
use std::io::Write;
use std::path::Path;

/// The temperature channel's line (`None` for a log without the column): the reading and
/// the rise the isolation compensates Rs and Rr with, or why the channel is not used.
fn temperature_line(t: &monitor_api::replay::TemperatureReport) -> Option<String> {
    use monitor_api::replay::ChannelUse;
    let status = t.temperature_channel.as_ref()?;
    let reading = t
        .winding_temperature_c
        .map_or("no reading".to_string(), |c| format!("{c:.1} degC"));
    let not_used = match status {
        ChannelUse::NotUsed { why } => Some(words::channel_dropped(why)),
        ChannelUse::Used => None,
    };
    Some(match (not_used, t.measured_rise_k) {
        (Some(why), _) => format!(
            "temperature channel not used: {why}; heating tracked from the resistances (last reading {reading})"
        ),
        (None, Some(rise)) => format!(
            "winding temperature: {reading}, {rise:+.1} K since commissioning (temperature channel; Rs and Rr compensated, copper 0.393 %/K)"
        ),
        (None, None) => format!("winding temperature: {reading} (temperature channel)"),
    })
}

/// The verdict line of `diagnose` and the demo: the decision table's line, as the door
/// spells it for the JSON and Python too.
pub(super) fn verdict(out: &mut impl Write, rep: &DiagnoseReport) -> anyhow::Result<()> {
    writeln!(out, "verdict: {}", words::verdict_line(rep, &CliWords))?;
    Ok(())
}

/// Every analysis' finding, one line each: its source, what it concluded and against what,
/// and its sentence (the evidence the verdict's decision table read).
fn findings_block(out: &mut impl Write, rep: &DiagnoseReport, story: &Story) -> anyhow::Result<()> {
    writeln!(out, "findings:")?;
    for (f, (summary, _)) in rep.findings.iter().zip(&story.findings) {
        let named = f.named().map_or(String::new(), |n| {
            format!(
                " (confidence {:.2}; {})",
                n.confidence,
                words::against_text(f.source(), f.finding.against)
            )
        });
        writeln!(
            out,
            "  {:<16} {:<12} {summary}{named}",
            f.source().name(),
            f.state_name(),
        )?;
    }
    Ok(())
}

/// `diagnose`'s timeline, lamps, candidates, unbalance and rotor.
pub fn diagnose(mut out: &mut dyn std::io::Write, log: &Path, d: &Diagnosed) -> anyhow::Result<()> {
    let rep = &d.report;
    let story = Story::of(rep, &CliWords);
    writeln!(
        out,
        "diagnose {} ({} rows, {:.0} Hz, angle: {})",
        log.display(),
        rep.rows,
        d.sample_rate_hz,
        angle_source_name(rep.angle_source)
    )?;
    data_quality(&mut out, &rep.data_quality)?;
    commissioning(&mut out, &rep.commissioning, &story)?;
    for s in &story.skipped {
        writeln!(out, "skipped: {s}")?;
    }
    if rep.skipped.is_empty() {
        timeline(&mut out, rep, &story)?;
        findings(&mut out, rep, &story)?;
        events(&mut out, &rep.isolation)?;
    }
    unbalance(&mut out, &rep.unbalance, &story)?;
    // The rotor's finding or why there is none, in one line ("rotor: ...").
    writeln!(out, "{}", story.rotor)?;
    for (n, note) in rep
        .commissioning
        .outside_range
        .iter()
        .zip(&story.outside_range)
    {
        writeln!(out, "note at {:.2} s: {note}", n.t_s)?;
    }
    findings_block(&mut out, rep, &story)?;
    writeln!(out, "verdict: {}", story.verdict_line)?;
    Ok(())
}

/// The timeline's header: each column over its values, the speed with its unit, as the
/// demo's `speed rpm` (the time's unit is beside each value; the residuals are normalised).
const TIMELINE_HEADER: &str = "    time speed rad/s  r1      r2      r3      r4       lamps state";

/// A timeline row's time [s], speed [rad/s] and residuals, under [`TIMELINE_HEADER`].
fn timeline_cells(t_s: f64, speed_rad_s: f32, r: [f32; 4]) -> String {
    format!(
        "{t_s:6.2} s {speed_rad_s:11.1}  {:+.4} {:+.4} {:+.4} {:+.4}",
        r[0], r[1], r[2], r[3]
    )
}

/// The timeline: time [s], the mechanical speed [rad/s], residuals, lamps and the panel's
/// state per point.
fn timeline(out: &mut impl Write, rep: &DiagnoseReport, story: &Story) -> anyhow::Result<()> {
    writeln!(out, "\n{TIMELINE_HEADER}")?;
    for (p, note) in rep.timeline.iter().zip(&story.timeline_notes) {
        let lamps: String = p.lamps.iter().map(|l| lamp(*l)).collect();
        writeln!(
            out,
            "{}  {lamps}  {}{}",
            timeline_cells(p.t_s, p.speed_rad_s, p.residuals),
            panel_text(&p.panel),
            note.as_ref()
                .filter(|_| !matches!(p.panel.state, MonitorState::Moved(_)))
                .map(|n| format!("  [{n}]"))
                .unwrap_or_default()
        )?;
    }
    Ok(())
}

/// What the run found: the final lamps, the first detection, the candidates, the
/// isolation's verdict with its detection limits, the temperature, what cannot be
/// separated.
fn findings(out: &mut impl Write, rep: &DiagnoseReport, story: &Story) -> anyhow::Result<()> {
    let lit: Vec<&str> = rep
        .lamps
        .iter()
        .filter(|(_, v)| **v)
        .map(|(k, _)| k.as_str())
        .collect();
    writeln!(
        out,
        "\nfinal lamps: {}",
        if lit.is_empty() {
            "none".to_string()
        } else {
            lit.join(" ")
        }
    )?;
    first_detection(out, rep, story)?;
    writeln!(out, "candidates: {}", candidate_list(&rep.candidates))?;
    writeln!(
        out,
        "lamps' candidates (signature matching): {}",
        candidate_list(&rep.signature_candidates)
    )?;
    writeln!(out, "isolation: {}", story.isolation)?;
    if let Some(line) = detection_limits_line(&rep.isolation.detection_limits) {
        writeln!(out, "{line}")?;
    }
    if let Some(line) = temperature_line(&rep.isolation.temperature) {
        writeln!(out, "{line}")?;
    }
    for (g, reason) in rep.isolation.groups.iter().zip(&story.groups) {
        writeln!(
            out,
            "  cannot be separated: {} ({reason})",
            g.faults
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(" / "),
        )?;
    }
    Ok(())
}

/// When the lamps first lit, as the verdict reads it: a detection where the residual finding
/// is one, else what the lamps lit for (the operating point's load move or heating, the
/// load outside the commissioned range), which is not a detection of a fault.
fn first_detection(
    out: &mut impl Write,
    rep: &DiagnoseReport,
    story: &Story,
) -> anyhow::Result<()> {
    use monitor_core::verdict::{FindingSource, State};
    let of = |s: FindingSource| rep.findings.iter().find(|f| f.source() == s);
    let summary_of = |s: FindingSource| {
        rep.findings
            .iter()
            .position(|f| f.source() == s)
            .and_then(|k| story.findings.get(k))
            .map(|(summary, _)| summary.as_str())
    };
    let residual = of(FindingSource::Residuals).map(|f| f.finding.state);
    match (rep.first_detection_s, residual) {
        (None, _) => writeln!(out, "first detection: none")?,
        (Some(t), Some(State::Explained)) => writeln!(
            out,
            "lamps lit: first at {t:.2} s, explained by the operating point ({}), not a fault detection",
            summary_of(FindingSource::OperatingPoint).unwrap_or("a load move or heating")
        )?,
        (Some(t), Some(State::OutOfRange)) => writeln!(
            out,
            "lamps lit: first at {t:.2} s, only outside the commissioned load or voltage range, not a fault detection"
        )?,
        (Some(t), _) => writeln!(out, "first detection: {t:.2} s")?,
    }
    Ok(())
}

/// The healthy verdict's detection limits in a line (none without them).
fn detection_limits_line(limits: &[monitor_api::replay::DetectionLimit]) -> Option<String> {
    (!limits.is_empty()).then(|| {
        format!(
            "  smallest changes the isolation detects at the commissioned point (smaller ones pass as healthy; a FAULT also needs {:.0} %): {}",
            100.0 * monitor_api::replay::MIN_FAULT_CHANGE,
            limits
                .iter()
                .map(|l| format!("{} {}", l.fault.name(), limit_pct(l.change)))
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

/// A detection limit in per cent with two significant digits (0.106 -> "11 %",
/// 0.0016 -> "0.16 %").
fn limit_pct(change: f32) -> String {
    let p = 100.0 * change;
    if p >= 10.0 {
        format!("{p:.0} %")
    } else if p >= 1.0 {
        format!("{p:.1} %")
    } else {
        format!("{p:.2} %")
    }
}

/// Segments of the negative sequence the text report lists (the JSON has up to
/// the replay's own limit of segments).
const SEGMENTS_LISTED: usize = 8;

/// The negative-sequence analysis: the whole log's ratio and phase, its steady stretches,
/// and the winding's judgement in a sentence.
fn unbalance(
    out: &mut impl Write,
    u: &monitor_api::replay::UnbalanceReport,
    story: &Story,
) -> anyhow::Result<()> {
    writeln!(
        out,
        "unbalance: |I2|/|I1| = {}, suspect phase: {}",
        words::sequence_ratio(u.negative_sequence_ratio),
        words::suspect(u)
    )?;
    if u.segments.len() > 1 {
        stretches(out, u)?;
    }
    // A named phase with its reference; else the findings below say the winding's
    // sentence, once.
    if let Some(line) = words::winding_line(u, &CliWords).filter(|_| u.suspect_phase.is_some()) {
        writeln!(out, "winding: {line}")?;
    }
    shorted_turns(out, u)?;
    // (Where no phase is named the winding's sentence above says it already.)
    if let (Some(w), Some(_)) = (&story.least_change_widened, u.suspect_phase) {
        writeln!(out, "  {w}")?;
    }
    Ok(())
}

/// How many turns are shorted, and the model's own estimate where a calibration gave it.
fn shorted_turns(
    out: &mut impl Write,
    u: &monitor_api::replay::UnbalanceReport,
) -> anyhow::Result<()> {
    if let Some(t) = &u.shorted_turns {
        writeln!(out, "  {}", words::shorted_turns(t))?;
    }
    if let (Some(c), Some(p)) = (&u.shorted_turns, &u.shorted_turns_physics) {
        if c.basis != p.basis {
            writeln!(out, "  (the model alone: {})", words::shorted_turns(p))?;
        }
    }
    Ok(())
}

/// The steady stretches of the negative sequence (the first [`SEGMENTS_LISTED`]), the
/// judged one marked.
fn stretches(out: &mut impl Write, u: &monitor_api::replay::UnbalanceReport) -> anyhow::Result<()> {
    writeln!(out, "  steady stretches (least-squares phasors):")?;
    for (k, s) in u.segments.iter().enumerate().take(SEGMENTS_LISTED) {
        writeln!(
            out,
            "    at {:.2}..{:.2} s: |I1| {:.3} A, I2/I1 {} at {:.0} deg{}",
            s.from_s,
            s.to_s,
            s.i1_peak_a,
            words::sequence_ratio(s.negative_sequence_ratio),
            s.angle_deg,
            if u.judged_segment == Some(k) {
                "  <- judged"
            } else {
                ""
            }
        )?;
    }
    if u.segments.len() > SEGMENTS_LISTED {
        writeln!(
            out,
            "    ... {} more (--json lists them)",
            u.segments.len() - SEGMENTS_LISTED
        )?;
    }
    Ok(())
}

/// Most load moves the text report lists (every name is listed; `--json` has up to
/// [`monitor_api::replay::MAX_EVENTS`] events).
const LOAD_MOVES_LISTED: usize = 10;

/// The isolation's events with their times: every name, and the first
/// [`LOAD_MOVES_LISTED`] load moves.
fn events(out: &mut impl Write, iso: &monitor_api::replay::IsolationReport) -> anyhow::Result<()> {
    use monitor_api::replay::IsolationEvent;
    if iso.events.is_empty() {
        return Ok(());
    }
    let moves = iso
        .events
        .iter()
        .filter(|e| matches!(e, IsolationEvent::LoadMoved { .. }))
        .count();
    writeln!(out, "events:")?;
    let mut listed = 0;
    for e in &iso.events {
        if matches!(e, IsolationEvent::LoadMoved { .. }) {
            listed += 1;
            if listed > LOAD_MOVES_LISTED {
                continue;
            }
        }
        writeln!(out, "  {}", words::event_line(e))?;
    }
    let more = moves.saturating_sub(LOAD_MOVES_LISTED) + iso.events_dropped;
    if more > 0 {
        writeln!(
            out,
            "  ... and {more} more load moves (diagnose --json lists the first 200 events)"
        )?;
    }
    Ok(())
}

/// The data-quality stage's finding in one line, and what was done about it.
pub(super) fn data_quality(out: &mut impl Write, q: &DataQuality) -> anyhow::Result<()> {
    writeln!(out, "data quality: {}", q.summary())?;
    for a in &q.actions {
        writeln!(out, "  done: {a}")?;
    }
    if !q.trusted {
        writeln!(out, "  NOT TRUSTED: {}", q.not_trusted_because.join("; "))?;
    }
    Ok(())
}

/// What `diagnose` did about its thresholds.
fn commissioning(
    out: &mut impl Write,
    c: &CommissioningReport,
    story: &Story,
) -> anyhow::Result<()> {
    // (Where the residuals never ran the log's `skipped:` line says why, once.)
    if c.thresholds != monitor_api::replay::Thresholds::NotUsed {
        writeln!(out, "thresholds: {}", story.thresholds)?;
    }
    if c.state == monitor_api::replay::CommissioningOutcome::Learned {
        let span = |s: Option<[f32; 2]>, u: &str| {
            s.map(|[a, b]| format!("{a:.1}..{b:.1} {u}"))
                .unwrap_or_else(|| "-".into())
        };
        writeln!(
            out,
            "  learned {:.2} s of evaluated running; load (active current) {}, voltage |V| {}",
            c.seconds_evaluated,
            span(c.load_current_a, "A"),
            span(c.voltage_v, "V")
        )?;
    }
    if let Some(p) = &c.first_quasi_steady {
        let r = p.residuals;
        writeln!(
            out,
            "  first quasi-steady point {:.2} s: r1..r4 = {:+.4} {:+.4} {:+.4} {:+.4}",
            p.t_s, r[0], r[1], r[2], r[3]
        )?;
    }
    if let Some(a) = &story.advice {
        writeln!(out, "  {a}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 65: the speed column says its unit, and every header stands over its column.
    #[test]
    fn the_timeline_header_gives_the_speed_its_unit_over_its_column() {
        let row = format!(
            "{}  {}  healthy",
            timeline_cells(12.5, 150.25, [0.0001, -0.0123, 0.5, -0.25]),
            "○●○○"
        );
        let h = TIMELINE_HEADER;
        assert!(h.contains("speed rad/s"), "{h}");
        let col = |s: &str, at: &str| s.find(at).unwrap_or(usize::MAX);
        let chars = |s: &str, at: usize| s[..at].chars().count();
        // Right-aligned numbers end under their header's end; the rest start under it.
        assert_eq!(col(h, "time") + 4, col(&row, "12.50 s") + 7, "{h}\n{row}");
        assert_eq!(col(h, "rad/s") + 5, col(&row, "150.2") + 5, "{h}\n{row}");
        for (label, value) in [
            ("r1", "+0.0001"),
            ("r2", "-0.0123"),
            ("r3", "+0.5000"),
            ("r4", "-0.2500"),
        ] {
            assert_eq!(col(h, label), col(&row, value), "{label}: {h}\n{row}");
        }
        assert_eq!(
            chars(h, col(h, "lamps")),
            chars(&row, col(&row, "○●")),
            "{h}\n{row}"
        );
        assert_eq!(
            chars(h, col(h, "state")),
            chars(&row, col(&row, "healthy")),
            "{h}\n{row}"
        );
    }
}
