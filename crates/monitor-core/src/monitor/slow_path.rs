//! The monitor's slow path: everything at the end of a block of `decimation` samples
//! (plausibility, timing, the d-q filters, the residuals, the gate, the lamps or
//! commissioning, the signature matching and the negative sequence), and its cold paths
//! (sensor flags, discarded blocks, gaps, recoveries).

use super::{Monitor, ResidualForm, Sample, SensorFlags};
use crate::frames::{clarke, SinCos};
use crate::residuals::residuals;
use crate::sequence::{
    asymmetry_correction_rad, over_positive, sequence_result, winding_asymmetry,
};
use crate::signature::{match_signature, Diagnosis, Fault, FAULT_COUNT};

/// The gate's ripple rule (`MonitorConfig::steady_gate_per_s`): the gate opens after it
/// has been closed for this many hold times (`gate_hold_s`, 1.5 s by default) while the
/// operating point's slow trend has been steady for [`RIPPLE_TREND_HOLDS`]: longer than a
/// load or supply step's transient keeps it closed, so a persistent closure over a steady
/// trend is a ripple the steady-state model averages over, not a transient.
const RIPPLE_CLOSED_HOLDS: u32 = 3;
/// How long the trend must have been steady for the ripple rule [hold times] (1 s by
/// default): a step's trend moves for about a second (the trend filters' corner, 0.5 Hz).
const RIPPLE_TREND_HOLDS: u32 = 2;

