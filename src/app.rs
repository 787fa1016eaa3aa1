//! The firmware's application logic, hardware-free: what runs per sample, what the sample
//! task hands over, and what thread mode does with it.
//!
//! - [`SamplePath`] (`app/sample_path.rs`) runs in the high-priority sample task:
//!   [`RawFrame`] -> [`Sample`] -> [`Monitor::update`], and applies [`Command`]s between
//!   samples. Bounded work, no panics, no allocation, no copy of the core's output per
//!   sample: every [`Settings::status_every`] samples the task hands thread mode a small
//!   [`MonitorStatus`] ([`SamplePath::status`]).
//! - [`Supervisor`] runs in thread mode every [`PANEL_PERIOD_MS`]: the button, the
//!   commissioning procedure ([`CommissioningProcedure`]), the liveness watch
//!   ([`SampleWatch`]: the watchdog is petted only while samples flow), the fault
//!   isolation (`monitor_core::isolation::Follower` on the statuses: which fault, how
//!   large; with the evidence across operating points, `monitor_core::isolation::Evidence`,
//!   at most about 1 M instructions per 0.1 s block, docs/firmware.md "Size") and the panel.
//!   [`carry_out`] turns its actions into commands, storing the learned calibration first.
//!
//! The host tests (`tests/sil/`) drive exactly these types with simulated data; the
//! firmware (`src/firmware.rs`) only adds the hardware around them.
//!
//! [`Sample`]: monitor_core::Sample
//! [`RawFrame`]: crate::sampling::RawFrame
//! [`Monitor::update`]: monitor_core::Monitor::update

use crate::board;
use crate::clip_watch::{self, ClipWatch, RangeChange};
use crate::commissioning::{Action, CommissioningProcedure, RunEnd};
use crate::flash_record::CalibrationRecord;
use crate::liveness::{LivenessChange, SampleWatch};
use crate::offset_trim::TrimResult;
use crate::panel::{self, blink_code, winding_code, Mode, PanelInput, PanelLamps, NOT_NAMED_CODE};
use crate::range_watch::{RangeMoment, RangeWatch};
use crate::reset_record::PreviousRun;
use crate::sampling::TICK_HZ;
use crate::supply::{ReferenceAdc, ReferenceChange, ReferenceWatch, REFERENCE_PERIOD_MS};
use monitor_core::isolation::{Baseline, Evidence, Follower, Named, Step};
use monitor_core::verdict::Verdict;
use monitor_core::{
    CommissioningRun, ConfigError, Fault, Isolation, IsolationState, Isolator, MonitorConfig,
    MotorModel, Operating, OperatingPoint, Phase, ReferenceMachine, SensorFlags, SteadyPoint,
};

mod isolation;
pub use isolation::{board_isolator, isolation_summary};
mod lamps;
pub use lamps::{panel_call, panel_input, PanelIsolation};
mod sample_path;
pub use sample_path::{AppError, Command, CommandError, FrameBuilder, SamplePath};
mod settings;
pub use settings::{Settings, SettingsError};
mod status_line;
pub use status_line::{status_line, BoardCounters};
mod store;
pub use store::{carry_out, AcquisitionPause, NoPause};
mod period;
pub use period::{period, PeriodInput, PeriodOutput, ThreadHw, ThreadState};

/// The machine the firmware monitors by default: the "2.2 kW" reference machine
/// (`monitor_core::reference::MOTOR_2P2KW`: 400 V, 50 Hz, 4 poles, Gamma model, Bl for the
/// rated 14.6 N m near rated speed). Edit here for another machine.
pub const DEFAULT_MACHINE: ReferenceMachine = monitor_core::reference::MOTOR_2P2KW;

/// Thread mode's period (button, commissioning, liveness, panel), ms.
pub const PANEL_PERIOD_MS: u32 = 50;
/// Independent watchdog timeout, ms: the MCU resets this long after the last pet.
pub const WATCHDOG_TIMEOUT_MS: u32 = 500;
// The boot's first timeout is the longer: the running one is set once thread mode runs.
const _: () = assert!(crate::watchdog::BOOT_TIMEOUT_MS > WATCHDOG_TIMEOUT_MS);
/// How long the panel shows "monitor failed" after a reset by a panic, a stalled sample
/// path or a hang, ms.
pub const FAILED_BOOT_SHOW_MS: u32 = 5_000;
/// Button debounce: presses closer together than this count once, ms.
pub const BUTTON_DEBOUNCE_MS: u32 = 300;

