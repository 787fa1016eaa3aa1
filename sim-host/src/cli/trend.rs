//! `sim-host trend`: a motor's indicators across its stored logs, the trend alarm and the
//! days to FAULT; without `--motor`, the fleet's motors ranked by how fast they move.

use super::render;
use clap::Args;
use monitor_api::words::trend as words;
use monitor_store::trend::{MotorTrend, Normalisation, TrendOptions};
use monitor_store::Store;
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `trend`.
#[derive(Debug, Args)]
#[command(
    about = "A motor's history: its indicators trended across the stored logs, with an alarm on the trend",
    long_about = "Read the store `sim-host fleet --store PATH` writes and trend each motor's \
indicators over the last --window-days of its logs: the winding's negative-sequence change \
|I2w|/|I1| (a short grows it), the isolation's parity residuals e_d, e_q, e_T (a resistance, \
inductance or load change moves them) and the rotor's sideband (broken bars). An indicator none \
of a motor's logs measured (the residuals of logs without voltages) is left out of its table, \
JSON and plot, never drawn as zero.\n\nEach indicator \
is first brought to the motor's usual operating point: a least-squares fit on the load (the \
current I1) and the windings' temperature rise, made on the motor's first logs, is removed, so \
a load that moves from day to day or a season that warms the windings is not a trend. Then \
Theil-Sen's slope per day with Sen's 95 % interval, and the indicator's own scatter about the \
line (1.4826 MAD). The TREND ALARM: the indicator's stored value at its FAULT level on two logs \
in a row (what the logs show, whatever the fit still needs), or the interval lies on the fault's \
side of zero AND the line moves the indicator by more than --k scatters over the window. Where the indicator has a FAULT \
level (the level a single log's verdict names the fault at), the days until the line reaches \
it, where Sen's interval excludes a flat line. Once raised, the alarm holds until the \
indicator is back within --k scatters of the motor's reference (its first --window-days of logs \
whose verdict is healthy or watching, or its logs up to --reference-until) on two logs in a row.\n\nWithout --motor: the fleet's motors, alarmed first, then the fastest-moving (the \
indicator that moves most, in scatters over the window).\n\nExamples:\n  sim-host fleet \
motors.toml logs/*.csv --store history.db\n  sim-host trend --store history.db\n  sim-host \
trend --store history.db --motor pump_7 --plot pump_7.svg\n  sim-host trend --store history.db \
--since 2026-11-01 --json\n\nThe statistics, the normalisation and their limits: \
docs/trend.md."
)]
pub struct TrendArgs {
    /// The store (SQLite) `sim-host fleet --store` wrote.
    #[arg(long, value_name = "PATH")]
    pub store: PathBuf,
    /// Only this motor (its name in the fleet's motor table).
    #[arg(long, value_name = "ID")]
    pub motor: Option<String>,
    /// Only logs from this UTC day on (YYYY-MM-DD).
    #[arg(long, value_name = "DATE")]
    pub since: Option<String>,
    /// The window the slope is taken over, ending at the motor's last log [days].
    #[arg(long, default_value_t = 14.0, value_name = "DAYS")]
    pub window_days: f64,
    /// How many scatters the line must move over the window to alarm.
    #[arg(long, default_value_t = 3.0, value_name = "K")]
    pub k: f64,
    /// The baseline: each motor's logs up to the end of this UTC day (YYYY-MM-DD) are its
    /// reference (the bands, the scatters from the reference, the alarm's clearing).
    /// Default: each motor's first --window-days of logs whose verdict is healthy or watching.
    #[arg(long, value_name = "DATE")]
    pub reference_until: Option<String>,
    /// Draw the indicators over time (with the OK / WATCH / FAULT bands) into FILE.svg or
    /// FILE.png.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `trend --json`.
#[derive(Serialize)]
struct TrendReport<'a> {
    store: String,
    options: TrendOptions,
    motors: Vec<words::SpelledMotor<'a>>,
}

/// Runs `trend`.
///
/// # Errors
/// No store at the path, not a store, a bad date or window, a plot that cannot be written:
/// one line each.
pub fn run(args: &TrendArgs) -> anyhow::Result<()> {
    let (since, reference_until_s) = check(args)?;
    let store = Store::open_existing(&args.store)?;
    let rebuilt = store.sync_mirror()?;
    if rebuilt > 0 {
        eprintln!(
            "store {}: {rebuilt} Parquet file(s) missing from the mirror, written now",
            args.store.display()
        );
    }
    let rows = store.rows(args.motor.as_deref(), since)?;
    if rows.is_empty() {
        match &args.motor {
            Some(m) => anyhow::bail!("no logs of motor {m} in the store {}", args.store.display()),
            None => anyhow::bail!("the store {} holds no logs", args.store.display()),
        }
    }
    // A motor whose logs all took the files' modification times on one day has no trend:
    // said before anything else, on stderr.
    for warning in monitor_store::one_day_of_modified_times(&rows) {
        eprintln!("{warning}");
    }
    let opts = TrendOptions {
        window_days: args.window_days,
        k_scatter: args.k,
        reference_until_s,
        ..TrendOptions::default()
    };
    let motors = monitor_store::trend::trend(&rows, &opts);
    if let Some(p) = &args.plot {
        render::trend_plot::write(p, &motors, &opts)
            .map_err(|e| anyhow::anyhow!("--plot {}: {e}", p.display()))?;
    }
    if args.json {
        return render::json::print(
            &mut crate::cli::out::stdout(),
            &TrendReport {
                store: args.store.display().to_string(),
                options: opts,
                motors: words::spelled(&motors),
            },
        );
    }
    let mut out = super::out::text();
    print_table(&mut out, &motors, args.motor.is_some())?;
    Ok(())
}

