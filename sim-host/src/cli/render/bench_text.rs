//! The benchmarks' text tables: `bench`'s figures and detection limits, and
//! `bench --isolation`'s summaries and confusion matrix.

use monitor_api::replay::{angle_source_name, state_name, IsolationName};
use monitor_core::Fault;
use monitor_studies::bench::isolation::{
    CaseOutcome, CaseResult, IsolationBench, IsolationConfusion,
};
use monitor_studies::bench::{BenchFigures, DetectionLimitCase, Spread};
use std::io::Write;

/// A timing as "median (min-max)".
fn spread(s: &Spread, decimals: usize) -> String {
    format!(
        "{:.d$} ({:.d$}-{:.d$})",
        s.median,
        s.min,
        s.max,
        d = decimals
    )
}

/// `bench`'s figures and, with `--detection`, the detection limits.
pub fn bench(
    out: &mut dyn std::io::Write,
    f: &BenchFigures,
    limits: Option<&[DetectionLimitCase]>,
) -> anyhow::Result<()> {
    writeln!(
        out,
        "reference scenario: 2.2 kW, direct-on-line, 14.6 N m from 2.5 s, 10 s at 10 kHz ({} rows); median (range) of {} runs",
        f.rows, f.repeat
    )?;
    writeln!(
        out,
        "simulator, in memory : {} simulated s per wall s",
        spread(&f.sim_in_memory_s_per_s, 0)
    )?;
    writeln!(
        out,
        "simulator, CSV writes: {} simulated s per wall s",
        spread(&f.sim_with_csv_s_per_s, 0)
    )?;
    writeln!(
        out,
        "accuracy             : max |i| error {:.2e} A against a 100x finer step (step {:.0} us)",
        f.max_current_error_a,
        f.step_s * 1e6
    )?;
    writeln!(
        out,
        "core Monitor         : {} ns per sample (host)",
        spread(&f.monitor_ns_per_sample, 1)
    )?;
    writeln!(
        out,
        "(motulator 0.5.0 reference: 5.14 simulated s per wall s with DOP853 at the same accuracy)"
    )?;
    if let Some(limits) = limits {
        writeln!(out, "\nsmallest change detected within 10 s, service profile with load and supply steps, zero false alarms:")?;
        writeln!(out, "motor   fault            increase  decrease")?;
        let pct = |x: Option<f64>| {
            x.map(|v| format!("{:7.1} %", 100.0 * v))
                .unwrap_or_else(|| "  > 90 %".into())
        };
        for l in limits {
            writeln!(
                out,
                "{:<7} {:<15} {}  {}",
                l.motor,
                l.fault.name(),
                pct(l.smallest_increase),
                pct(l.smallest_decrease)
            )?;
        }
    }
    Ok(())
}

/// `bench --isolation`: the summary per motor and angle mode, the confusion matrices, and
/// every case not named right.
///
/// # Errors
/// Stdout errors.
pub fn isolation_bench(mut out: &mut dyn std::io::Write, b: &IsolationBench) -> anyhow::Result<()> {
    isolation_summaries(&mut out, b)?;
    for c in &b.confusion {
        confusion_matrix(&mut out, c)?;
    }
    cases_not_named_right(&mut out, b)?;
    wrong_names(&mut out, b)
}

