//! Replay of a measurement log through the no_std core: exactly the code the firmware
//! runs ([`monitor_core::Monitor`]), fed row by row; what `sim-host diagnose` runs
//! ([`diagnose_file`]).
//!
//! The host converts each CSV row into a core [`Sample`](monitor_core::Sample)
//! ([`LogSampler`], the host's counterpart of the firmware's ADC sampler): voltages and
//! currents as f32, the encoder count (from `enc_count`, or synthesised by integrating
//! `wm_rad_s` on a 4096-count disc when the log has only a speed column), and a 1 MHz
//! timestamp.
//! Logs without voltages or without speed cannot feed the residuals (every residual of
//! eq. 37 needs Vqs or omega_r); for those only the negative-sequence analysis runs, on an
//! angle from an SRF-PLL locked to the currents, and the report says what was skipped and
//! why. The faulty phase is named by the core's one method
//! ([`monitor_core::sequence::suspect_phase`]), with the slip estimated from the current
//! magnitude where the log has no speed.
//!
//! Every row reaches the replay through the data-quality stage ([`monitor_io::log::quality`],
//! [`diagnose_file`], [`diagnose_rows`]): times in seconds, repeated and backward rows
//! dropped, gaps passed on with their real elapsed time (the core bridges the short ones
//! and restarts its estimators after the long ones), bad cells flagged (the core holds
//! them out, the current-only analysis skips them). What the stage found is the report's
//! `data_quality`; what commissioning did is its `commissioning` ([`commission`]).

mod commission;
mod diagnose;
mod events;
mod front;
mod isolation;
mod isolation_name;
mod options;
mod pipe;
mod report;
mod rotor;
mod sampler;
mod sequences;
mod step;
mod temperature;
mod trig;
mod unsettled;
pub mod verdict;
mod winding;

use report::timeline_point;

pub use commission::{
    grace_s, min_learned_s, CommissioningOutcome, CommissioningReport, QuasiSteadyPoint, RangeNote,
    MIN_LEARNED_S,
};
pub use diagnose::{
    diagnose_file, diagnose_file_observed, diagnose_log, diagnose_rows, Diagnosed, ReplayObserver,
};
pub use events::{IsolationEvent, LOAD_MOVE_FRACTION, MAX_EVENTS};
pub use isolation::serialize_state;
pub use isolation::{
    state_name, DetectionLimit, FaultCandidate, IsolationBaseline, IsolationGroup, IsolationName,
    IsolationReport, NameGiven, SensorPhaseReport, NOMINAL_UNCERTAINTY,
};
pub use options::{
    check_parallel_paths, monitor_config_for_log, CommissionWindow, FieldNames, LoadModel,
    OptionError, OptionField, ReplayOptions, Spelling, TimelineStep, Words, PARALLEL_PATHS,
};
pub use report::{
    BaselineSource, Detection, DiagnoseReport, MonitorState, Panel, TimelinePoint, UnbalanceReport,
};
pub use rotor::{
    band_of, blackman_harris, RotorBand, RotorReport, SlipSource, BLACKMAN_HARRIS_4,
    EDGE_SPREAD_DB, FAULT_EDGE_DB, MAIN_LOBE_HALF_BINS, MAX_SLIP, MAX_STRETCH_S, MIN_BINS,
    MIN_SLIP, SLIP_STEADY,
};
pub use sampler::LogSampler;
pub use sequences::{SequenceWindow, WINDOW_PERIODS};
pub use temperature::TemperatureReport;
pub use verdict::{FindingReport, Rule, Verdict};
pub use winding::level::{
    LabelledRun, LevelBasis, ShortedTurns, TurnCalibration, TurnLevelOptions,
};
pub use winding::{
    describe_against, segments, Against, HealthyReference, OperatingPointSource,
    PhaseProbabilities, SequenceSegment, BALANCED_RATIO, DEFAULT_SPREAD_CURRENTS,
    DEFAULT_SPREAD_VOLTAGES, HEALTHY_RUN_DIFFERENCE_CURRENTS, HEALTHY_RUN_DIFFERENCE_VOLTAGES,
    NO_BASELINE_SPREAD, NO_BASELINE_SPREAD_VOLTAGES, WINDING_FAULT_PROBABILITY, WITHIN_LOG_SPREAD,
};

