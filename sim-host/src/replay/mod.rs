//! Replay of a measurement log through the no_std core: exactly the code the firmware
//! runs ([`monitor_core::Monitor`]), fed row by row; what `sim-host diagnose` runs
//! ([`diagnose_file`]).
//!
//! The host converts each CSV row into a core [`Sample`] ([`LogSampler`], the host's
//! counterpart of the firmware's ADC sampler): voltages and currents as f32,
//! the encoder count (from `enc_count`, or synthesised by integrating `wm_rad_s` on a
//! 4096-count disc when the log has only a speed column), and a 1 MHz timestamp.
//! Logs without voltages or without speed cannot feed the residuals (every residual of
//! eq. 37 needs Vqs or omega_r); for those only the negative-sequence analysis runs, on an
//! angle from an SRF-PLL locked to the currents, and the report says what was skipped and
//! why. The faulty phase is named by the core's one method
//! ([`monitor_core::sequence::suspect_phase`]), with the slip estimated from the current
//! magnitude where the log has no speed.
//!
//! Every row reaches the replay through the data-quality stage ([`crate::log::quality`],
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
mod pipe;
mod report;
mod sequences;
mod temperature;
mod trig;
mod unsettled;
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
pub(crate) use isolation::serialize_state;
pub use isolation::{
    state_name, DetectionLimit, FaultCandidate, IsolationBaseline, IsolationGroup, IsolationName,
    IsolationReport, NameGiven, SensorPhaseReport, NOMINAL_UNCERTAINTY,
};
pub use report::{
    BaselineSource, Detection, DiagnoseReport, MonitorState, Panel, TimelinePoint, UnbalanceReport,
    Verdict,
};
pub use sequences::{SequenceWindow, WINDOW_PERIODS};
pub use temperature::TemperatureReport;
pub use winding::{
    segments, HealthyReference, OperatingPointSource, SequenceSegment, DEFAULT_SPREAD_CURRENTS,
    DEFAULT_SPREAD_VOLTAGES, LEAST_CHANGE_SPREADS, NO_BASELINE_SPREAD, NO_BASELINE_SPREAD_VOLTAGES,
};

use crate::log::{Channels, LogError, Row};
use crate::params::ParamFile;
use commission::CommissionTracker;
use isolation::IsolationTracker;
use monitor_core::{
    Abc, AngleSource, CommissioningState, ConfigError, Isolator, Monitor, MonitorConfig,
    MonitorOutput, ResidualForm, Sample,
};
use serde::Serialize;

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
/// The least relative change of a named fault for the verdict `fault`: the core's one rule
/// ([`monitor_core::isolation::MIN_FAULT_CHANGE`], 5 %), shared by `diagnose`, the HMI's log
/// replay, the demo ([`Replay::finish`]) and the board's FAULT lamp. Below it the verdict is
/// `watching`, with the name and its size.
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
    /// A bad option.
    #[error("{0}")]
    Option(String),
    /// The commissioning window was not learned (and `--allow-incomplete` was not given).
    #[error("{why}: give a window inside the log's healthy running, or --allow-incomplete to report with the fixed thresholds")]
    IncompleteCommissioning {
        /// What happened.
        why: String,
    },
    /// Reading the log failed.
    #[error(transparent)]
    Log(#[from] LogError),
}

/// Replay options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayOptions {
    /// Frame angle source.
    pub angle_source: AngleSource,
    /// Residual form for the lamps.
    pub residual_form: ResidualForm,
    /// Commissioning window [start, end) in log seconds; None = fixed thresholds.
    pub commission: Option<(f64, f64)>,
    /// Report a commissioning window that was not learned instead of refusing.
    pub allow_incomplete: bool,
    /// Timeline resolution [s] (one point per interval).
    pub timeline_step_s: f64,
    /// The healthy machine's negative sequence to judge the winding against (`diagnose
    /// --baseline HEALTHY.csv`); without it, the one learned in the commissioning window,
    /// else none ([`UnbalanceBaseline`]).
    pub unbalance_baseline: Option<HealthyReference>,
    /// What is known of the load ([`LoadModel`]; `diagnose --load`).
    pub load: LoadModel,
}

