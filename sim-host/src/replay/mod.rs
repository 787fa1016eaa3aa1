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
mod isolation;

pub use commission::{grace_s, CommissioningReport, RangeNote, SteadyPoint};
pub use isolation::{FaultCandidate, IsolationGroup, IsolationReport, SensorPhaseReport};

use crate::log::quality::{
    BadCells, CellLimits, CleanSink, DataQuality, QualityStage, SegmentBreak, TimeBase,
    MAX_BRIDGED_GAP_S,
};
use crate::log::{Channels, LogError, LogFile, Row, RowSink};
use crate::params::ParamFile;
use commission::CommissionTracker;
use isolation::IsolationTracker;
use monitor_core::angle::SrfPll;
use monitor_core::frames::{clarke, park, AlphaBeta, SinCos};
use monitor_core::sequence::{
    asymmetry_correction_rad, single_phase_gain, slip_for_current, winding_asymmetry,
    SequenceAnalyzer, SinglePhaseGain, ZeroSequence,
};
use monitor_core::SteadyPoint as IsolationPoint;
use monitor_core::{
    Abc, AngleSource, CommissioningState, ConfigError, Fault, Isolator, Monitor, MonitorConfig,
    MonitorOutput, ResidualForm, Sample,
};
use serde::Serialize;
use std::path::Path;

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
    pub unbalance_baseline: Option<UnbalanceBaseline>,
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
        }
    }
}

/// The monitor configuration for replaying a log: the parameter file's machine and supply
/// at the log's sample rate, 1 MHz timestamps. The sensor limits are generous (twice the
/// simulator's default ADC ranges, [`crate::sim::default_ranges`]) because a log does not
/// say its ADC ranges. (The firmware's configuration is `drive_monitor::app`'s
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
    let (v_range, i_range) = crate::sim::default_ranges(&p.motor, p.supply.v_ll_rms, p.supply.f_hz);
    cfg.limits.v_max = 2.0 * v_range as f32;
    cfg.limits.i_max = 2.0 * i_range as f32;
    cfg
}

/// Converts log rows to core samples, synthesising encoder counts from speed if needed
/// (the host's counterpart of the firmware's `drive_monitor::sampling::AdcSampler`).
#[derive(Debug, Clone, Default)]
pub struct LogSampler {
    theta_m: f64,
    last_t: Option<f64>,
}