/// The default machine in the core's precision.
pub fn default_motor() -> MotorModel {
    DEFAULT_MACHINE.motor.model()
}

/// Core configuration for the board: [`DEFAULT_MACHINE`] on its rated supply, sampled at
/// `sample_rate_hz`, 1 MHz timestamps, a 16-bit x4 encoder counter with
/// [`board::ENCODER_COUNTS_PER_REV`] counts per revolution, and sensor limits beyond any
/// reading the front end gives ([`board::LIMIT_OVER_FULL_SCALE`] times its full scale: a
/// reading at its edge is a clip, held out and named nothing, not an impossible one). (The
/// host's configuration for replaying a log is `monitor_replay::monitor_config_for_log`.)
pub fn board_monitor_config(sample_rate_hz: u32) -> MonitorConfig {
    let supply = DEFAULT_MACHINE.supply;
    let mut cfg = MonitorConfig::new(
        default_motor(),
        supply.f_hz as f32,
        supply.v_ll_rms as f32,
        sample_rate_hz as f32,
    );
    cfg.tick_hz = TICK_HZ as f32;
    cfg.encoder.counter_bits = 16;
    cfg.encoder.counts_per_rev = board::ENCODER_COUNTS_PER_REV;
    cfg.limits.v_max = board::LIMIT_OVER_FULL_SCALE * board::VOLTAGE_FULL_SCALE_V;
    cfg.limits.i_max = board::LIMIT_OVER_FULL_SCALE * board::CURRENT_FULL_SCALE_A;
    cfg
}

/// What the sample task hands thread mode: the little the panel, the supervision and the
/// log line need, built every [`Settings::status_every`] samples.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MonitorStatus {
    /// Samples processed since boot (wrapping): the liveness signal.
    pub samples: u32,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Residual lamps r1..r4 as the core decided them.
    pub residual_lamps: [bool; 4],
    /// The core detected a fault (a lamp or a sensor fault).
    pub fault_detected: bool,
    /// Sensor faults from impossible readings.
    pub sensor_fault: SensorFlags,
    /// The most probable fault candidate and its probability.
    pub top: Option<(Fault, f32)>,
    /// The second most probable candidate (probability > 0), for the log.
    pub second: Option<(Fault, f32)>,
    /// Mechanical speed from the encoder, rad/s.
    pub speed_rad_s: f32,
    /// The zero-crossing detector's lock (`None` with other angle sources).
    pub zero_crossing_locked: Option<bool>,
    /// Learned thresholds are in force (else the default ones).
    pub commissioned: bool,
    /// The latest commissioning run.
    pub run: CommissioningRun,
    /// The model's inputs in the monitor's frame: I_qs, i_ds, V_qs [A, A, V] and the
    /// electrical rotor speed (for the status line and the HMI).
    pub operating: Operating,
    /// The frame's frequency [Hz] (the supply frequency in steady state).
    pub frame_hz: f32,
    /// The quasi-steady gate is open (else a transient: the lamps hold).
    pub quasi_steady: bool,
    /// The lamps are being evaluated.
    pub evaluating: bool,
    /// The threshold band of r1..r4 in force, (centre, half-width)
    /// (`Monitor::threshold_bands`).
    pub bands: [(f32, f32); 4],
    /// The steady-state operating point of the monitor's filtered outputs, for the fault
    /// isolation in thread mode ([`SteadyPoint::from_output`]).
    pub point: SteadyPoint,
    /// Shorted turns: the phase the core's negative-sequence analysis names and the
    /// winding's part of `|I2/I1|` (the supply's unbalance taken out; named only above a
    /// healthy machine's own asymmetry, `monitor_core::sequence::INHERENT_ASYMMETRY_RATIO`).
    pub winding: Option<(Phase, f32)>,
    /// The winding phase's confidence, 0..1 (`monitor_core::NegativeSequence::phase_confidence`;
    /// 0 without a phase): the decision table's confidence of shorted turns on the board.
    pub winding_confidence: f32,
    /// The filtered `V_ds` [V] (with `operating`: the operating point without the frame's
    /// angle, [`MonitorStatus::operating_point`]).
    pub vds: f32,
    /// The operating point has left the commissioned range: set by [`Supervisor::tick`]
    /// ([`RangeWatch::moved`]), false as the sample path hands it ([`panel_input`] shows
    /// the amber state only when no fault is named).
    pub moved: bool,
    /// Samples since boot with a conversion at the front end's linear limit (clipped,
    /// held out of the residuals, no sensor named: [`crate::sampling::Clipped`]); wraps.
    pub clipped: u32,
    /// Of those, the samples in which a voltage channel clipped; wraps.
    pub clipped_voltage: u32,
    /// Of those, the samples in which a current channel clipped; wraps.
    pub clipped_current: u32,
    /// Latched encoder counts since boot rejected as a step beyond the maximum speed
    /// (`acquisition::EncoderCheck`); wraps.
    pub encoder_rejects: u32,
    /// Clipping persists in steady running: the front end's range is too small for this
    /// motor (the range state: the verdict could not judge, the panel's mark, the status
    /// line's `clip_range=`). Set by [`Supervisor::tick`] ([`ClipWatch`]), false as the
    /// sample path hands it.
    pub clip_range: bool,
}

