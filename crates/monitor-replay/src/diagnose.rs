//! A log through the data-quality stage and a [`Replay`]: what `sim-host diagnose` runs
//! ([`diagnose_file`]), the glitch bursts filled or held out, and the observer of every
//! output (the live HMI's log source).

mod front;
mod pipe;

use crate::error::ReplayError;
use crate::options::ReplayOptions;
use crate::progress::{CountedRows, Forward, READ_SHARE};
use crate::quality::DataQualityStage;
use crate::replay::{Replay, ReplayObserver};
use crate::report::DiagnoseReport;
use crate::sampler::CLOCK_RESET_GAP_S;
use crate::stage::Finish;
use front::{Direct, Handled, ReplaySink};
use monitor_core::SensorFlags;
use monitor_io::log::quality::{
    CellLimits, CleanSink, DataQuality, NotJudged, QualityStage, MAX_BRIDGED_GAP_S,
};
use monitor_io::log::{Channels, LogError, LogFile, OpenOptions, Row, RowSink};
use monitor_io::params::ParamFile;
use std::path::Path;

/// A log replayed by [`diagnose_file`] or [`diagnose_rows`].
#[derive(Debug, Clone)]
pub struct Diagnosed {
    /// The report (`diagnose --json`), `data_quality` included.
    pub report: DiagnoseReport,
    /// The log's nominal sample rate (the data-quality stage's) [Hz].
    pub sample_rate_hz: f64,
}

/// Replays rows held in memory, through the data-quality stage, and returns the report.
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_rows(
    params: &ParamFile,
    channels: Channels,
    rows: &[Row],
    opts: ReplayOptions,
) -> Result<DiagnoseReport, ReplayError> {
    replay_through_quality(params, channels, "the log", opts, |stage| {
        for r in rows {
            if !stage.row(r) {
                break;
            }
        }
        Ok(())
    })
    .map(|d| d.report)
}

/// Streams a log file through the data-quality stage and the core (`sim-host
/// diagnose`): the stage's time base configures the monitor, and every row is replayed,
/// with bounded memory whatever the log's length. `progress` gets the fraction of the work
/// done, forward only: the rows replayed against the log's estimated rows up to 0.95, and
/// 1 once the report is built (a progress bar's).
///
/// # Errors
/// [`ReplayError::Log`] naming the file, line and column, or the stage's time-base
/// errors (a log without rows or sampled below 8 samples per supply period, with the rate
/// needed); [`ReplayError::Config`] when the core rejects the configuration;
/// [`ReplayError::IncompleteCommissioning`] for a window not learned without
/// `allow_incomplete`.
pub fn diagnose_file(
    params: &ParamFile,
    path: &Path,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    diagnose_log(params, &LogFile::open(path)?, opts, progress)
}

/// [`diagnose_file`] on a log already opened (any format, a TDMS group chosen:
/// [`LogFile::open_with`]).
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_log(
    params: &ParamFile,
    file: &LogFile,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    diagnose_log_fitted(params, file, opts, None, progress)
}

/// [`diagnose_log`] with the full-order machine fitted to the log against the parameter
/// file (`fit`, where the caller ran one: `monitor_api`'s, from `identify`), which the
/// parameter fit's finding reads where nothing was commissioned
/// ([`crate::verdict::machine_fit::StartFit::finding`]).
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_log_fitted(
    params: &ParamFile,
    file: &LogFile,
    opts: ReplayOptions,
    fit: Option<crate::verdict::machine_fit::StartFit>,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    let mut bar = Forward::new(progress);
    let d = replay_observed(
        params,
        file.channels(),
        file.shown(),
        opts,
        None,
        fit,
        |stage| read_counted(file, stage, &mut bar),
    );
    if d.is_ok() {
        bar.to(1.0);
    }
    d
}

/// Streams `file` into `stage`, the progress moving with the rows handed over
/// ([`CountedRows`]), to [`READ_SHARE`] once the read is over.
fn read_counted(
    file: &LogFile,
    stage: &mut dyn RowSink,
    bar: &mut Forward,
) -> Result<(), LogError> {
    let mut counted = CountedRows::new(stage, bar, file.estimated_rows());
    let read = file.for_each_row(&mut |_| {}, &mut counted).map(|_| ());
    bar.to(READ_SHARE);
    read
}

/// [`diagnose_file`] that hands every replayed row's output to `observer` as it goes, the
/// log opened with `open` (a TDMS group, the parameter file's `[columns]` mapping).
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_file_observed(
    params: &ParamFile,
    path: &Path,
    open: &OpenOptions,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
    observer: &mut dyn ReplayObserver,
) -> Result<Diagnosed, ReplayError> {
    let file = LogFile::open_with(path, open)?;
    let mut bar = Forward::new(progress);
    let d = replay_observed(
        params,
        file.channels(),
        file.shown(),
        opts,
        Some(observer),
        None,
        |stage| read_counted(&file, stage, &mut bar),
    );
    if d.is_ok() {
        bar.to(1.0);
    }
    d
}