impl LogSampler {
    /// The core sample for `row` (voltages 0 when the log has none).
    pub fn sample(&mut self, row: &Row) -> Sample {
        let count = match (row.enc_count, row.wm_rad_s) {
            (Some(c), _) => c as u32,
            (None, Some(w)) => {
                if let Some(t0) = self.last_t {
                    self.theta_m += w * (row.t_s - t0);
                }
                floor_i64(self.theta_m / std::f64::consts::TAU * f64::from(COUNTS_PER_REV)) as u32
            }
            (None, None) => 0,
        };
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

/// One point of the diagnosis timeline.
#[derive(Debug, Clone, Serialize)]
pub struct TimelinePoint {
    /// Time [s].
    pub t_s: f64,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Lamps r1..r4.
    pub lamps: [bool; 4],
    /// Most probable fault, if any.
    pub top: Option<String>,
    /// Its probability.
    pub top_probability: f32,
    /// Mechanical speed [rad/s].
    pub speed_rad_s: f32,
    /// Lamps are being evaluated (running, settled, commissioned or fixed).
    pub evaluating: bool,
    /// Learning healthy statistics.
    pub commissioning: bool,
    /// The operating point is quasi-steady (the steady-state residuals apply).
    pub quasi_steady: bool,
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// Beside a lit r2..r4 lamp: the operating point has left the commissioned range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_note: Option<String>,
}

/// Result of the negative-sequence analysis (JSON key `unbalance`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct UnbalanceReport {
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// "a", "b", "c" or null.
    pub suspect_phase: Option<String>,
    /// arg(I2w/I1) [deg]: the winding's part (the supply's part taken out).
    pub angle_deg: f32,
    /// |I2w|/|I1|: the winding's part of the negative sequence.
    pub winding_ratio: f32,
    /// |V2/Z2|/|I1|: the part the supply's voltage unbalance drives (0 without voltages).
    pub supply_ratio: f32,
    /// |V2|/|V1| (null without voltage columns).
    pub voltage_negative_sequence_ratio: Option<f32>,
    /// The model correction arg(Z1/Z2) used [deg].
    pub correction_deg: f32,
    /// One phase's current sensor with a gain error, from the zero sequence of the three
    /// measured currents (zero for a star without neutral, whatever the machine does), or
    /// null; its part of the negative sequence is taken out before a winding is blamed.
    pub current_sensor_phase: Option<SensorPhaseReport>,
    /// The same for the voltage sensors (phase voltages against the star point), or null.
    pub voltage_sensor_phase: Option<SensorPhaseReport>,
    /// What was measured, before the baseline is taken out (sensor-corrected): `I2/I1` and
    /// `V2/I1` (re, im); a healthy log's are the `--baseline` of a later one.
    pub measured: UnbalanceBaseline,
    /// The healthy negative sequence the winding is judged against: `"commissioning"`
    /// (learned in the window, used while |I1| is within [`BASELINE_I1_TOLERANCE`] of its
    /// value there), `"file"` (`--baseline`), or null (none: the supply's part alone is
    /// taken out).
    pub baseline: Option<String>,
}

/// What `diagnose` reports (DESIGN.md §3 JSON keys, plus `verdict`, `data_quality` and
/// `commissioning`).
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseReport {
    /// `fault`, `healthy` or `could not judge` ([`Verdict`]).
    pub verdict: Verdict,
    /// Why the verdict could not be given (empty otherwise).
    pub verdict_withheld_because: Vec<String>,
    /// Final lamps `{"r1":bool,..}`.
    pub lamps: std::collections::BTreeMap<String, bool>,
    /// Final fault candidates, most probable first, with their estimated size: from the
    /// isolation ([`IsolationReport`]) when a fault was detected; an impossible sensor
    /// reading names its sensor outright (size null).
    pub candidates: Vec<FaultCandidate>,
    /// What the isolation concluded: the fault named, its size, the groups that cannot
    /// be separated, and one sentence.
    pub isolation: IsolationReport,
    /// The paper's matching of the final lamps against the fault signature matrix (Table
    /// 1 in voltage orientation), most probable first: the lamps' own candidates.
    pub signature_candidates: Vec<FaultCandidate>,
    /// First time a lamp lit or a sensor fault was seen [s], or null.
    pub first_detection_s: Option<f64>,
    /// Negative-sequence analysis of the currents.
    pub unbalance: UnbalanceReport,
    /// Faults ever named while the lamps were lit, with the time first named.
    pub detections: Vec<(String, f64)>,
    /// Analyses skipped for lack of a column, with the reason.
    pub skipped: Vec<String>,
    /// Angle source used.
    pub angle_source: String,
    /// Commissioning window asked for, if any [s].
    pub commission: Option<(f64, f64)>,
    /// What commissioning did (state, window used, range covered).
    pub commissioning: CommissioningReport,
    /// What the data-quality stage found and did.
    pub data_quality: DataQuality,
    /// Rows replayed.
    pub rows: u64,
    /// Largest |normalised residual| while evaluating, r1..r4.
    pub max_abs_residual: [f32; 4],
    /// Timeline (one point per `timeline_step_s`).
    pub timeline: Vec<TimelinePoint>,
}

/// `diagnose`'s overall answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// A lamp lit, a sensor fault was seen, or the isolation named a fault (other than
    /// the friction class, which a load change also moves).
    Fault,
    /// Evaluated, and no lamp lit.
    Healthy,
    /// The data or the setup does not allow an answer (see `verdict_withheld_because`).
    CouldNotJudge,
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
    i_max: f64,
    rows: u64,
    evaluated: bool,
    /// A detection happened inside the commissioned operating range (or without one).
    detected_in_range: bool,
    first_detection: Option<f64>,
    detections: Vec<(String, f64)>,
    /// Bit `k`: [`Fault::ALL`]`[k]` is in `detections` (a test per row without comparing
    /// names).
    detected_faults: u32,
    timeline: Vec<TimelinePoint>,
    next_point: f64,
    dt_s: f64,
    max_abs: [f32; 4],
    last: MonitorOutput,
    t0: Option<f64>,
    isolation: IsolationTracker,
    // Current-only unbalance analysis.
    pll: SrfPll,
    seq: SequenceAnalyzer,
    seq_v: SequenceAnalyzer,
    /// Zero sequences of the measured currents and voltages (per-phase sensor redundancy).
    zero_i: ZeroSequence,
    zero_v: ZeroSequence,
    /// The negative sequence at the end of the commissioning window (the latest while
    /// learning).
    learned_unbalance: Option<UnbalanceBaseline>,
    v_max: f64,
    /// The sequence analysis' PLL follows the voltages (else the currents).
    pll_on_voltage: bool,
    /// Time of the last row the sequence analysis saw [s].
    seq_t: Option<f64>,
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
        let dt = (1.0 / sample_rate_hz) as f32;
        Ok(Replay {
            monitor,
            sampler: LogSampler::default(),
            opts,
            params: *params,
            channels,
            commission: CommissionTracker::new(opts.commission, &cfg),
            k_sigma: cfg.thresholds.k_sigma,
            i_max: f64::from(cfg.limits.i_max),
            rows: 0,
            evaluated: false,
            detected_in_range: false,
            first_detection: None,
            detections: Vec::new(),
            detected_faults: 0,
            timeline: Vec::new(),
            next_point: 0.0,
            dt_s: 1.0 / sample_rate_hz,
            max_abs: [0.0; 4],
            last: MonitorOutput::default(),
            t0: None,
            isolation: IsolationTracker::new(Isolator::new(
                params.motor.model(),
                params.supply.v_phase_peak() as f32,
                params.supply.f_hz as f32,
            )),
            // Locks to the voltage vector where logged (normalised by its nominal peak), else
            // to the current vector (normalised by the no-load, magnetising, current peak).
            pll: SrfPll::new(
                dt,
                params.supply.f_hz as f32,
                10.0,
                if channels.voltages {
                    params.supply.v_phase_peak() as f32
                } else {
                    (params.supply.v_phase_peak()
                        / (params.supply.omega_rad_s() * params.motor.ls_h))
                        as f32
                },
            ),
            seq: SequenceAnalyzer::new(2.0, dt),
            seq_v: SequenceAnalyzer::new(2.0, dt),
            zero_i: ZeroSequence::new(2.0, dt),
            zero_v: ZeroSequence::new(2.0, dt),
            learned_unbalance: None,
            v_max: f64::from(cfg.limits.v_max),
            pll_on_voltage: channels.voltages,
            seq_t: None,
        })
    }

    /// Feeds one row; returns the monitor's output (default output for current-only logs).
    pub fn push(&mut self, row: &Row) -> MonitorOutput {
        self.rows += 1;
        let t0 = *self.t0.get_or_insert(row.t_s);
        let t = row.t_s - t0;
        self.track_sequences(row, t);
        let Some(mon) = self.monitor.as_mut() else {
            return self.last;
        };
        self.commission.before(mon, t);
        let s = self.sampler.sample(row);
        let out = *mon.update(&s);
        let range_note = self.commission.after(mon, t, &out);
        self.evaluated |= out.evaluating;
        if out.evaluating {
            for (m, r) in self.max_abs.iter_mut().zip(out.residuals) {
                *m = m.max(r.abs());
            }
        }
        // With a commissioning window asked for, lamps lit on the fixed thresholds before
        // the learned ones are in force are not detections: the window says the nominal
        // parameters are not to be trusted (a sensor fault counts at any time).
        let counts = out.sensor_fault.any() || self.commission.thresholds_trusted(&out);
        let point = self.steady_point(&out);
        self.isolation.after(t, self.dt_s, &out, &point, counts);
        if matches!(out.commissioning, CommissioningState::Learning(_)) {
            self.learned_unbalance = Some(self.unbalance_ratios().0);
        }
        if out.fault_detected && counts {
            self.detected_in_range |=
                out.sensor_fault.any() || !self.commission.outside_learned_range(&out);
            if self.first_detection.is_none() {
                self.first_detection = Some(t);
            }
            if let Some((f, _)) = out.top() {
                let bit = 1u32 << f.index();
                if self.detected_faults & bit == 0 {
                    self.detected_faults |= bit;
                    self.detections.push((f.name().to_string(), t));
                }
            }
        }
        // The sample nearest each timeline step (half a sample early counts: the data-quality
        // stage's sample clock may put the sample at the step a hair before it).
        if t + 0.5 * self.dt_s >= self.next_point {
            self.next_point += self.opts.timeline_step_s;
            self.timeline.push(timeline_point(t, &out, range_note));
        }
        self.last = out;
        out
    }

    /// The sequence analysis of every log (the monitor's own runs on its frame without the
    /// voltages' negative sequence): a PLL locked to the current vector, the currents' and,
    /// where logged, the voltages' positive and negative sequences on its angle. A row with
    /// a bad current is skipped (the monitor holds such samples out itself); a bad voltage
    /// leaves the voltages' analysis alone.
    fn track_sequences(&mut self, row: &Row, t: f64) {
        // Samples missing from the stream: the PLL's angle advances over the missing time
        // at its frequency (as the monitor's frame does), so that the sequences stay put.
        let mut filled = 0usize;
        if let Some(prev) = self.seq_t.replace(t) {
            let missing = t - prev - self.dt_s;
            if missing > 0.5 * self.dt_s && missing <= MAX_BRIDGED_GAP_S {
                self.pll.skip(missing as f32);
                let m = (missing / self.dt_s).round();
                if m <= FILLED_SAMPLES as f64 {
                    filled = m as usize;
                }
            }
        }
        let ok = |x: &[f64; 3], max: f64| x.iter().all(|v| v.is_finite() && v.abs() <= max);
        if !ok(&row.i_abc, self.i_max) {
            return;
        }
        let abc = |x: &[f64; 3]| Abc {
            a: x[0] as f32,
            b: x[1] as f32,
            c: x[2] as f32,
        };
        let i_abc = abc(&row.i_abc);
        let i = clarke(i_abc);
        let v_abc = row
            .v_abc
            .as_ref()
            .filter(|v| self.channels.voltages && ok(v, self.v_max))
            .map(abc);
        let v = v_abc.map(clarke);
        let sc = SinCos::from_angle(self.pll.theta_pll());
        // Locked to the voltages where logged: a winding asymmetry puts tens of per cent of
        // negative sequence into the currents, whose 2f ripple would wobble the angle; the
        // supply's own unbalance is a few per cent.
        match v {
            Some(v) if self.pll_on_voltage => self.pll.update(v, sc),
            _ => self.pll.update(i, sc),
        };
        // A few missing samples: the sequence filters get the vectors turned back to the
        // missing instants (a filter that skips a sample of the other sequence's 2f image
        // keeps an error of about that sample's share: 0.1 % of samples dropped at random
        // read as a 0.15 % voltage unbalance, enough to name a winding).
        let w_dt = self.pll.omega_rad_s() * self.dt_s as f32;
        for j in (1..=filled).rev() {
            let back = SinCos::from_angle(j as f32 * w_dt);
            let turn = |x: AlphaBeta| {
                let d = park(x, back);
                AlphaBeta {
                    alpha: d.d,
                    beta: d.q,
                }
            };
            let sc_j = SinCos::from_angle(self.pll.theta_pll() - j as f32 * w_dt);
            self.seq.update(turn(i), sc_j);
            if let Some(v) = v {
                self.seq_v.update(turn(v), sc_j);
            }
        }
        self.seq.update(i, sc);
        self.zero_i.update(i_abc, sc);
        if let (Some(v), Some(v_abc)) = (v, v_abc) {
            self.seq_v.update(v, sc);
            self.zero_v.update(v_abc, sc);
        }
    }

    /// One phase's sensor gain error in the currents and in the voltages (the zero
    /// sequence, [`single_phase_gain`]), evidence from [`SENSOR_PHASE_MIN_RATIO`] on.
    fn sensor_phases(&self) -> (Option<SinglePhaseGain>, Option<SinglePhaseGain>) {
        let current = single_phase_gain(
            self.seq.positive(),
            self.seq.negative(),
            self.zero_i.phasor(),
            SENSOR_PHASE_MIN_RATIO,
        );
        let voltage = self
            .channels
            .voltages
            .then(|| {
                single_phase_gain(
                    self.seq_v.positive(),
                    self.seq_v.negative(),
                    self.zero_v.phasor(),
                    SENSOR_PHASE_MIN_RATIO,
                )
            })
            .flatten();
        (current, voltage)
    }

    /// The steady-state vectors for the isolation: the positive sequences of voltage and
    /// current on the sequence analysis' angle, its PLL's frequency, and the monitor's
    /// electrical speed (encoder, filtered).
    fn steady_point(&self, out: &MonitorOutput) -> IsolationPoint {
        let (v, i) = (self.seq_v.positive(), self.seq.positive());
        IsolationPoint {
            i: monitor_core::Dq { d: i.0, q: i.1 },
            v: monitor_core::Dq { d: v.0, q: v.1 },
            we_rad_s: self.pll.omega_rad_s(),
            wr_rad_s: out.operating.wr,
        }
    }

    /// The negative-sequence report: the core's one faulty-phase method
    /// ([`monitor_core::sequence::winding_asymmetry`]) with the supply's own unbalance taken
    /// out where voltages are logged. The slip is the monitor's (encoder) where it runs,
    /// else the equivalent circuit's for the measured current magnitude
    /// ([`slip_for_current`]).
    /// The sensor-corrected `I2/I1` and `V2/I1` (module docs of
    /// [`monitor_core::sequence`]), with the sensors found wrong on one phase.
    fn unbalance_ratios(
        &self,
    ) -> (
        UnbalanceBaseline,
        Option<SinglePhaseGain>,
        Option<SinglePhaseGain>,
    ) {
        let p = self.seq.positive();
        let p2 = p.0 * p.0 + p.1 * p.1;
        let over_i1 = |x: (f32, f32)| {
            if p2 > 0.0 {
                [(x.0 * p.0 + x.1 * p.1) / p2, (x.1 * p.0 - x.0 * p.1) / p2]
            } else {
                [0.0, 0.0]
            }
        };
        // A sensor's own negative sequence is not the winding's (nor the supply's).
        let (gi, gv) = self.sensor_phases();
        let neg_i = gi.map_or(self.seq.negative(), |g| {
            g.corrected_negative(p, self.seq.negative(), self.zero_i.phasor())
        });
        let neg_v = gv.map_or(self.seq_v.negative(), |g| {
            g.corrected_negative(
                self.seq_v.positive(),
                self.seq_v.negative(),
                self.zero_v.phasor(),
            )
        });
        // With one voltage sensor wrong, the voltages' negative sequence (corrected or not:
        // the analysis' PLL locked to the wrong readings leaves a few tenths of a per cent)
        // cannot say how much of I2 the supply drives: the currents alone judge the winding.
        let ratios = UnbalanceBaseline {
            i2_over_i1: over_i1(neg_i),
            v2_over_i1: (self.channels.voltages && gv.is_none()).then(|| over_i1(neg_v)),
            i1_peak_a: self.seq.positive_magnitude(),
        };
        (ratios, gi, gv)
    }

    fn unbalance_report(&self, out: &MonitorOutput) -> UnbalanceReport {
        let m = self.params.motor.model();
        let omega = self.pll.omega_rad_s();
        let we = if omega > 1.0 {
            omega
        } else {
            self.params.supply.omega_rad_s() as f32
        };
        let (measured, gi, gv) = self.unbalance_ratios();
        // The commissioning window's only once it was learned, and only at about its
        // operating point: a motor's own asymmetry gives an I2/I1 that moves with the slip.
        let i1 = self.seq.positive_magnitude();
        let learned = self.learned_unbalance.filter(|b| {
            matches!(out.commissioning, CommissioningState::Commissioned)
                && (i1 - b.i1_peak_a).abs() <= BASELINE_I1_TOLERANCE * b.i1_peak_a
        });
        let (base, base_name) = match (self.opts.unbalance_baseline, learned) {
            (Some(b), _) => (Some(b), Some("file")),
            (None, Some(b)) => (Some(b), Some("commissioning")),
            (None, None) => (None, None),
        };
        let minus = |x: [f32; 2], b: Option<[f32; 2]>| {
            let b = b.unwrap_or([0.0; 2]);
            (x[0] - b[0], x[1] - b[1])
        };
        let i2 = minus(measured.i2_over_i1, base.map(|b| b.i2_over_i1));
        let v2 = measured
            .v2_over_i1
            .map(|v| minus(v, base.and_then(|b| b.v2_over_i1)));
        let slip = if self.monitor.is_some() {
            1.0 - out.operating.wr / we
        } else {
            let v_pk = if self.channels.voltages {
                self.seq_v.positive_magnitude()
            } else {
                self.params.supply.v_phase_peak() as f32
            };
            slip_for_current(&m, v_pk, we, self.seq.positive_magnitude())
        };
        // A current-only log locks the analysis' PLL to the currents: one wrong current
        // sensor's negative sequence (g/3 of I1) wobbles the angle at 2f and leaves about
        // g^2/3 in I2 after the correction (measured: 0.7 % for g = -15 % at 1 kHz), so a
        // winding is named only above that.
        let min_ratio = match gi {
            Some(g) if !self.pll_on_voltage => 0.005f32.max(0.5 * g.gain_error * g.gain_error),
            _ => 0.005,
        };
        let w = winding_asymmetry(i2, v2, &m, we, slip, min_ratio);
        UnbalanceReport {
            negative_sequence_ratio: monitor_core::fast_hypot(
                measured.i2_over_i1[0],
                measured.i2_over_i1[1],
            ),
            suspect_phase: w.suspect_phase.map(|p| p.name().to_string()),
            angle_deg: w.angle_rad.to_degrees(),
            correction_deg: asymmetry_correction_rad(&m, we, slip).to_degrees(),
            winding_ratio: w.ratio,
            supply_ratio: w.supply_ratio,
            voltage_negative_sequence_ratio: measured.v2_over_i1.map(|v| {
                // |V2|/|V1| = |V2/I1| |I1|/|V1|
                let i1 = self.seq.positive_magnitude();
                monitor_core::fast_hypot(v[0], v[1]) * i1
                    / self.seq_v.positive_magnitude().max(1e-9)
            }),
            current_sensor_phase: gi.as_ref().map(SensorPhaseReport::from),
            voltage_sensor_phase: gv.as_ref().map(SensorPhaseReport::from),
            measured,
            baseline: base_name.map(str::to_string),
        }
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
        let detected = self.first_detection.is_some() || self.isolation.named_a_fault();
        self.isolation.report(detected)
    }

    /// Every label the isolation named so far (a fault's name or `b/bl`), each with the
    /// first time it was named [s] (the replay's time), in that order: a name given and
    /// later withdrawn stays here.
    pub fn isolation_names(&self) -> &[(String, f64)] {
        self.isolation.names()
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

    /// Ends the replay and builds the report (`data_quality` left at its default for the
    /// caller to fill).
    pub fn finish(self) -> DiagnoseReport {
        let out = self.last;
        let mut skipped = Vec::new();
        if !self.channels.voltages {
            skipped.push(
                "residuals r1..r4 and fault signatures: need the voltages va_V, vb_V, vc_V (Vqs)"
                    .to_string(),
            );
        } else if !(self.channels.speed || self.channels.encoder) {
            skipped.push(
                "residuals r1..r4 and fault signatures: need the speed (wm_rad_s or enc_count)"
                    .to_string(),
            );
        }
        let unbalance = self.unbalance_report(&out);
        let mut signature_candidates: Vec<FaultCandidate> = Fault::ALL
            .iter()
            .zip(out.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| FaultCandidate {
                fault: f.name().to_string(),
                probability: p,
                change: None,
                phase: None,
            })
            .collect();
        signature_candidates.sort_by(|a, b| b.probability.total_cmp(&a.probability));
        let detected = self.first_detection.is_some() || self.isolation.named_a_fault();
        let (mut isolation, mut isolated) = self.isolation.report(detected);
        isolation::refine_single_phase(
            &mut isolation,
            &mut isolated,
            unbalance.current_sensor_phase.as_ref(),
            unbalance.voltage_sensor_phase.as_ref(),
        );
        let candidates = if out.sensor_fault.any() {
            signature_candidates.clone()
        } else {
            isolated
        };
        let lamps = (0..4)
            .map(|k| {
                (
                    format!("r{}", k + 1),
                    out.lamps.get(k).copied().unwrap_or(false),
                )
            })
            .collect();
        let mut withheld = skipped.clone();
        if self.monitor.is_some() && !self.evaluated && self.first_detection.is_none() {
            withheld.push(
                "the lamps were never evaluated (the motor never ran settled and quasi-steady with voltage)"
                    .to_string(),
            );
        }
        if let Some(why) = self.commission.why_incomplete() {
            withheld.push(why);
        }
        if let Some(why) = self.commission.nominal_misfit() {
            withheld.push(why);
        }
        if let (Some(t), false) = (self.first_detection, self.detected_in_range) {
            withheld.push(format!(
                "the lamps lit (first at {t:.2} s) only while the load or the voltage was outside the range commissioned: to the paper's model a load change is a Bl change and the learned means hold only where they were learned, so a fault cannot be told from the new operating point; commission over the whole load and voltage range"
            ));
        }
        let verdict = if !withheld.is_empty() {
            Verdict::CouldNotJudge
        } else if detected {
            Verdict::Fault
        } else {
            Verdict::Healthy
        };
        DiagnoseReport {
            verdict,
            verdict_withheld_because: if verdict == Verdict::CouldNotJudge {
                withheld
            } else {
                Vec::new()
            },
            lamps,
            candidates,
            isolation,
            signature_candidates,
            first_detection_s: self.first_detection,
            unbalance,
            detections: self.detections,
            skipped,
            angle_source: angle_source_name(self.opts.angle_source).to_string(),
            commission: self.opts.commission,
            commissioning: self.commission.report(self.k_sigma),
            data_quality: DataQuality::default(),
            rows: self.rows,
            max_abs_residual: self.max_abs,
            timeline: self.timeline,
        }
    }
}

