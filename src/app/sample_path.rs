//! The per-sample path of the sample task ([`SamplePath`]: [`RawFrame`] -> `Sample` ->
//! [`Monitor::update`], the start-up offset trim, the status for thread mode) and the
//! [`Command`]s thread mode sends it, applied between two samples.

use super::{board_monitor_config, MonitorStatus};
use crate::acquisition::{LinearRanges, SampleBuilder, HALF_LEN, OVERSAMPLING};
use crate::board::{CurrentCode, VoltageCode};
use crate::board::{FrontEnd, ZeroBias, ZERO_BIAS};
use crate::flash_record::CalibrationRecord;
use crate::offset_trim::{OffsetTrim, TrimKind, TrimResult, REPORT_STEP_CODES};
use crate::sampling::{AdcSampler, Clipped, RawFrame, SamplingError};
use monitor_core::{
    CommissioningError, ConfigError, Fault, Install, Monitor, MonitorConfig, MonitorOutput,
    SteadyPoint,
};

/// Why the application could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AppError {
    /// The core rejected the configuration.
    Config(ConfigError),
    /// The sample rate does not fit the timestamp clock.
    Sampling(SamplingError),
}

/// Requests from thread mode to the sample task (applied between two samples).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Start a commissioning run of `duration_s` seconds of evaluated running; the learned
    /// calibration goes into force once stored ([`Install::AfterStorage`]).
    StartCommissioning {
        /// Learning time, s (> 0).
        duration_s: f32,
    },
    /// Cancel run `run` if it is still learning.
    CancelCommissioning {
        /// The run's id.
        run: u16,
    },
    /// The flash holds `stored` after storing run `run`'s calibration (read back): the
    /// core puts exactly that into force (`None`: the default thresholds) and ends the run.
    CalibrationStored {
        /// The run's id.
        run: u16,
        /// The record read back (`None`: no valid record).
        stored: Option<CalibrationRecord>,
    },
    /// Install a calibration read from flash at boot.
    SetCalibration(CalibrationRecord),
    /// Stop the acquisition until thread mode has erased and written the flash
    /// ([`super::AcquisitionPause`]); the sample task carries it out on the registers, the
    /// sample path has nothing to do.
    PauseAcquisition,
    /// Correct every reading for the ADC's reference: VDDA now over VDDA at commissioning
    /// ([`crate::supply::ReferenceGain`]); 1 removes the correction.
    ReferenceGain(f32),
}

/// Why the core did not carry out a [`Command`] as asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandError {
    /// A start was refused.
    Commissioning(CommissioningError),
    /// A cancel found that run not learning (it had ended or learned already).
    NotLearning,
    /// A stored or stored-back calibration is out of the core's range (the default
    /// thresholds are in force for `CalibrationStored`; the previous ones for
    /// `SetCalibration`).
    Calibration(ConfigError),
}

impl CommandError {
    /// A short description for logs.
    pub fn describe(&self) -> &'static str {
        match self {
            CommandError::Commissioning(CommissioningError::Duration) => {
                "commissioning refused: bad duration"
            }
            CommandError::Commissioning(CommissioningError::Busy) => {
                "commissioning refused: a run is active"
            }
            CommandError::Commissioning(CommissioningError::StaleRun) => {
                "commissioning report for an older run"
            }
            CommandError::NotLearning => "cancel: the run is not learning",
            CommandError::Calibration(_) => "calibration out of the core's range",
        }
    }
}

impl Command {
    /// A short name for logs.
    pub fn name(&self) -> &'static str {
        match self {
            Command::StartCommissioning { .. } => "start-commissioning",
            Command::CancelCommissioning { .. } => "cancel-commissioning",
            Command::CalibrationStored { .. } => "calibration-stored",
            Command::SetCalibration(_) => "set-calibration",
            Command::PauseAcquisition => "pause-acquisition",
            Command::ReferenceGain(_) => "reference-gain",
        }
    }
}