impl MonitorStatus {
    /// The operating point without the d-q frame's angle ([`OperatingPoint::from_dq`] of
    /// `V_ds`, `V_qs`, `i_ds`, `I_qs`): what the commissioned range is learned and judged on.
    pub fn operating_point(&self) -> OperatingPoint {
        OperatingPoint::from_dq(
            self.vds,
            self.operating.vqs,
            self.operating.i_f,
            self.operating.iqs,
        )
    }

    /// What the clip watch reads of this status ([`ClipWatch`]).
    pub fn clip_moment(&self) -> clip_watch::ClipMoment {
        clip_watch::ClipMoment {
            samples: self.samples,
            clipped: self.clipped,
            clipped_voltage: self.clipped_voltage,
            clipped_current: self.clipped_current,
            speed_rad_s: self.speed_rad_s,
        }
    }

    /// What the operating-range watch reads of this status.
    pub fn range_moment(&self) -> RangeMoment {
        RangeMoment {
            point: self.operating_point(),
            stage: self.run.stage,
            run: self.run.id,
            quasi_steady: self.quasi_steady,
            commissioned: self.commissioned,
            evaluating: self.evaluating,
        }
    }
}

/// What thread mode does after one [`Supervisor::tick`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tick {
    /// Pet the watchdog (samples flow).
    pub pet_watchdog: bool,
    /// The panel mode shown.
    pub mode: Mode,
    /// The decision table's verdict on the latest status ([`panel_call`]; the status line's
    /// `call=`): the FAULT lamp blinks for [`Verdict::Fault`] only.
    pub call: Verdict,
    /// The lamps to show.
    pub lamps: PanelLamps,
    /// The commissioning action to carry out ([`carry_out`]).
    pub action: Action,
    /// A commissioning run (or a start request) ended: log it.
    pub run_ended: Option<RunEnd>,
    /// The sample path's liveness changed: log it (and write or clear the reset record).
    pub liveness: Option<LivenessChange>,
    /// A new correction for the ADC's reference to hand the sample task
    /// ([`Command::ReferenceGain`]: VDDA now over VDDA at commissioning,
    /// [`crate::supply::ReferenceGain`]).
    pub reference_gain: Option<f32>,
    /// The range state changed (clipping persists in steady running, or no longer:
    /// [`ClipWatch`]): log it.
    pub clip_range: Option<RangeChange>,
}

