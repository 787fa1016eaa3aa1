//! The text renderer: the human tables of every command, written to stdout through
//! [`crate::cli::stdout`] (a closed pipe or a full disk is an error that `main` recognises, not
//! a panic).

use super::json::Table1Report;
use monitor_core::{IsolationState, Phase};
use sim_host::analysis::compare::CompareReport;
use sim_host::analysis::explain::ExplainReport;
use sim_host::demo::{DemoRun, MonitorState};
use sim_host::hmi::IsolationView;
use sim_host::log::quality::DataQuality;
use sim_host::replay::{
    angle_source_name, state_name, CommissioningReport, DiagnoseReport, Diagnosed, IsolationName,
    Panel, Verdict,
};
use sim_host::sim::SimSummary;
use std::io::Write;
use std::path::Path;

/// A lamp as a character: lit or dark.
fn lamp(on: bool) -> &'static str {
    if on {
        "●"
    } else {
        "○"
    }
}

/// A number for the tables (NaN as "-").
fn number(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        "-".into()
    }
}

/// The demo's timeline and conclusion.
pub fn demo(run: &DemoRun) -> anyhow::Result<()> {
    use sim_host::demo::{Story, LOAD_BACK_AT_S, LOAD_STEP_AT_S, LOAD_STEP_SCALE};
    let mut out = crate::cli::stdout();
    let fault = format!("{} {:+.0} %", run.fault.name(), 100.0 * run.change);
    match run.story {
        Story::Service { .. } => writeln!(
            out,
            "3 hp induction motor, 220 V 60 Hz, started direct-on-line; 12-bit sensors with noise; the load is\n\
             an unknown input, as in service. Commissioning 2.0-4.0 s learns the healthy motor; the load rises\n\
             {:.0} % at {LOAD_STEP_AT_S:.1} s and falls back at {LOAD_BACK_AT_S:.1} s; at {:.1} s: {fault}.\n",
            100.0 * (LOAD_STEP_SCALE - 1.0),
            run.fault_at_s,
        )?,
        Story::Paper { .. } => writeln!(
            out,
            "3 hp induction motor, 220 V 60 Hz, direct-on-line start, the paper's fixed viscous load; 12-bit\n\
             sensors with noise. Commissioning 2.0-4.0 s learns the healthy residuals; at {:.1} s: {fault}.\n",
            run.fault_at_s,
        )?,
    }
    writeln!(out, "  time   speed rpm   r1 r2 r3 r4   state")?;
    for p in &run.points {
        let state = panel_text(&p.panel);
        let mark = match (p.fault_injected, p.load_step) {
            (true, _) => "  <- fault injected".to_string(),
            (false, Some(k)) if k > 1.0 => format!("  <- load +{:.0} %", 100.0 * (k - 1.0)),
            (false, Some(_)) => "  <- load back".to_string(),
            (false, None) => String::new(),
        };
        let l = p.lamps.map(lamp);
        writeln!(
            out,
            "{:5.2} s  {:7.0}     {}  {}  {}  {}   {state}{mark}",
            p.t_s, p.speed_rpm, l[0], l[1], l[2], l[3]
        )?;
    }
    writeln!(out)?;
    for e in &run.report.isolation.events {
        if matches!(e, sim_host::replay::IsolationEvent::LoadMoved { .. }) {
            writeln!(out, "event: {} (not a fault)", e.line().trim())?;
        }
    }
    match run.detected_after_s() {
        Some(t) => writeln!(
            out,
            "detected {t:.2} s after the fault was injected (the first red FAULT state)"
        )?,
        None => writeln!(out, "the injected fault never lit the red FAULT state")?,
    }
    writeln!(
        out,
        "lamps' candidates (the paper's signature matching): {}",
        candidate_list(&run.report.signature_candidates)
    )?;
    writeln!(
        out,
        "fault candidates (isolation, with size): {}{}",
        candidate_list(&run.report.candidates),
        if run.correct_fault_named() {
            "  — the injected fault is named"
        } else {
            ""
        }
    )?;
    writeln!(out, "isolation: {}", run.report.isolation.verdict)?;
    if matches!(run.fault, monitor_core::Fault::B | monitor_core::Fault::Bl) {
        writeln!(
            out,
            "note: B and Bl scale one load term (B + Bl) w: to the paper's model a friction change is a load \
             change. With the load an unknown input (service, the default) it is a load move, never a fault; \
             under the paper's fixed viscous load (--paper) it is the fault b/bl, and B and Bl cannot be told apart."
        )?;
    }
    verdict(&mut out, &run.report)
}