use commission::CommissionTracker;
use isolation::chunk::RowFlags;
use isolation::IsolationTracker;
use monitor_core::{AngleSource, ConfigError, Isolator, Monitor, MonitorOutput};
use monitor_io::log::{Channels, LogError, Row};
use monitor_io::params::ParamFile;
use sampler::sample_of;
use serde::Serialize;
use step::{
    bands_for, bands_needed, book_detection, lamps_since_moved, note_residuals, timeline_step_due,
    BlockView, LastOutput, RestartHold, NO_BANDS,
};

/// Timestamp tick rate used for replays [Hz].
pub const TICK_HZ: f64 = 1.0e6;
/// Counts per revolution of the synthesised encoder (1024 lines x 4).
pub const COUNTS_PER_REV: u32 = 4096;
/// Zero sequence (|3 I0|/|I1|) from which one phase's sensor gain error is reported: 0.5 %,
/// about ten times what 12-bit sensors with 0.1 % noise and 0.2 % gain mismatch leave after
/// the sequence analysis' 2 Hz filters (a one-phase gain error `g` gives about `g`).
pub const SENSOR_PHASE_MIN_RATIO: f32 = 0.005;
/// Missing samples up to this many in a row are filled for the sequence analysis (the
/// vectors turned back at the supply frequency); longer gaps only advance the angle.
pub const FILLED_SAMPLES: usize = 50;
/// The commissioning window's negative sequence is the winding's baseline only while |I1|
/// stays within this fraction of its value there (a motor's own asymmetry moves with the
/// slip; `diagnose --baseline` is the user's choice and is always used).
pub const BASELINE_I1_TOLERANCE: f32 = 0.1;
/// The least running, in seconds, on which the lamps must have been judged (evaluated,
/// quasi-steady, on thresholds in force) for the verdict `healthy`: less is "could not
/// judge" with how much was judged. One rule for `diagnose`, the HMI's log replay and the
/// demo (all report through [`Replay::finish`]).
pub const MIN_JUDGED_S: f64 = 1.0;
/// The least relative change of a named fault for the verdict `fault`: the core's
/// ([`monitor_core::isolation::MIN_FAULT_CHANGE`], 5 %), read by the one verdict's decision
/// table (`monitor_core::verdict`) for `diagnose`, the HMI's log replay, the demo
/// ([`Replay::finish`]) and the board's FAULT lamp. Below it the verdict is `watching`, with
/// the name and its size.
pub const MIN_FAULT_CHANGE: f32 = monitor_core::isolation::MIN_FAULT_CHANGE;

/// Errors from setting up or running a replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The core rejected the configuration built from the parameter file and the log.
    #[error("cannot configure the monitor: {source} (sample rate {sample_rate_hz:.1} Hz)")]
    Config {
        /// The field and what it must satisfy.
        source: ConfigError,
        /// The log's sample rate.
        sample_rate_hz: f64,
    },
    /// An option the replay does not take, naming its field.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The log holds no row to replay.
    #[error("{log}: no rows to replay")]
    NoRows {
        /// How messages name the log.
        log: String,
    },
    /// The commissioning window was not learned (and `allow_incomplete` was not asked).
    #[error("{}", self.spelled(&FieldNames))]
    IncompleteCommissioning {
        /// The window asked for (`START:END`).
        window: String,
        /// What happened.
        why: String,
    },
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] LogError),
}

impl ReplayError {
    /// The message in a front end's words (`spell` names the options it refers to).
    pub fn spelled(&self, spell: &dyn Spelling) -> String {
        match self {
            ReplayError::Option(e) => e.spelled(spell),
            ReplayError::IncompleteCommissioning { window, why } => format!(
                "{}: {why}: give a window inside the log's healthy running, or {} to report with the fixed thresholds",
                spell.option(OptionField::Commission, window),
                spell.option(OptionField::AllowIncomplete, "")
            ),
            e => e.to_string(),
        }
    }
}

