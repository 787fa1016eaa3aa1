//! The winding's judgement: each stretch's reading and the healthy reference it is judged
//! against (module docs of [`super`], steps 2, 3 and 5), and the negative-sequence report
//! (`unbalance`) built from the judgement.

use super::level::TurnLevelOptions;
use super::probability::{
    judge_alone, judge_external, judge_within, External, PhaseJudged, PhaseReading,
};
use super::{
    abs, cdiv, mean, measured_of, segment_of, segments, Against, Complex32, HealthyReference,
    OperatingPointSource, PhaseProbabilities, SequenceSegment, CURRENT_MODEL_UNCERTAINTY,
    FULL_LOAD_SLIP_MAX, MAX_SEGMENTS, MEASURED_REFERENCE_UNCERTAINTY_DEG, MIN_SEGMENT_WINDOWS,
    SLIP_MODEL_UNCERTAINTY,
};
use super::{BaselineSource, UnbalanceReport};
use crate::windows::SensorPhaseReport;
use crate::windows::{sensor_phase, SequenceWindow};
use monitor_core::sequence::{
    asymmetry_correction_rad, equivalent_impedance, slip_for_current, SinglePhaseGain,
};
use monitor_core::MotorModel;
use monitor_io::params::ParamFile;

/// What every stretch is judged with: the model, the nominal supply, and whether the
/// speed is measured.
struct Judge {
    m: MotorModel,
    v_nominal: f32,
    speed: bool,
}

impl Judge {
    /// The model's slip at an operating point: from the speed where measured, else where
    /// the model draws `i1` [A, peak] when the file can draw it between no load and
    /// [`FULL_LOAD_SLIP_MAX`]; `None` when neither (with the source it came from).
    fn slip(&self, we: f32, wr: Option<f32>, i1: f32) -> Option<(f32, OperatingPointSource)> {
        if let (true, Some(wr)) = (self.speed, wr) {
            let s = (1.0 - wr / we).clamp(1e-4, 0.5);
            return Some((s, OperatingPointSource::Speed));
        }
        let (lo, hi) = self.current_range(we);
        (i1 >= lo && i1 <= hi).then(|| {
            (
                slip_for_current(&self.m, self.v_nominal, we, i1),
                OperatingPointSource::CurrentMagnitude,
            )
        })
    }

    /// The currents the file can draw between no load and [`FULL_LOAD_SLIP_MAX`], widened
    /// by the model's uncertainty.
    fn current_range(&self, we: f32) -> (f32, f32) {
        let i_at = |s: f32| self.v_nominal / abs(equivalent_impedance(&self.m, we, s));
        (
            (1.0 - CURRENT_MODEL_UNCERTAINTY) * i_at(1e-4),
            (1.0 + CURRENT_MODEL_UNCERTAINTY) * i_at(FULL_LOAD_SLIP_MAX),
        )
    }

    /// The reference angle at a stretch's operating point: `(arg Z1, uncertainty)`
    /// [rad], the slip where one is used, and where it came from (module docs, step 5).
    fn reference_angle(
        &self,
        seg: &SequenceSegment,
    ) -> (f32, f32, Option<f32>, OperatingPointSource) {
        let (m, we) = (&self.m, seg.we);
        let corr = |s: f32| asymmetry_correction_rad(m, we, s);
        if let Some(v1) = seg.v1 {
            let u = MEASURED_REFERENCE_UNCERTAINTY_DEG.to_radians();
            return (v1.im.atan2(v1.re), u, None, OperatingPointSource::Voltages);
        }
        let spread = |s: f32, lo: f32, hi: f32| {
            let c = corr(s);
            (c, (corr(lo) - c).abs().max((corr(hi) - c).abs()))
        };
        match self.slip(we, seg.wr, seg.i1_peak_a) {
            Some((s, OperatingPointSource::Speed)) => {
                let k = 1.0 + SLIP_MODEL_UNCERTAINTY;
                let (c, u) = spread(s, s / k, s * k);
                (c, u, Some(s), OperatingPointSource::Speed)
            }
            Some((s, source)) => {
                let i1 = seg.i1_peak_a;
                let s_of = |i: f32| slip_for_current(m, self.v_nominal, we, i);
                let (c, u) = spread(
                    s,
                    s_of((1.0 - CURRENT_MODEL_UNCERTAINTY) * i1),
                    s_of((1.0 + CURRENT_MODEL_UNCERTAINTY) * i1),
                );
                (c, u, Some(s), source)
            }
            None => {
                let (c0, c1) = (corr(1e-4), corr(FULL_LOAD_SLIP_MAX));
                let (mid, half) = (0.5 * (c0 + c1), 0.5 * (c0 - c1).abs());
                (mid, half, None, OperatingPointSource::AssumedRange)
            }
        }
    }