/// What the replay knows of the load torque.
///
/// The paper's model has a fixed viscous load `Bl wr` (eq. 4), so to it any change of the
/// load is a change of Bl, and the friction class B/Bl is one of its faults (Table 1). In
/// service the load moves all day and nothing tells a change of the load from a change of
/// the friction: with the load as an unknown input B and Bl cannot be judged, and a reading
/// of them is an operating-point change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoadModel {
    /// The load is an unknown input (real service; the default): the friction class is
    /// never named, its reading is reported as a load move (an event and the verdict
    /// sentence); electrical faults are named from the stator-voltage equations and, at a
    /// load measured just before a deviation, the torque against it.
    #[default]
    Unknown,
    /// The paper's fixed viscous load (Table 1, the demo): a B/Bl change is a fault, named
    /// as the friction class `b/bl`.
    Viscous,
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
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            angle_source: AngleSource::RotorFluxCurrentModel,
            residual_form: ResidualForm::Steady,
            commission: None,
            allow_incomplete: false,
            timeline_step_s: 0.1,
            unbalance_baseline: None,
            load: LoadModel::Unknown,
        }
    }
}

/// The monitor configuration for replaying a log: the parameter file's machine and supply
/// at the log's sample rate, 1 MHz timestamps. The sensor limits are the log's
/// ([`ParamFile::log_limits`]: twice the sensor ranges, because a log does not say its ADC
/// ranges), the same the data-quality stage judges cells by. (The firmware's configuration is `drive_monitor::app`'s
/// `board_monitor_config`.)
pub fn monitor_config_for_log(
    p: &ParamFile,
    sample_rate_hz: f64,
    opts: &ReplayOptions,
) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(
        p.motor.model(),
        p.supply.f_hz as f32,
        p.supply.v_ll_rms as f32,
        sample_rate_hz as f32,
    );
    cfg.angle_source = opts.angle_source;
    cfg.residual_form = opts.residual_form;
    cfg.tick_hz = TICK_HZ as f32;
    let limits = p.log_limits();
    cfg.limits.v_max = limits.v_max_v;
    cfg.limits.i_max = limits.i_max_a;
    cfg.limits.max_speed_rad_s = limits.wm_max_rad_s;
    cfg
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

/// The core sample of `row` from `sampler`, its encoder count moved on by `enc_offset`
/// (counts handed on over a clock reset: [`Replay`]'s `enc_offset`).
fn sample_of(sampler: &mut LogSampler, enc_offset: i64, row: &Row) -> Sample {
    if enc_offset == 0 {
        sampler.sample(row)
    } else {
        sampler.sample(&Row {
            enc_count: row.enc_count.map(|c| c.wrapping_add(enc_offset)),
            ..*row
        })
    }
}

/// Books a counted detection at `t` [s]: the first one's time, and each fault the output
/// ranks first the first time it does.
fn note_detection(
    first: &mut Option<f64>,
    detections: &mut Vec<Detection>,
    t: f64,
    out: &MonitorOutput,
) {
    if first.is_none() {
        *first = Some(t);
    }
    if let Some((fault, _)) = out.top() {
        if !detections.iter().any(|d| d.fault == fault) {
            detections.push(Detection { fault, t_s: t });
        }
    }
}

/// Whether the sample at `t` [s] (interval `dt_s`) is the one nearest the timeline step
/// `next` (half a sample early counts); if so, `next` moves on by `step_s`, past `t` after a
/// gap (one point for the gap, not one per step missed).
fn timeline_step_due(next: &mut f64, t: f64, dt_s: f64, step_s: f64) -> bool {
    if t + 0.5 * dt_s < *next {
        return false;
    }
    *next += step_s;
    if *next <= t {
        *next += (((t - *next) / step_s).floor() + 1.0) * step_s;
    }
    true
}