/// The healthy machine's negative sequence, relative to its positive sequence: what a
/// motor's own asymmetry and the sensors' mismatch put there before any fault. The
/// winding analysis judges the change from it (`unbalance.baseline`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UnbalanceBaseline {
    /// `I2/I1` (re, im), the sensor-corrected currents'.
    pub i2_over_i1: [f32; 2],
    /// `V2/I1` [ohm] (re, im), where voltages are logged.
    pub v2_over_i1: Option<[f32; 2]>,
    /// |I1| [A, peak] where it was taken (the operating point).
    pub i1_peak_a: f32,
    /// The electrical rotor speed [rad/s] where it was taken, where the log has a speed
    /// (the operating point).
    pub wr_rad_s: Option<f32>,
}

/// The isolation's tracker for a replay of a log with `channels` under `params` (no
/// isolator for a machine it rejects), `load` what is known of the load, `decimation` the
/// core's block (the rows the tracker hands on together).
fn isolation_tracker(
    params: &ParamFile,
    channels: Channels,
    load: LoadModel,
    words: Words,
    decimation: u16,
) -> IsolationTracker {
    let isolator = Isolator::new(
        params.motor.model(),
        params.supply.v_phase_peak() as f32,
        params.supply.f_hz as f32,
    );
    IsolationTracker::new(
        isolator.ok(),
        channels.temperature,
        load,
        words,
        u32::from(decimation),
    )
}

/// The sequence analysis of a replay of a log with `channels` at `sample_rate_hz` (the
/// sample limits the monitor's, [`monitor_config_for_log`]). Errors: the filters' checks
/// ([`sequences::SequenceFront::new`]).
fn sequence_front(
    params: &ParamFile,
    channels: Channels,
    sample_rate_hz: f64,
) -> Result<sequences::SequenceFront, monitor_core::ConfigError> {
    let cfg = monitor_config_for_log(params, sample_rate_hz, &ReplayOptions::default());
    sequences::SequenceFront::new(
        params,
        channels.voltages,
        sample_rate_hz,
        f64::from(cfg.limits.i_max),
        f64::from(cfg.limits.v_max),
    )
}

/// Streaming replay: feed rows, then [`Replay::finish`].
pub struct Replay {
    monitor: Option<Monitor>,
    sampler: LogSampler,
    opts: ReplayOptions,
    params: ParamFile,
    channels: Channels,
    commission: CommissionTracker,
    k_sigma: f32,
    rows: u64,
    evaluated: bool,
    /// Seconds of running on which the lamps were judged: evaluated, quasi-steady, on
    /// thresholds in force ([`MIN_JUDGED_S`] for a healthy verdict).
    judged_s: f64,
    /// A detection happened inside the commissioned operating range (or without one).
    detected_in_range: bool,
    first_detection: Option<f64>,
    detections: Vec<Detection>,
    /// The fault probabilities whose first fault is in `detections` already (NaN: none
    /// yet; [`step::note_detection`]).
    top_seen: [f32; monitor_core::FAULT_COUNT],
    timeline: Vec<TimelinePoint>,
    next_point: f64,
    dt_s: f64,
    max_abs: [f32; 4],
    /// What the next row needs of the monitor's output after the last row (a copy of the
    /// whole output per row is what it saves).
    last: LastOutput,
    /// What the rows up to the monitor's next revision take from its output
    /// ([`Replay::block_row`]).
    view: BlockView,
    t0: Option<f64>,
    isolation: IsolationTracker,
    /// The symmetrical components, sample by sample ([`sequences::SequenceFront`]; on the
    /// reading thread in `diagnose`, whose steps come with the rows: [`Replay::push_step`]).
    seq_front: sequences::SequenceFront,
    /// The least-squares windows with the monitor's learning and speed.
    book: sequences::WindowBook,
    /// The lamps lit now first lit while the operating point had moved (or the load
    /// explained them), and have not all been dark since: their release after the load came
    /// back is still the amber state.
    lamps_since_moved: bool,
    /// The isolation's wait after a restart of the monitor's estimators.
    restart: RestartHold,
    /// The stretch where the quasi-steady gate held the lamps, at the log's end.
    unsettled: unsettled::Unsettled,
    /// Added to every row's encoder count after a clock reset: the turn over the bridged
    /// time ([`Replay::clock_reset`]).
    enc_offset: i64,
}