impl Monitor {
    /// Holds the sensor faults in `bad` for a second and names them outright.
    #[cold]
    #[inline(never)]
    pub(super) fn flag(&mut self, bad: SensorFlags) {
        self.revision = self.revision.wrapping_add(1);
        self.sensor_hold.hold(bad, self.derived.hold_blocks);
        self.out.sensor_fault = self.sensor_hold.flags();
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

    /// Discards the current block after an impossible reading and restarts the frame's
    /// estimator if a bad value reached it.
    #[cold]
    #[inline(never)]
    fn discard_block(&mut self) {
        self.sums.clear();
        self.settle_left = self.derived.settle_blocks;
        self.frame.restart(&self.cfg, false);
    }

    // Kept out of line so the per-sample path does not carry its register pressure. The
    // steps are separate functions for reading; each is inlined here.
    #[inline(never)]
    pub(super) fn slow_path(&mut self, s: &Sample, wr_rad_s: f32, sc: SinCos) {
        self.revision = self.revision.wrapping_add(1);
        self.block_end(s, wr_rad_s, sc);
        self.frame.take_snapshot();
    }

    /// Everything at the end of a block (see [`Monitor::slow_path`]).
    #[inline(always)]
    fn block_end(&mut self, s: &Sample, wr_rad_s: f32, sc: SinCos) {
        let off_time = self.block_timing(s.timestamp_ticks);
        // Plausibility of the block: saturation flags, range (NaN and inf fail, see update);
        // a clipped reading holds the block out too, naming no sensor.
        let (bad, clipped) = self.extremes.take_verdict(&self.derived);
        if bad.current | bad.voltage {
            self.flag(bad);
            self.discard_block();
            return;
        }
        if clipped {
            self.discard_block();
            return;
        }
        if let Some(elapsed) = off_time {
            self.timing_event(elapsed);
            return;
        }
        let iqs = self.filter_block(wr_rad_s);
        self.check_sums(s, sc);
        let op = self.filters.operating();
        self.out.operating = op;
        let d = match self.cfg.residual_form {
            ResidualForm::Steady => None,
            ResidualForm::Full => Some(self.filters.derivatives(iqs, wr_rad_s)),
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
            self.report_countdown = self.derived.report_every;
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
        (elapsed.wrapping_sub(self.derived.block_ticks_lo) > self.derived.block_ticks_span)
            .then_some(elapsed)
    }

    /// A block whose timestamps are off: the block is left out of the filters; a gap up to
    /// `max_bridged_gap_s` is bridged by advancing the frame's estimator over the missing
    /// time; anything else (a longer gap, a stalled, repeated or backward clock) restarts
    /// it and the settling time.
    #[cold]
    #[inline(never)]
    fn timing_event(&mut self, elapsed_ticks: u32) {
        self.sums.clear();
        let t = &mut self.out.timing;
        if elapsed_ticks > self.derived.block_ticks && elapsed_ticks <= self.derived.max_gap_ticks {
            // Roll the frame back to the end of the last block and advance it over the whole
            // block's real time: the samples after the gap were transformed in a frame behind
            // by the gap's angle, and the rotor-flux model took their currents in it (left
            // in, its flux would need a rotor time constant to recover, and the residuals
            // moved by 0.08 after a 10 ms gap). The block's samples are lost; at most one
            // block (2.5 ms at 10 kHz) besides the gap.
            t.gaps_bridged = t.gaps_bridged.saturating_add(1);
            self.frame.bridge(elapsed_ticks as f32 / self.cfg.tick_hz);
        } else {
            t.timing_faults = t.timing_faults.saturating_add(1);
            self.settle_left = self.derived.settle_blocks;
            self.frame.restart(&self.cfg, true);
        }
    }

    /// Restarts after a non-finite internal state: the d-q filters, the frame's estimator
    /// and the settling time, as at power-up (the commissioning and the calibration are
    /// kept).
    #[cold]
    #[inline(never)]
    fn recover(&mut self) {
        let t = &mut self.out.timing;
        t.recoveries = t.recoveries.saturating_add(1);
        self.filters.reset();
        self.sums.clear();
        self.settle_left = self.derived.settle_blocks;
        self.frame.restart(&self.cfg, true);
    }

    /// Ends the block: resynchronises the frame's sin/cos with the estimator's angle, feeds
    /// the block means to the d-q filters and returns the block's mean I_qs.
    #[inline(always)]
    fn filter_block(&mut self, wr_rad_s: f32) -> f32 {
        if let Some(locked) = self.frame.resync() {
            self.out.zero_crossing_locked = Some(locked);
        }
        let means = self.sums.take_means();
        self.filters.update(&means, wr_rad_s);
        self.out.frame_omega_rad_s = self.frame.omega_rad_s();
        means.i.q
    }

    /// Squared voltage magnitude (frame independent), V_ds (in the frame `sc` of this
    /// block's last sample) and the sum checks on that sample (3-wire machine:
    /// ia + ib + ic = 0); ages the sensor-fault hold and the settling time.
    #[inline(always)]
    fn check_sums(&mut self, s: &Sample, sc: SinCos) {
        let vab = clarke(s.v_abc);
        self.checks
            .update_vmag2(vab.alpha * vab.alpha + vab.beta * vab.beta);
        self.out.vds = self
            .filters
            .update_vds(vab.alpha * sc.cos + vab.beta * sc.sin);
        let vn = crate::frames::park(vab, sc.negated());
        self.filters.update_voltage_negative(vn);
        let bad = self.checks.sums(s, &self.cfg.limits);
        if bad.current | bad.voltage {
            self.flag(bad);
        }
        let was_flagged = self.out.sensor_fault.any();
        self.sensor_hold.age();
        self.out.sensor_fault = self.sensor_hold.flags();
        if was_flagged && !self.out.sensor_fault.any() {
            self.out.diagnosis = Diagnosis::default();
        }
        self.settle_left = self.settle_left.saturating_sub(1);
    }

    /// Quasi-steady-state gate on the filtered derivatives (`steady_gate_per_s`), with its
    /// timeout and its ripple rule: a closure longer than [`RIPPLE_CLOSED_HOLDS`] holds
    /// while the slow trend has been steady for [`RIPPLE_TREND_HOLDS`] holds is a ripple
    /// (a broken rotor bar's `2 s f` torque ripple, a pulsating load), not a transient.
    #[inline(always)]
    fn update_gate(&mut self) {
        let g = self.cfg.steady_gate_per_s;
        if g > 0.0 {
            if self.filters.changing(g, &self.derived) {
                self.gate_left = self.derived.gate_blocks.max(1);
            } else {
                self.gate_left = self.gate_left.saturating_sub(1);
            }
            if self.filters.trend_changing(g, &self.derived) {
                self.trend_steady_for = 0;
            } else {
                self.trend_steady_for = self.trend_steady_for.saturating_add(1);
            }
        }
        if self.gate_left == 0 {
            self.gate_closed_for = 0;
        } else {
            self.gate_closed_for = self.gate_closed_for.saturating_add(1);
        }
        let hold = self.derived.gate_blocks.max(1);
        let ripple = self.gate_closed_for > RIPPLE_CLOSED_HOLDS.saturating_mul(hold)
            && self.trend_steady_for > RIPPLE_TREND_HOLDS.saturating_mul(hold);
        self.out.quasi_steady = self.gate_left == 0
            || ripple
            || self.gate_closed_for > self.derived.gate_timeout_blocks;
    }

    /// Commissioning (learning the healthy statistics) or the lamp logic, on the normalised
    /// residuals `rn`, while the motor runs settled and quasi-steady.
    #[inline(always)]
    fn update_lamps(&mut self, rn: [f32; 4]) {
        let running = self.settle_left == 0
            && self.checks.vmag2() > self.derived.v_run_min2
            && !self.out.sensor_fault.any();
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
    /// (electrical rotor speed `wr_rad_s`).
    #[inline(always)]
    fn update_negative_sequence(&mut self, wr_rad_s: f32) {
        let we = self.out.frame_omega_rad_s;
        let slip = if we.abs() > 1.0 {
            1.0 - wr_rad_s / we
        } else {
            0.0
        };
        let we = we.abs().max(1.0);
        let corr = asymmetry_correction_rad(&self.cfg.motor, we, slip);
        let f = &self.filters;
        let p = f.positive();
        let mut out = sequence_result(p, f.negative(), corr, self.cfg.unbalance_min_ratio);
        // The phase from the winding's part: the supply's V2/Z2 taken out (module docs of
        // `crate::sequence`).
        let w = winding_asymmetry(
            over_positive(p, f.negative()),
            Some(over_positive(p, f.voltage_negative())),
            &self.cfg.motor,
            we,
            slip,
            self.cfg.unbalance_min_ratio,
        );
        out.suspect_phase = w.suspect_phase;
        out.winding_ratio = w.ratio;
        out.phase_confidence = w.phase_confidence;
        self.out.unbalance = out;
    }
}
