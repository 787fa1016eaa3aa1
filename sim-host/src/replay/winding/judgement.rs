//! The winding's judgement: each steady segment's change from the healthy reference,
//! the phase it names, and the negative-sequence report (`unbalance`) built from them.

use super::{
    abs, cdiv, mean, measured_of, segment_of, segments, sub, HealthyReference,
    OperatingPointSource, SequenceSegment, C, CURRENT_MODEL_UNCERTAINTY, DEFAULT_SPREAD_CURRENTS,
    DEFAULT_SPREAD_VOLTAGES, FULL_LOAD_SLIP_MAX, LEAST_CHANGE_SPREADS, MAX_SEGMENTS,
    MEASURED_REFERENCE_UNCERTAINTY_DEG, MIN_SEGMENT_WINDOWS, NO_BASELINE_SPREAD,
    NO_BASELINE_SPREAD_VOLTAGES, SLIP_MODEL_UNCERTAINTY,
};
use crate::replay::report::BaselineSource;
use crate::replay::sequences::{sensor_phase, SequenceWindow};
use crate::replay::{Replay, SensorPhaseReport, UnbalanceReport, BASELINE_I1_TOLERANCE};
use monitor_core::sequence::{
    asymmetry_correction_rad, equivalent_impedance, judge_phase, slip_for_current, PhaseJudgement,
    PhaseNotNamed, SinglePhaseGain,
};
use monitor_core::{MotorModel, Phase};

/// The reference angle at a segment's operating point: `(arg Z1, uncertainty)` [rad], the
/// slip where one is used, and where it came from (module docs, step 4).
fn reference_angle(
    seg: &SequenceSegment,
    m: &MotorModel,
    v_peak_nominal: f32,
    speed: bool,
) -> (f32, f32, Option<f32>, OperatingPointSource) {
    let we = seg.we;
    let corr = |s: f32| asymmetry_correction_rad(m, we, s);
    if let Some(v1) = seg.v1 {
        return (
            v1.1.atan2(v1.0),
            MEASURED_REFERENCE_UNCERTAINTY_DEG.to_radians(),
            None,
            OperatingPointSource::Voltages,
        );
    }
    let spread = |s: f32, lo: f32, hi: f32| {
        let c = corr(s);
        (c, (corr(lo) - c).abs().max((corr(hi) - c).abs()))
    };
    if let (true, Some(wr)) = (speed, seg.wr) {
        let s = (1.0 - wr / we).clamp(1e-4, 0.5);
        let (c, u) = spread(
            s,
            s / (1.0 + SLIP_MODEL_UNCERTAINTY),
            s * (1.0 + SLIP_MODEL_UNCERTAINTY),
        );
        return (c, u, Some(s), OperatingPointSource::Speed);
    }
    let i_at = |s: f32| {
        let z = equivalent_impedance(m, we, s);
        v_peak_nominal / abs(z)
    };
    let i1 = seg.i1_peak_a;
    let (i_lo, i_hi) = (
        (1.0 - CURRENT_MODEL_UNCERTAINTY) * i_at(1e-4),
        (1.0 + CURRENT_MODEL_UNCERTAINTY) * i_at(FULL_LOAD_SLIP_MAX),
    );
    if i1 >= i_lo && i1 <= i_hi {
        let s_of = |i: f32| slip_for_current(m, v_peak_nominal, we, i);
        let s = s_of(i1);
        let (c, u) = spread(
            s,
            s_of((1.0 - CURRENT_MODEL_UNCERTAINTY) * i1),
            s_of((1.0 + CURRENT_MODEL_UNCERTAINTY) * i1),
        );
        return (c, u, Some(s), OperatingPointSource::CurrentMagnitude);
    }
    let (c0, c1) = (corr(1e-4), corr(FULL_LOAD_SLIP_MAX));
    (
        0.5 * (c0 + c1),
        0.5 * (c0 - c1).abs(),
        None,
        OperatingPointSource::AssumedRange,
    )
}