/// Thread mode's logic: button, commissioning procedure, liveness watch and panel.
#[derive(Clone, Copy, Debug)]
pub struct Supervisor {
    procedure: CommissioningProcedure,
    watch: SampleWatch,
    latest: MonitorStatus,
    failed_until_ms: Option<u32>,
    last_press_ms: Option<u32>,
    /// The fault isolation's schedule (its isolator holds the tracked winding rise).
    pub isolation: Option<Follower>,
    /// The operating points kept since a deviation began and their joint isolation (the
    /// host's replay keeps the same: `monitor_core::isolation::Evidence`).
    evidence: Evidence,
    /// The isolation baseline learned in the latest commissioning run (stored with its
    /// calibration), `None` while learning or when that run learned too little.
    run_baseline: Option<Baseline>,
    sample_rate_hz: u32,
    /// The monitor has evaluated once since boot (settled, voltage present).
    running: bool,
    /// The built-in default motor is monitored (the panel marks it).
    default_motor: bool,
    /// The clock runs on the HSI: the crystal did not start (the panel marks it).
    clock_fallback: bool,
    /// The brown-out level is below the goal: records refused (the panel marks it).
    bor_below_goal: bool,
    /// Sensors whose start-up offset was out of bound ([`Supervisor::set_offset_fault`]).
    offset_fault: SensorFlags,
    /// The ADC's reference, measured at start-up and every second
    /// ([`crate::supply::ReferenceWatch`]); out of band it flags both sensors.
    reference: ReferenceWatch,
    /// The commissioned operating range (RAM only) and the "moved" judgement.
    range: RangeWatch,
    /// Whether clipping persists in steady running (the range state).
    clips: ClipWatch,
    /// A change of the range state since the last tick, for its log.
    clip_change: Option<RangeChange>,
    /// The correction of the readings for the reference's drift since commissioning.
    gain: crate::supply::ReferenceGain,
    /// VDDA the record being stored holds (in force once the run ends commissioned).
    pending_vdda: Option<f32>,
    /// A run ended commissioned in this tick: its VDDA goes into force.
    gain_on_commissioning: bool,
}

impl Supervisor {
    /// A supervisor for `settings`, booting at `now_ms` after `previous` (a failed previous
    /// run shows "monitor failed" for [`FAILED_BOOT_SHOW_MS`]), with the sample path's
    /// `status` before sampling starts (so the panel shows the record loaded at boot from
    /// the first period on).
    pub fn new(
        settings: &Settings,
        previous: PreviousRun,
        now_ms: u32,
        status: MonitorStatus,
    ) -> Self {
        Self {
            procedure: CommissioningProcedure::new(
                settings.commissioning_duration_s,
                settings.commissioning_stall_ms,
            ),
            watch: SampleWatch::new(settings.sample_rate_hz, now_ms),
            latest: status,
            failed_until_ms: previous
                .failed()
                .then(|| now_ms.wrapping_add(FAILED_BOOT_SHOW_MS)),
            last_press_ms: None,
            isolation: board_isolator().ok().map(Follower::new),
            evidence: Evidence::default(),
            run_baseline: None,
            sample_rate_hz: settings.sample_rate_hz,
            running: false,
            default_motor: false,
            clock_fallback: false,
            bor_below_goal: false,
            offset_fault: SensorFlags::default(),
            reference: ReferenceWatch::new(REFERENCE_PERIOD_MS),
            range: RangeWatch::new(),
            clips: ClipWatch::new(settings.sample_rate_hz),
            clip_change: None,
            gain: crate::supply::ReferenceGain::default(),
            pending_vdda: None,
            gain_on_commissioning: false,
        }
    }

    /// The start-up offset trim found a channel out of bound ([`crate::offset_trim`]): from
    /// now on that sensor counts as faulty in every status (the panel's "input invalid", the
    /// status line's `sens=`, and the isolation does not use the statuses).
    pub fn set_offset_fault(&mut self, trim: &TrimResult) {
        self.offset_fault.voltage |= trim.voltage_fault();
        self.offset_fault.current |= trim.current_fault();
    }

    /// The start-up check of the ADC's reference (VDDA from VREFINT,
    /// [`crate::board::ReferenceCheck`]) at `now_ms`; the periodic checks follow from
    /// [`Supervisor::poll_reference`]. A reference outside its band, or unreadable, scales
    /// every reading, so while the latest check says so both sensors count as faulty, as
    /// an offset out of bound does (the panel's "input invalid", the status line's `sens=`);
    /// a check in band clears that again. Returns a change of the verdict for the log.
    pub fn observe_reference(
        &mut self,
        check: crate::board::ReferenceCheck,
        now_ms: u32,
    ) -> Option<ReferenceChange> {
        self.reference.observe(check, now_ms)
    }

