//! Replay of a measurement log through the no_std core: exactly the code the firmware
//! runs ([`monitor_core::Monitor`]), fed row by row.
//!
//! The host converts each CSV row into a core [`Sample`]: voltages and currents as f32,
//! the encoder count (from `enc_count`, or synthesised by integrating `wm_rad_s` on a
//! 4096-count disc when the log has only a speed column), and a 1 MHz timestamp.
//! Logs without voltages or without speed cannot feed the residuals (every residual of
//! eq. 37 needs Vqs or omega_r); for those only the negative-sequence analysis runs, on an
//! angle from an SRF-PLL locked to the currents, and the report says what was skipped and
//! why.

use crate::log::{Channels, Row};
use crate::params::ParamFile;
use monitor_core::angle::SrfPll;
use monitor_core::frames::{clarke, SinCos};
use monitor_core::sequence::{asymmetry_correction_rad, SequenceAnalyzer};
use monitor_core::{
    Abc, AngleSource, Fault, Monitor, MonitorConfig, MonitorOutput, MotorModel, ResidualForm,
    Sample,
};
use serde::Serialize;

/// Timestamp tick rate used for replays [Hz].
pub const TICK_HZ: f64 = 1.0e6;
/// Counts per revolution of the synthesised encoder (1024 lines x 4).
pub const COUNTS_PER_REV: u32 = 4096;

/// Errors from setting up a replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The core rejected the configuration built from the parameter file and the log.
    #[error("cannot configure the monitor: {0}")]
    Config(String),
    /// A bad option.
    #[error("{0}")]
    Option(String),
}

/// The core's view of the parameter file (f32).
pub fn motor_model(p: &ParamFile) -> MotorModel {
    let m = &p.motor;
    MotorModel {
        rs_ohm: m.rs_ohm as f32,
        rr_ohm: m.rr_ohm as f32,
        ls_h: m.ls_h as f32,
        lr_h: m.lr_h as f32,
        lm_h: m.lm_h as f32,
        pole_pairs: (m.poles / 2).min(255) as u8,
        j_kgm2: m.j_kgm2 as f32,
        b_nms: m.b_nms as f32,
        bl_nms: m.bl_nms as f32,
    }
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
            angle_source: AngleSource::RotorFlux,
            residual_form: ResidualForm::Steady,
            commission: None,
            timeline_step_s: 0.1,
        }
    }
}

/// Builds the monitor configuration for a parameter file and a sample rate. The sensor
/// limits are generous (4x the nominal phase peak voltage, 10x the rated-ish current
/// scale) because a log does not say its ADC ranges.
pub fn monitor_config(p: &ParamFile, sample_rate_hz: f64, opts: &ReplayOptions) -> MonitorConfig {
    let mut cfg = MonitorConfig::new(
        motor_model(p),
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

/// Converts log rows to core samples, synthesising encoder counts from speed if needed.
#[derive(Debug, Clone, Default)]
pub struct SampleMaker {
    theta_m: f64,
    last_t: Option<f64>,
}

impl SampleMaker {
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

/// A fault candidate.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Candidate {
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
    pub candidates: Vec<Candidate>,
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
    maker: SampleMaker,
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
        let cfg = monitor_config(params, sample_rate_hz, &opts);
        let can_residuals = channels.voltages && (channels.speed || channels.encoder);
        let monitor = if can_residuals {
            Some(Monitor::new(cfg).map_err(|e| {
                ReplayError::Config(format!("{e} (sample rate {sample_rate_hz:.1} Hz)"))
            })?)
        } else {
            cfg.validate().map_err(|e| {
                ReplayError::Config(format!("{e} (sample rate {sample_rate_hz:.1} Hz)"))
            })?;
            None
        };
        let dt = (1.0 / sample_rate_hz) as f32;
        Ok(Replay {
            monitor,
            maker: SampleMaker::default(),
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
                    mon.start_commissioning((b - a) as f32);
                }
            }
        }
        let s = self.maker.sample(row);
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
                commissioning: matches!(
                    out.commissioning,
                    monitor_core::Commissioning::Learning(_)
                ),
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
            let m = motor_model(&self.params);
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
        let mut candidates: Vec<Candidate> = Fault::ALL
            .iter()
            .zip(out.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| Candidate {
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
/// magnitude: the slip at which the equivalent circuit on the parameter file's supply draws
/// the measured |I1| (bisection on 0..0.5; no load -> s ~ 0).
fn current_only_unbalance(p: &ParamFile, seq: &SequenceAnalyzer, omega: f32) -> UnbalanceReport {
    let m = motor_model(p);
    let we = if omega > 1.0 {
        omega
    } else {
        p.supply.omega_rad_s() as f32
    };
    let u0 = seq.result(0.0, 0.0);
    let i1 = seq.positive_magnitude();
    let vpk = p.supply.v_phase_peak() as f32;
    let (mut lo, mut hi) = (1e-4f32, 0.5f32);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        let z = monitor_core::sequence::equivalent_impedance(&m, we, mid);
        let i = vpk / (z.0 * z.0 + z.1 * z.1).sqrt();
        if i < i1 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let slip = 0.5 * (lo + hi);
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
        AngleSource::RotorFlux => "rotor-flux",
    }
}

/// Replays whole rows (in memory) and returns the report.
///
/// # Errors
/// As [`Replay::new`].
pub fn diagnose_rows(
    params: &ParamFile,
    channels: Channels,
    rows: &[Row],
    opts: ReplayOptions,
) -> Result<DiagnoseReport, ReplayError> {
    let fs = match (rows.first(), rows.last()) {
        (Some(a), Some(b)) if rows.len() > 1 => (rows.len() - 1) as f64 / (b.t_s - a.t_s),
        _ => {
            return Err(ReplayError::Option(
                "the log needs at least two rows".into(),
            ))
        }
    };
    let mut r = Replay::new(params, channels, fs, opts)?;
    for row in rows {
        r.push(row);
    }
    Ok(r.finish())
}
