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

use crate::log::{Channels, LogError, LogFile, Row, RowSink};
use crate::params::ParamFile;
use monitor_core::angle::SrfPll;
use monitor_core::frames::{clarke, SinCos};
use monitor_core::sequence::{asymmetry_correction_rad, slip_for_current, SequenceAnalyzer};
use monitor_core::{
    Abc, AngleSource, CommissioningState, ConfigError, Fault, Monitor, MonitorConfig,
    MonitorOutput, ResidualForm, Sample,
};
use serde::Serialize;
use std::path::Path;

/// Timestamp tick rate used for replays [Hz].
pub const TICK_HZ: f64 = 1.0e6;
/// Counts per revolution of the synthesised encoder (1024 lines x 4).
pub const COUNTS_PER_REV: u32 = 4096;

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
    /// Timeline resolution [s] (one point per interval).
    pub timeline_step_s: f64,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            angle_source: AngleSource::RotorFluxCurrentModel,
            residual_form: ResidualForm::Steady,
            commission: None,
            timeline_step_s: 0.1,
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
                (self.theta_m / std::f64::consts::TAU * f64::from(COUNTS_PER_REV)).floor() as i64
                    as u32
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
            timestamp_ticks: ((row.t_s * TICK_HZ).round() as i64) as u32,
            v_saturated: false,
            i_saturated: false,
        }
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
}

/// A fault candidate of the signature matching.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FaultCandidate {
    /// DESIGN.md fault name.
    pub fault: String,
    /// Probability.
    pub probability: f32,
}

/// Result of the negative-sequence analysis (JSON key `unbalance`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct UnbalanceReport {
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// "a", "b", "c" or null.
    pub suspect_phase: Option<String>,
    /// arg(I2/I1) [deg].
    pub angle_deg: f32,
    /// The model correction arg(Z1/Z2) used [deg].
    pub correction_deg: f32,
}

/// What `diagnose` reports (DESIGN.md §3 JSON keys).
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseReport {
    /// Final lamps `{"r1":bool,..}`.
    pub lamps: std::collections::BTreeMap<String, bool>,
    /// Final fault candidates, most probable first.
    pub candidates: Vec<FaultCandidate>,
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
    /// Commissioning window used, if any [s].
    pub commission: Option<(f64, f64)>,
    /// Rows replayed.
    pub rows: u64,
    /// Largest |normalised residual| while evaluating, r1..r4.
    pub max_abs_residual: [f32; 4],
    /// Timeline (one point per `timeline_step_s`).
    pub timeline: Vec<TimelinePoint>,
}

/// Streaming replay: feed rows, then [`Replay::finish`].
pub struct Replay {
    monitor: Option<Monitor>,
    sampler: LogSampler,
    opts: ReplayOptions,
    params: ParamFile,
    channels: Channels,
    commission_started: bool,
    rows: u64,
    first_detection: Option<f64>,
    detections: Vec<(String, f64)>,
    timeline: Vec<TimelinePoint>,
    next_point: f64,
    max_abs: [f32; 4],
    last: MonitorOutput,
    t0: Option<f64>,
    // Current-only unbalance analysis.
    pll: SrfPll,
    seq: SequenceAnalyzer,
}

