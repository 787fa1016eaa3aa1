//! The per-sample drive monitor: one type that runs on the board and on the host.
//!
//! Pipeline for every sample (10 kHz by default):
//! 1. check the sample (finite, inside the sensor ranges, ADC not saturated, currents and
//!    voltages summing to about zero, encoder not jumping): an impossible reading is held
//!    out of the filters and lights the matching sensor-fault candidate;
//! 2. Clarke of voltages and currents; the frame angle from the configured source
//!    ([`AngleSource`], one estimator: `frame.rs`); Park of both (one sin/cos evaluation
//!    per block, small rotations in between);
//! 3. encoder speed by the M/T method; electrical speed `wr = Np wm`;
//! 4. the d-q quantities summed over the block (`block.rs`).
//!
//! Every `decimation` samples (400 Hz by default: 25 samples at 10 kHz) the slow path
//! (`slow_path.rs`) feeds the block means to second-order filters of `Iqs, i_ds, Vqs, wr`
//! (values and derivatives) and of the negative sequence, evaluates the residuals
//! (eq. 37, or eq. 36 with [`ResidualForm::Full`]), normalises them, feeds commissioning or
//! the lamp logic, and matches the lamps against Table 1. The residuals act on quantities
//! filtered at `filter_hz` (5 Hz by default), so evaluating them at 400 Hz loses nothing.
//!
//! The configuration is in `config.rs`, the output in `output.rs`, the commissioning API
//! in `commissioning.rs`.

use crate::angle::AngleSource;
use crate::commissioning::Learner;
use crate::encoder::MtSpeed;
use crate::error::ConfigError;
use crate::frames::{clarke, park, Abc};
use crate::residuals::Normaliser;
use crate::signature::FAULT_COUNT;
use crate::threshold::Lamps;
use block::{BlockExtremes, BlockSums, Checks, Derived, DqFilters, SensorHold};
use frame::Frame;

mod block;
mod commissioning;
mod config;
mod frame;
mod output;
mod slow_path;

pub use config::{decimation_for, MonitorConfig, ResidualForm, SensorLimits, TARGET_BLOCK_RATE_HZ};
pub use output::{CommissioningState, MonitorOutput, SensorFlags, TimingEvents};

/// One sample from the sensors.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sample {
    /// Phase-to-neutral voltages [V].
    pub v_abc: Abc,
    /// Phase currents [A].
    pub i_abc: Abc,
    /// Raw encoder counter (free running, `EncoderConfig::counter_bits` wide).
    pub encoder_count: u32,
    /// Free-running timestamp in ticks of `MonitorConfig::tick_hz` (wraps).
    pub timestamp_ticks: u32,
    /// A voltage channel's ADC was at its end stop.
    pub v_saturated: bool,
    /// A current channel's ADC was at its end stop.
    pub i_saturated: bool,
    /// A reading was at or beyond its front end's linear range (an analog clip: a DOL
    /// start's inrush on a current front end sized for the running current; the firmware's
    /// per-conversion check). The sample's block is held out of the filters and the
    /// residuals, as a saturated one is, but no sensor is flagged: a clip says the front
    /// end's range was exceeded, not that a sensor gives readings no machine gives. (Whether
    /// clipping persists, and what that says of the front end's range, is the caller's to
    /// judge; the firmware's `clip_watch`.)
    pub clipped: bool,
}

/// The drive monitor. Construction validates the configuration; [`Monitor::update`] never
/// panics and never allocates.
///
/// Cost structure (see docs/performance.md's instruction counts): the per-sample fast path does the
/// plausibility check, the M/T speed, Clarke, one sin/cos, three Park rotations and five
/// accumulations; the d-q quantities are block-averaged over `decimation` samples (a
/// boxcar anti-alias filter with nulls at multiples of the slow rate) and everything else
/// runs once per block.
#[derive(Debug, Clone)]
pub struct Monitor {
    cfg: MonitorConfig,
    /// Values derived once from `cfg`.
    derived: Derived,
    /// The frame angle estimator and the frame's sin/cos.
    frame: Frame,
    mt: MtSpeed,
    /// The block's extremes, for its plausibility check.
    extremes: BlockExtremes,
    /// The block's sums of the d-q quantities.
    sums: BlockSums,
    filters: DqFilters,
    checks: Checks,
    norm: Normaliser,
    lamps: Lamps,
    learner: Learner,
    /// Blocks until the lamps may be evaluated (after start, a discarded block, a timing
    /// fault or a recovery).
    settle_left: u32,
    sensor_hold: SensorHold,
    /// Blocks until the next negative-sequence result.
    report_countdown: u16,
    /// Blocks the quasi-steady gate stays closed.
    gate_left: u32,
    /// Blocks the gate has been closed for.
    gate_closed_for: u32,
    /// Blocks the operating point's slow trend has been steady for (the gate's ripple
    /// rule, `MonitorConfig::steady_gate_per_s`).
    trend_steady_for: u32,
    /// Timestamp of the last sample of the previous block, once there was one.
    block_end_ticks: Option<u32>,
    /// The lamps last matched against the signatures (`None`: match at the next block).
    matched_lamps: Option<[bool; 4]>,
    /// Bumped (wrapping) wherever the output may change other than its per-sample speed:
    /// [`Monitor::revision`].
    revision: u32,
    out: MonitorOutput,
}