/// The timeline point of an output at `t`.
fn timeline_point(t: f64, out: &MonitorOutput, range_note: Option<String>) -> TimelinePoint {
    let top = out.top();
    TimelinePoint {
        t_s: t,
        residuals: out.residuals,
        lamps: out.lamps,
        top: top.map(|(f, _)| f.name().to_string()),
        top_probability: top.map(|(_, p)| p).unwrap_or(0.0),
        speed_rad_s: out.speed_rad_s,
        evaluating: out.evaluating,
        commissioning: matches!(out.commissioning, CommissioningState::Learning(_)),
        quasi_steady: out.quasi_steady,
        negative_sequence_ratio: out.unbalance.negative_sequence_ratio,
        range_note,
    }
}

/// Name of an angle source as used on the command line.
pub fn angle_source_name(a: AngleSource) -> &'static str {
    match a {
        AngleSource::ZeroCrossing => "zero-crossing",
        AngleSource::Pll => "pll",
        AngleSource::RotorFluxCurrentModel => "rotor-flux",
    }
}

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
/// with bounded memory whatever the log's length.
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
    replay_through_quality(params, file.channels(), file.shown(), opts, |stage| {
        file.for_each_row(progress, stage).map(|_| ())
    })
}

/// Watches a replay row by row ([`diagnose_file_observed`]): the live HMI's log source.
pub trait ReplayObserver {
    /// The monitor's output after `row` (as the data-quality stage passed it on, glitches
    /// filled in); `replay` for its time base and thresholds ([`Replay::time_of`],
    /// [`Replay::threshold_bands`]).
    fn output(&mut self, row: &Row, out: &MonitorOutput, replay: &Replay);
    /// The replay starts again from the log's first row (the reader's fast path handed
    /// over to the exact reader): forget every output so far.
    fn restart(&mut self);
}