/// The bench's heading and one line per motor and angle mode.
fn isolation_summaries(out: &mut impl Write, b: &IsolationBench) -> anyhow::Result<()> {
    writeln!(
        out,
        "isolation bench: {} cases at {:.0} Hz, 12-bit noisy sensors, loads 1.0 and 0.6 x the file's Bl, sizes -50/-10/+10/+50 % ({:.0} s wall)",
        b.cases.len(),
        b.sample_rate_hz,
        b.wall_s
    )?;
    writeln!(
        out,
        "motor   mode        detected   named right  wrong >=0.5  size error median / max  time to name (median)"
    )?;
    let opt = |x: Option<f64>, scale: f64, unit: &str| {
        x.map(|v| format!("{:.1}{unit}", scale * v))
            .unwrap_or_else(|| "-".into())
    };
    for s in &b.summaries {
        writeln!(
            out,
            "{:<7} {:<10} {:>4}/{:<4}  {:>4}/{:<4}   {:>6}       {:>8} / {:<8}      {}",
            s.motor,
            angle_source_name(s.mode),
            s.detected,
            s.cases,
            s.named_right,
            s.cases,
            s.wrong_named,
            opt(s.size_error_median, 100.0, " %"),
            opt(s.size_error_max, 100.0, " %"),
            opt(s.time_to_name_median_s, 1.0, " s"),
        )?;
    }
    Ok(())
}

/// One angle mode's confusion matrix (rows: the true faults; columns: what was named).
fn confusion_matrix(out: &mut impl Write, c: &IsolationConfusion) -> anyhow::Result<()> {
    writeln!(
        out,
        "\nconfusion matrix, {} (rows: true fault; columns: named at the end; all motors, sizes, loads):",
        angle_source_name(c.mode)
    )?;
    let short = |o: &CaseOutcome| match o {
        CaseOutcome::Named(IsolationName::Fault(Fault::CurrentSensor)) => "i_sens",
        CaseOutcome::Named(IsolationName::Fault(Fault::VoltageSensor)) => "v_sens",
        CaseOutcome::Named(IsolationName::Fault(Fault::SpeedSensor)) => "w_sens",
        CaseOutcome::Unknown => "unkn",
        o => o.name(),
    };
    write!(out, "{:<15}", "true \\ named")?;
    for col in &c.columns {
        write!(out, "{:>7}", short(col))?;
    }
    writeln!(out)?;
    for (r, counts) in c.rows.iter().zip(&c.counts) {
        write!(out, "{:<15}", r.name())?;
        for n in counts {
            write!(out, "{n:>7}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

/// Every case not named right: the name at the end and the candidates.
fn cases_not_named_right(out: &mut impl Write, b: &IsolationBench) -> anyhow::Result<()> {
    writeln!(out, "\nnot named right (named at the end; candidates):")?;
    for c in b.cases.iter().filter(|c| !c.right) {
        let cands: Vec<String> = c
            .candidates
            .iter()
            .take(3)
            .map(|c| match c.change {
                Some(ch) => format!("{} {:+.0} % p={:.2}", c.fault, 100.0 * ch, c.probability),
                None => format!("{} p={:.2}", c.fault, c.probability),
            })
            .collect();
        writeln!(
            out,
            "  {:<6} {:<10} {:<15} {:+4.0} % load {:.1}: {} ({}){}",
            c.motor,
            angle_source_name(c.mode),
            c.fault.name(),
            100.0 * c.change,
            c.load_scale,
            c.named,
            if cands.is_empty() {
                state_name(c.state).to_string()
            } else {
                cands.join(", ")
            },
            if c.detected { "" } else { ", not detected" }
        )?;
    }
    Ok(())
}

/// The cases with a wrong name at probability >= 0.5 (the bar: none).
fn wrong_names(out: &mut impl Write, b: &IsolationBench) -> anyhow::Result<()> {
    let wrong: Vec<&CaseResult> = b
        .cases
        .iter()
        .filter(|c| !c.wrong_names.is_empty())
        .collect();
    if wrong.is_empty() {
        writeln!(out, "\nwrong names at probability >= 0.5: none")?;
        return Ok(());
    }
    writeln!(
        out,
        "\nWRONG NAMES at probability >= 0.5 ({} cases):",
        wrong.len()
    )?;
    for c in wrong {
        writeln!(
            out,
            "  {} {} {} {:+.0} % load {:.1}: {}",
            c.motor,
            angle_source_name(c.mode),
            c.fault,
            100.0 * c.change,
            c.load_scale,
            c.wrong_names.join(", ")
        )?;
    }
    Ok(())
}