    /// The model's `arg Z1` at an operating point where its slip is known.
    fn z1_angle(&self, we: f32, wr: Option<f32>, i1: f32) -> Option<f32> {
        self.slip(we, wr, i1)
            .map(|(s, _)| asymmetry_correction_rad(&self.m, we, s))
    }

    /// One stretch's reading (module docs, step 2): the sensors' own negative sequence
    /// taken out; with one voltage sensor wrong the voltages cannot say how much of `I2`
    /// the supply drives, and the currents alone judge.
    fn reading(&self, index: usize, seg: &SequenceSegment) -> PhaseReading {
        let op = self.reference_angle(seg);
        let slip = op.2.unwrap_or(0.0).max(1e-4);
        let (gi, gv) = sensor_phases(seg);
        let [p, n, z] = seg.pnz;
        let r = match gi {
            Some(g) => seg.r + (cdiv(g.corrected_negative(p, n, z), p) - cdiv(n, p)),
            None => seg.r,
        };
        let v2 = seg.v2.filter(|_| gv.is_none());
        let (w, supply) = winding_part(r, v2, &self.m, seg.we, slip);
        PhaseReading {
            index,
            w,
            supply,
            voltages: v2.is_some(),
            i1: seg.i1_peak_a,
            wr: seg.wr,
            we: seg.we,
            sem: seg.sem,
            op,
            z1_angle: self.z1_angle(seg.we, seg.wr, seg.i1_peak_a),
            z_ratio: self.z_ratio(seg.we, op.2),
        }
    }

    /// The model's `|Z1/Z2|` at slip `s` (`None`: the largest of no load and
    /// [`FULL_LOAD_SLIP_MAX`]).
    fn z_ratio(&self, we: f32, s: Option<f32>) -> f32 {
        let at = |s: f32| {
            let z1 = abs(equivalent_impedance(&self.m, we, s));
            let z2 = abs(equivalent_impedance(&self.m, we, 2.0 - s));
            if z2 > 0.0 {
                z1 / z2
            } else {
                1.0
            }
        };
        match s {
            Some(s) => at(s),
            None => at(1e-4).max(at(FULL_LOAD_SLIP_MAX)),
        }
    }
}

/// The winding part `I2/I1 - V2/(Z2 I1)` of a reading (module docs, step 2), and the
/// supply's part `|V2/Z2|/|I1|` (0 without voltages).
fn winding_part(
    i2: Complex32,
    v2: Option<Complex32>,
    m: &MotorModel,
    we: f32,
    s: f32,
) -> (Complex32, f32) {
    match v2 {
        Some(v2) => {
            let z2 = equivalent_impedance(m, we, 2.0 - s);
            let supply = cdiv(v2, z2);
            ((i2 - supply), abs(supply))
        }
        None => (i2, 0.0),
    }
}

/// A healthy reference's `I2/I1` and `V2/I1`, and what [`External`] needs of it.
struct Outside {
    r: Complex32,
    v2: Option<Complex32>,
    ext: External,
}

/// The negative-sequence report (module docs) of the least-squares `windows` of a log of
/// `params`' machine (`speed`: the log has a speed), judged against `baseline` (the healthy
/// runs given, else the commissioning window's), with the turns counted by `level`.
pub(crate) fn unbalance_report(
    windows: &[SequenceWindow],
    params: &ParamFile,
    speed: bool,
    baseline: Option<HealthyReference>,
    level: TurnLevelOptions,
) -> UnbalanceReport {
    let segs = segments(windows);
    let judge = Judge {
        m: params.motor.model(),
        v_nominal: params.supply.v_phase_peak() as f32,
        speed,
    };
    let we0 = std::f32::consts::TAU * params.supply.f_hz as f32;
    let outside = baseline
        .map(|f| from_runs(&judge, &f, we0))
        .or_else(|| learned_reference(&judge, windows, we0));
    let judged = judge_stretches(&judge, &segs, outside.as_ref());
    let mut report = report_without_judgement(windows, &segs, outside.as_ref(), baseline);
    match &judged {
        None => report.phase_not_judged = Some(no_stretch_reason(params.supply.f_hz)),
        Some(j) => {
            fill_judgement(&mut report, j, &segs);
            let poles = params.motor.poles.max(2) as f32 / 2.0;
            if let Some(o) = &outside {
                report.least_change_widened = super::reasons::widened(j, &o.ext, poles);
            }
        }
    }
    report.segments = listed_segments(segs, judged.map(|j| j.index));
    report.shorted_turns_physics =
        super::level::physics(&report, &judge.m, we0, judge.v_nominal, &level);
    report.shorted_turns = match level.calibration {
        Some(cal) => super::level::calibrated(&report, &cal),
        None => report.shorted_turns_physics,
    };
    if report.suspect_phase.is_none() {
        report.shorted_turns_reach =
            super::level::reach(&report, &judge.m, we0, judge.v_nominal, &level);
    }
    report
}