/// The winding part `I2/I1 - V2/(Z2 I1)` of a reading (module docs, step 3), and the
/// supply's part `|V2/Z2|/|I1|` (0 without voltages).
fn winding_part(i2: C, v2: Option<C>, m: &MotorModel, we: f32, s: f32) -> (C, f32) {
    match v2 {
        Some(v2) => {
            let z2 = equivalent_impedance(m, we, 2.0 - s);
            let supply = cdiv(v2, z2);
            (sub(i2, supply), abs(supply))
        }
        None => (i2, 0.0),
    }
}

/// The healthy reference a segment is judged against (module docs, step 2).
struct Reference {
    r: C,
    v2: Option<C>,
    i1: f32,
    sigma: f32,
    source: Option<BaselineSource>,
}

/// A segment's judgement.
struct Judged {
    index: usize,
    change: C,
    supply_ratio: f32,
    judgement: PhaseJudgement,
    reference: (f32, f32, Option<f32>, OperatingPointSource),
    sigma: f32,
    least_change: f32,
    source: Option<BaselineSource>,
}

/// What every segment is judged with: the model, the nominal supply, whether the speed is
/// measured, and the healthy references.
struct Judge {
    m: MotorModel,
    v_nominal: f32,
    speed: bool,
    file: Option<HealthyReference>,
    learned: Option<Reference>,
    s0: f32,
}

impl Judge {
    /// The healthy reference a segment is judged against (module docs, step 2).
    fn reference_for(&self, seg: &SequenceSegment) -> Reference {
        if let Some(f) = self.file {
            let c = |x: [f32; 2]| (x[0], x[1]);
            return Reference {
                r: c(f.mean.i2_over_i1),
                v2: f.mean.v2_over_i1.map(c),
                i1: f.mean.i1_peak_a,
                sigma: f.sigma(self.s0),
                source: Some(BaselineSource::File),
            };
        }
        match &self.learned {
            Some(l) if (seg.i1_peak_a - l.i1).abs() <= BASELINE_I1_TOLERANCE * l.i1 => Reference {
                r: l.r,
                v2: l.v2,
                i1: l.i1,
                sigma: l.sigma,
                source: l.source,
            },
            _ => Reference {
                r: (0.0, 0.0),
                v2: None,
                i1: seg.i1_peak_a,
                sigma: if seg.v2.is_some() {
                    NO_BASELINE_SPREAD_VOLTAGES
                } else {
                    NO_BASELINE_SPREAD
                },
                source: None,
            },
        }
    }

    /// One segment's change from its reference, judged (module docs, steps 3 and 4).
    fn judge(&self, index: usize, seg: &SequenceSegment) -> Judged {
        let m = &self.m;
        let reference = self.reference_for(seg);
        let op = reference_angle(seg, m, self.v_nominal, self.speed);
        let s = op.2.unwrap_or(0.0).max(1e-4);
        // A sensor's own negative sequence is not the winding's (nor the supply's); with one
        // voltage sensor wrong the voltages cannot say how much of I2 the supply drives, and
        // the currents alone judge.
        let (gi, gv) = sensor_phases(seg);
        let [p, n, z] = seg.pnz;
        let r = match gi {
            Some(g) => {
                let d = sub(cdiv(g.corrected_negative(p, n, z), p), cdiv(n, p));
                (seg.r.0 + d.0, seg.r.1 + d.1)
            }
            None => seg.r,
        };
        let v2 = seg.v2.filter(|_| gv.is_none());
        let (w, supply_ratio) = winding_part(r, v2, m, seg.we, s);
        let ref_v2 = reference.v2.filter(|_| v2.is_some());
        let (w_ref, _) = winding_part(reference.r, ref_v2, m, seg.we, s);
        let change = sub(w, w_ref);
        // Another operating point than the reference's, without the voltages to take the
        // supply's part out: I2/I1 moves with I1.
        let moved = if v2.is_none() && seg.i1_peak_a > 0.0 {
            abs(w_ref) * (1.0 - reference.i1 / seg.i1_peak_a).abs()
        } else {
            0.0
        };
        let healthy = reference.sigma.hypot(moved);
        let sigma = healthy.hypot(seg.sem);
        let least_change = LEAST_CHANGE_SPREADS * healthy;
        Judged {
            index,
            change,
            supply_ratio,
            judgement: judge_phase(change, op.0, op.1, sigma, least_change),
            reference: op,
            sigma,
            least_change,
            source: reference.source,
        }
    }
}