    /// The periodic reference check at `now_ms` on `adc` (ADC1's injected VREFINT
    /// conversion on the board): starts a due measurement or takes its result
    /// ([`ReferenceWatch::poll`]). Returns a change of the verdict for the log.
    pub fn poll_reference(
        &mut self,
        now_ms: u32,
        adc: &mut impl ReferenceAdc,
    ) -> Option<ReferenceChange> {
        self.reference.poll(now_ms, adc)
    }

    /// The reference watch (the latest VDDA for the status line).
    pub fn reference(&self) -> &ReferenceWatch {
        &self.reference
    }

    /// Whether the built-in default motor is monitored (no valid motor record at boot): the
    /// panel shows it ([`crate::panel`], "Built-in default motor"). Off until set.
    pub fn set_default_motor(&mut self, default_motor: bool) {
        self.default_motor = default_motor;
    }

    /// Whether the clock fell back to the internal oscillator (the crystal did not start):
    /// the panel shows it ([`crate::panel`], "Clock on the internal oscillator"). Off until
    /// set.
    pub fn set_clock_fallback(&mut self, fallback: bool) {
        self.clock_fallback = fallback;
    }

    /// Whether the brown-out reset level is below the goal (`supply::BorCheck`: records
    /// refused, a commissioning ends "not stored"): the panel shows it ([`crate::panel`],
    /// "Brown-out level below the goal"). Off until set.
    pub fn set_bor_below_goal(&mut self, below: bool) {
        self.bor_below_goal = below;
    }

    /// The commissioned operating range and the "moved" judgement.
    pub fn range(&self) -> &RangeWatch {
        &self.range
    }

    /// The latest status from the sample task.
    pub fn latest(&self) -> &MonitorStatus {
        &self.latest
    }

    /// The commissioning procedure.
    pub fn procedure(&self) -> &CommissioningProcedure {
        &self.procedure
    }

    /// One period at `now_ms`: `status` is the sample task's latest status if a new one
    /// came, `button` whether the button was pressed since the last tick.
    pub fn tick(&mut self, now_ms: u32, status: Option<MonitorStatus>, button: bool) -> Tick {
        if let Some(s) = status {
            self.take_status(s);
        }
        let watch = self.watch.poll(self.latest.samples, now_ms);
        let pressed = self.debounce(button, now_ms);
        let (mut action, run_ended) = if watch.stalled {
            (Action::None, None)
        } else {
            self.commissioning_step(pressed, now_ms)
        };
        if let Action::Store { record, .. } = &mut action {
            record.isolation = self.run_baseline;
            // The reference the run learned at: later readings are corrected to it.
            record.vdda_v = self.reference.in_band_v();
            self.pending_vdda = record.vdda_v;
        }
        self.expire_failed_show(now_ms);
        let mode = self.mode(watch.stalled);
        let failed = self.procedure.last_failure().is_some();
        self.latest.moved = self.range.moved(&self.latest.range_moment());
        self.latest.clip_range = self.clips.too_small();
        let isolation = self.panel_isolation();
        let input = PanelInput {
            default_motor: self.default_motor,
            clock_fallback: self.clock_fallback,
            bor_below_goal: self.bor_below_goal,
            ..panel_input(mode, &self.latest, isolation, failed)
        };
        Tick {
            pet_watchdog: watch.pet_watchdog,
            mode,
            call: panel_call(&self.latest, isolation).verdict,
            lamps: panel::render(&input, now_ms),
            action,
            run_ended,
            liveness: watch.change,
            reference_gain: self.reference_gain(run_ended),
            clip_range: self.clip_change.take(),
        }
    }