impl Replay {
    /// Prepares a replay of a log with the given channels and sample rate.
    ///
    /// # Errors
    /// [`ReplayError::Config`] when the core rejects the configuration (e.g. a sample rate
    /// below 8x the supply frequency); [`ReplayError::Option`] for options
    /// [`ReplayOptions::validate`] refuses.
    pub fn new(
        params: &ParamFile,
        channels: Channels,
        sample_rate_hz: f64,
        opts: ReplayOptions,
    ) -> Result<Self, ReplayError> {
        opts.validate()?;
        let cfg = monitor_config_for_log(params, sample_rate_hz, &opts);
        let config_error = |source| ReplayError::Config {
            source,
            sample_rate_hz,
        };
        let can_residuals = channels.voltages && (channels.speed || channels.encoder);
        let monitor = if can_residuals {
            Some(Monitor::new(cfg).map_err(config_error)?)
        } else {
            cfg.validate().map_err(config_error)?;
            None
        };
        Ok(Replay {
            monitor,
            sampler: LogSampler::default(),
            opts,
            params: *params,
            channels,
            commission: CommissionTracker::new(opts.commission, opts.words, &cfg),
            k_sigma: cfg.thresholds.k_sigma,
            rows: 0,
            evaluated: false,
            judged_s: 0.0,
            detected_in_range: false,
            first_detection: None,
            detections: Vec::new(),
            top_seen: [f32::NAN; monitor_core::FAULT_COUNT],
            timeline: Vec::new(),
            next_point: 0.0,
            dt_s: 1.0 / sample_rate_hz,
            max_abs: [0.0; 4],
            last: LastOutput::default(),
            view: BlockView::default(),
            t0: None,
            isolation: isolation_tracker(params, channels, opts.load, opts.words, cfg.decimation),
            lamps_since_moved: false,
            seq_front: sequence_front(params, channels, sample_rate_hz).map_err(config_error)?,
            book: sequences::WindowBook::new(),
            restart: RestartHold::new(f64::from(cfg.settle_s)),
            unsettled: unsettled::Unsettled::default(),
            enc_offset: 0,
        })
    }

    /// Feeds one row; returns the monitor's output (default output for current-only logs).
    pub fn push(&mut self, row: &Row) -> MonitorOutput {
        let t = row.t_s - *self.t0.get_or_insert(row.t_s);
        let step = self.seq_front.track(row, t);
        self.book.take(&mut self.seq_front);
        self.push_step(row, &step);
        self.output()
    }

    /// The monitor's last output (the default for a current-only log).
    fn output(&self) -> MonitorOutput {
        self.monitor
            .as_ref()
            .map_or_else(MonitorOutput::default, |m| *m.output())
    }

    /// [`Replay::push`] with the sequence analysis' step for the row already taken (by a
    /// [`sequences::SequenceFront`] of its own on another thread, whose closed windows were
    /// queued first: [`Replay::queue_window`]).
    fn push_step(&mut self, row: &Row, step: &sequences::SequenceStep) {
        self.rows += 1;
        let t0 = *self.t0.get_or_insert(row.t_s);
        let t = row.t_s - t0;
        let wr = self.monitor.as_ref().map(|_| self.last.wr_rad_s);
        self.book.row(step, self.last.learning, wr);
        let Some(mon) = self.monitor.as_mut() else {
            return;
        };
        self.commission.before(mon, t);
        mon.update(&sample_of(&mut self.sampler, self.enc_offset, row));
        let fresh = self.revise(t);
        let Some(mon) = self.monitor.as_ref() else {
            return;
        };
        // (The output is read where the monitor keeps it: no copy per row.)
        let out = mon.output();
        let BlockView {
            flags,
            judging,
            lamps_lit,
            ..
        } = self.view;
        let point = step.point(out.operating.wr_rad_s);
        let settled = self.restart.settled(t, out);
        let usable = flags.with_counts(flags.counts() && settled);
        let (dt_s, tc) = (self.dt_s, row.t_winding_c);
        self.isolation.after(t, dt_s, usable, &point, tc);
        // The sample nearest each timeline step (half a sample early counts: the data-quality
        // stage's sample clock may put the sample at the step a hair before it).
        let (dt_s, step_s) = (self.dt_s, self.opts.timeline_step.seconds());
        if timeline_step_due(&mut self.next_point, t, dt_s, step_s) {
            let point = timeline_point(self, t, out, self.view.range_note.clone());
            self.timeline.push(point);
        }
        // The running the lamps were judged on ([`MIN_JUDGED_S`]).
        if judging {
            self.judged_s += self.dt_s;
        }
        self.lamps_since_moved = lamps_since_moved(
            (self.lamps_since_moved, lamps_lit),
            out,
            &self.commission,
            &self.isolation,
        );
        if fresh {
            self.last = LastOutput::of(out, flags);
        }
    }

