//! The per-sample drive monitor: one type that runs on the board and on the host.
//!
//! Pipeline for every sample (10 kHz by default):
//! 1. check the sample (finite, inside the sensor ranges, ADC not saturated, currents and
//!    voltages summing to about zero, encoder not jumping): an impossible reading is held
//!    out of the filters and lights the matching sensor-fault candidate;
//! 2. Clarke of voltages and currents; the frame angle from the configured source
//!    ([`AngleSource`]); Park of both (one sin/cos evaluation per sample);
//! 3. encoder speed by the M/T method; electrical speed `wr = Np wm`;
//! 4. second-order filters of `Iqs, i_ds, Vqs, wr` (values and derivatives);
//! 5. positive/negative-sequence separation of the currents.
//!
//! Every `decimation` samples (400 Hz by default: 25 samples at 10 kHz) the slow path
//! evaluates the residuals
//! (eq. 37, or eq. 36 with [`ResidualForm::Full`]), normalises them, feeds commissioning or
//! the lamp logic, and matches the lamps against Table 1. The residuals act on quantities
//! filtered at `filter_hz` (5 Hz by default), so evaluating them at 400 Hz loses nothing.

use crate::angle::{AngleSource, RotorFluxCurrentModel, SrfPll, ZeroCrossing};
use crate::commissioning::Learner;
use crate::encoder::MtSpeed;
use crate::error::ConfigError;
use crate::filter::{LowPass, Svf};
use crate::frames::{clarke, park, Abc, Dq, SinCos};
use crate::residuals::{residuals, Derivatives, Normaliser, Operating};
use crate::sequence::asymmetry_correction_rad;
use crate::sequence::sequence_result;
use crate::signature::{match_signature, Diagnosis, Fault, FAULT_COUNT};
use crate::threshold::Lamps;
use core::f32::consts::TAU;

mod commissioning;
mod config;
mod output;

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
}

/// The drive monitor. Construction validates the configuration; [`Monitor::update`] never
/// panics and never allocates.
///
/// Cost structure (see the README's instruction counts): the per-sample fast path does the
/// plausibility check, the M/T speed, Clarke, one sin/cos, three Park rotations and five
/// accumulations; the d-q quantities are block-averaged over `decimation` samples (a
/// boxcar anti-alias filter with nulls at multiples of the slow rate) and everything else
/// runs once per block.
#[derive(Debug, Clone)]
pub struct Monitor {
    cfg: MonitorConfig,
    zc: ZeroCrossing,
    pll: SrfPll,
    rfo: RotorFluxCurrentModel,
    mt: MtSpeed,
    /// sin/cos of the frame angle, advanced by small rotations between resyncs.
    sc: SinCos,
    dt: f32,
    v_max_bits: u32,
    i_max_bits: u32,
    block_sat: u8,
    block_vmax: u32,
    block_imax: u32,
    // Block accumulators (fast path).
    acc: [f32; 5],
    acc_n: u16,
    // Slow-path filters.
    f_iqs: Svf,
    f_ids: Svf,
    f_vqs: Svf,
    f_wr: Svf,
    f_nd: Svf,
    f_nq: Svf,
    /// Filtered squared voltage magnitude |V|^2 [V^2] (compared with `v_run_min2`: no
    /// square root per block).
    vmag2: LowPass,
    /// (`min_voltage_frac` x `v_phase_peak`)^2 [V^2].
    v_run_min2: f32,
    f_vds: LowPass,
    isum: LowPass,
    imax: LowPass,
    vsum: LowPass,
    vmax: LowPass,
    norm: Normaliser,
    lamps: Lamps,
    learner: Learner,
    settle_left: u32,
    settle_blocks: u32,
    hold_blocks: u32,
    sensor_hold: [u32; 3],
    report_countdown: u16,
    report_every: u16,
    gate_left: u32,
    gate_blocks: u32,
    gate_closed_for: u32,
    gate_timeout_blocks: u32,
    gate_floor: [f32; 3],
    /// Timestamp of the last sample of the previous block, once there was one.
    block_end_ticks: Option<u32>,
    /// Block lengths in ticks accepted as on time: `lo..=lo + span`.
    block_ticks_lo: u32,
    block_ticks_span: u32,
    /// Expected ticks per block and the longest gap bridged, in ticks.
    block_ticks: u32,
    max_gap_ticks: u32,
    /// The frame's estimator as it stood at the end of the last block: a block with a gap
    /// inside is rolled back to it and bridged from there ([`Monitor::timing_event`]).
    snap_zc: ZeroCrossing,
    snap_pll: SrfPll,
    snap_rfo: RotorFluxCurrentModel,
    np: f32,
    matched_lamps: Option<[bool; 4]>,
    out: MonitorOutput,
}