/// The per-sample path: scaling, the core, commands.
#[derive(Clone, Debug)]
pub struct SamplePath {
    monitor: Monitor,
    sampler: AdcSampler,
    samples: u32,
    trim: OffsetTrim,
    /// Clipped samples since boot (wrapping): any front end, the voltages', the currents'.
    clipped: [u32; 3],
    /// Rejected encoder counts since boot (wrapping).
    encoder_rejects: u32,
    /// The front end at the reference of commissioning: the record's scaling with the
    /// start-up trim's offsets (in codes at that reference).
    front_end: FrontEnd,
    /// The reference correction in force: VDDA now over VDDA at commissioning.
    reference_gain: f32,
    /// Where the front end's zero is biased ([`ZERO_BIAS`]): how the correction moves it.
    zero_bias: ZeroBias,
}

impl SamplePath {
    /// Build from a core configuration, the board's front end and the sample rate.
    ///
    /// # Errors
    /// [`AppError`] if the core or the sampler rejects the settings.
    pub fn new(
        cfg: MonitorConfig,
        front_end: FrontEnd,
        sample_rate_hz: u32,
    ) -> Result<Self, AppError> {
        Ok(Self {
            monitor: Monitor::new(cfg).map_err(AppError::Config)?,
            sampler: AdcSampler::new(front_end, sample_rate_hz).map_err(AppError::Sampling)?,
            samples: 0,
            trim: OffsetTrim::new(&front_end),
            clipped: [0; 3],
            encoder_rejects: 0,
            front_end,
            reference_gain: 1.0,
            zero_bias: ZERO_BIAS,
        })
    }

    /// The board setup at `sample_rate_hz` (the [`Settings`](super::Settings) value): the configuration of
    /// [`board_monitor_config`] and the default front end.
    ///
    /// # Errors
    /// As [`SamplePath::new`].
    pub fn for_board(sample_rate_hz: u32) -> Result<Self, AppError> {
        Self::new(
            board_monitor_config(sample_rate_hz),
            FrontEnd::DEFAULT,
            sample_rate_hz,
        )
    }

    /// Apply a command.
    ///
    /// # Errors
    /// [`CommandError`] when the core refused or could not do what was asked (see there
    /// for what is in force then).
    pub fn command(&mut self, cmd: Command) -> Result<(), CommandError> {
        let m = &mut self.monitor;
        match cmd {
            Command::StartCommissioning { duration_s } => m
                .start_commissioning_with(duration_s, Install::AfterStorage)
                .map(|_| ())
                .map_err(CommandError::Commissioning),
            Command::CancelCommissioning { run } => m
                .cancel_commissioning(run)
                .then_some(())
                .ok_or(CommandError::NotLearning),
            Command::CalibrationStored { run, stored } => m
                .calibration_stored(run, stored.map(Into::into))
                .map_err(CommandError::Calibration),
            Command::SetCalibration(rec) => m
                .set_calibration(rec.into())
                .map_err(CommandError::Calibration),
            Command::PauseAcquisition => Ok(()),
            Command::ReferenceGain(gain) => {
                self.set_reference_gain(gain);
                Ok(())
            }
        }
    }

    /// The offset trim ([`crate::offset_trim`]): adds `raw` (the frame also given to
    /// [`SamplePath::on_frame`]); at the end of the start-up window, and of each later
    /// window in which the shaft stood and the currents were zero, puts the trimmed
    /// channels' offsets into force in the front end. Returns the start-up trim (its
    /// out-of-bound channels go to [`Supervisor::set_offset_fault`](super::Supervisor::set_offset_fault))
    /// and the re-trims that moved a zero by [`REPORT_STEP_CODES`] or more (to log); `None`
    /// otherwise.
    pub fn trim_offsets(&mut self, raw: &RawFrame) -> Option<TrimResult> {
        let trim = self.trim.add(raw)?;
        let gain = self.reference_gain;
        let bias = self.zero_bias;
        let fe = &mut self.front_end;
        let channels = (fe.voltage.iter_mut().zip(trim.voltage))
            .chain(fe.current.iter_mut().zip(trim.current));
        let mut moved = false;
        for (scale, channel) in channels {
            if let Some(offset) = channel.offset() {
                // Measured in codes at today's reference; the front end keeps them at
                // commissioning's: an absolute zero's code x gain, a zero at VDDA / 2's as
                // it is.
                let at_commissioning = match bias {
                    ZeroBias::Absolute => offset * gain,
                    ZeroBias::HalfVdda => offset,
                };
                moved |= (at_commissioning - scale.offset_code).abs() >= REPORT_STEP_CODES;
                scale.offset_code = at_commissioning;
            }
        }
        self.apply_front_end();
        (trim.kind == TrimKind::StartUp || moved).then_some(trim)
    }

