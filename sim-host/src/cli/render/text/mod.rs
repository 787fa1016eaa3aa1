//! The text renderer: the human tables of every command, written to stdout through
//! [`crate::cli::out::stdout`] (a closed pipe or a full disk is an error that `main` recognises, not
//! a panic).

mod analysis;
mod diagnose;

pub use analysis::{compare, explain, ladder};
pub use diagnose::diagnose;

use super::json::{Converted, Table1Report};
use diagnose::verdict;
use monitor_api::files::DataQuality;
use monitor_api::replay::{state_name, IsolationName, Panel};
use monitor_api::sim::SimSummary;
use monitor_core::IsolationState;
use monitor_studies::demo::{DemoRun, MonitorState};
use sim_host::hmi::IsolationView;
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
pub fn demo(mut out: &mut dyn std::io::Write, run: &DemoRun) -> anyhow::Result<()> {
    demo_story(&mut out, run)?;
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
    demo_conclusion(&mut out, run)?;
    verdict(&mut out, &run.report)
}

/// The demo's story: the motor, the load, the commissioning and the fault.
fn demo_story(out: &mut impl Write, run: &DemoRun) -> anyhow::Result<()> {
    use monitor_studies::demo::{DemoStory, LOAD_BACK_AT_S, LOAD_STEP_AT_S, LOAD_STEP_SCALE};
    let fault = format!("{} {:+.0} %", run.fault.name(), 100.0 * run.change);
    match run.story {
        DemoStory::Service { .. } => writeln!(
            out,
            "3 hp induction motor, 220 V 60 Hz, started direct-on-line; 12-bit sensors with noise; the load is\n\
             an unknown input, as in service. Commissioning 2.0-4.0 s learns the healthy motor; the load rises\n\
             {:.0} % at {LOAD_STEP_AT_S:.1} s and falls back at {LOAD_BACK_AT_S:.1} s; at {:.1} s: {fault}.\n",
            100.0 * (LOAD_STEP_SCALE - 1.0),
            run.fault_at_s,
        )?,
        DemoStory::Paper { .. } => writeln!(
            out,
            "3 hp induction motor, 220 V 60 Hz, direct-on-line start, the paper's fixed viscous load; 12-bit\n\
             sensors with noise. Commissioning 2.0-4.0 s learns the healthy residuals; at {:.1} s: {fault}.\n",
            run.fault_at_s,
        )?,
    }
    Ok(())
}

/// What the demo concluded: the load moves, when the fault was detected, the candidates,
/// the isolation, and a note on the friction class.
fn demo_conclusion(out: &mut impl Write, run: &DemoRun) -> anyhow::Result<()> {
    for e in &run.report.isolation.events {
        if matches!(e, monitor_api::replay::IsolationEvent::LoadMoved { .. }) {
            writeln!(
                out,
                "event: {} (not a fault)",
                monitor_api::words::diagnose::event_line(e).trim()
            )?;
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
    writeln!(
        out,
        "isolation: {}",
        monitor_api::words::diagnose::said(
            &run.report.isolation.said,
            &crate::cli::words::CliWords
        )
    )?;
    if matches!(run.fault, monitor_core::Fault::B | monitor_core::Fault::Bl) {
        writeln!(
            out,
            "note: B and Bl scale one load term (B + Bl) w: to the paper's model a friction change is a load \
             change. With the load an unknown input (service, the default) it is a load move, never a fault; \
             under the paper's fixed viscous load (--paper) it is the fault b/bl, and B and Bl cannot be told apart."
        )?;
    }
    Ok(())
}

/// Candidates as `rr p 0.76 (rr +50 %), speed_sensor p 0.24 (speed_sensor -2 %)`, or `none`.
fn candidate_list(c: &[monitor_api::replay::FaultCandidate]) -> String {
    if c.is_empty() {
        return "none".into();
    }
    monitor_studies::fault_signatures::candidates_text(
        c.iter().map(|c| (c.fault, c.probability, c.change)),
    )
    .join(", ")
}

/// `simulate`'s one-line summary.
pub fn simulate(
    out: &mut dyn std::io::Write,
    path: &Path,
    wall_s: f64,
    s: &SimSummary,
) -> anyhow::Result<()> {
    writeln!(
        out,
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
pub fn convert(out: &mut dyn std::io::Write, c: &Converted) -> anyhow::Result<()> {
    writeln!(
        out,
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

/// The data-quality stage's warnings on stderr, one line each.
pub fn quality_warnings(q: &DataQuality) {
    let mut err = std::io::stderr().lock();
    let mut line = |l: String| {
        for part in crate::cli::out::wrap(&l) {
            let _ = writeln!(err, "{part}");
        }
    };
    for w in &q.warnings {
        line(format!("warning: {w}"));
    }
    if !q.trusted {
        line(format!(
            "warning: no verdict from this log: {}",
            q.not_trusted_because.join("; ")
        ));
    }
}

/// `table1`'s measured signatures beside the paper's and the physical ones.
pub fn table1(out: &mut dyn std::io::Write, t: &Table1Report) -> anyhow::Result<()> {
    writeln!(
        out,
        "Table 1 end to end — {}, angle: {}",
        t.motor, t.angle_source
    )?;
    // r1..r4 one character apart: the row stays within the 160 columns a crew's
    // terminal wraps at, the four candidates of an rr row included.
    writeln!(
        out,
        "fault           change   measured  paper       physics   isolation (size)       lamps' candidates"
    )?;
    let bits = |s: &[u8; 4]| s.map(|b| if b == 1 { "I" } else { "0" }).join(" ");
    for r in &t.rows {
        let diff = if r.signature == r.paper { " " } else { "*" };
        let cands: Vec<String> = r
            .candidates
            .iter()
            .map(|c| format!("{} {:.0}%", c.fault, 100.0 * c.probability))
            .collect();
        writeln!(
            out,
            "{:<15} {:+5.0} %   {}   {} {diff}   {}   {:<22} {}",
            r.fault.name(),
            100.0 * r.change,
            bits(&r.signature),
            bits(&r.paper),
            bits(&r.expected),
            match (r.named, r.named_change) {
                (Some(IsolationName::Fault(n)), Some(c)) => format!("{n} ({:+.0} %)", 100.0 * c),
                (Some(n), _) => n.to_string(),
                (None, _) if r.isolation_state == IsolationState::Isolated => {
                    "not alone".to_string()
                }
                (None, _) => format!("none ({})", state_name(r.isolation_state)),
            },
            if cands.is_empty() {
                "none".to_string()
            } else {
                cands.join(", ")
            }
        )?;
    }
    let phys = t.rows.iter().filter(|r| r.signature == r.expected).count();
    writeln!(
        out,
        "\n{} of {n} rows equal the paper's Table 1, {phys} of {n} the physically expected signature.\n\
         Signatures r1 r2 r3 r4: 'I' = the residual moves; '*' = differs from the paper (docs/paper-errata.md says why).",
        t.matches_paper,
        n = t.rows.len()
    )?;
    Ok(())
}