/// Index of the block accumulators.
const ACC_ID: usize = 0;
const ACC_IQ: usize = 1;
const ACC_VQ: usize = 2;
const ACC_ND: usize = 3;
const ACC_NQ: usize = 4;

impl Monitor {
    /// Builds a monitor.
    ///
    /// # Errors
    /// The first [`ConfigError`] found by [`MonitorConfig::validate`].
    pub fn new(cfg: MonitorConfig) -> Result<Self, ConfigError> {
        cfg.validate()?;
        let dt = 1.0 / cfg.sample_rate_hz;
        let dec = f32::from(cfg.decimation);
        let slow_dt = dt * dec;
        let slow_hz = cfg.sample_rate_hz / dec;
        let m = &cfg.motor;
        let imr_min = 0.05 * cfg.v_phase_peak / (TAU * cfg.supply_hz * m.ls_h);
        let reference = Operating {
            iqs: 0.0,
            i_f: cfg.v_phase_peak / (TAU * cfg.supply_hz * m.ls_h),
            vqs: cfg.v_phase_peak,
            wr_rad_s: TAU * cfg.supply_hz,
        };
        let sum_lp = 5.0f32.min(0.2 * slow_hz);
        let zc = ZeroCrossing::new(
            dt,
            cfg.supply_hz,
            0.2 * cfg.supply_hz,
            4.0 * cfg.supply_hz,
            0.02 * cfg.v_phase_peak,
        );
        let pll = SrfPll::new(dt, cfg.supply_hz, cfg.pll_bw_hz, cfg.v_phase_peak);
        let rfo = RotorFluxCurrentModel::new(dt, m.rr_ohm, m.lr_h, imr_min);
        Ok(Monitor {
            zc,
            pll,
            rfo,
            mt: MtSpeed::new(&cfg.encoder, cfg.tick_hz, cfg.limits.max_speed_rad_s, dt),
            sc: SinCos::default(),
            dt,
            v_max_bits: cfg.limits.v_max.to_bits(),
            i_max_bits: cfg.limits.i_max.to_bits(),
            block_sat: 0,
            block_vmax: 0,
            block_imax: 0,
            acc: [0.0; 5],
            acc_n: 0,
            f_iqs: Svf::new(cfg.filter_hz, slow_dt),
            f_ids: Svf::new(cfg.filter_hz, slow_dt),
            f_vqs: Svf::new(cfg.filter_hz, slow_dt),
            f_wr: Svf::new(cfg.filter_hz, slow_dt),
            f_nd: Svf::new(cfg.sequence_hz, slow_dt),
            f_nq: Svf::new(cfg.sequence_hz, slow_dt),
            vmag2: LowPass::new(sum_lp, slow_dt),
            v_run_min2: (cfg.min_voltage_frac * cfg.v_phase_peak)
                * (cfg.min_voltage_frac * cfg.v_phase_peak),
            f_vds: LowPass::new(cfg.filter_hz, slow_dt),
            isum: LowPass::new(sum_lp, slow_dt),
            imax: LowPass::new(sum_lp, slow_dt),
            vsum: LowPass::new(sum_lp, slow_dt),
            vmax: LowPass::new(sum_lp, slow_dt),
            norm: Normaliser::new(m, reference, cfg.floor_fraction),
            lamps: Lamps::new(
                cfg.thresholds,
                f32::from(cfg.decimation) / cfg.sample_rate_hz,
            ),
            learner: Learner::default(),
            settle_left: (cfg.settle_s * slow_hz) as u32,
            settle_blocks: (cfg.settle_s * slow_hz) as u32,
            hold_blocks: slow_hz as u32,
            sensor_hold: [0; 3],
            report_countdown: 0,
            report_every: ((0.1 * slow_hz) as u16).max(1),
            gate_left: 0,
            gate_blocks: (cfg.gate_hold_s * slow_hz) as u32,
            gate_closed_for: 0,
            gate_timeout_blocks: (cfg.gate_timeout_s * slow_hz) as u32,
            // Floors of the relative rates: magnetising current, 10 % voltage, 10 % speed.
            gate_floor: [
                reference.i_f,
                0.1 * cfg.v_phase_peak,
                0.1 * TAU * cfg.supply_hz,
            ],
            block_end_ticks: None,
            block_ticks_lo: (cfg.tick_hz * dt * (dec - 0.5)) as u32,
            block_ticks_span: (cfg.tick_hz * dt) as u32,
            block_ticks: (cfg.tick_hz * slow_dt + 0.5) as u32,
            max_gap_ticks: (cfg.tick_hz * (slow_dt + cfg.max_bridged_gap_s)) as u32,
            snap_zc: zc,
            snap_pll: pll,
            snap_rfo: rfo,
            np: m.np(),
            matched_lamps: None,
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

    /// Processes one sample and returns the updated output. Never panics: a non-finite,
    /// out-of-range or saturated reading is held out of the estimators and flags its sensor.
    pub fn update(&mut self, s: &Sample) -> &MonitorOutput {
        // Plausibility is checked once per block (slow path): the ADC flags are collected
        // here, the values' range and finiteness are checked on the block's extremes there.
        // A NaN or absurd reading poisons only its own block, which is then discarded.
        self.block_sat |= u8::from(s.i_saturated) | (u8::from(s.v_saturated) << 1);
        let m = 0x7fff_ffffu32;
        let vb = (s.v_abc.a.to_bits() & m)
            .max(s.v_abc.b.to_bits() & m)
            .max(s.v_abc.c.to_bits() & m);
        let ib = (s.i_abc.a.to_bits() & m)
            .max(s.i_abc.b.to_bits() & m)
            .max(s.i_abc.c.to_bits() & m);
        self.block_vmax = self.block_vmax.max(vb);
        self.block_imax = self.block_imax.max(ib);

        let speed = self.mt.update_checked(s.encoder_count, s.timestamp_ticks);
        let wm = match speed {
            Some(w) => w,
            None => {
                self.flag([false, false, true]);
                // A jump is not motion: keep the last speed.
                self.out.speed_rad_s
            }
        };
        self.out.speed_rad_s = wm;
        let wr = wm * self.np;

        let v = clarke(s.v_abc);
        let i = clarke(s.i_abc);
        // One trig evaluation per block; between resyncs the frame's sin/cos is advanced by
        // small rotations (SinCos::rotated) at the estimator's frequency.
        let sc = match self.cfg.angle_source {
            AngleSource::ZeroCrossing => SinCos::from_angle(self.zc.update(s.v_abc.a)),
            AngleSource::Pll => {
                let sc_pll = self.sc;
                let w = self.pll.update(v, sc_pll);
                self.sc = sc_pll.rotated(w * self.dt);
                sc_pll.minus_quarter_turn()
            }
            AngleSource::RotorFluxCurrentModel => self.sc,
        };
        let i_dq: Dq = park(i, sc);
        if self.cfg.angle_source == AngleSource::RotorFluxCurrentModel {
            self.rfo.update(i_dq, wr);
            self.sc = sc.rotated(self.rfo.omega_rad_s() * self.dt);
        }
        let v_q = -v.alpha * sc.sin + v.beta * sc.cos;
        let n = park(i, sc.negated());
        self.acc[ACC_ID] += i_dq.d;
        self.acc[ACC_IQ] += i_dq.q;
        self.acc[ACC_VQ] += v_q;
        self.acc[ACC_ND] += n.d;
        self.acc[ACC_NQ] += n.q;
        self.acc_n += 1;
        if self.acc_n >= self.cfg.decimation {
            self.slow_path(s, wr, sc);
        }
        &self.out
    }

    #[cold]
    #[inline(never)]
    fn flag(&mut self, bad: [bool; 3]) {
        for (h, b) in self.sensor_hold.iter_mut().zip(bad) {
            if b {
                *h = self.hold_blocks.max(1);
            }
        }
        self.out.sensor_fault = self.held_sensor_flags();
        let sf = self.out.sensor_fault;
        // An impossible reading names its sensor outright.
        let mut p = [0.0f32; FAULT_COUNT];
        let n = [sf.current, sf.voltage, sf.speed]
            .iter()
            .filter(|x| **x)
            .count()
            .max(1) as f32;
        for (flag, fault) in [
            (sf.current, Fault::CurrentSensor),
            (sf.voltage, Fault::VoltageSensor),
            (sf.speed, Fault::SpeedSensor),
        ] {
            if flag {
                if let Some(x) = p.get_mut(fault.index()) {
                    *x = 1.0 / n;
                }
            }
        }
        self.out.diagnosis = Diagnosis {
            probabilities: p,
            exact: true,
        };
        self.out.fault_detected = true;
    }

    /// Discards the current block after an impossible reading and restarts the angle
    /// estimators if a bad value reached them.
    #[cold]
    #[inline(never)]
    fn discard_block(&mut self) {
        self.acc = [0.0; 5];
        self.acc_n = 0;
        self.settle_left = self.settle_blocks;
        self.restart_estimators(false);
    }

    /// Restarts the frame's estimators: the rotor-flux model when its state is not finite
    /// or its magnetising current beyond the current range (a burst of huge readings leaves
    /// a finite but absurd flux that would take seconds to decay), or when `all`; the PLL
    /// when not finite or `all`; the zero-crossing detector always.
    #[cold]
    #[inline(never)]
    fn restart_estimators(&mut self, all: bool) {
        let dt = 1.0 / self.cfg.sample_rate_hz;
        let m = &self.cfg.motor;
        if all
            || !(self.rfo.theta().is_finite()
                && self.rfo.imr().abs() <= self.cfg.limits.i_max
                && self.rfo.omega_rad_s().is_finite())
        {
            let imr_min = 0.05 * self.cfg.v_phase_peak / (TAU * self.cfg.supply_hz * m.ls_h);
            self.rfo = RotorFluxCurrentModel::new(dt, m.rr_ohm, m.lr_h, imr_min);
        }
        if all || !(self.pll.theta_pll().is_finite() && self.pll.omega_rad_s().is_finite()) {
            self.pll = SrfPll::new(
                dt,
                self.cfg.supply_hz,
                self.cfg.pll_bw_hz,
                self.cfg.v_phase_peak,
            );
        }
        self.zc = ZeroCrossing::new(
            dt,
            self.cfg.supply_hz,
            0.2 * self.cfg.supply_hz,
            4.0 * self.cfg.supply_hz,
            0.02 * self.cfg.v_phase_peak,
        );
        self.sc = SinCos::default();
    }

    // Kept out of line so the per-sample path does not carry its register pressure. The
    // steps are separate functions for reading; each is inlined here.
    #[inline(never)]
    fn slow_path(&mut self, s: &Sample, wr: f32, sc: SinCos) {
        self.block_end(s, wr, sc);
        self.snapshot_frame();
    }

    /// Everything at the end of a block (see [`Monitor::slow_path`]).
    #[inline(always)]
    fn block_end(&mut self, s: &Sample, wr: f32, sc: SinCos) {
        let off_time = self.block_timing(s.timestamp_ticks);
        // Plausibility of the block: saturation flags, range (NaN and inf fail, see update).
        let i_bad = (self.block_sat & 1 != 0) | (self.block_imax > self.i_max_bits);
        let v_bad = (self.block_sat & 2 != 0) | (self.block_vmax > self.v_max_bits);
        self.block_sat = 0;
        self.block_imax = 0;
        self.block_vmax = 0;
        if i_bad | v_bad {
            self.flag([i_bad, v_bad, false]);
            self.discard_block();
            return;
        }
        if let Some(elapsed) = off_time {
            self.timing_event(elapsed);
            return;
        }
        let iqs = self.filter_block(wr);
        self.check_sums(s, sc);
        let op = Operating {
            iqs: self.f_iqs.y,
            i_f: self.f_ids.y,
            vqs: self.f_vqs.y,
            wr_rad_s: self.f_wr.y,
        };
        self.out.operating = op;
        let d = match self.cfg.residual_form {
            ResidualForm::Steady => None,
            ResidualForm::Full => Some(Derivatives {
                diqs: self.f_iqs.dy,
                ddiqs: self.f_iqs.ddy(iqs),
                dwr: self.f_wr.dy,
                ddwr: self.f_wr.ddy(wr),
                dvqs: self.f_vqs.dy,
            }),
        };
        let raw = residuals(&self.cfg.motor, op, d);
        let Some(rn) = self.norm.apply(&raw) else {
            // Only a non-finite internal state gets here (the inputs were checked).
            self.recover();
            return;
        };
        self.out.residuals = rn;
        self.update_gate();
        self.update_lamps(rn);
        if self.out.sensor_fault.any() {
            self.matched_lamps = None;
        } else if self.matched_lamps != Some(self.out.lamps) {
            // Matching only when the lamps change.
            self.out.diagnosis = match_signature(self.out.lamps, self.signatures());
            self.matched_lamps = Some(self.out.lamps);
        }
        // Negative sequence: ten times a second is plenty for a 2 Hz filter.
        if self.report_countdown == 0 {
            self.report_countdown = self.report_every;
            self.update_negative_sequence(op.wr_rad_s);
        }
        self.report_countdown -= 1;
        self.out.fault_detected = self.out.sensor_fault.any() || self.out.lamps.iter().any(|x| *x);
    }

    /// The block's length in time, from the timestamps of its last sample and of the
    /// previous block's: `None` when on time (within half a sample period of `decimation`
    /// periods), else the elapsed ticks (a gap, a stalled or a backward clock).
    #[inline(always)]
    fn block_timing(&mut self, ticks: u32) -> Option<u32> {
        let prev = self.block_end_ticks.replace(ticks)?;
        let elapsed = ticks.wrapping_sub(prev);
        (elapsed.wrapping_sub(self.block_ticks_lo) > self.block_ticks_span).then_some(elapsed)
    }

    /// Keeps the frame's estimator as it stands at the end of a block (only the one in
    /// use changes from sample to sample).
    #[inline(always)]
    fn snapshot_frame(&mut self) {
        match self.cfg.angle_source {
            AngleSource::ZeroCrossing => self.snap_zc = self.zc,
            AngleSource::Pll => self.snap_pll = self.pll,
            AngleSource::RotorFluxCurrentModel => self.snap_rfo = self.rfo,
        }
    }

    /// Advances the frame's estimators over `missing_s` seconds without samples and puts
    /// the frame's sin/cos on the new angle.
    fn skip_estimators(&mut self, missing_s: f32) {
        self.rfo.skip(missing_s);
        self.pll.skip(missing_s);
        self.zc.skip(missing_s);
        match self.cfg.angle_source {
            AngleSource::Pll => self.sc = SinCos::from_angle(self.pll.theta_pll()),
            AngleSource::RotorFluxCurrentModel => self.sc = SinCos::from_angle(self.rfo.theta()),
            AngleSource::ZeroCrossing => {}
        }
    }

    /// A block whose timestamps are off: the block is left out of the filters; a gap up to
    /// `max_bridged_gap_s` is bridged by advancing the frame's estimators over the missing
    /// time; anything else (a longer gap, a stalled, repeated or backward clock) restarts
    /// them and the settling time.
    #[cold]
    #[inline(never)]
    fn timing_event(&mut self, elapsed_ticks: u32) {
        self.acc = [0.0; 5];
        self.acc_n = 0;
        let t = &mut self.out.timing;
        if elapsed_ticks > self.block_ticks && elapsed_ticks <= self.max_gap_ticks {
            // Roll the frame back to the end of the last block and advance it over the whole
            // block's real time: the samples after the gap were transformed in a frame behind
            // by the gap's angle, and the rotor-flux model took their currents in it (left
            // in, its flux would need a rotor time constant to recover, and the residuals
            // moved by 0.08 after a 10 ms gap). The block's samples are lost; at most one
            // block (2.5 ms at 10 kHz) besides the gap.
            t.gaps_bridged = t.gaps_bridged.saturating_add(1);
            match self.cfg.angle_source {
                AngleSource::ZeroCrossing => self.zc = self.snap_zc,
                AngleSource::Pll => self.pll = self.snap_pll,
                AngleSource::RotorFluxCurrentModel => self.rfo = self.snap_rfo,
            }
            self.skip_estimators(elapsed_ticks as f32 / self.cfg.tick_hz);
        } else {
            t.timing_faults = t.timing_faults.saturating_add(1);
            self.settle_left = self.settle_blocks;
            self.restart_estimators(true);
        }
    }

    /// Restarts after a non-finite internal state: the d-q filters, every estimator and the
    /// settling time, as at power-up (the commissioning and the calibration are kept).
    #[cold]
    #[inline(never)]
    fn recover(&mut self) {
        let t = &mut self.out.timing;
        t.recoveries = t.recoveries.saturating_add(1);
        for f in [
            &mut self.f_iqs,
            &mut self.f_ids,
            &mut self.f_vqs,
            &mut self.f_wr,
            &mut self.f_nd,
            &mut self.f_nq,
        ] {
            f.reset();
        }
        self.f_vds.y = 0.0;
        self.acc = [0.0; 5];
        self.acc_n = 0;
        self.settle_left = self.settle_blocks;
        self.restart_estimators(true);
    }

    /// Ends the block: resynchronises the frame's sin/cos with the estimator's angle, feeds
    /// the block means to the d-q filters and returns the block's mean I_qs.
    #[inline(always)]
    fn filter_block(&mut self, wr: f32) -> f32 {
        match self.cfg.angle_source {
            AngleSource::Pll => self.sc = SinCos::from_angle(self.pll.theta_pll()),
            AngleSource::RotorFluxCurrentModel => self.sc = SinCos::from_angle(self.rfo.theta()),
            AngleSource::ZeroCrossing => self.out.zero_crossing_locked = Some(self.zc.locked()),
        }
        let k = 1.0 / f32::from(self.acc_n.max(1));
        let a = self.acc;
        self.acc = [0.0; 5];
        self.acc_n = 0;
        let (ids, iqs, vqs) = (a[ACC_ID] * k, a[ACC_IQ] * k, a[ACC_VQ] * k);
        self.f_iqs.update(iqs);
        self.f_ids.update(ids);
        self.f_vqs.update(vqs);
        self.f_wr.update(wr);
        self.f_nd.update(a[ACC_ND] * k);
        self.f_nq.update(a[ACC_NQ] * k);
        self.out.frame_omega_rad_s = match self.cfg.angle_source {
            AngleSource::ZeroCrossing => self.zc.omega_rad_s(),
            AngleSource::Pll => self.pll.omega_rad_s(),
            AngleSource::RotorFluxCurrentModel => self.rfo.omega_rad_s(),
        };
        iqs
    }

    /// Squared voltage magnitude (frame independent), V_ds (in the frame `sc` of this block's last
    /// sample) and the sum checks on that sample (3-wire machine: ia + ib + ic = 0); ages
    /// the sensor-fault hold and the settling time.
    #[inline(always)]
    fn check_sums(&mut self, s: &Sample, sc: SinCos) {
        let vab = clarke(s.v_abc);
        self.vmag2
            .update(vab.alpha * vab.alpha + vab.beta * vab.beta);
        self.out.vds = self.f_vds.update(vab.alpha * sc.cos + vab.beta * sc.sin);
        let l = self.cfg.limits;
        let i = s.i_abc;
        self.isum.update((i.a + i.b + i.c).abs());
        self.imax
            .update(crate::maxf(crate::maxf(i.a.abs(), i.b.abs()), i.c.abs()));
        let i_bad = self.isum.y > l.current_sum_frac * self.imax.y + 1e-3 * l.i_max;
        let mut v_bad = false;
        if l.voltage_sum_frac > 0.0 {
            let v = s.v_abc;
            self.vsum.update((v.a + v.b + v.c).abs());
            self.vmax
                .update(crate::maxf(crate::maxf(v.a.abs(), v.b.abs()), v.c.abs()));
            v_bad = self.vsum.y > l.voltage_sum_frac * self.vmax.y + 1e-3 * l.v_max;
        }
        if i_bad | v_bad {
            self.flag([i_bad, v_bad, false]);
        }
        let was_flagged = self.out.sensor_fault.any();
        for h in self.sensor_hold.iter_mut() {
            *h = h.saturating_sub(1);
        }
        self.out.sensor_fault = self.held_sensor_flags();
        if was_flagged && !self.out.sensor_fault.any() {
            self.out.diagnosis = Diagnosis::default();
        }
        self.settle_left = self.settle_left.saturating_sub(1);
    }

    /// The sensor faults still within their hold time.
    #[inline(always)]
    fn held_sensor_flags(&self) -> SensorFlags {
        SensorFlags {
            current: self.sensor_hold[0] > 0,
            voltage: self.sensor_hold[1] > 0,
            speed: self.sensor_hold[2] > 0,
        }
    }

    /// Quasi-steady-state gate on the filtered derivatives (`steady_gate_per_s`).
    #[inline(always)]
    fn update_gate(&mut self) {
        let g = self.cfg.steady_gate_per_s;
        if g > 0.0 {
            let [fi, fv, fw] = self.gate_floor;
            let fast = self.f_iqs.dy.abs() > g * (self.f_iqs.y.abs() + fi)
                || self.f_ids.dy.abs() > g * (self.f_ids.y.abs() + fi)
                || self.f_vqs.dy.abs() > g * (self.f_vqs.y.abs() + fv)
                || self.f_wr.dy.abs() > g * (self.f_wr.y.abs() + fw);
            if fast {
                self.gate_left = self.gate_blocks.max(1);
            } else {
                self.gate_left = self.gate_left.saturating_sub(1);
            }
        }
        if self.gate_left == 0 {
            self.gate_closed_for = 0;
        } else {
            self.gate_closed_for = self.gate_closed_for.saturating_add(1);
        }
        self.out.quasi_steady =
            self.gate_left == 0 || self.gate_closed_for > self.gate_timeout_blocks;
    }

    /// Commissioning (learning the healthy statistics) or the lamp logic, on the normalised
    /// residuals `rn`, while the motor runs settled and quasi-steady.
    #[inline(always)]
    fn update_lamps(&mut self, rn: [f32; 4]) {
        let running =
            self.settle_left == 0 && self.vmag2.y > self.v_run_min2 && !self.out.sensor_fault.any();
        if self.learner.is_active() {
            // Learning on evaluated blocks, or the learned calibration awaiting storage.
            if running && self.out.quasi_steady && self.learner.is_learning() {
                if let Some(cal) = self.learner.learn(rn) {
                    self.lamps.set_calibration(Some(cal));
                }
            }
            self.refresh_commissioning_state();
            self.out.lamps = [false; 4];
        } else if running && self.out.quasi_steady {
            self.out.lamps = self.lamps.update(rn);
        }
        self.out.evaluating = running && self.out.quasi_steady && !self.learner.is_active();
    }

    /// The negative-sequence result with the faulty-phase correction at the present slip
    /// (electrical rotor speed `wr`).
    #[inline(always)]
    fn update_negative_sequence(&mut self, wr: f32) {
        let we = self.out.frame_omega_rad_s;
        let slip = if we.abs() > 1.0 { 1.0 - wr / we } else { 0.0 };
        let corr = asymmetry_correction_rad(&self.cfg.motor, we.abs().max(1.0), slip);
        self.out.unbalance = sequence_result(
            (self.f_ids.y, self.f_iqs.y),
            (self.f_nd.y, self.f_nq.y),
            corr,
            self.cfg.unbalance_min_ratio,
        );
    }
}

#[cfg(test)]
mod tests;