    /// Where the front end's zero is biased (the board's [`ZERO_BIAS`] unless set).
    pub fn set_zero_bias(&mut self, bias: ZeroBias) {
        self.zero_bias = bias;
        self.apply_front_end();
    }

    /// Corrects every reading for the ADC's reference (`Command::ReferenceGain`): `gain`
    /// = VDDA now over VDDA at commissioning ([`crate::supply::ReferenceGain`]). The front
    /// end's swing is not ratiometric (the isolated amplifiers' gain is theirs), so the
    /// swing around the zero read at VDDA now is `1 / gain` times the swing the same input
    /// gave at commissioning: `x = (code - zero now) (gain per_lsb)`. The zero's code now
    /// depends on its bias ([`crate::board::ZeroBias`]): a zero at VDDA / 2 stays where it
    /// was (`zero now = offset`); an absolute one moves with the swing (`zero now = offset /
    /// gain`). The front end rescaled once, nothing added per sample. A gain that is not
    /// finite or outside 0.9..=1.1 (beyond the reference's band, whose readings are flagged
    /// anyway) is ignored.
    pub fn set_reference_gain(&mut self, gain: f32) {
        if gain.is_finite() && (0.9..=1.1).contains(&gain) {
            self.reference_gain = gain;
            self.apply_front_end();
        }
    }

    /// The reference correction in force (1: none).
    pub fn reference_gain(&self) -> f32 {
        self.reference_gain
    }

    /// The sampler's front end: [`SamplePath::front_end`]'s scaled by the reference gain.
    fn apply_front_end(&mut self) {
        let g = self.reference_gain;
        let absolute = self.zero_bias == ZeroBias::Absolute;
        let mut fe = self.front_end;
        for scale in fe.voltage.iter_mut().chain(fe.current.iter_mut()) {
            if absolute {
                scale.offset_code /= g;
            }
            scale.per_lsb *= g;
        }
        self.sampler.set_front_end(fe);
    }

    /// The ADC sampler (for timestamp resynchronisation after lost samples).
    pub fn sampler_mut(&mut self) -> &mut AdcSampler {
        &mut self.sampler
    }

    /// The ADC sampler.
    pub fn sampler(&self) -> &AdcSampler {
        &self.sampler
    }

    /// The core monitor.
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// Samples processed since boot (wrapping).
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Process one sample's readings: scaled and stamped ([`AdcSampler::build`]; a clipped
    /// sample goes to the core as clipped, which holds its block out of the residuals and
    /// names no sensor) into [`Monitor::update`]; the clipped samples (any front end, and
    /// each) and the rejected encoder counts counted for the status line and thread mode's
    /// clip watch.
    #[inline]
    pub fn on_frame(&mut self, raw: &RawFrame) {
        let sample = self.sampler.build(raw);
        self.monitor.update(&sample);
        self.samples = self.samples.wrapping_add(1);
        let clips = raw.clips();
        let [any, voltage, current] = &mut self.clipped;
        *any = any.wrapping_add(u32::from(sample.clipped));
        *voltage = voltage.wrapping_add(u32::from(clips.voltage));
        *current = current.wrapping_add(u32::from(clips.current));
        self.encoder_rejects = self
            .encoder_rejects
            .wrapping_add(u32::from(raw.encoder_rejects));
    }

