//! A log replayed on the HMI (`sim-host hmi LOG --params P`): the log goes through the
//! one reader, the data-quality stage and the core exactly as `diagnose` replays it
//! ([`monitor_api::replay::diagnose_file_observed`]), on a worker thread that keeps a reading
//! every [`SNAPSHOT_EVERY_S`] of log time; the screen plays those readings back at 1x,
//! 10x or as fast as they come, with pause
//! and seek. The data-quality warnings and the
//! verdict appear when the whole log is analysed.

use super::{
    quit_key, Controls, HmiState, Key, PlaybackControls, Snapshot, Source, Speed, HISTORY_S,
    SNAPSHOT_EVERY_S,
};
use monitor_api::files::ParamFile;
use monitor_api::files::{LogFile, OpenOptions, Row};
use monitor_api::replay::{
    diagnose_file_observed, Replay, ReplayError, ReplayObserver, ReplayOptions,
};
use monitor_core::MonitorOutput;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

/// Seek of the arrow keys [s].
pub const SEEK_S: f64 = 5.0;
/// Seek of page up / page down [s].
pub const SEEK_FAR_S: f64 = 60.0;
/// Readings handed to the screen at once by the worker.
const BATCH: usize = 64;

/// What the worker has found so far.
#[derive(Debug, Default)]
struct ReplayAnalysis {
    snapshots: Vec<Snapshot>,
    done: bool,
    warnings: Vec<String>,
    verdict: Option<String>,
    /// The verdict's line, as `diagnose` prints it (what it was judged against).
    verdict_line: Option<String>,
    error: Option<String>,
}

/// The log replay source.
pub struct LogReplay {
    path: PathBuf,
    shared: Arc<Mutex<ReplayAnalysis>>,
    worker: Option<JoinHandle<()>>,
    controls: PlaybackControls,
    /// Warnings already shown.
    warned: bool,
}

impl LogReplay {
    /// Starts analysing `path` with the motor `params` and `opts` (as `diagnose`), to be
    /// played back at `speed`.
    ///
    /// # Errors
    /// The log cannot be opened or its header is not a log's ([`LogFile::open`]); errors
    /// further in show on the screen.
    pub fn start(
        params: ParamFile,
        path: &Path,
        opts: ReplayOptions,
        speed: Speed,
    ) -> Result<Self, ReplayError> {
        Self::start_with(params, path, OpenOptions::default(), opts, speed)
    }

    /// [`LogReplay::start`] with the log opened with `open` (the parameter file's
    /// `[columns]` mapping, a TDMS group).
    ///
    /// # Errors
    /// As [`LogReplay::start`].
    pub fn start_with(
        params: ParamFile,
        path: &Path,
        open: OpenOptions,
        opts: ReplayOptions,
        speed: Speed,
    ) -> Result<Self, ReplayError> {
        LogFile::open_with(path, &open)?;
        let shared = Arc::new(Mutex::new(ReplayAnalysis::default()));
        let worker = {
            let shared = Arc::clone(&shared);
            let path = path.to_path_buf();
            std::thread::spawn(move || analyse(&params, &path, &open, opts, &shared))
        };
        Ok(LogReplay {
            path: path.to_path_buf(),
            shared,
            worker: Some(worker),
            controls: PlaybackControls {
                speed,
                paused: false,
                position_s: 0.0,
                analysed_s: 0.0,
                done: false,
                verdict: None,
            },
            warned: false,
        })
    }

    /// Waits until the whole log is analysed (tests, and the plain-text mode at `max`).
    pub fn wait(&mut self) {
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }

    /// The playback as it stands.
    pub fn controls(&self) -> &PlaybackControls {
        &self.controls
    }

    /// Moves the playback to `t_s` (clamped to what is analysed).
    pub fn seek_to(&mut self, t_s: f64) {
        self.controls.position_s = t_s.clamp(0.0, self.controls.analysed_s);
    }

    /// Shows the reading at the playback position and the residuals before it.
    fn show(&self, a: &ReplayAnalysis, state: &mut HmiState) {
        let pos = self.controls.position_s;
        let end = a.snapshots.partition_point(|s| s.t_s <= pos + 1e-9);
        let start = a.snapshots[..end].partition_point(|s| s.t_s < pos - HISTORY_S);
        state.history = a.snapshots[start..end]
            .iter()
            .map(|s| (s.t_s, s.residuals))
            .collect();
        state.latest = end.checked_sub(1).map(|k| a.snapshots[k].clone());
    }
}

impl Drop for LogReplay {
    fn drop(&mut self) {
        // The worker stops at its next batch once nobody holds the analysis.
        self.worker.take();
    }
}