impl Replay {
    /// The negative-sequence report (module docs).
    pub(in crate::replay) fn unbalance_report(&self) -> UnbalanceReport {
        let windows = self.book.windows();
        let segs = segments(windows);
        let (measured, whole_ratio) = measured_of(windows, &segs);
        let s0 = if self.channels.voltages {
            DEFAULT_SPREAD_VOLTAGES
        } else {
            DEFAULT_SPREAD_CURRENTS
        };
        let learned = learned_reference(windows, s0);
        let judge = Judge {
            m: self.params.motor.model(),
            v_nominal: self.params.supply.v_phase_peak() as f32,
            speed: self.monitor.is_some(),
            file: self.opts.unbalance_baseline,
            learned,
            s0,
        };
        let judged: Vec<Judged> = segs
            .iter()
            .enumerate()
            .map(|(k, seg)| judge.judge(k, seg))
            .collect();
        let pick = standing_out(&judged);
        // The sensors at the log's end (as the isolation's candidates are).
        let (gi, gv) = segs.last().map_or((None, None), sensor_phases);
        let file = self.opts.unbalance_baseline;
        let mut report = UnbalanceReport {
            negative_sequence_ratio: whole_ratio,
            suspect_phase: None,
            phase_confidence: 0.0,
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
            spread: 0.0,
            baseline_runs: file.map_or(0, |f| f.runs),
            baseline_spread: file.and_then(|f| f.measured_spread()),
            judged_segment: None,
            segments: Vec::new(),
            current_sensor_phase: gi.as_ref().map(SensorPhaseReport::from),
            voltage_sensor_phase: gv.as_ref().map(SensorPhaseReport::from),
            measured,
            baseline: file.map(|_| BaselineSource::File),
        };
        match pick {
            None => report.phase_not_judged = Some(no_stretch_reason(self.params.supply.f_hz)),
            Some(j) => fill_judgement(&mut report, j, &segs),
        }
        report.segments = listed_segments(segs, pick.map(|j| j.index));
        report
    }
}

/// The commissioning window's reference: its steady windows' (`s0`: the default spread),
/// where there are enough of them.
fn learned_reference(windows: &[SequenceWindow], s0: f32) -> Option<Reference> {
    let learned: Vec<&SequenceWindow> = windows.iter().filter(|w| w.steady && w.learning).collect();
    (learned.len() >= MIN_SEGMENT_WINDOWS).then(|| {
        let s = segment_of(&learned);
        Reference {
            r: s.r,
            v2: s.v2,
            i1: s.i1_peak_a,
            sigma: s0,
            source: Some(BaselineSource::Commissioning),
        }
    })
}

/// The segment whose change stands out most from its spread among those that name a
/// phase, else the one that stands out most (a short segment's own scatter counts).
fn standing_out(judged: &[Judged]) -> Option<&Judged> {
    let z = |j: &Judged| abs(j.change) / j.sigma.max(1e-6);
    let largest = |it: &mut dyn Iterator<Item = &Judged>| {
        it.max_by(|a, b| z(a).total_cmp(&z(b))).map(|j| j.index)
    };
    largest(&mut judged.iter().filter(|j| j.judgement.phase.is_some()))
        .or_else(|| largest(&mut judged.iter()))
        .and_then(|k| judged.get(k))
}

/// Why the phase is not judged when no segment is steady long enough (`f_hz`: the supply
/// frequency).
fn no_stretch_reason(f_hz: f64) -> String {
    format!(
        "cannot judge the phase: no steady stretch of at least {} least-squares windows ({:.2} s): the log is too short or its operating point never settled",
        MIN_SEGMENT_WINDOWS,
        MIN_SEGMENT_WINDOWS as f64 * crate::replay::sequences::WINDOW_PERIODS / f_hz
    )
}