/// Runs `feed` into the data-quality stage in front of a replay; builds the report.
fn replay_through_quality(
    params: &ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    replay_observed(params, channels, shown, opts, None, None, feed)
}

/// [`replay_through_quality`] with an optional observer of every output. Without one,
/// the replay runs on a thread of its own beside the data-quality stage ([`pipe`]: the
/// same results, on two cores).
fn replay_observed<'a>(
    params: &'a ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    observer: Option<&'a mut dyn ReplayObserver>,
    fit: Option<crate::verdict::machine_fit::StartFit>,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    match observer {
        None => {
            let ((read, quality, handled), replay) =
                pipe::on_own_thread(params, channels, opts, |p| {
                    let mut sink = ReplaySink::new(params, p);
                    let (read, quality) = through_quality(&mut sink, params, shown, feed);
                    (read, quality, sink.into_parts().1)
                });
            conclude(replay?, &handled, (read, quality), shown, opts, fit)
        }
        Some(o) => {
            let direct = Direct::new(params, channels, opts, Some(o));
            let mut sink = ReplaySink::new(params, direct);
            let (read, quality) = through_quality(&mut sink, params, shown, feed);
            let (mut direct, handled) = sink.into_parts();
            if let Some(e) = direct.error.take() {
                return Err(e);
            }
            conclude(
                direct.replay.take(),
                &handled,
                (read, quality),
                shown,
                opts,
                fit,
            )
        }
    }
}