/// The temperature channel's line (`None` for a log without the column): the reading and
/// the rise the isolation compensates Rs and Rr with, or why the channel is not used.
fn temperature_line(t: &sim_host::replay::TemperatureReport) -> Option<String> {
    let status = t.temperature_channel.as_deref()?;
    let reading = t
        .winding_temperature_c
        .map_or("no reading".to_string(), |c| format!("{c:.1} degC"));
    Some(match (status.strip_prefix("not used: "), t.measured_rise_k) {
        (Some(why), _) => format!(
            "temperature channel not used: {why}; heating tracked from the resistances (last reading {reading})"
        ),
        (None, Some(rise)) => format!(
            "winding temperature: {reading}, {rise:+.1} K since commissioning (temperature channel; Rs and Rr compensated, copper 0.393 %/K)"
        ),
        (None, None) => format!("winding temperature: {reading} (temperature channel)"),
    })
}

/// Candidates as `rr p 0.76 (rr +50 %), speed_sensor p 0.24 (speed_sensor -2 %)`, or `none`.
fn candidate_list(c: &[sim_host::replay::FaultCandidate]) -> String {
    if c.is_empty() {
        return "none".into();
    }
    sim_host::fault_signatures::candidates_text(
        c.iter().map(|c| (c.fault, c.probability, c.change)),
    )
    .join(", ")
}

/// `simulate`'s one-line summary.
pub fn simulate(path: &Path, wall_s: f64, s: &SimSummary) -> anyhow::Result<()> {
    writeln!(
        crate::cli::stdout(),
        "wrote {} rows ({} s at {} Hz) to {} in {:.2} s; final speed {:.2} rad/s, slip {:.4}",
        s.rows,
        s.duration_s,
        s.sample_rate_hz,
        path.display(),
        wall_s,
        s.final_wm_rad_s,
        s.final_slip
    )?;
    Ok(())
}

/// `convert`'s one line.
pub fn convert(c: &crate::cli::convert::Converted) -> anyhow::Result<()> {
    writeln!(
        crate::cli::stdout(),
        "converted {} ({}) to {} ({}): {} rows, {:.1} MB, in {:.2} s",
        c.input,
        c.input_format,
        c.output,
        c.output_format,
        c.rows,
        c.output_bytes as f64 / 1e6,
        c.wall_s
    )?;
    Ok(())
}

/// The state column of a demo or `diagnose` timeline point: the HMI's lamp word and header
/// ([`sim_host::hmi::lamp_and_header`]), so the three say the same state, fault and size.
fn panel_text(p: &Panel) -> String {
    let candidates = match &p.state {
        MonitorState::Fault(c) => c.as_slice(),
        _ => &[],
    };
    let iso = p.isolation.as_ref().map(|(r, c)| IsolationView::new(r, c));
    let (lamp, text) = sim_host::hmi::lamp_and_header(
        &p.state,
        p.fault_lamp,
        Some(p.call),
        candidates,
        iso.as_ref(),
    );
    if lamp.is_empty() {
        text
    } else {
        format!("{lamp} {text}")
    }
}