/// Converts log rows to core samples, synthesising encoder counts from speed if needed
/// (the host's counterpart of the firmware's `drive_monitor::sampling::AdcSampler`).
///
/// The count handed to the core is one continuous count: each row advances it by the
/// encoder's own step where this row and the one before carry `enc_count`, else by the
/// speed channel's `floor(theta_m C / 2 pi)` step (`theta_m` the integral of `wm_rad_s`,
/// `C` = [`COUNTS_PER_REV`]), else not at all. A log that switches between the two (the
/// data-quality stage drops a bad count where the speed channel is good) gives no jump.
#[derive(Debug, Clone, Default)]
pub struct LogSampler {
    theta_m: f64,
    last_t: Option<f64>,
    /// The last row's encoder count, if it had one.
    last_enc: Option<i64>,
    /// The count handed on (`None` before the first row).
    count: Option<i64>,
    /// The speed channel's synthesised count at the last row.
    synth: i64,
}

impl LogSampler {
    /// The core sample for `row` (voltages 0 when the log has none).
    pub fn sample(&mut self, row: &Row) -> Sample {
        if let (Some(t0), Some(w)) = (self.last_t, row.wm_rad_s) {
            self.theta_m += w * (row.t_s - t0);
        }
        let synth = floor_i64(self.theta_m / std::f64::consts::TAU * f64::from(COUNTS_PER_REV));
        let count = match (self.count, row.enc_count, self.last_enc) {
            (None, Some(c), _) => c,
            (None, None, _) => synth,
            (Some(n), Some(c), Some(l)) => n.wrapping_add(c.wrapping_sub(l)),
            (Some(n), _, _) if row.wm_rad_s.is_some() => {
                n.wrapping_add(synth.wrapping_sub(self.synth))
            }
            (Some(n), _, _) => n,
        };
        self.count = Some(count);
        self.synth = synth;
        self.last_enc = row.enc_count;
        let count = count as u32;
        self.last_t = Some(row.t_s);
        let v = row.v_abc.unwrap_or([0.0; 3]);
        let i = row.i_abc;
        Sample {
            v_abc: Abc {
                a: v[0] as f32,
                b: v[1] as f32,
                c: v[2] as f32,
            },
            i_abc: Abc {
                a: i[0] as f32,
                b: i[1] as f32,
                c: i[2] as f32,
            },
            encoder_count: count,
            timestamp_ticks: round_i64(row.t_s * TICK_HZ) as u32,
            v_saturated: false,
            i_saturated: false,
        }
    }
}

/// `x.floor() as i64` (saturating; 0 for NaN) without a call into libm: the baseline
/// x86-64 target has no rounding instruction, and the replay converts every row.
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    // `t as f64` is exact wherever x has a fraction (|x| < 2^52).
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// `x.round() as i64` (half away from zero, saturating; 0 for NaN), as [`floor_i64`].
fn round_i64(x: f64) -> i64 {
    let t = x as i64;
    // Exact wherever x has a fraction (|x| < 2^52).
    let frac = x - t as f64;
    if frac >= 0.5 {
        t.saturating_add(1)
    } else if frac <= -0.5 {
        t.saturating_sub(1)
    } else {
        t
    }
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
    timeline: Vec<TimelinePoint>,
    next_point: f64,
    dt_s: f64,
    max_abs: [f32; 4],
    /// What the next row needs of the monitor's output after the last row (a copy of the
    /// whole output per row is what it saves).
    last: LastOutput,
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
    /// The monitor's count of timing faults (estimator restarts) at the last row.
    timing_faults_seen: u32,
    /// The isolation ignores points until this time [s] (the settling after a restart).
    isolation_hold_until: f64,
    /// The stretch where the quasi-steady gate held the lamps, at the log's end.
    unsettled: unsettled::Unsettled,
    /// The monitor's settling time after a restart [s].
    settle_s: f64,
    /// Added to every row's encoder count after a clock reset: the turn over the bridged
    /// time ([`Replay::clock_reset`]).
    enc_offset: i64,
}