/// The report's keys that do not depend on the judgement (`outside`: the healthy
/// reference from outside the log, if any; `file`: the healthy runs given).
fn report_without_judgement(
    windows: &[SequenceWindow],
    segs: &[SequenceSegment],
    outside: Option<&Outside>,
    file: Option<HealthyReference>,
) -> UnbalanceReport {
    let (measured, whole_ratio) = measured_of(windows, segs);
    // The sensors at the log's end (as the isolation's candidates are).
    let (gi, gv) = segs.last().map_or((None, None), sensor_phases);
    UnbalanceReport {
        negative_sequence_ratio: whole_ratio,
        suspect_phase: None,
        phase_confidence: 0.0,
        phase_probabilities: PhaseProbabilities::default(),
        phase_not_judged: None,
        angle_deg: 0.0,
        winding_ratio: 0.0,
        supply_ratio: 0.0,
        voltage_negative_sequence_ratio: measured_voltage_ratio(windows),
        correction_deg: 0.0,
        correction_uncertainty_deg: 0.0,
        operating_point: None,
        slip: None,
        least_change: 0.0,
        least_change_widened: None,
        spread: 0.0,
        judged_against: None,
        baseline_runs: file.map_or(0, |f| f.runs),
        baseline_spread: file.and_then(|f| f.measured_spread()),
        judged_segment: None,
        reference_segment: None,
        segments: Vec::new(),
        ratio_over_time: windows
            .iter()
            .filter(|w| w.complete)
            .map(|w| {
                let r = abs(cdiv(w.i.negative(), w.i.positive()));
                (0.5 * (w.from_s + w.to_s), r)
            })
            .collect(),
        current_sensor_phase: gi.as_ref().map(SensorPhaseReport::from),
        voltage_sensor_phase: gv.as_ref().map(SensorPhaseReport::from),
        measured,
        baseline: outside.map(|o| match o.ext.against {
            Against::Commissioning => BaselineSource::Commissioning,
            _ => BaselineSource::File,
        }),
        shorted_turns: None,
        shorted_turns_physics: None,
        shorted_turns_reach: None,
    }
}

/// The stretches judged (module docs, steps 3 and 4): against the reference from outside
/// the log where there is one, else against each other, else one against nothing.
fn judge_stretches(
    judge: &Judge,
    segs: &[SequenceSegment],
    outside: Option<&Outside>,
) -> Option<PhaseJudged> {
    let readings: Vec<PhaseReading> = segs
        .iter()
        .enumerate()
        .map(|(k, seg)| judge.reading(k, seg))
        .collect();
    let angle_at = |rd: &PhaseReading, i1: f32| judge.z1_angle(rd.we, rd.wr, i1);
    match outside {
        Some(o) => {
            let part = |rd: &PhaseReading| {
                let v2 = o.v2.filter(|_| rd.voltages);
                let slip = rd.op.2.unwrap_or(0.0).max(1e-4);
                winding_part(o.r, v2, &judge.m, rd.we, slip)
            };
            judge_external(&readings, &o.ext, &part, &angle_at)
        }
        None => judge_within(&readings, &angle_at).or_else(|| readings.first().map(judge_alone)),
    }
}

/// The `--baseline` runs as a reference: their mean, the spread of a change from it.
fn from_runs(judge: &Judge, f: &HealthyReference, we0: f32) -> Outside {
    Outside {
        r: super::of_pair(f.mean.i2_over_i1),
        v2: f.mean.v2_over_i1.map(super::of_pair),
        ext: External {
            i1: f.mean.i1_peak_a,
            wr: f.mean.wr_rad_s,
            z1_angle: judge.z1_angle(we0, f.mean.wr_rad_s, f.mean.i1_peak_a),
            runs: f.runs,
            sum_sq_dev: f.sum_sq_dev,
            against: Against::HealthyRuns,
        },
    }
}

