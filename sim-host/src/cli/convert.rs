//! `sim-host convert IN OUT`: rewrite a log in another format (CSV, TDMS, Parquet, by the
//! extensions), through the one reader and the one writer (`monitor_api::files::LogFile` and `LogWriter`).
//!
//! The rows are copied as the reader hands them over (non-finite cells and times that do
//! not increase included): judging them stays the data-quality stage's, in the command
//! that analyses the output. The output is written atomically and may not be the input;
//! SIGINT/SIGTERM remove the temporary file (exit status 130 / 143). A progress bar goes to
//! stderr for inputs above 20 MB when it is a terminal.

use super::out::Interruption;
use super::output_guard::OutputGuard;
use super::render::json::Converted;
use super::{progress, render};
use clap::Args;
use monitor_api::files::{Format, LogFile, LogWriter, OpenOptions, Row, RowSink};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `convert`.
#[derive(Debug, Args)]
#[command(
    about = "Convert a log between CSV, TDMS and Parquet (formats by extension)",
    long_about = "Convert a measurement log between CSV, TDMS (.tdms) and Parquet (.parquet, .pq); \
the formats are chosen by the file extensions (anything else is CSV). Channels keep the CSV \
column names (t_s, va_V, vb_V, vc_V, ia_A, ib_A, ic_A, wm_rad_s, enc_count). Every writer \
stores t_s at f64 and the other channels at f32 precision (7 significant digits). A TDMS \
input whose time is in the waveform properties (wf_start_offset, wf_increment) gets a t_s \
column.\n\nA log whose channels have other names or units (Ia in mA, time in ms, speed in \
rpm) is read through the [columns] table of the parameter file given with --params \
(docs/design.md); the output then has the schema's names and SI units.\n\nThe output is \
written atomically and is never the input.\n\nExamples:\n  \
sim-host convert run.csv run.parquet\n  sim-host convert daq.tdms --group Motor daq.csv\n  \
sim-host convert --params examples/params/daq_2p2kw.toml examples/logs/daq_2p2kw.csv run.csv"
)]
pub struct ConvertArgs {
    /// The log to read.
    pub input: PathBuf,
    /// The log to write (atomically; never the input).
    pub output: PathBuf,
    /// The TDMS group holding the channels (when the input has several).
    #[arg(long, value_name = "NAME")]
    pub group: Option<String>,
    /// A parameter file whose `[columns]` table maps the input's channels and units to the
    /// schema's (docs/design.md); the output has the schema's names and SI units.
    #[arg(long, value_name = "P.toml")]
    pub params: Option<PathBuf>,
    /// Print one JSON summary document on stdout instead of the text summary.
    #[arg(long)]
    pub json: bool,
}

/// Forwards rows to the writer until an error or a signal.
struct Copy<'a> {
    w: Option<LogWriter>,
    args: &'a ConvertArgs,
    channels: monitor_api::files::Channels,
    error: Option<monitor_api::files::LogError>,
    interruption: &'a Interruption,
    rows: u64,
}

impl RowSink for Copy<'_> {
    fn row(&mut self, row: &Row) -> bool {
        let Some(w) = self.w.as_mut() else {
            return false;
        };
        if let Err(e) = w.write_row(row) {
            self.error = Some(e);
            return false;
        }
        self.rows += 1;
        !self.interruption.caught()
    }

    fn restart(&mut self) {
        // The CSV fast path met a cell it does not take and the exact reader starts over
        // (handing over the same rows, or naming the bad line): a new output, the old one's
        // temporary file removed.
        self.w = None;
        self.rows = 0;
        match LogWriter::create(&self.args.output, self.channels) {
            Ok(w) => self.w = Some(w),
            Err(e) => self.error = Some(e),
        }
    }
}

/// Checks that the output is none of the inputs and opens the input log (its channels
/// mapped by the `--params` file's `[columns]` table, if given).
///
/// # Errors
/// An output that is an input, an unreadable parameter file, an unreadable or malformed
/// input.
fn open_input(args: &ConvertArgs) -> anyhow::Result<LogFile> {
    let mut inputs = vec![args.input.as_path()];
    inputs.extend(args.params.as_deref());
    OutputGuard::new(&inputs).check_files(&[&args.output])?;
    let columns = match &args.params {
        Some(p) => monitor_api::files::load_params(p)?.1,
        None => Default::default(),
    };
    let opts = OpenOptions {
        group: args.group.clone(),
        columns,
    };
    Ok(LogFile::open_with(&args.input, &opts)?)
}

/// Runs `convert`.
///
/// # Errors
/// An output that is the input, an unreadable or malformed input (one line naming the
/// file, line and column), an I/O error writing the output, or [`super::out::Interrupted`].
pub fn run(args: &ConvertArgs) -> anyhow::Result<()> {
    let file = open_input(args)?;
    let start = Instant::now();
    let interruption = Interruption::catch()?;
    let big = std::fs::metadata(&args.input)
        .map(|m| m.len() > 20_000_000)
        .unwrap_or(false);
    let bar = progress::bar(progress::FRACTION_STEPS, "convert", big);
    let mut sink = Copy {
        w: Some(LogWriter::create(&args.output, file.channels())?),
        args,
        channels: file.channels(),
        error: None,
        interruption: &interruption,
        rows: 0,
    };
    let read = file.for_each_row(&mut |f| progress::set_fraction(&bar, f), &mut sink);
    bar.finish_and_clear();
    let Copy { w, error, rows, .. } = sink;
    if let Some(sig) = interruption.signal(&format!(
        "temporary file removed, {} not written",
        args.output.display()
    )) {
        drop(w);
        return Err(sig.into());
    }
    read?;
    if let Some(e) = error {
        return Err(e.into());
    }
    if let Some(w) = w {
        w.finish()?;
    }
    let done = Converted {
        input: args.input.display().to_string(),
        input_format: file.format().name(),
        output: args.output.display().to_string(),
        output_format: Format::of_path(&args.output).name(),
        rows,
        output_bytes: std::fs::metadata(&args.output)
            .map(|m| m.len())
            .unwrap_or(0),
        wall_s: start.elapsed().as_secs_f64(),
    };
    if args.json {
        render::json::print(&mut crate::cli::out::stdout(), &done)
    } else {
        render::text::convert(&mut crate::cli::out::text(), &done)
    }
}