    /// Takes a new status `s` from the sample task as the latest: adds the sensor faults
    /// thread mode knows of (an offset out of bound, a reference out of band), then feeds
    /// the fault isolation, the operating range and the clip watch with it.
    fn take_status(&mut self, mut s: MonitorStatus) {
        let reference = self.reference.flags_sensors();
        s.sensor_fault.voltage |= self.offset_fault.voltage || reference;
        s.sensor_fault.current |= self.offset_fault.current || reference;
        let previous = self.latest.samples;
        self.latest = s;
        self.follow(&s, previous);
        self.range.observe(&s.range_moment());
        if let Some(change) = self.clips.observe(&s.clip_moment()) {
            self.clip_change = Some(change);
        }
    }

    /// The clip watch (the range state).
    pub fn clips(&self) -> &ClipWatch {
        &self.clips
    }

    /// Whether `button` (pressed since the last tick) counts as a press at `now_ms`: not
    /// within [`BUTTON_DEBOUNCE_MS`] of the previous press (every press restarts that time).
    fn debounce(&mut self, button: bool, now_ms: u32) -> bool {
        let pressed = button
            && self
                .last_press_ms
                .is_none_or(|t| now_ms.wrapping_sub(t) >= BUTTON_DEBOUNCE_MS);
        if button {
            self.last_press_ms = Some(now_ms);
        }
        pressed
    }

    /// The commissioning procedure's step at `now_ms` while samples flow: a debounced
    /// press (`pressed`) first, else the latest run's progress. Returns the action and a
    /// run that ended (a commissioned one puts its operating range into force).
    fn commissioning_step(&mut self, pressed: bool, now_ms: u32) -> (Action, Option<RunEnd>) {
        let mut action = Action::None;
        let mut run_ended = None;
        if pressed {
            action = self.procedure.button(&self.latest.run, now_ms);
        }
        if action == Action::None {
            let step = self.procedure.on_status(&self.latest.run, now_ms);
            action = step.action;
            run_ended = step.ended;
        }
        if let Some(RunEnd::Commissioned { run }) = run_ended {
            self.range.commit(run);
            self.gain_on_commissioning = true;
        }
        (action, run_ended)
    }

    /// The reference's correction at the end of a tick: the VDDA of a run that ended
    /// commissioned (`run_ended`) goes into force, else the latest measurement against the
    /// commissioned VDDA ([`crate::supply::ReferenceGain::observe`]); a new gain, if any.
    fn reference_gain(&mut self, run_ended: Option<RunEnd>) -> Option<f32> {
        let latest = self.reference.latest();
        if core::mem::take(&mut self.gain_on_commissioning)
            && matches!(run_ended, Some(RunEnd::Commissioned { .. }))
        {
            return self.gain.commissioned(self.pending_vdda, latest);
        }
        latest.and_then(|check| self.gain.observe(check))
    }

    /// Puts the VDDA of the commissioning `record` loaded at boot into force for the
    /// reference's correction ([`crate::supply::ReferenceGain`]; a record without it: no
    /// correction). The gain follows at the next measurement ([`Tick::reference_gain`]).
    pub fn restore_reference(&mut self, record: &CalibrationRecord) {
        self.gain.commissioned(record.vdda_v, None);
    }

    /// The reference's correction in force.
    pub fn reference_correction(&self) -> &crate::supply::ReferenceGain {
        &self.gain
    }

    /// Ends the boot's "monitor failed" show once `now_ms` has reached its end.
    fn expire_failed_show(&mut self, now_ms: u32) {
        // The wrapping clock has reached `t` when `now - t` is "small" (less than half the
        // clock's range).
        if self
            .failed_until_ms
            .is_some_and(|t| now_ms.wrapping_sub(t) < u32::MAX / 2)
        {
            self.failed_until_ms = None;
        }
    }

    /// The panel mode: the boot's "monitor failed" show first, then a `stalled` sample
    /// path, an active commissioning run, and whether learned thresholds are in force.
    fn mode(&self, stalled: bool) -> Mode {
        if self.failed_until_ms.is_some() {
            Mode::Failed
        } else if stalled {
            Mode::SamplingStalled
        } else if self.latest.run.stage.is_active() {
            Mode::Commissioning
        } else if self.latest.commissioned {
            Mode::Commissioned
        } else {
            Mode::NotCommissioned
        }
    }
}

#[cfg(test)]
mod tests;