impl Replay {
    /// Prepares a replay of a log with the given channels and sample rate.
    ///
    /// # Errors
    /// [`ReplayError::Config`] when the core rejects the configuration (e.g. a sample rate
    /// below 8x the supply frequency); [`ReplayError::Option`] for a commissioning window
    /// with end <= start.
    pub fn new(
        params: &ParamFile,
        channels: Channels,
        sample_rate_hz: f64,
        opts: ReplayOptions,
    ) -> Result<Self, ReplayError> {
        if let Some((a, b)) = opts.commission {
            if !(b > a && a >= 0.0) {
                return Err(ReplayError::Option(format!(
                    "--commission {a}:{b}: the window must be START:END with 0 <= START < END (seconds)"
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
            commission_started: false,
            rows: 0,
            first_detection: None,
            detections: Vec::new(),
            timeline: Vec::new(),
            next_point: 0.0,
            max_abs: [0.0; 4],
            last: MonitorOutput::default(),
            t0: None,
            // Locks to the current vector; normalised by the no-load (magnetising) current peak.
            pll: SrfPll::new(
                dt,
                params.supply.f_hz as f32,
                10.0,
                (params.supply.v_phase_peak() / (params.supply.omega_rad_s() * params.motor.ls_h))
                    as f32,
            ),
            seq: SequenceAnalyzer::new(2.0, dt),
        })
    }

    /// Feeds one row; returns the monitor's output (default output for current-only logs).
    pub fn push(&mut self, row: &Row) -> MonitorOutput {
        self.rows += 1;
        let t0 = *self.t0.get_or_insert(row.t_s);
        let t = row.t_s - t0;
        let Some(mon) = self.monitor.as_mut() else {
            // Current-only: PLL on the current vector, sequence analysis.
            let i = clarke(Abc {
                a: row.i_abc[0] as f32,
                b: row.i_abc[1] as f32,
                c: row.i_abc[2] as f32,
            });
            let sc = SinCos::from_angle(self.pll.theta_pll());
            self.pll.update(i, sc);
            self.seq.update(i, sc);
            return self.last;
        };
        if let Some((a, _)) = self.opts.commission {
            if !self.commission_started && t >= a {
                self.commission_started = true;
                if let Some((a, b)) = self.opts.commission {
                    // Replay::new checked the window (END > START); a window the core still
                    // refuses (shorter than f32 resolves) leaves the fixed thresholds.
                    let _ = mon.start_commissioning((b - a) as f32);
                }
            }
        }
        let s = self.sampler.sample(row);
        let out = *mon.update(&s);
        if out.evaluating {
            for (m, r) in self.max_abs.iter_mut().zip(out.residuals) {
                *m = m.max(r.abs());
            }
        }
        if out.fault_detected {
            if self.first_detection.is_none() {
                self.first_detection = Some(t);
            }
            if let Some((f, _)) = out.top() {
                if !self.detections.iter().any(|(n, _)| n == f.name()) {
                    self.detections.push((f.name().to_string(), t));
                }
            }
        }
        if t >= self.next_point {
            self.next_point += self.opts.timeline_step_s;
            let top = out.top();
            self.timeline.push(TimelinePoint {
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
            });
        }
        self.last = out;
        out
    }

    /// The learned calibration (mean and spread of r1..r4), once commissioning is done.
    pub fn calibration(&self) -> Option<monitor_core::Calibration> {
        self.monitor.as_ref().and_then(|m| m.calibration())
    }

    /// Ends the replay and builds the report.
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
        let unbalance = if self.monitor.is_some() {
            let m = self.params.motor.model();
            let we = out.frame_omega_rad_s.abs().max(1.0);
            let slip = 1.0 - out.operating.wr / we;
            UnbalanceReport {
                negative_sequence_ratio: out.unbalance.negative_sequence_ratio,
                suspect_phase: out.unbalance.suspect_phase.map(|p| p.name().to_string()),
                angle_deg: out.unbalance.angle_rad.to_degrees(),
                correction_deg: asymmetry_correction_rad(&m, we, slip).to_degrees(),
            }
        } else {
            current_only_unbalance(&self.params, &self.seq, self.pll.omega_rad_s())
        };
        let mut candidates: Vec<FaultCandidate> = Fault::ALL
            .iter()
            .zip(out.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| FaultCandidate {
                fault: f.name().to_string(),
                probability: p,
            })
            .collect();
        candidates.sort_by(|a, b| b.probability.total_cmp(&a.probability));
        let lamps = (0..4)
            .map(|k| {
                (
                    format!("r{}", k + 1),
                    out.lamps.get(k).copied().unwrap_or(false),
                )
            })
            .collect();
        DiagnoseReport {
            lamps,
            candidates,
            first_detection_s: self.first_detection,
            unbalance,
            detections: self.detections,
            skipped,
            angle_source: angle_source_name(self.opts.angle_source).to_string(),
            commission: self.opts.commission,
            rows: self.rows,
            max_abs_residual: self.max_abs,
            timeline: self.timeline,
        }
    }
}

/// Current-only unbalance: the slip is not measured, so it is estimated from the current
/// magnitude ([`slip_for_current`] on the parameter file's supply); the phase is then named
/// as the monitor names it.
fn current_only_unbalance(p: &ParamFile, seq: &SequenceAnalyzer, omega: f32) -> UnbalanceReport {
    let m = p.motor.model();
    let we = if omega > 1.0 {
        omega
    } else {
        p.supply.omega_rad_s() as f32
    };
    let u0 = seq.result(0.0, 0.0);
    let slip = slip_for_current(
        &m,
        p.supply.v_phase_peak() as f32,
        we,
        seq.positive_magnitude(),
    );
    let corr = asymmetry_correction_rad(&m, we, slip);
    let u = seq.result(corr, 0.005);
    UnbalanceReport {
        negative_sequence_ratio: u.negative_sequence_ratio,
        suspect_phase: u.suspect_phase.map(|p| p.name().to_string()),
        angle_deg: u0.angle_rad.to_degrees(),
        correction_deg: corr.to_degrees(),
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

/// Replays whole rows (in memory) and returns the report.
///
/// # Errors
/// As [`Replay::new`]; [`ReplayError::Option`] for fewer than two rows.
pub fn diagnose_rows(
    params: &ParamFile,
    channels: Channels,
    rows: &[Row],
    opts: ReplayOptions,
) -> Result<DiagnoseReport, ReplayError> {
    let times: Vec<f64> = rows
        .iter()
        .take(crate::log::RATE_ESTIMATE_ROWS)
        .map(|r| r.t_s)
        .collect();
    let fs = crate::log::sample_rate_hz(&times)
        .ok_or_else(|| ReplayError::Option("the log needs at least two rows".into()))?;
    let mut r = Replay::new(params, channels, fs, opts)?;
    for row in rows {
        r.push(row);
    }
    Ok(r.finish())
}

/// A log replayed by [`diagnose_file`].
#[derive(Debug, Clone)]
pub struct Diagnosed {
    /// The report (`diagnose --json`).
    pub report: DiagnoseReport,
    /// The log's sample rate ([`crate::log::sample_rate_hz`]) [Hz].
    pub sample_rate_hz: f64,
}

/// Streams a log file through the core (`sim-host diagnose`): the first rows give the
/// sample rate, the monitor is configured for it, and every row is replayed, with bounded
/// memory whatever the log's length.
///
/// # Errors
/// [`ReplayError::Log`] naming the file, line and column; [`ReplayError::Option`] for a log
/// of fewer than two rows; [`ReplayError::Config`] when the core rejects the configuration.
pub fn diagnose_file(
    params: &ParamFile,
    path: &Path,
    opts: ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Diagnosed, ReplayError> {
    let file = LogFile::open(path)?;
    let mut sink = StreamingReplay {
        params,
        shown: file.shown(),
        channels: file.channels(),
        opts,
        head: Vec::new(),
        replay: None,
        error: None,
    };
    file.for_each_row(progress, &mut sink)?;
    if let Some(e) = sink.error {
        return Err(e);
    }
    if sink.replay.is_none() {
        // Fewer rows than the rate estimate wants: start on what there is.
        sink.start()?;
    }
    let sample_rate_hz = sink.sample_rate_hz()?;
    match sink.replay {
        Some(replay) => Ok(Diagnosed {
            report: replay.finish(),
            sample_rate_hz,
        }),
        None => Err(sink.too_short()),
    }
}

/// The replay of a streamed log: holds the first rows until the sample rate is known.
struct StreamingReplay<'a> {
    params: &'a ParamFile,
    shown: &'a str,
    channels: Channels,
    opts: ReplayOptions,
    head: Vec<Row>,
    replay: Option<Replay>,
    error: Option<ReplayError>,
}

impl StreamingReplay<'_> {
    fn sample_rate_hz(&self) -> Result<f64, ReplayError> {
        let times: Vec<f64> = self.head.iter().map(|r| r.t_s).collect();
        crate::log::sample_rate_hz(&times).ok_or_else(|| self.too_short())
    }

    fn too_short(&self) -> ReplayError {
        ReplayError::Option(format!(
            "{}: the log needs at least two data rows",
            self.shown
        ))
    }

    /// Configures the monitor for the rate of the rows held and replays them.
    fn start(&mut self) -> Result<(), ReplayError> {
        let fs = self.sample_rate_hz()?;
        let mut r = Replay::new(self.params, self.channels, fs, self.opts)?;
        for row in &self.head {
            r.push(row);
        }
        self.replay = Some(r);
        Ok(())
    }
}

impl RowSink for StreamingReplay<'_> {
    fn row(&mut self, row: &Row) -> bool {
        if let Some(r) = self.replay.as_mut() {
            r.push(row);
            return true;
        }
        self.head.push(*row);
        if self.head.len() < crate::log::RATE_ESTIMATE_ROWS {
            return true;
        }
        match self.start() {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    fn restart(&mut self) {
        self.head.clear();
        self.replay = None;
        self.error = None;
    }
}
