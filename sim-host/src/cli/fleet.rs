//! `sim-host fleet`: many motors' logs judged on one machine ([`monitor_api::fleet`]), one row
//! per log, as CSV or JSON: the same table the Python package's Dask run returns.

use super::render;
use clap::Args;
use rayon::prelude::*;
use std::path::PathBuf;

/// Arguments of `fleet`.
#[derive(Debug, Args)]
#[command(
    about = "Judge many motors' logs: one row per log (motor, verdict, fault, size, phase, ...)",
    long_about = "Diagnose many logs of many motors on this machine, in parallel, and print one row \
per log: motor, file, rows, rate_hz, verdict, fault, size, phase, confidence, \
first_detection_s, load_moves, data_quality, error. A bad file is a row with its error, never a \
failed run; a log pattern that matches no file (`'logs/pump_*.csv'`, or a shell glob that matched \
nothing) is an error naming the pattern.\n\nWith --store PATH each judged log is also appended to a store of the motors' \
history (SQLite at PATH, one transaction per log, and a Parquet mirror in PATH.parquet/, \
partitioned by motor and day): its motor is the table's name for it, its time the log's own \
(a time column of timestamps in [columns], a TDMS wf_start_time), else the date in its file \
name by the motor's time_from_name pattern, else the file's modification time (the run warns \
of those). A log already stored (the same bytes at the same path) is skipped, not \
judged again; a run killed mid-way loses no stored row, and the next run finishes it. Read the \
store with `sim-host trend --store PATH` (docs/trend.md).\n\nThe motor table (TOML) says which parameter file, commissioning window, healthy \
baseline and load belong to which motor, and which logs are its (a pattern on the file name; \
paths relative to the table's folder):\n\n  [[motor]]\n  name = \"pump_7\"\n  params = \
\"params/pump_7.toml\"\n  logs = \"pump_7_*\"\n  commission = [2.0, 4.0]   # optional\n  \
baseline = [\"healthy/pump_7\"]   # optional: healthy logs or folders\n  load = \"unknown\"   # \
optional: or \"viscous\"\n  time_from_name = \"pump_7_%Y%m%d_%H%M\"   # optional: the \
log's date in its file name (chrono's strftime)\n\nFor hundreds of motors and many machines, the Python package runs the \
same rows on a Dask cluster (docs/python.md).\n\nExample:\n  sim-host fleet motors.toml logs/*.csv \
--json\n  sim-host fleet motors.toml logs/*.csv --store history.db\n  sim-host trend --store history.db"
)]
pub struct FleetArgs {
    /// The motor table (TOML).
    pub motors: PathBuf,
    /// The logs (CSV, TDMS or Parquet); a file name with `*` or `?` that names no file is a
    /// pattern, expanded in its folder (a pattern that matches no file is an error).
    #[arg(required = true)]
    pub logs: Vec<PathBuf>,
    /// Print one JSON document (a list of rows) instead of CSV.
    #[arg(long)]
    pub json: bool,
    /// Also append each judged log to the store at PATH (SQLite; its Parquet mirror in
    /// PATH.parquet/), skipping logs already stored.
    #[arg(long, value_name = "PATH")]
    pub store: Option<PathBuf>,
}

/// Runs `fleet`.
///
/// # Errors
/// A motor table that cannot be read, a store that is one of the files the run reads
/// ("refusing to overwrite the input ..."), or an error writing to standard output (a
/// log's own error is its row's).
pub fn run(args: &FleetArgs) -> anyhow::Result<()> {
    let table = monitor_api::fleet::MotorTable::load(&args.motors)?;
    let logs = monitor_api::fleet::expand_logs(&args.logs)?;
    if let Some(store) = &args.store {
        monitor_api::fleet::check_fleet_outputs(
            Some(&args.motors),
            &table,
            &logs,
            &[monitor_api::files::NamedFile::path(store)],
        )?;
    }
    let rows: Vec<monitor_api::fleet::FleetRow> = match &args.store {
        Some(path) => super::store_run::judge_into(&table, &logs, path)?,
        None => logs
            .par_iter()
            .map(|log| monitor_api::fleet::row(&table, log))
            .collect(),
    };
    if args.json {
        return render::json::print(&mut crate::cli::out::stdout(), &rows);
    }
    // (The header comes from the rows' field names: monitor_api::fleet::COLUMNS.)
    let mut w = csv::Writer::from_writer(super::out::stdout());
    for r in &rows {
        w.serialize(r)?;
    }
    w.flush()?;
    Ok(())
}