    /// Between two of the monitor's revisions ([`Monitor::revision`]) only its speed moves:
    /// what depends on the rest of the output is done on the revision's first row, in
    /// [`Replay::block_row`] (whether this row at `t` [s] is one: the answer), every row
    /// does what depends on its time or its own values ([`Replay::push_step`]).
    fn revise(&mut self, t: f64) -> bool {
        let Some(mon) = self.monitor.as_ref() else {
            return false;
        };
        let revision = mon.revision();
        if self.view.revision == Some(revision) {
            self.unsettled.tick(t);
            return false;
        }
        let out = mon.output();
        let range_note = self.commission.after(mon, t, out);
        let bands = bands_needed(mon, out);
        let out = *out;
        self.block_row(t, &out, bands, (revision, range_note));
        true
    }

    /// The part of a row that depends on the monitor's output other than its speed, done
    /// on the first row of each of its revisions ([`Monitor::revision`]; the rows after it
    /// up to the next would repeat it to the bit): the residuals' extremes, the flags, the
    /// held stretch, a counted detection, and what the rows up to the next need (`bands`: the
    /// threshold bands in force, `range_note`: the commissioned range's note now).
    fn block_row(
        &mut self,
        t: f64,
        out: &MonitorOutput,
        bands: [(f32, f32); 4],
        (revision, range_note): (u32, Option<String>),
    ) {
        note_residuals(&mut self.evaluated, &mut self.max_abs, out);
        // With a commissioning window asked for, lamps lit on the fixed thresholds before
        // the learned ones are in force are not detections: the window says the nominal
        // parameters are not to be trusted (a sensor fault counts at any time).
        let trusted = self.commission.thresholds_trusted(out);
        let flags = RowFlags::of(out, trusted);
        let counts = flags.counts();
        let bands = bands_for(bands, out, counts, self.detected_in_range);
        let held_bands = if out.quasi_steady { NO_BANDS } else { bands };
        let judged = self.evaluated;
        self.unsettled
            .after(t, (out, flags), held_bands, judged, trusted);
        if out.fault_detected && counts {
            let first = (&mut self.detected_in_range, &mut self.first_detection);
            let booked = (&mut self.detections, &mut self.top_seen);
            book_detection(first, booked, &self.commission, (t, out, bands));
        }
        self.view = BlockView {
            revision: Some(revision),
            flags,
            judging: out.evaluating && out.quasi_steady && trusted,
            lamps_lit: out.lamps.iter().any(|l| *l),
            range_note,
        };
    }

    /// The acquisition clock was reset before the next row (`diagnose` carries the time on
    /// by [`front::CLOCK_RESET_GAP_S`]): the encoder count handed on goes on by the turn
    /// over the bridged time at the monitor's speed (the count the data-quality stage hands
    /// on continues with no step).
    fn clock_reset(&mut self) {
        let w = self
            .monitor
            .as_ref()
            .map_or(0.0, |m| f64::from(m.output().speed_rad_s));
        let turned = w * front::CLOCK_RESET_GAP_S / std::f64::consts::TAU;
        self.enc_offset = self
            .enc_offset
            .wrapping_add((turned * f64::from(COUNTS_PER_REV)).round() as i64);
    }

    /// `row` with the encoder offset of the clock resets so far ([`Replay::clock_reset`]):
    /// the row as the monitor sees it.
    fn with_encoder_offset(&self, row: &Row) -> Row {
        Row {
            enc_count: row.enc_count.map(|c| c.wrapping_add(self.enc_offset)),
            ..*row
        }
    }

    /// Queues a window the sequence analysis closed on another thread, before the step of
    /// the row it closed at ([`Replay::push_step`]).
    fn queue_window(&mut self, w: Option<SequenceWindow>) {
        self.book.queue(w);
    }

    /// Takes over the sequence analysis that ran on another thread, once every row was
    /// pushed: its last window is the replay's to close ([`Replay::finish`]).
    fn set_sequence_front(&mut self, front: sequences::SequenceFront) {
        self.seq_front = front;
    }