/// The commissioning window's reference: its steady windows' (one run's worth: the
/// default spread), where there are enough of them.
fn learned_reference(judge: &Judge, windows: &[SequenceWindow], we0: f32) -> Option<Outside> {
    let learned: Vec<&SequenceWindow> = windows.iter().filter(|w| w.steady && w.learning).collect();
    (learned.len() >= MIN_SEGMENT_WINDOWS).then(|| {
        let s = segment_of(&learned);
        Outside {
            r: s.r,
            v2: s.v2,
            ext: External {
                i1: s.i1_peak_a,
                wr: s.wr,
                z1_angle: judge.z1_angle(we0, s.wr, s.i1_peak_a),
                runs: 1,
                sum_sq_dev: 0.0,
                against: Against::Commissioning,
            },
        }
    })
}

/// Why the phase is not judged when no stretch is steady long enough (`f_hz`: the supply
/// frequency).
fn no_stretch_reason(f_hz: f64) -> super::PhaseNotJudged {
    super::PhaseNotJudged::NoSteadyStretch {
        windows: MIN_SEGMENT_WINDOWS,
        seconds: MIN_SEGMENT_WINDOWS as f64 * crate::windows::WINDOW_PERIODS / f_hz,
    }
}

/// The judged stretch's keys of the report.
fn fill_judgement(report: &mut UnbalanceReport, j: &PhaseJudged, segs: &[SequenceSegment]) {
    let p = j.posterior;
    let named = p.named();
    report.suspect_phase = named.map(|n| n.0);
    report.phase_confidence = named.map_or(0.0, |n| n.1);
    report.phase_probabilities = PhaseProbabilities {
        no_short: p.no_short,
        a: p.phases[0],
        b: p.phases[1],
        c: p.phases[2],
    };
    let op = j.reading.op;
    report.angle_deg = super::arg_deg(j.change);
    report.winding_ratio = abs(j.change);
    report.supply_ratio = j.supply_ratio;
    report.correction_deg = op.0.to_degrees();
    report.correction_uncertainty_deg = op.1.to_degrees();
    report.operating_point = Some(op.3);
    report.slip = op.2;
    let least = j.least_change_at(j.sigma);
    report.least_change = least.unwrap_or(0.0);
    report.spread = j.sigma;
    report.judged_against = Some(j.against);
    report.phase_not_judged = segs.get(j.index).and_then(|s| {
        let reference = j.reference.and_then(|k| segs.get(k));
        super::reasons::not_named(j, s, reference, least)
    });
    report.judged_segment = Some(j.index.min(MAX_SEGMENTS - 1));
    report.reference_segment = j.reference.filter(|&k| k < MAX_SEGMENTS);
}

/// One phase's current sensor and voltage sensor with a gain error in a stretch (the zero
/// sequence, `monitor_core::sequence::single_phase_gain`).
fn sensor_phases(seg: &SequenceSegment) -> (Option<SinglePhaseGain>, Option<SinglePhaseGain>) {
    let [p, n, z] = seg.pnz;
    (
        sensor_phase(p, n, z),
        seg.v_pnz.and_then(|[p, n, z]| sensor_phase(p, n, z)),
    )
}

/// The stretches the report lists: the first [`MAX_SEGMENTS`], the judged one last among
/// them when it lies beyond (then at index `MAX_SEGMENTS - 1`).
fn listed_segments(mut segs: Vec<SequenceSegment>, judged: Option<usize>) -> Vec<SequenceSegment> {
    if segs.len() > MAX_SEGMENTS {
        let keep = judged
            .filter(|&k| k >= MAX_SEGMENTS - 1)
            .map(|k| segs[k].clone());
        segs.truncate(MAX_SEGMENTS);
        if let Some(k) = keep {
            segs[MAX_SEGMENTS - 1] = k;
        }
    }
    segs
}

/// |V2|/|V1| of the log's steady windows (null without voltages).
fn measured_voltage_ratio(windows: &[SequenceWindow]) -> Option<f32> {
    let vs: Vec<_> = windows
        .iter()
        .filter(|w| w.steady)
        .map(|w| w.v)
        .collect::<Option<Vec<_>>>()?;
    if vs.is_empty() {
        return None;
    }
    let p = mean(vs.iter().map(|v| v.positive()));
    let n = mean(vs.iter().map(|v| v.negative()));
    (abs(p) > 0.0).then(|| abs(n) / abs(p))
}