/// The verdict line of `diagnose` and the demo.
fn verdict(out: &mut impl Write, rep: &DiagnoseReport) -> anyhow::Result<()> {
    let u = &rep.unbalance;
    if let (Verdict::Fault, Some(p), Some(_)) = (rep.verdict, u.suspect_phase, u.baseline) {
        let also = if rep.verdict_withheld_because.is_empty() {
            String::new()
        } else {
            format!("; not judged: {}", rep.verdict_withheld_because.join("; "))
        };
        let named = named_fault(rep);
        writeln!(
            out,
            "verdict: FAULT{}{} shorted turns in phase {} (the negative sequence changed by {:.1} % of I1, confidence {:.2}){also}",
            named,
            if named.is_empty() { "" } else { " and" },
            p.name(),
            100.0 * u.winding_ratio,
            u.phase_confidence
        )?;
        return Ok(());
    }
    match rep.verdict {
        Verdict::Fault if rep.lamps.values().any(|l| *l) || !rep.candidates.is_empty() => {
            writeln!(out, "verdict: FAULT{}", named_fault(rep))?
        }
        // Dark lamps and no candidate at the end: say what the verdict rests on.
        Verdict::Fault => writeln!(
            out,
            "verdict: FAULT: the lamps lit at {}{}; they are dark at the end and the isolation names no single fault",
            rep.first_detection_s
                .map_or("-".into(), |t| format!("{t:.2} s")),
            if rep.detections.is_empty() {
                String::new()
            } else {
                format!(
                    " (the lamps' matching named {})",
                    rep.detections
                        .iter()
                        .map(|d| format!("{} at {:.2} s", IsolationName::expected(d.fault), d.t_s))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        )?,
        Verdict::Healthy => writeln!(out, "verdict: healthy")?,
        Verdict::Watching => writeln!(
            out,
            "verdict: {}",
            rep.verdict_withheld_because.join("; ")
        )?,
        Verdict::CouldNotJudge => writeln!(
            out,
            "verdict: could not judge: {}",
            rep.verdict_withheld_because.join("; ")
        )?,
    }
    Ok(())
}

/// The fault the isolation named, with its size and phase, as ` rs +50 %` (empty when it
/// named none).
fn named_fault(rep: &DiagnoseReport) -> String {
    let Some(IsolationName::Fault(f)) = rep.isolation.named else {
        return String::new();
    };
    let c = rep.candidates.iter().find(|c| c.fault == f);
    let size = c
        .and_then(|c| c.change)
        .or(rep.isolation.named_change)
        .map_or(String::new(), |x| format!(" {:+.0} %", 100.0 * x));
    let phase = c
        .and_then(|c| c.phase)
        .map_or(String::new(), |p| format!(" (phase {})", p.name()));
    format!(" {}{size}{phase}", f.name())
}

/// `diagnose`'s timeline, lamps, candidates and unbalance.
pub fn diagnose(log: &Path, d: &Diagnosed) -> anyhow::Result<()> {
    let rep = &d.report;
    let mut out = crate::cli::stdout();
    writeln!(
        out,
        "diagnose {} ({} rows, {:.0} Hz, angle: {})",
        log.display(),
        rep.rows,
        d.sample_rate_hz,
        angle_source_name(rep.angle_source)
    )?;
    data_quality(&mut out, &rep.data_quality)?;
    commissioning(&mut out, &rep.commissioning)?;
    for s in &rep.skipped {
        writeln!(out, "skipped: {s}")?;
    }
    if rep.skipped.is_empty() {
        writeln!(
            out,
            "\n  time    speed   r1      r2      r3      r4      lamps     state"
        )?;
        for p in &rep.timeline {
            let lamps: String = p.lamps.iter().map(|l| lamp(*l)).collect();
            let r = p.residuals;
            writeln!(
                out,
                "{:6.2} s {:6.1} {:+.4} {:+.4} {:+.4} {:+.4}  {lamps}  {}{}",
                p.t_s,
                p.speed_rad_s,
                r[0],
                r[1],
                r[2],
                r[3],
                panel_text(&p.panel),
                p.range_note
                    .as_ref()
                    .filter(|_| !matches!(p.panel.state, MonitorState::Moved(_)))
                    .map(|n| format!("  [{n}]"))
                    .unwrap_or_default()
            )?;
        }
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
        match rep.first_detection_s {
            Some(t) => writeln!(out, "first detection: {t:.2} s")?,
            None => writeln!(out, "first detection: none")?,
        }
        writeln!(out, "candidates: {}", candidate_list(&rep.candidates))?;
        writeln!(
            out,
            "lamps' candidates (signature matching): {}",
            candidate_list(&rep.signature_candidates)
        )?;
        writeln!(out, "isolation: {}", rep.isolation.verdict)?;
        if let Some(line) = detection_limits_line(&rep.isolation.detection_limits) {
            writeln!(out, "{line}")?;
        }
        if let Some(line) = temperature_line(&rep.isolation.temperature) {
            writeln!(out, "{line}")?;
        }
        for g in &rep.isolation.groups {
            writeln!(
                out,
                "  cannot be separated: {} ({})",
                g.faults
                    .iter()
                    .map(|f| f.name())
                    .collect::<Vec<_>>()
                    .join(" / "),
                g.reason
            )?;
        }
        events(&mut out, &rep.isolation)?;
    }
    unbalance(&mut out, &rep.unbalance)?;
    for n in &rep.commissioning.outside_range {
        writeln!(out, "note at {:.2} s: {}", n.t_s, n.note)?;
    }
    verdict(&mut out, rep)
}

/// The healthy verdict's detection limits in a line (none without them).
fn detection_limits_line(limits: &[sim_host::replay::DetectionLimit]) -> Option<String> {
    (!limits.is_empty()).then(|| {
        format!(
            "  smallest changes the isolation detects at the commissioned point (smaller ones pass as healthy; a FAULT also needs {:.0} %): {}",
            100.0 * sim_host::replay::MIN_FAULT_CHANGE,
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
/// `sim_host::replay::winding::MAX_SEGMENTS`).
const SEGMENTS_LISTED: usize = 8;

/// The negative-sequence analysis: the whole log's ratio and phase, its steady stretches,
/// and the winding's judgement in a sentence.
fn unbalance(out: &mut impl Write, u: &sim_host::replay::UnbalanceReport) -> anyhow::Result<()> {
    writeln!(
        out,
        "unbalance: |I2|/|I1| = {:.2} %, suspect phase: {}",
        100.0 * u.negative_sequence_ratio,
        u.suspect_phase.map_or("none", Phase::name)
    )?;
    if u.segments.len() > 1 {
        writeln!(out, "  steady stretches (least-squares phasors):")?;
        for (k, s) in u.segments.iter().enumerate().take(SEGMENTS_LISTED) {
            writeln!(
                out,
                "    at {:.2}..{:.2} s: |I1| {:.3} A, I2/I1 {:.1} % at {:.0} deg{}",
                s.from_s,
                s.to_s,
                s.i1_peak_a,
                100.0 * s.negative_sequence_ratio,
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
    }
    let against = match (u.baseline, u.baseline_runs) {
        (Some(sim_host::replay::BaselineSource::File), 1) => "against 1 healthy run".to_string(),
        (Some(sim_host::replay::BaselineSource::File), n) => format!(
            "against the mean of {n} healthy runs (their spread {:.1} %)",
            100.0 * u.baseline_spread.unwrap_or(0.0)
        ),
        (Some(sim_host::replay::BaselineSource::Commissioning), _) => {
            "against the commissioning window".to_string()
        }
        (None, _) => "with no healthy baseline".to_string(),
    };
    let reference = u.operating_point.map(|o| {
        format!(
            "reference angle {:.0} +/- {:.0} deg, {}",
            u.correction_deg,
            u.correction_uncertainty_deg,
            o.describe()
        )
    });
    match (u.suspect_phase, &u.phase_not_judged) {
        (Some(p), _) => writeln!(
            out,
            "winding: shorted turns in phase {} (confidence {:.2}): the negative sequence changed by {:.1} % of I1 {against}, least change {:.1} %; {}",
            p.name(),
            u.phase_confidence,
            100.0 * u.winding_ratio,
            100.0 * u.least_change,
            reference.unwrap_or_default()
        )?,
        (None, Some(why)) => writeln!(out, "winding: {why}")?,
        (None, None) => {}
    }
    Ok(())
}

/// Most load moves the text report lists (every name is listed; `--json` has up to
/// [`sim_host::replay::MAX_EVENTS`] events).
const LOAD_MOVES_LISTED: usize = 10;

/// The isolation's events with their times: every name, and the first
/// [`LOAD_MOVES_LISTED`] load moves.
fn events(out: &mut impl Write, iso: &sim_host::replay::IsolationReport) -> anyhow::Result<()> {
    use sim_host::replay::IsolationEvent;
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
        writeln!(out, "  {}", e.line())?;
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
fn data_quality(out: &mut impl Write, q: &DataQuality) -> anyhow::Result<()> {
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
fn commissioning(out: &mut impl Write, c: &CommissioningReport) -> anyhow::Result<()> {
    writeln!(out, "thresholds: {}", c.thresholds)?;
    if c.state == sim_host::replay::CommissioningOutcome::Learned {
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
    if let Some(a) = &c.advice {
        writeln!(out, "  {a}")?;
    }
    Ok(())
}

/// The data-quality stage's warnings on stderr, one line each.
pub fn quality_warnings(q: &DataQuality) {
    let mut err = std::io::stderr().lock();
    for w in &q.warnings {
        let _ = writeln!(err, "warning: {w}");
    }
    if !q.trusted {
        let _ = writeln!(
            err,
            "warning: no verdict from this log: {}",
            q.not_trusted_because.join("; ")
        );
    }
}

/// `table1`'s measured signatures beside the paper's and the physical ones.
pub fn table1(t: &Table1Report) -> anyhow::Result<()> {
    let mut out = crate::cli::stdout();
    writeln!(
        out,
        "Table 1 end to end — {}, angle: {}",
        t.motor, t.angle_source
    )?;
    writeln!(out, "fault           change   measured r1 r2 r3 r4   paper r1 r2 r3 r4   physics r1 r2 r3 r4   isolation (size)       lamps' candidates")?;
    let bits = |s: &[u8; 4]| s.map(|b| if b == 1 { "I" } else { "0" });
    for r in &t.rows {
        let (m, p, e) = (bits(&r.signature), bits(&r.paper), bits(&r.expected));
        let diff = if r.signature == r.paper { " " } else { "*" };
        let cands: Vec<String> = r
            .candidates
            .iter()
            .map(|c| format!("{} {:.0}%", c.fault, 100.0 * c.probability))
            .collect();
        writeln!(
            out,
            "{:<15} {:+5.0} %        {}  {}  {}  {}          {}  {}  {}  {} {diff}          {}  {}  {}  {}   {:<22} {}",
            r.fault.name(),
            100.0 * r.change,
            m[0],
            m[1],
            m[2],
            m[3],
            p[0],
            p[1],
            p[2],
            p[3],
            e[0],
            e[1],
            e[2],
            e[3],
            match (r.named, r.named_change) {
                (Some(IsolationName::Fault(n)), Some(c)) => format!("{n} ({:+.0} %)", 100.0 * c),
                (Some(n), _) => n.to_string(),
                (None, _) if r.isolation_state == IsolationState::Isolated => {
                    "not alone".to_string()
                }
                (None, _) => format!("none ({})", state_name(r.isolation_state)),
            },
            if cands.is_empty() { "none".to_string() } else { cands.join(", ") }
        )?;
    }
    let phys = t.rows.iter().filter(|r| r.signature == r.expected).count();
    writeln!(
        out,
        "\n{} of {n} rows equal the paper's Table 1, {phys} of {n} the physically expected signature \
         ('I' = residual moves; '*' = differs from the paper; see docs/paper-errata.md for why).",
        t.matches_paper,
        n = t.rows.len()
    )?;
    Ok(())
}

/// The effects of a model, as the text tables name it: `bare` without effects, else
/// `prefix` and the names joined by `sep`.
fn model_name(effects: &[monitor_core::EffectKind], bare: &str, prefix: &str, sep: &str) -> String {
    if effects.is_empty() {
        bare.to_string()
    } else {
        let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
        format!("{prefix}{}", names.join(sep))
    }
}

/// `compare`'s errors, worst windows and fitted values.
pub fn compare(log: &Path, r: &CompareReport) -> anyhow::Result<()> {
    let mut out = crate::cli::stdout();
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
    if !r.worst_windows.is_empty() {
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
    }
    for a in &r.advice {
        writeln!(out, "  advice: {a}")?;
    }
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
    for w in &r.implausible_because {
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
        writeln!(out, "  {w}")?;
    }
    for s in &r.skipped {
        writeln!(out, "  skipped: {s}")?;
    }
    writeln!(out, "  unbalance: {}", r.unbalance.summary)?;
    Ok(())
}

/// `explain`'s ranking and verdict.
pub fn explain(log: &Path, r: &ExplainReport) -> anyhow::Result<()> {
    let mut out = crate::cli::stdout();
    writeln!(out, "explain {}", log.display())?;
    data_quality(&mut out, &r.data_quality)?;
    writeln!(
        out,
        "  model as configured: {}; error {} (held-back {}), noise floor {}",
        model_name(&r.effects, "paper's model", "", ","),
        number(r.baseline_normalized_rms_error),
        number(r.baseline_validation_normalized_rms_error),
        number(r.noise_floor)
    )?;
    // The answer first, then how it was reached.
    writeln!(out, "{}", r.verdict)?;
    writeln!(
        out,
        "  ranking: the plausible fits by the error they leave on the held-back part of the log, then the fits whose parameters are not physical (a fit that explains much with an impossible value is no explanation)"
    )?;
    writeln!(
        out,
        "  {:<4} {:<18} {:>10} {:>10} {:>10}  fitted",
        "rank", "effect", "error", "held-back", "explained"
    )?;
    for (i, k) in r.ranking.iter().enumerate() {
        writeln!(
            out,
            "  {:<4} {:<18} {:>10} {:>10} {:>9.0}%  {}",
            i + 1,
            k.effect.name(),
            number(k.normalized_rms_error),
            number(k.validation_normalized_rms_error),
            100.0 * k.explained_fraction,
            k.summary
        )?;
        for w in &k.implausible_because {
            writeln!(out, "       not plausible: {w}")?;
        }
    }
    for s in &r.skipped {
        writeln!(out, "  skipped: {s}")?;
    }
    writeln!(out, "  unbalance: {}", r.unbalance.summary)?;
    if let Some(words) = r.base_refit.as_ref().map(|b| b.in_words()) {
        if !words.is_empty() {
            writeln!(out, "  {words}")?;
        }
    }
    Ok(())
}