/// Runs `feed` into the data-quality stage in front of `clean`: the read's result and
/// the stage's report.
fn through_quality<S: CleanSink>(
    clean: &mut S,
    params: &ParamFile,
    shown: &str,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> (Result<(), LogError>, Result<DataQuality, LogError>) {
    let mut stage = QualityStage::new(clean, CellLimits::for_params(params), shown);
    let read = feed(&mut stage);
    (read, stage.finish())
}

/// The report of a replay whose rows have all been read (`None`: never configured), after
/// `handled`.
fn conclude(
    replay: Option<Replay>,
    handled: &Handled,
    (read, quality): (Result<(), LogError>, Result<DataQuality, LogError>),
    shown: &str,
    opts: ReplayOptions,
    fit: Option<crate::verdict::machine_fit::StartFit>,
) -> Result<Diagnosed, ReplayError> {
    read?;
    let mut quality = quality?;
    let Some(replay) = replay else {
        return Err(ReplayError::NoRows {
            log: shown.to_string(),
        });
    };
    if replay.commissioning_incomplete() && !opts.allow_incomplete {
        if let Some(not_learned) = replay.commissioning_not_learned() {
            // What the data-quality stage distrusts is often why nothing was learned
            // (swapped channels, a dead sensor): said in the same line.
            let data_quality = if quality.trusted {
                Vec::new()
            } else {
                quality.not_trusted_because.clone()
            };
            return Err(ReplayError::IncompleteCommissioning {
                not_learned,
                data_quality,
            });
        }
    }
    let can_residuals = replay.monitor().is_some();
    let sensors = replay
        .monitor()
        .map_or_else(SensorFlags::default, |m| m.output().sensor_fault);
    let mut report = replay.end();
    if let Some(f) = fit
        .as_ref()
        .and_then(crate::verdict::machine_fit::StartFit::finding)
    {
        report.put_machine_fit(f);
    }
    describe_actions(&mut quality, can_residuals, handled);
    let dq = DataQualityStage::new(quality).finish(sensors);
    // Data the stage does not trust carry no finding (the sensors' impossible readings at
    // the end are the core's own finding: a sensor the isolation names with its size stands).
    if let Some(why) = &dq.distrusts {
        report.distrust(why);
    }
    report.put_finding(dq.finding);
    report.data_quality = dq.quality;
    report.conclude();
    Ok(Diagnosed {
        report,
        sample_rate_hz: handled.rate_hz,
    })
}

/// What `diagnose` did about what the stage found, in the report's `actions`.
fn describe_actions(q: &mut DataQuality, monitor: bool, sink: &Handled) {
    let who = if monitor {
        "the monitor"
    } else {
        "the unbalance analysis"
    };
    if q.gaps_bridged > 0 {
        q.actions.push(format!(
            "short gaps: {who} advanced its estimators over the real elapsed time"
        ));
    }
    if q.long_gaps > 0 || q.clock_resets > 0 {
        q.actions.push(format!(
            "long gaps and clock resets: {who} restarted its estimators and settled again"
        ));
    }
    if sink.short_bursts > 0 {
        q.actions.push(format!(
            "{} bursts of bad cells up to {MAX_BRIDGED_GAP_S} s: {} rows of glitches within a quarter supply period filled in between their neighbours along the rotation, the longer bursts left out and bridged like gaps",
            sink.short_bursts, sink.filled_rows
        ));
    }
    if sink.long_bursts > 0 {
        q.actions.push(format!(
            "{} bursts of bad cells longer than {MAX_BRIDGED_GAP_S} s: given to {who}, which holds them out and flags the sensor",
            sink.long_bursts
        ));
    }
    if q.repeated_or_backward_rows + q.non_finite_times > 0 {
        q.actions
            .push("rows with a repeated, backward or unreadable time: dropped".to_string());
    }
    if sink.rows_other_rate > 0 {
        q.actions.push(format!(
            "{} rows at another sample rate resampled onto the monitor's {:.0} Hz clock (interpolated along the rotation)",
            sink.rows_other_rate, sink.rate_hz
        ));
    }
    if q.clock_resets > 0 {
        q.actions.push(format!(
            "after each clock reset the replay's time goes on from the last row's plus {CLOCK_RESET_GAP_S} s (the times reported are the replay's)"
        ));
    }
    q.not_judged = sink
        .not_judged
        .iter()
        .map(|&(from_s, to_s, why)| NotJudged {
            from_s,
            to_s,
            why: why.to_string(),
        })
        .collect();
    for n in &q.not_judged {
        q.warnings.push(format!(
            "{:.2}..{:.2} s not judged: {}",
            n.from_s, n.to_s, n.why
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verdict::{decided_on_this_thread, Verdict};
    use monitor_sim::{simulate_to_vec, Scenario};

    /// A 4 s log of the 2.2 kW reference machine at 2 kHz, an encoder logged.
    fn log() -> Vec<Row> {
        let text =
            "duration_s = 4.0\nsample_rate_hz = 2000.0\nseed = 5\n[sensors]\nencoder = true\n";
        let sc = Scenario::from_toml_str(text, "verdict-once").expect("scenario"); // ok: test
        simulate_to_vec(&ParamFile::reference_2p2kw(), &sc).expect("simulate") // ok: test
    }

    /// The verdicts one `diagnose` decides: `monitor_core::verdict::decide` through
    /// `verdict::conclude`, counted on this thread (the replay runs on a thread of its own;
    /// the report is concluded here).
    fn decided_by(channels: Channels, rows: &[Row], opts: ReplayOptions) -> (u32, DiagnoseReport) {
        let before = decided_on_this_thread();
        let report =
            diagnose_rows(&ParamFile::reference_2p2kw(), channels, rows, opts).expect("diagnose"); // ok: test
        (decided_on_this_thread() - before, report)
    }

    #[test]
    fn a_diagnosis_decides_its_verdict_once() {
        let rows = log();
        let all = Channels {
            voltages: true,
            speed: true,
            encoder: true,
            temperature: false,
        };
        let commissioned = ReplayOptions {
            commission: Some(crate::options::CommissionWindow::of(1.0, 2.5)),
            allow_incomplete: true,
            ..ReplayOptions::default()
        };
        let current_only = Channels {
            voltages: false,
            speed: false,
            encoder: false,
            temperature: false,
        };
        // Every row's time repeated: the data-quality stage drops them and does not trust
        // the log, so its finding makes every other finding "not judged" first.
        let doubled: Vec<Row> = rows.iter().flat_map(|r| [*r, *r]).collect();
        for (what, channels, rows, opts) in [
            ("file", all, &rows, ReplayOptions::default()),
            ("commissioned", all, &rows, commissioned),
            (
                "currents only",
                current_only,
                &rows,
                ReplayOptions::default(),
            ),
            ("rows repeated", all, &doubled, ReplayOptions::default()),
        ] {
            let (n, report) = decided_by(channels, rows, opts);
            assert_eq!(n, 1, "{what}: the verdict was decided {n} times");
            // (The repeated rows take the distrusting path: untrusted data, could not judge.)
            let repeated = what == "rows repeated";
            assert_eq!(report.data_quality.trusted, !repeated, "{what}");
            assert_eq!(report.verdict == Verdict::CouldNotJudge, repeated, "{what}");
        }
    }

    #[test]
    fn a_replay_finished_decides_once() {
        let rows = log();
        let all = Channels {
            voltages: true,
            speed: true,
            encoder: true,
            temperature: false,
        };
        let mut replay = Replay::new(
            &ParamFile::reference_2p2kw(),
            all,
            2000.0,
            ReplayOptions::default(),
        )
        .expect("replay"); // ok: test
        for r in &rows {
            replay.push(r);
        }
        let before = decided_on_this_thread();
        let report = replay.finish();
        assert_eq!(decided_on_this_thread() - before, 1);
        assert_eq!(report.rows, rows.len() as u64);
    }
}