/// The arguments checked, before anything is read: the window, k, the dates (returned as
/// seconds since 1970-01-01 UTC: `--since`'s day's start, `--reference-until`'s day's end)
/// and the plot's name.
///
/// # Errors
/// One line naming the option and what it must be.
fn check(args: &TrendArgs) -> anyhow::Result<(Option<i64>, Option<i64>)> {
    if !(args.window_days.is_finite() && args.window_days > 0.0) {
        anyhow::bail!(
            "--window-days must be a positive number of days, got {}",
            args.window_days
        );
    }
    if !(args.k.is_finite() && args.k > 0.0) {
        anyhow::bail!("--k must be a positive number of scatters, got {}", args.k);
    }
    let since = match &args.since {
        Some(d) => Some(monitor_store::parse_day(d).ok_or_else(|| {
            anyhow::anyhow!("--since {d}: not a date; give the UTC day as YYYY-MM-DD")
        })?),
        None => None,
    };
    let until = match &args.reference_until {
        Some(d) => Some(
            monitor_store::parse_day(d)
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "--reference-until {d}: not a date; give the UTC day as YYYY-MM-DD"
                    )
                })?
                .saturating_add(86_400),
        ),
        None => None,
    };
    if let Some(p) = &args.plot {
        let ext = p.extension().and_then(|e| e.to_str()).unwrap_or_default();
        if !matches!(ext, "svg" | "png") {
            anyhow::bail!(
                "--plot {}: give a file name ending in .svg or .png",
                p.display()
            );
        }
        super::output_guard::OutputGuard::new(&[args.store.as_path()]).check_files(&[p])?;
    }
    Ok((since, until))
}

/// The text table: a line per motor (ranked), and per indicator with `detail`. `moved`:
/// the fastest indicator's line's change over the window, in its scatters; `from ref`: the
/// indicator furthest from the motor's reference, its line at the last log in reference
/// scatters; `-` where there is none (too few logs: the detail lines say so).
fn print_table(
    out: &mut impl std::io::Write,
    motors: &[MotorTrend],
    detail: bool,
) -> std::io::Result<()> {
    writeln!(
        out,
        "{:<16} {:>5}  {:<10} {:<10} {:>6} {:>9}  {:<6} fastest indicator",
        "motor", "logs", "first", "last", "moved", "from ref", "alarm"
    )?;
    let abs = |x: Option<f64>| x.map_or(0.0, f64::abs);
    for m in motors {
        let fastest = m
            .indicators
            .iter()
            .filter(|t| t.moves_scatters.is_some())
            .max_by(|a, b| abs(a.moves_scatters).total_cmp(&abs(b.moves_scatters)));
        let furthest = m
            .indicators
            .iter()
            .filter_map(|t| t.from_reference_scatters)
            .max_by(|a, b| a.abs().total_cmp(&b.abs()));
        let num = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.1}"));
        writeln!(
            out,
            "{:<16} {:>5}  {:<10} {:<10} {:>6} {:>9}  {:<6} {}",
            m.motor,
            m.logs,
            m.first_day,
            m.last_day,
            num(fastest.map(|_| m.fastest_scatters)),
            num(furthest),
            if m.alarm { "ALARM" } else { "-" },
            fastest.map_or("", |t| t.indicator.as_str())
        )?;
        if detail || m.alarm {
            print_detail(out, m)?;
        }
    }
    Ok(())
}

/// A motor's detail lines: each indicator's sentence, its reference, each normalisation
/// once with the indicators it applies to.
fn print_detail(out: &mut impl std::io::Write, m: &MotorTrend) -> std::io::Result<()> {
    for t in &m.indicators {
        writeln!(out, "    {}", words::sentence(t))?;
    }
    let r = &m.reference;
    writeln!(
        out,
        "    reference: {} ({} logs, {} to {})",
        words::reference_how(r),
        r.logs,
        r.first_day.as_deref().unwrap_or("-"),
        r.last_day.as_deref().unwrap_or("-")
    )?;
    let mut seen: Vec<(&Normalisation, Vec<&str>)> = Vec::new();
    for t in &m.indicators {
        match seen.iter_mut().find(|(n, _)| **n == t.normalisation) {
            Some((_, v)) => v.push(&t.indicator),
            None => seen.push((&t.normalisation, vec![&t.indicator])),
        }
    }
    for (n, v) in seen {
        writeln!(out, "    {}: {}", v.join(", "), words::normalisation(n))?;
    }
    Ok(())
}