/// The judged segment's keys of the report.
fn fill_judgement(report: &mut UnbalanceReport, j: &Judged, segs: &[SequenceSegment]) {
    report.suspect_phase = j.judgement.phase;
    report.phase_confidence = j.judgement.confidence;
    report.angle_deg = j.change.1.atan2(j.change.0).to_degrees();
    report.winding_ratio = abs(j.change);
    report.supply_ratio = j.supply_ratio;
    report.correction_deg = j.reference.0.to_degrees();
    report.correction_uncertainty_deg = j.reference.1.to_degrees();
    report.operating_point = Some(j.reference.3);
    report.slip = j.reference.2;
    report.least_change = j.least_change;
    report.spread = j.sigma;
    report.baseline = j.source;
    report.phase_not_judged = segs.get(j.index).and_then(|s| not_judged_reason(j, s));
    report.judged_segment = Some(j.index.min(MAX_SEGMENTS - 1));
}

/// One phase's current sensor and voltage sensor with a gain error in a segment (the zero
/// sequence, `monitor_core::sequence::single_phase_gain`).
fn sensor_phases(seg: &SequenceSegment) -> (Option<SinglePhaseGain>, Option<SinglePhaseGain>) {
    let [p, n, z] = seg.pnz;
    (
        sensor_phase(p, n, z),
        seg.v_pnz.and_then(|[p, n, z]| sensor_phase(p, n, z)),
    )
}

/// The segments the report lists: the first [`MAX_SEGMENTS`], the judged one last among
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

/// A change of `I2/I1` below this is no asymmetry to speak of (the noise of 12-bit sensors):
/// no reason is given for naming no phase.
pub const BALANCED_RATIO: f32 = 0.005;

/// Why the judged segment names no phase, in a sentence; `None` when it names one, or when
/// the change is below [`BALANCED_RATIO`] (nothing to judge).
fn not_judged_reason(j: &Judged, seg: &SequenceSegment) -> Option<String> {
    let why = j.judgement.not_named?;
    if why == PhaseNotNamed::BelowLeastChange && abs(j.change) < BALANCED_RATIO {
        return None;
    }
    let at = format!("{:.1}..{:.1} s", seg.from_s, seg.to_s);
    let change = 100.0 * abs(j.change);
    Some(match (why, j.source) {
        (PhaseNotNamed::BelowLeastChange, None) => format!(
            "cannot judge the phase: the negative sequence ({change:.1} % of I1 at {at}) is within what a healthy machine's own asymmetry may reach ({:.0} %) and there is no healthy baseline (give --baseline with healthy logs of this motor, or commission)",
            100.0 * j.least_change
        ),
        (PhaseNotNamed::BelowLeastChange, Some(_)) => format!(
            "no phase: the change of the negative sequence ({change:.1} % of I1 at {at}) is within what healthy runs differ by (least change {:.1} %)",
            100.0 * j.least_change
        ),
        (PhaseNotNamed::NearBorder, _) => {
            let dev = j.judgement.deviation_rad.to_degrees();
            let u = j.judgement.uncertainty_rad.to_degrees();
            let next = neighbour(j);
            format!(
                "cannot judge the phase: the change ({change:.1} % of I1 at {at}) points {:.0} deg from phase {}'s centre, towards phase {}, and its angle is uncertain by {u:.0} deg (reference angle +/-{:.0} deg, {})",
                dev,
                j.judgement.nearest.name(),
                next.name(),
                j.reference.1.to_degrees(),
                j.reference.3.describe()
            )
        }
    })
}

/// The phase on the other side of the nearest sector border.
fn neighbour(j: &Judged) -> Phase {
    let third = std::f32::consts::TAU / 3.0;
    let ang = j.change.1.atan2(j.change.0) - j.reference.0;
    let x = monitor_core::frames::wrap_angle(ang) / third;
    let k = x.round();
    let other = if x > k { k + 1.0 } else { k - 1.0 };
    Phase::from_turns(other as i32)
}
