//! The replay's sequence analysis: a PLL on the voltages (else the currents), the positive,
//! negative and zero sequences of the currents and voltages, one phase's sensor gain error,
//! and the negative-sequence report ([`UnbalanceReport`]).

use super::report::BaselineSource;
use super::{
    Replay, SensorPhaseReport, UnbalanceBaseline, UnbalanceReport, BASELINE_I1_TOLERANCE,
    FILLED_SAMPLES, SENSOR_PHASE_MIN_RATIO,
};
use crate::log::quality::MAX_BRIDGED_GAP_S;
use crate::log::Row;
use monitor_core::frames::{clarke, park, AlphaBeta, SinCos};
use monitor_core::sequence::{
    asymmetry_correction_rad, single_phase_gain, slip_for_current, winding_asymmetry,
    SinglePhaseGain, INHERENT_ASYMMETRY_RATIO,
};
use monitor_core::SteadyPoint as IsolationPoint;
use monitor_core::{Abc, CommissioningState, MonitorOutput};

impl Replay {
    /// The sequence analysis of every log (the monitor's own runs on its frame without the
    /// voltages' negative sequence): a PLL locked to the current vector, the currents' and,
    /// where logged, the voltages' positive and negative sequences on its angle. A row with
    /// a bad current is skipped (the monitor holds such samples out itself); a bad voltage
    /// leaves the voltages' analysis alone.
    pub(super) fn track_sequences(&mut self, row: &Row, t: f64) {
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
    pub(super) fn steady_point(&self, out: &MonitorOutput) -> IsolationPoint {
        let (v, i) = (self.seq_v.positive(), self.seq.positive());
        IsolationPoint {
            i: monitor_core::Dq { d: i.0, q: i.1 },
            v: monitor_core::Dq { d: v.0, q: v.1 },
            we_rad_s: self.pll.omega_rad_s(),
            wr_rad_s: out.operating.wr_rad_s,
        }
    }

    /// The negative-sequence report: the core's one faulty-phase method
    /// ([`monitor_core::sequence::winding_asymmetry`]) with the supply's own unbalance taken
    /// out where voltages are logged. The slip is the monitor's (encoder) where it runs,
    /// else the equivalent circuit's for the measured current magnitude
    /// ([`slip_for_current`]).
    /// The sensor-corrected `I2/I1` and `V2/I1` (module docs of
    /// [`monitor_core::sequence`]), with the sensors found wrong on one phase.
    pub(super) fn unbalance_ratios(
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

    pub(super) fn unbalance_report(&self, out: &MonitorOutput) -> UnbalanceReport {
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
            (Some(b), _) => (Some(b), Some(BaselineSource::File)),
            (None, Some(b)) => (Some(b), Some(BaselineSource::Commissioning)),
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
            1.0 - out.operating.wr_rad_s / we
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
        // Without a healthy baseline nothing tells the winding's part from the machine's own
        // build asymmetry and the sensors' mismatch (nor, without voltages, from the
        // supply's): below a healthy machine's inherent asymmetry the phase is not judged.
        let inherent = base.is_none();
        let min_ratio = if inherent {
            min_ratio.max(INHERENT_ASYMMETRY_RATIO)
        } else {
            min_ratio
        };
        let w = winding_asymmetry(i2, v2, &m, we, slip, min_ratio);
        let phase_not_judged = (inherent && w.suspect_phase.is_none() && w.ratio >= 0.005)
            .then(|| {
                format!(
                    "cannot judge the phase: the winding's part of the negative sequence ({:.1} % of I1) is within a healthy machine's own asymmetry ({:.0} %) and there is no healthy baseline (give --baseline with a healthy log of this motor, or commission)",
                    100.0 * w.ratio,
                    100.0 * INHERENT_ASYMMETRY_RATIO
                )
            });
        UnbalanceReport {
            negative_sequence_ratio: monitor_core::fast_hypot(
                measured.i2_over_i1[0],
                measured.i2_over_i1[1],
            ),
            suspect_phase: w.suspect_phase,
            phase_confidence: w.phase_confidence,
            phase_not_judged,
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
            baseline: base_name,
        }
    }
}