    /// The status for thread mode, from the latest output.
    pub fn status(&self) -> MonitorStatus {
        let o = self.monitor.output();
        let (top, second) = candidates(o);
        MonitorStatus {
            samples: self.samples,
            residuals: o.residuals,
            residual_lamps: o.lamps,
            fault_detected: o.fault_detected,
            sensor_fault: o.sensor_fault,
            top,
            second,
            speed_rad_s: o.speed_rad_s,
            zero_crossing_locked: o.zero_crossing_locked,
            commissioned: self.monitor.calibration().is_some(),
            run: self.monitor.commissioning(),
            operating: o.operating,
            frame_hz: o.frame_omega_rad_s / core::f32::consts::TAU,
            quasi_steady: o.quasi_steady,
            evaluating: o.evaluating,
            bands: self.monitor.threshold_bands(),
            point: SteadyPoint::from_output(o),
            winding: o
                .unbalance
                .suspect_phase
                .map(|p| (p, o.unbalance.winding_ratio)),
            winding_confidence: o.unbalance.phase_confidence,
            vds: o.vds,
            moved: false,
            clipped: self.clipped[0],
            clipped_voltage: self.clipped[1],
            clipped_current: self.clipped[2],
            encoder_rejects: self.encoder_rejects,
            clip_range: false,
        }
    }
}

/// One sample's conversions and latched encoder counts -> its [`RawFrame`], as the sample
/// task builds it: [`SampleBuilder`] (each ADC's oversampled sequences summed with every
/// conversion checked against its channel's linear range, a clip held through the filter's
/// memory; the latched counts checked against the maximum speed and averaged; the
/// inverter's ripple filtered out), its result as the frame's codes, count and flags. No
/// allocation, no panics.
#[derive(Clone, Copy, Debug)]
pub struct FrameBuilder {
    builder: SampleBuilder,
}

impl FrameBuilder {
    /// A builder at `sample_rate_hz` whose filter restores the gain at `supply_hz`, with
    /// the channels' linear `ranges` (`motor_source::linear_ranges`) and the encoder's
    /// largest step between two triggers `max_step` (`motor_source::EncoderSetup`).
    pub fn new(sample_rate_hz: u32, supply_hz: f32, ranges: LinearRanges, max_step: u16) -> Self {
        Self {
            builder: SampleBuilder::new(sample_rate_hz, supply_hz, &ranges, max_step),
        }
    }

    /// After a gap in the triggers (a recovery, a paused acquisition): the next latched
    /// count starts the encoder check afresh.
    pub fn restart(&mut self) {
        self.builder.restart();
    }

    /// A sample that is dropped (`adc_rules::IdleDiscard`): its latched counts still go
    /// through the encoder check, so the next sample's first step is one trigger long.
    pub fn skip(&mut self, latched: &[u16; OVERSAMPLING]) {
        self.builder.skip(latched);
    }

    /// One sample: `v` and `i` its sequences of ADC1 and ADC2 (`[a, b, c, a, b, c, ...]`),
    /// `latched` the encoder counts latched at its triggers (oldest first).
    #[inline]
    pub fn frame(
        &mut self,
        v: &[u16; HALF_LEN],
        i: &[u16; HALF_LEN],
        latched: &[u16; OVERSAMPLING],
    ) -> RawFrame {
        let b = self.builder.build(v, i, latched);
        let ([va, vb, vc], [ia, ib, ic], [voltage, current]) = (b.v, b.i, b.clipped);
        RawFrame {
            v: [VoltageCode(va), VoltageCode(vb), VoltageCode(vc)],
            i: [CurrentCode(ia), CurrentCode(ib), CurrentCode(ic)],
            encoder_count: b.count,
            clipped: Clipped { voltage, current },
            encoder_rejects: b.encoder_rejects,
        }
    }
}

/// A candidate of the status: a fault and its probability, or none.
type StatusCandidate = Option<(Fault, f32)>;

/// The status's two candidates from the core's output: the most probable fault
/// ([`MonitorOutput::top`]) and the most probable after it, the first of equals as the
/// top's; each only with a probability above zero.
pub(super) fn candidates(o: &MonitorOutput) -> (StatusCandidate, StatusCandidate) {
    let top = o.top();
    let second = o
        .diagnosis
        .probabilities
        .iter()
        .zip(Fault::ALL)
        .filter(|(p, f)| **p > 0.0 && Some(*f) != top.map(|t| t.0))
        .fold(None::<(Fault, f32)>, |best, (p, f)| match best {
            Some((_, bp)) if bp >= *p => best,
            _ => Some((f, *p)),
        });
    (top, second)
}