/// [`diagnose_file`] that hands every replayed row's output to `observer` as it goes.
///
/// # Errors
/// As [`diagnose_file`].
pub fn diagnose_file_observed(
    params: &ParamFile,
    path: &Path,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
    observer: &mut dyn ReplayObserver,
) -> Result<Diagnosed, ReplayError> {
    let file = LogFile::open(path)?;
    replay_observed(
        params,
        file.channels(),
        file.shown(),
        opts,
        Some(observer),
        |stage| file.for_each_row(progress, stage).map(|_| ()),
    )
}

/// Runs `feed` into the data-quality stage in front of a replay; builds the report.
fn replay_through_quality(
    params: &ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    replay_observed(params, channels, shown, opts, None, feed)
}

/// [`replay_through_quality`] with an optional observer of every output.
fn replay_observed<'a>(
    params: &'a ParamFile,
    channels: Channels,
    shown: &str,
    opts: ReplayOptions,
    observer: Option<&'a mut dyn ReplayObserver>,
    feed: impl FnOnce(&mut dyn RowSink) -> Result<(), LogError>,
) -> Result<Diagnosed, ReplayError> {
    let mut sink = ReplaySink {
        observer,
        params,
        channels,
        opts,
        replay: None,
        rate_hz: 0.0,
        other_rate: false,
        rows_other_rate: 0,
        restarts: 0,
        burst: Vec::new(),
        burst_forwarded: false,
        short_bursts: 0,
        long_bursts: 0,
        last_good: None,
        filled_rows: 0,
        error: None,
    };
    let mut stage = QualityStage::new(&mut sink, CellLimits::for_params(params), shown);
    let read = feed(&mut stage);
    let quality = stage.finish();
    if let Some(e) = sink.error {
        return Err(e);
    }
    read?;
    let mut quality = quality?;
    let Some(replay) = sink.replay.take() else {
        return Err(ReplayError::Option(format!("{shown}: no rows to replay")));
    };
    if replay.commissioning_incomplete() && !opts.allow_incomplete {
        let why = replay.commission.why_incomplete().unwrap_or_default();
        return Err(ReplayError::IncompleteCommissioning { why });
    }
    let can_residuals = replay.monitor.is_some();
    let mut report = replay.finish();
    describe_actions(&mut quality, can_residuals, &sink);
    if !quality.trusted {
        report.verdict = Verdict::CouldNotJudge;
        report.verdict_withheld_because.extend(
            quality
                .not_trusted_because
                .iter()
                .map(|w| format!("data quality: {w}")),
        );
    }
    report.data_quality = quality;
    Ok(Diagnosed {
        report,
        sample_rate_hz: sink.rate_hz,
    })
}