    /// The learned calibration (mean and spread of r1..r4), once commissioning is done.
    pub fn calibration(&self) -> Option<monitor_core::Calibration> {
        self.monitor.as_ref().and_then(|m| m.calibration())
    }

    /// The threshold bands of r1..r4 in force, (centre, half-width)
    /// ([`Monitor::threshold_bands`]); `None` for a current-only log.
    pub fn threshold_bands(&self) -> Option<[(f32, f32); 4]> {
        self.monitor.as_ref().map(Monitor::threshold_bands)
    }

    /// Time of `row` since the replay's first row [s] (the timeline's time).
    pub fn time_of(&self, row: &Row) -> f64 {
        row.t_s - self.t0.unwrap_or(row.t_s)
    }

    /// What the isolation concludes now, as [`Replay::finish`] would report it (the report
    /// and the candidates listed), for a screen that follows the replay.
    pub fn isolation_now(&self) -> (IsolationReport, Vec<FaultCandidate>) {
        let detected = self.detected();
        self.isolation.report(detected)
    }

    /// Whether a fault was detected: a lamp lit or the isolation named a fault, unless the
    /// isolation ends finding that the windings' heating explains it
    /// (`monitor_core::isolation`, "Heating is not a fault"), or, with the load an unknown
    /// input, that the load moved ([`LoadModel::Unknown`]: the lamps' torque residuals see a
    /// load change as the paper's Bl fault).
    fn detected(&self) -> bool {
        // With the load unknown, lamps whose matching only ever named the friction class
        // (B, Bl: the load term) read a load move, not a fault.
        let only_load = self.opts.load == LoadModel::Unknown
            && !self.detections.is_empty()
            && self
                .detections
                .iter()
                .all(|d| matches!(d.fault, monitor_core::Fault::B | monitor_core::Fault::Bl))
            && !self.out_sensor_fault_seen();
        let lamps =
            self.first_detection.is_some() && !self.isolation.load_explains_lamps() && !only_load;
        !self.isolation.heating_explains_lamps() && (lamps || self.isolation.named_a_fault())
    }

    /// A sensor fault was flagged at the end (the lamps' detections then stand).
    fn out_sensor_fault_seen(&self) -> bool {
        self.last.sensor_fault
    }

    /// Every name the isolation gave so far (a fault or the friction class `b/bl`), each
    /// with the first time it was given [s] (the replay's time), in that order: a name
    /// given and later withdrawn stays here.
    pub fn isolation_names(&self) -> &[NameGiven] {
        self.isolation.names()
    }

    /// Where the load or the voltage of `out` has left the range learned in
    /// commissioning: the note ("load (active current) 9.52 is 47 % above the commissioned
    /// 6.47..6.48"); `None` inside it or without a learned window. The HMI shows this as
    /// the amber "operating point moved" state: to the paper's model a load change is a Bl
    /// change, so lamps lit there are not a fault unless the isolation names one.
    pub fn operating_point_moved(&self, out: &MonitorOutput) -> Option<String> {
        self.commission.moved_note(out)
    }

    /// The core monitor (`None` for a current-only log).
    pub fn monitor(&self) -> Option<&Monitor> {
        self.monitor.as_ref()
    }

    /// The core monitor, to start a commissioning run by hand (the live HMI's key); `None`
    /// for a current-only log.
    pub fn monitor_mut(&mut self) -> Option<&mut Monitor> {
        self.monitor.as_mut()
    }

    /// True when a commissioning window was asked for and not learned.
    pub fn commissioning_incomplete(&self) -> bool {
        self.monitor.is_some() && self.commission.incomplete()
    }
}

/// Serialises an angle source by its command-line name ([`angle_source_name`]), for
/// `#[serde(serialize_with = "serialize_angle_source")]` on a report's field.
pub fn serialize_angle_source<S: serde::Serializer>(
    a: &AngleSource,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.serialize_str(angle_source_name(*a))
}

/// Name of an angle source as used on the command line.
pub fn angle_source_name(a: AngleSource) -> &'static str {
    match a {
        AngleSource::ZeroCrossing => "zero-crossing",
        AngleSource::Pll => "pll",
        AngleSource::RotorFluxCurrentModel => "rotor-flux",
    }
}