impl Monitor {
    /// Builds a monitor.
    ///
    /// # Errors
    /// The first [`ConfigError`] found by [`MonitorConfig::validate`].
    pub fn new(cfg: MonitorConfig) -> Result<Self, ConfigError> {
        cfg.validate()?;
        let derived = Derived::new(&cfg);
        let block_dt = derived.block_dt_s;
        Ok(Monitor {
            derived,
            frame: Frame::new(&cfg),
            mt: MtSpeed::new(
                &cfg.encoder,
                cfg.tick_hz,
                cfg.limits.max_speed_rad_s,
                derived.dt_s,
            ),
            extremes: BlockExtremes::default(),
            sums: BlockSums::default(),
            filters: DqFilters::new(&cfg, block_dt)?,
            checks: Checks::new(derived.block_rate_hz, block_dt)?,
            norm: Normaliser::new(
                &cfg.motor,
                block::no_load_reference(&cfg),
                cfg.floor_fraction,
            ),
            // The period as f32::from(decimation) / sample_rate_hz (not dt x decimation,
            // which differs in the last bit and moves a debounce by a block).
            lamps: Lamps::new(
                cfg.thresholds,
                f32::from(cfg.decimation) / cfg.sample_rate_hz,
            ),
            learner: Learner::default(),
            settle_left: derived.settle_blocks,
            sensor_hold: SensorHold::default(),
            report_countdown: 0,
            gate_left: 0,
            gate_closed_for: 0,
            trend_steady_for: 0,
            block_end_ticks: None,
            matched_lamps: None,
            revision: 0,
            out: MonitorOutput {
                zero_crossing_locked: (cfg.angle_source == AngleSource::ZeroCrossing)
                    .then_some(false),
                ..MonitorOutput::default()
            },
            cfg,
        })
    }

    /// The fault signature matrix the lamps are matched against: the physical one for
    /// rotor-flux orientation, the paper's Table 1 for voltage orientation (see
    /// [`crate::signature`]).
    pub fn signatures(&self) -> &'static [[bool; 4]; FAULT_COUNT] {
        crate::signature::signatures_for(self.cfg.angle_source)
    }

    /// The configuration in use.
    pub fn config(&self) -> &MonitorConfig {
        &self.cfg
    }

    /// The last output.
    pub fn output(&self) -> &MonitorOutput {
        &self.out
    }

    /// A count (wrapping) that changes whenever the output's fields other than
    /// `speed_rad_s`, or the threshold bands, may have changed: at each block's end (the
    /// slow path, once per `decimation` samples), at a sensor flag, and at a commissioning
    /// call. Between two changes only `speed_rad_s` moves, so a reader of every sample may
    /// skip what depends on the rest. (Counted off the per-sample path.)
    pub fn revision(&self) -> u32 {
        self.revision
    }

    /// Processes one sample and returns the updated output. Never panics: a non-finite,
    /// out-of-range or saturated reading is held out of the estimators and flags its sensor;
    /// a clipped one ([`Sample::clipped`]) is held out and flags nothing.
    pub fn update(&mut self, s: &Sample) -> &MonitorOutput {
        // Plausibility is checked once per block (slow path): the ADC flags and the
        // readings' extremes are collected here, their range and finiteness are checked
        // there. A NaN or absurd reading poisons only its own block, which is then
        // discarded.
        self.extremes.add(s);
        let wm = match self.mt.update_checked(s.encoder_count, s.timestamp_ticks) {
            Some(w) => w,
            None => {
                self.flag(SensorFlags {
                    speed: true,
                    ..SensorFlags::default()
                });
                // A jump is not motion: keep the last speed.
                self.out.speed_rad_s
            }
        };
        self.out.speed_rad_s = wm;
        let wr = wm * self.derived.np;

        let v = clarke(s.v_abc);
        let i = clarke(s.i_abc);
        let (sc, i_dq) = self.frame.update(s.v_abc.a, v, i, wr, self.derived.dt_s);
        let v_q = -v.alpha * sc.sin + v.beta * sc.cos;
        let n = park(i, sc.negated());
        self.sums.add(i_dq, v_q, n);
        if self.sums.len() >= self.cfg.decimation {
            self.slow_path(s, wr, sc);
        }
        &self.out
    }
}

#[cfg(test)]
mod tests;