/// What `diagnose` did about what the stage found, in the report's `actions`.
fn describe_actions(q: &mut DataQuality, monitor: bool, sink: &ReplaySink<'_>) {
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
            "{} rows at another sample rate not diagnosed (the monitor runs at {:.0} Hz)",
            sink.rows_other_rate, sink.rate_hz
        ));
        q.warnings.push(format!(
            "{} rows at another sample rate were not diagnosed",
            sink.rows_other_rate
        ));
    }
}

/// The replay behind the data-quality stage: configured when the stage knows the time
/// base; rows of segments at another sample rate are counted, not replayed (the monitor's
/// configuration follows from one rate).
struct ReplaySink<'a> {
    observer: Option<&'a mut dyn ReplayObserver>,
    params: &'a ParamFile,
    channels: Channels,
    opts: ReplayOptions,
    replay: Option<Replay>,
    rate_hz: f64,
    other_rate: bool,
    rows_other_rate: u64,
    restarts: u64,
    burst: Vec<Row>,
    burst_forwarded: bool,
    short_bursts: u64,
    long_bursts: u64,
    last_good: Option<Row>,
    filled_rows: u64,
    error: Option<ReplayError>,
}

/// Glitches spanning (with their good neighbours) at most this fraction of a supply
/// period are filled in between the neighbours: a quarter period keeps the phase step
/// between them unambiguous.
const FILL_PERIODS: f64 = 0.25;