/// The worker: the replay with an observer that keeps the readings.
fn analyse(
    params: &ParamFile,
    path: &Path,
    open: &OpenOptions,
    opts: ReplayOptions,
    shared: &Arc<Mutex<ReplayAnalysis>>,
) {
    let mut keeper = Keeper {
        params: *params,
        shared: Arc::clone(shared),
        pending: Vec::new(),
        next_s: 0.0,
        stop: false,
    };
    let result = diagnose_file_observed(params, path, open, opts, &mut |_| {}, &mut keeper);
    keeper.flush();
    let mut a = shared.lock().unwrap_or_else(PoisonError::into_inner);
    a.done = true;
    match result {
        Ok(d) => {
            let r = d.report;
            let story = monitor_api::words::diagnose::Story::of(&r, &crate::flags::CliWords);
            a.warnings.extend(r.data_quality.warnings.iter().cloned());
            a.warnings.extend(story.withheld_because);
            let v = serde_json::to_value(r.verdict)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string));
            a.verdict = v;
            a.verdict_line = Some(story.verdict_line);
        }
        Err(e) => {
            a.error = Some(monitor_api::files::one_line(
                &monitor_api::words::replay_error(&e, &crate::flags::CliWords),
            ))
        }
    }
}

/// Keeps a reading every [`SNAPSHOT_EVERY_S`] and hands them over in batches.
struct Keeper {
    params: ParamFile,
    shared: Arc<Mutex<ReplayAnalysis>>,
    pending: Vec<Snapshot>,
    next_s: f64,
    stop: bool,
}

impl Keeper {
    fn flush(&mut self) {
        let mut a = self.shared.lock().unwrap_or_else(PoisonError::into_inner);
        a.snapshots.append(&mut self.pending);
        // Nobody watches any more: the analysis is not needed.
        self.stop = Arc::strong_count(&self.shared) == 1;
    }
}

impl ReplayObserver for Keeper {
    fn output(&mut self, row: &Row, out: &MonitorOutput, replay: &Replay) {
        if self.stop {
            return;
        }
        let t = replay.time_of(row);
        if t + 1e-9 < self.next_s {
            return;
        }
        self.next_s = (t / SNAPSHOT_EVERY_S).floor() * SNAPSHOT_EVERY_S + SNAPSHOT_EVERY_S;
        let snap = Snapshot::from_replay(t, out, replay, &self.params);
        self.pending.push(snap);
        if self.pending.len() >= BATCH {
            self.flush();
        }
    }

    fn restart(&mut self) {
        self.pending.clear();
        self.next_s = 0.0;
        let mut a = self.shared.lock().unwrap_or_else(PoisonError::into_inner);
        a.snapshots.clear();
    }
}

impl Source for LogReplay {
    fn advance(&mut self, wall_s: f64, state: &mut HmiState) {
        let shared = Arc::clone(&self.shared);
        let a = shared.lock().unwrap_or_else(PoisonError::into_inner);
        let c = &mut self.controls;
        c.analysed_s = a.snapshots.last().map_or(0.0, |s| s.t_s);
        c.done = a.done;
        c.verdict.clone_from(&a.verdict);
        if !c.paused {
            c.position_s = match c.speed {
                Speed::X1 => c.position_s + wall_s,
                Speed::X10 => c.position_s + 10.0 * wall_s,
                Speed::Max => f64::INFINITY,
            }
            .min(c.analysed_s);
        }
        if a.done && !self.warned {
            self.warned = true;
            state.warnings.extend(a.warnings.iter().cloned());
            if let Some(e) = &a.error {
                state.warnings.push(e.clone());
            }
            let what = match &a.verdict {
                Some(v) => format!("log analysed: verdict {v}"),
                None => "log not analysed".to_string(),
            };
            state.event(what);
            if let Some(line) = &a.verdict_line {
                state.event(format!("verdict: {line}"));
            }
        }
        self.show(&a, state);
        state.controls = Controls::Replay(self.controls.clone());
    }

    fn key(&mut self, key: Key, state: &mut HmiState) -> bool {
        let c = &mut self.controls;
        let pos = c.position_s;
        match key {
            Key::Char(' ') => c.paused = !c.paused,
            Key::Char('>' | '.') => c.speed = c.speed.next(),
            Key::Char('<' | ',') => c.speed = c.speed.next().next(),
            Key::Left => self.seek_to(pos - SEEK_S),
            Key::Right => self.seek_to(pos + SEEK_S),
            Key::PageUp => self.seek_to(pos - SEEK_FAR_S),
            Key::PageDown => self.seek_to(pos + SEEK_FAR_S),
            Key::Home => self.seek_to(0.0),
            Key::End => self.seek_to(f64::INFINITY),
            _ => return quit_key(key, state),
        }
        // Seeking shows the reading at once, paused or not.
        self.advance(0.0, state);
        true
    }

    fn initial_state(&self) -> HmiState {
        HmiState::new(
            format!("log replay: {}", self.path.display()),
            Controls::Replay(self.controls.clone()),
        )
    }
}