impl Replay {
    /// Prepares a replay of a log with the given channels and sample rate.
    ///
    /// # Errors
    /// [`ReplayError::Config`] when the core rejects the configuration (e.g. a sample rate
    /// below 8x the supply frequency); [`ReplayError::Option`] for a commissioning window
    /// that is not `0 <= START < END`, both finite.
    pub fn new(
        params: &ParamFile,
        channels: Channels,
        sample_rate_hz: f64,
        opts: ReplayOptions,
    ) -> Result<Self, ReplayError> {
        if let Some((a, b)) = opts.commission {
            if !(b > a && a >= 0.0 && b.is_finite()) {
                return Err(ReplayError::Option(format!(
                    "--commission {a}:{b}: the window must be START:END with 0 <= START < END, both finite (seconds)"
                )));
            }
        }
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
            commission: CommissionTracker::new(opts.commission, &cfg),
            k_sigma: cfg.thresholds.k_sigma,
            rows: 0,
            evaluated: false,
            judged_s: 0.0,
            detected_in_range: false,
            first_detection: None,
            detections: Vec::new(),
            timeline: Vec::new(),
            next_point: 0.0,
            dt_s: 1.0 / sample_rate_hz,
            max_abs: [0.0; 4],
            last: LastOutput::default(),
            t0: None,
            isolation: IsolationTracker::new(
                Isolator::new(
                    params.motor.model(),
                    params.supply.v_phase_peak() as f32,
                    params.supply.f_hz as f32,
                )
                .ok(),
                channels.temperature,
                opts.load,
            ),
            lamps_since_moved: false,
            seq_front: sequence_front(params, channels, sample_rate_hz).map_err(config_error)?,
            book: sequences::WindowBook::new(),
            timing_faults_seen: 0,
            isolation_hold_until: f64::NEG_INFINITY,
            unsettled: unsettled::Unsettled::default(),
            settle_s: f64::from(cfg.settle_s),
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
        let Some(mon) = self.monitor.as_ref() else {
            return;
        };
        // (The output is read where the monitor keeps it: no copy per row.)
        let out = mon.output();
        let range_note = self.commission.after(mon, t, out);
        self.evaluated |= out.evaluating;
        if out.evaluating {
            for (m, r) in self.max_abs.iter_mut().zip(out.residuals) {
                *m = m.max(r.abs());
            }
        }
        // With a commissioning window asked for, lamps lit on the fixed thresholds before
        // the learned ones are in force are not detections: the window says the nominal
        // parameters are not to be trusted (a sensor fault counts at any time).
        let counts = out.sensor_fault.any() || self.commission.thresholds_trusted(out);
        // The bands only matter (and are only looked up) while the gate holds the lamps or a
        // lamp is lit.
        let bands = if out.quasi_steady && !out.fault_detected {
            [(0.0, 0.0); 4]
        } else {
            mon.threshold_bands()
        };
        self.unsettled.after(
            t,
            out,
            if out.quasi_steady {
                [(0.0, 0.0); 4]
            } else {
                bands
            },
            self.evaluated,
            self.commission.thresholds_trusted(out),
        );
        let point = step.point(out.operating.wr_rad_s);
        // After a restart of the monitor's estimators (a long gap, a clock reset) the
        // isolation waits out the monitor's settling time too: the restarted frame's
        // vectors look steady before they are right.
        if out.timing.timing_faults != self.timing_faults_seen {
            self.timing_faults_seen = out.timing.timing_faults;
            self.isolation_hold_until = t + self.settle_s;
        }
        let settled = t >= self.isolation_hold_until;
        self.isolation.after(
            t,
            self.dt_s,
            out,
            &point,
            counts && settled,
            row.t_winding_c,
        );
        if out.fault_detected && counts {
            // A detection counts as one inside the commissioned range only while the lamps
            // are evaluated (quasi-steady) and a lit lamp's residual is outside its band: a
            // lamp held through a transient, or after its residual came back (the load
            // returned into the range), detects nothing new there.
            let current = out.evaluating && lit_outside_band(out, bands);
            self.detected_in_range |=
                out.sensor_fault.any() || (current && !self.commission.outside_learned_range(out));
            note_detection(&mut self.first_detection, &mut self.detections, t, out);
        }
        // The sample nearest each timeline step (half a sample early counts: the data-quality
        // stage's sample clock may put the sample at the step a hair before it).
        if timeline_step_due(
            &mut self.next_point,
            t,
            self.dt_s,
            self.opts.timeline_step_s,
        ) {
            let point = timeline_point(self, t, out, range_note);
            self.timeline.push(point);
        }
        // The running the lamps were judged on ([`MIN_JUDGED_S`]), and whether the lamps lit
        // now lit while the load had moved.
        if out.evaluating && out.quasi_steady && self.commission.thresholds_trusted(out) {
            self.judged_s += self.dt_s;
        }
        if !out.lamps.iter().any(|l| *l) {
            self.lamps_since_moved = false;
        } else if self.commission.moved_note(out).is_some() || self.isolation.load_explains_lamps()
        {
            self.lamps_since_moved = true;
        }
        self.last = LastOutput::of(out);
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

/// What a replay keeps of the monitor's output after a row for the next one.
#[derive(Debug, Clone, Copy, Default)]
struct LastOutput {
    /// The commissioning window is being learned.
    learning: bool,
    /// The electrical rotor speed [rad/s].
    wr_rad_s: f32,
    /// A sensor fault is flagged.
    sensor_fault: bool,
}

impl LastOutput {
    fn of(out: &MonitorOutput) -> Self {
        LastOutput {
            learning: matches!(out.commissioning, CommissioningState::Learning(_)),
            wr_rad_s: out.operating.wr_rad_s,
            sensor_fault: out.sensor_fault.any(),
        }
    }
}

/// Whether a lit lamp's residual lies outside its band `(centre, half-width)` now.
fn lit_outside_band(out: &MonitorOutput, bands: [(f32, f32); 4]) -> bool {
    out.lamps
        .iter()
        .zip(out.residuals)
        .zip(bands)
        .any(|((lit, r), (c, h))| *lit && (r - c).abs() > h)
}

/// Serialises an angle source by its command-line name ([`angle_source_name`]).
pub(crate) fn serialize_angle_source<S: serde::Serializer>(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::quality::CellLimits;

    #[test]
    fn floor_and_round_as_std() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            9.223_372_036_854_775e18,
            -9.223_372_036_854_775e18,
            1e300,
            -1e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            values.push(v);
            values.push(((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi(k % 20));
            values.push((k as f64 - 50_000.0) * 0.25);
        }
        for v in values {
            assert_eq!(floor_i64(v), v.floor() as i64, "{v:e}");
            assert_eq!(round_i64(v), v.round() as i64, "{v:e}");
        }
    }

    #[test]
    fn the_monitor_and_the_quality_stage_judge_a_log_by_the_same_limits() {
        for p in [ParamFile::reference_2p2kw(), ParamFile::reference_3hp()] {
            let cfg = monitor_config_for_log(&p, 10_000.0, &ReplayOptions::default());
            let cells = CellLimits::for_params(&p);
            assert_eq!(f64::from(cfg.limits.v_max), cells.v_max);
            assert_eq!(f64::from(cfg.limits.i_max), cells.i_max);
            assert_eq!(f64::from(cfg.limits.max_speed_rad_s), cells.wm_max);
            // The speed limit is the core's own default for the supply.
            let core = MonitorConfig::new(
                p.motor.model(),
                p.supply.f_hz as f32,
                p.supply.v_ll_rms as f32,
                10_000.0,
            );
            assert_eq!(cfg.limits.max_speed_rad_s, core.limits.max_speed_rad_s);
            // Twice the sensor ranges.
            let r = p.sensor_ranges();
            assert_eq!(cells.v_max, 2.0 * r.v_range_v);
            assert_eq!(cells.i_max, 2.0 * r.i_range_a);
        }
    }
}