/// The row at `t` between rows `a` and `b`. The voltage and current space vectors turn
/// from `a`'s to `b`'s along the rotation (angle and magnitude interpolated linearly,
/// exact for a steady balanced set, where a straight line in abc would cut the circle's
/// chord), the zero sequence, the speed and the encoder count (rounded) along a line.
fn between(a: &Row, b: &Row, t: f64) -> Row {
    use monitor_core::frames::{clarke, inverse_clarke, zero_sequence, AlphaBeta};
    use nalgebra::Complex;
    let w = if b.t_s > a.t_s {
        ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mix = |x: f64, y: f64| x + w * (y - x);
    let turn = |x: [f64; 3], y: [f64; 3]| {
        let (p, q) = (clarke(Abc::from_array(x)), clarke(Abc::from_array(y)));
        let (zp, zq) = (Complex::new(p.alpha, p.beta), Complex::new(q.alpha, q.beta));
        let step = (zq * zp.conj()).arg();
        let z = Complex::from_polar(mix(zp.norm(), zq.norm()), zp.arg() + w * step);
        let x0 = mix(
            zero_sequence(Abc::from_array(x)),
            zero_sequence(Abc::from_array(y)),
        );
        inverse_clarke(
            AlphaBeta {
                alpha: z.re,
                beta: z.im,
            },
            x0,
        )
        .to_array()
    };
    Row {
        t_s: t,
        v_abc: a.v_abc.zip(b.v_abc).map(|(x, y)| turn(x, y)),
        i_abc: turn(a.i_abc, b.i_abc),
        wm_rad_s: a.wm_rad_s.zip(b.wm_rad_s).map(|(x, y)| mix(x, y)),
        enc_count: a
            .enc_count
            .zip(b.enc_count)
            .map(|(x, y)| x + (w * (y - x) as f64).round() as i64),
    }
}

impl CleanSink for ReplaySink<'_> {
    fn begin(&mut self, base: &TimeBase) -> bool {
        self.rate_hz = base.sample_rate_hz;
        match Replay::new(self.params, self.channels, base.sample_rate_hz, self.opts) {
            Ok(r) => {
                self.replay = Some(r);
                true
            }
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    fn row(&mut self, row: &Row, bad: BadCells) -> bool {
        if self.other_rate {
            self.rows_other_rate += 1;
            return true;
        }
        let Some(r) = self.replay.as_mut() else {
            return true;
        };
        if bad.any() && !self.burst_forwarded {
            // A glitch burst is held until it ends (dropped: the monitor bridges it like a
            // gap) or outlasts the longest gap bridged (a sensor that has failed: the rows
            // go to the monitor, which holds them out and flags the sensor).
            self.burst.push(*row);
            if self.burst.len() as f64 <= MAX_BRIDGED_GAP_S * self.rate_hz {
                return true;
            }
            self.burst_forwarded = true;
            self.long_bursts += 1;
            for b in self.burst.drain(..) {
                let out = r.push(&b);
                if let Some(o) = self.observer.as_deref_mut() {
                    o.output(&b, &out, r);
                }
            }
            return true;
        }
        if !bad.any() {
            if !self.burst.is_empty() && !self.burst_forwarded {
                self.short_bursts += 1;
                // A glitch of a few samples is filled in between its good neighbours (the
                // monitor would otherwise lose the whole block it falls in); a longer one
                // is left out, a gap the monitor bridges.
                let short = |a: &Row| (row.t_s - a.t_s) * self.params.supply.f_hz <= FILL_PERIODS;
                if let Some(a) = self.last_good.filter(short) {
                    for b in &self.burst {
                        let filled = between(&a, row, b.t_s);
                        let out = r.push(&filled);
                        if let Some(o) = self.observer.as_deref_mut() {
                            o.output(&filled, &out, r);
                        }
                    }
                    self.filled_rows += self.burst.len() as u64;
                }
            }
            self.burst.clear();
            self.burst_forwarded = false;
            self.last_good = Some(*row);
        }
        let out = r.push(row);
        if let Some(o) = self.observer.as_deref_mut() {
            o.output(row, &out, r);
        }
        true
    }

    fn new_segment(&mut self, why: SegmentBreak) -> bool {
        match why {
            SegmentBreak::RateChange(r) => {
                self.other_rate = (r / self.rate_hz - 1.0).abs() > 0.02;
            }
            SegmentBreak::Gap(_) | SegmentBreak::ClockReset => self.restarts += 1,
        }
        true
    }

    fn restart(&mut self) {
        if let Some(o) = self.observer.as_deref_mut() {
            o.restart();
        }
        self.replay = None;
        self.other_rate = false;
        self.rows_other_rate = 0;
        self.restarts = 0;
        self.burst.clear();
        self.burst_forwarded = false;
        self.short_bursts = 0;
        self.long_bursts = 0;
        self.last_good = None;
        self.filled_rows = 0;
        self.error = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced 50 Hz set (300 V, 10 A lagging 0.4 rad) with a zero sequence, at `t`.
    fn row(t: f64) -> Row {
        let w = std::f64::consts::TAU * 50.0 * t;
        let set = |amp: f64, lag: f64| {
            [0.0, 1.0, 2.0].map(|k| amp * (w - lag - k * std::f64::consts::TAU / 3.0).cos() + 0.5)
        };
        Row {
            t_s: t,
            v_abc: Some(set(300.0, 0.0)),
            i_abc: set(10.0, 0.4),
            wm_rad_s: Some(150.0 + 10.0 * t),
            enc_count: Some((100_000.0 * t) as i64),
        }
    }

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
    fn a_glitch_is_filled_along_the_rotation() {
        // A fifth of a period between the neighbours (4 ms at 50 Hz, four samples at 1 kHz):
        // a straight line in abc would miss by (omega h)^2 / 8 = 20 % of the amplitude.
        let (a, b) = (row(0.010), row(0.014));
        for t in [0.011, 0.012, 0.013] {
            let f = between(&a, &b, t);
            let truth = row(t);
            for (x, y) in f.i_abc.iter().zip(truth.i_abc) {
                assert!((x - y).abs() < 1e-9, "{t}: {x} vs {y}");
            }
            let (fv, tv) = (f.v_abc.unwrap_or_default(), truth.v_abc.unwrap_or_default()); // ok: test
            for (x, y) in fv.iter().zip(tv) {
                assert!((x - y).abs() < 1e-7, "{t}: {x} vs {y}");
            }
            assert!((f.wm_rad_s.unwrap_or(0.0) - (150.0 + 10.0 * t)).abs() < 1e-9);
        }
    }
}
