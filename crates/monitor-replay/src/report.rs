//! What a replay reports ([`DiagnoseReport`]): the timeline, the negative-sequence
//! analysis, the verdict, built by [`Replay::finish`].

use super::isolation::{self, FaultCandidate, IsolationReport, SensorPhaseReport};
use super::verdict::{findings, glance, FindingReport};
use super::{serialize_angle_source, CommissioningReport, Replay, UnbalanceBaseline};
use monitor_core::{AngleSource, CommissioningState, Fault, MonitorOutput, Phase};
use monitor_io::log::quality::DataQuality;
use monitor_io::log::Channels;
use serde::{Serialize, Serializer};

pub use super::verdict::{Rule, Verdict};

/// What the monitor is doing at a timeline point, as the panel would show it.
#[derive(Debug, Clone, PartialEq)]
pub enum MonitorState {
    /// Learning the healthy residuals; the fraction done.
    Commissioning(f32),
    /// The operating point is changing: the lamps hold.
    Transient,
    /// Settling after start (lamps not yet evaluated).
    Starting,
    /// Evaluating, no lamp lit.
    Healthy,
    /// Lamps lit: the candidates with their probabilities.
    Fault(Vec<(Fault, f32)>),
    /// The load or the voltage has left the commissioned range and no fault is named (the
    /// amber state): lamps may light, the FAULT lamp stays off; the note says where the
    /// operating point went ([`crate::Replay::operating_point_moved`]).
    Moved(String),
}

impl MonitorState {
    /// The state of a monitor output.
    pub fn of(o: &MonitorOutput) -> Self {
        match o.commissioning {
            CommissioningState::Learning(x) => MonitorState::Commissioning(x),
            _ if !o.quasi_steady => MonitorState::Transient,
            _ if !o.evaluating => MonitorState::Starting,
            _ if o.top().is_none() => MonitorState::Healthy,
            _ => MonitorState::Fault(MonitorState::signature(o)),
        }
    }

    /// The signature matching's candidates of `o` (probability above zero), most probable
    /// first.
    pub fn signature(o: &MonitorOutput) -> Vec<(Fault, f32)> {
        let mut c: Vec<(Fault, f32)> = Fault::ALL
            .iter()
            .zip(o.diagnosis.probabilities)
            .filter(|(_, p)| *p > 0.0)
            .map(|(f, p)| (*f, p))
            .collect();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        c
    }
}

impl Replay {
    /// The monitor's state at the replay's output `out` as the panel shows it, the one rule
    /// of the HMI, the demo and `diagnose`'s timeline: [`MonitorState::of`], except that
    /// where the load or the voltage has left the commissioned range
    /// ([`Replay::operating_point_moved`]) and neither the isolation nor a sensor check
    /// names a fault, an evaluated output (healthy or lamps lit) is the amber
    /// [`MonitorState::Moved`] with the note: to the paper's model a load change is a Bl
    /// change, so lamps lit there are not a fault (the friction class `b/bl` is not named
    /// as one).
    pub fn state(&self, out: &MonitorOutput) -> MonitorState {
        self.state_given(out, MonitorState::of(out), None)
    }

    /// [`Replay::state`] from the output's own state `state` ([`MonitorState::of`]) and,
    /// when the caller has it, the isolation's report now (else asked for only where the
    /// operating point has moved).
    fn state_given(
        &self,
        out: &MonitorOutput,
        state: MonitorState,
        isolation: Option<&IsolationReport>,
    ) -> MonitorState {
        let evaluated = matches!(state, MonitorState::Healthy | MonitorState::Fault(_));
        if !evaluated || out.sensor_fault.any() {
            return state;
        }
        let note = match self.operating_point_moved(out) {
            Some(note) => note,
            // With the load an unknown input, lamps lit for a load that moved inside the
            // commissioned range are the amber state too (`LoadModel::Unknown`).
            None if matches!(state, MonitorState::Fault(_))
                && self.isolation.load_explains_lamps() =>
            {
                LOAD_MOVED_NOTE.to_string()
            }
            // Lamps that lit while the load had moved are still releasing (they go out
            // after a second inside their bands): amber until they do, unless the isolation
            // names a fault meanwhile.
            None if matches!(state, MonitorState::Fault(_)) && self.lamps_since_moved => {
                LOAD_BACK_NOTE.to_string()
            }
            None => return state,
        };
        let named = match isolation {
            Some(r) => r.named,
            None => self.isolation_now().0.named,
        };
        if matches!(named, Some(isolation::IsolationName::Fault(_))) {
            state
        } else {
            MonitorState::Moved(note)
        }
    }

    /// What the panel shows at the replay's output `out`: the state ([`Replay::state`]),
    /// the FAULT lamp (off in the amber state) and, where the lamps are evaluated, the
    /// isolation's conclusion (asked for once).
    pub fn panel(&self, out: &MonitorOutput) -> Panel {
        let own = MonitorState::of(out);
        let evaluated = matches!(own, MonitorState::Healthy | MonitorState::Fault(_));
        let isolation = evaluated.then(|| self.isolation_now());
        let state = self.state_given(out, own, isolation.as_ref().map(|(r, _)| r));
        // Outside the evaluated points (a transient: the lamps hold) the isolation is
        // asked once here where the rule or the load's note needs it.
        let asked = (isolation.is_none() && (out.fault_detected || self.lamps_since_moved))
            .then(|| self.isolation_now());
        let report = isolation.as_ref().or(asked.as_ref());
        // Lamps held through the transient after a load move are the load's, not a fault,
        // unless the isolation names one.
        let held_for_load = self.lamps_since_moved
            && !matches!(
                report.and_then(|(r, _)| r.named),
                Some(isolation::IsolationName::Fault(_))
            );
        // The decision table (`monitor_core::verdict`), as the verdict and the board's
        // lamp read it: the FAULT lamp is lit for a named fault at even odds or better only.
        let moved = matches!(state, MonitorState::Moved(_)) || held_for_load;
        let call = glance(out, report, moved).decide().verdict;
        Panel {
            fault_lamp: call == Verdict::Fault && !moved,
            call,
            isolation,
            state,
        }
    }
}

/// The amber state's note where the lamps lit for a load that moved inside the commissioned
/// range, with the load an unknown input (`LoadModel::Unknown`).
pub const LOAD_MOVED_NOTE: &str =
    "load moved inside the commissioned range; the stator-voltage equations fit (the torque residuals read it as Bl)";

/// The amber state's note while lamps that lit for a load move go out after the load came
/// back into the commissioned range.
pub const LOAD_BACK_NOTE: &str =
    "the load came back; the lamps that lit while it had moved are going out";

/// One point of the diagnosis timeline.
#[derive(Debug, Clone, Serialize)]
pub struct TimelinePoint {
    /// Time [s].
    pub t_s: f64,
    /// Normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// Lamps r1..r4.
    pub lamps: [bool; 4],
    /// Most probable fault, if any (JSON: its name).
    pub top: Option<Fault>,
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
    /// Beside a lit r2..r4 lamp: the operating point has left the commissioned range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_note: Option<String>,
    /// What the panel shows ([`Replay::panel`]; not in the JSON, whose keys above carry
    /// it).
    #[serde(skip)]
    pub panel: Panel,
}

/// What the panel shows at an output ([`Replay::panel`]): the HMI, the demo's and
/// `diagnose`'s timelines.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The state ([`Replay::state`]).
    pub state: MonitorState,
    /// The FAULT lamp: the decision table's FAULT ([`Panel::call`]), off in the amber
    /// state.
    pub fault_lamp: bool,
    /// The decision table's verdict at this output (`monitor_core::verdict::Glance`, the
    /// board's rule).
    pub call: Verdict,
    /// What the isolation concluded where the lamps are evaluated (the report and the
    /// candidates listed, [`Replay::isolation_now`]), else `None`.
    pub isolation: Option<(IsolationReport, Vec<FaultCandidate>)>,
}

/// Result of the negative-sequence analysis (JSON key `unbalance`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct UnbalanceReport {
    /// |I2|/|I1|.
    pub negative_sequence_ratio: f32,
    /// The winding's faulty phase (JSON "a", "b", "c"), or null.
    pub suspect_phase: Option<Phase>,
    /// The probability that the winding has a short in `suspect_phase` (that there is a
    /// short, and in that phase), 0..1; 0 without a phase. A phase is named when it is
    /// more probable than no short; a FAULT needs
    /// [`super::WINDING_FAULT_PROBABILITY`]. How it is computed and calibrated:
    /// `docs/isolation.md`, "The phase's probability".
    pub phase_confidence: f32,
    /// The probabilities of no short and of a short in each phase.
    pub phase_probabilities: super::PhaseProbabilities,
    /// Why no phase is judged although the currents are unbalanced, or null: no healthy
    /// baseline, and the winding part is within a healthy machine's own asymmetry
    /// (`monitor_core::sequence::INHERENT_ASYMMETRY_RATIO`).
    pub phase_not_judged: Option<String>,
    /// arg(I2w/I1) [deg]: the winding's part (the supply's part taken out).
    pub angle_deg: f32,
    /// |I2w|/|I1|: the winding's part of the negative sequence.
    pub winding_ratio: f32,
    /// |V2/Z2|/|I1|: the part the supply's voltage unbalance drives (0 without voltages).
    pub supply_ratio: f32,
    /// |V2|/|V1| (null without voltage columns).
    pub voltage_negative_sequence_ratio: Option<f32>,
    /// The reference angle arg Z1 (the power-factor angle, shorted turns) used [deg].
    pub correction_deg: f32,
    /// Its uncertainty [deg] (it widens the phase's confidence).
    pub correction_uncertainty_deg: f32,
    /// Where the reference angle comes from (null when nothing was judged).
    pub operating_point: Option<super::OperatingPointSource>,
    /// The slip the reference angle was taken at, where one was used.
    pub slip: Option<f32>,
    /// The least change of the winding's negative sequence (fraction of |I1|) that names
    /// a phase at [`super::WINDING_FAULT_PROBABILITY`] (on its sector's centre, with the
    /// judged spread and reference angle); 0 when none does.
    pub least_change: f32,
    /// Where the reference ran at another operating point than the judged stretch: a
    /// sentence saying so and how much the least change was widened for it; else null.
    pub least_change_widened: Option<String>,
    /// The spread the change is judged with (each component, fraction of |I1|): the
    /// healthy reference's, the judged stretch's own and, at another operating point,
    /// what the load moves.
    pub spread: f32,
    /// What the change was judged against (null when nothing was judged).
    pub judged_against: Option<super::Against>,
    /// How many healthy runs `--baseline` gave (0: none).
    pub baseline_runs: u32,
    /// Their RMS distance from their mean (`|I2/I1|` units), null for fewer than two.
    pub baseline_spread: Option<f32>,
    /// Index into `segments` of the one judged (the largest change), null without one.
    pub judged_segment: Option<usize>,
    /// Index into `segments` of the stretch it was judged against, when judged within
    /// the log; else null.
    pub reference_segment: Option<usize>,
    /// The log's steady stretches of negative sequence, in time order.
    pub segments: Vec<super::SequenceSegment>,
    /// One phase's current sensor with a gain error, from the zero sequence of the three
    /// measured currents (zero for a star without neutral, whatever the machine does), or
    /// null; its part of the negative sequence is taken out before a winding is blamed.
    pub current_sensor_phase: Option<SensorPhaseReport>,
    /// The same for the voltage sensors (phase voltages against the star point), or null.
    pub voltage_sensor_phase: Option<SensorPhaseReport>,
    /// What was measured, before the baseline is taken out (sensor-corrected): `I2/I1` and
    /// `V2/I1` (re, im); a healthy log's are the `--baseline` of a later one.
    pub measured: UnbalanceBaseline,
    /// The healthy negative sequence the winding is judged against ([`BaselineSource`]),
    /// or null (none: the supply's part alone is taken out).
    pub baseline: Option<BaselineSource>,
    /// How many turns are shorted in the named phase, with its interval and where it comes
    /// from (`basis`: `physics`, or `calibration` where one was given); null without a
    /// named phase ([`super::winding::level`]).
    pub shorted_turns: Option<super::ShortedTurns>,
    /// The model's estimate, also where a calibration gave `shorted_turns`; null without a
    /// named phase.
    pub shorted_turns_physics: Option<super::ShortedTurns>,
}

impl UnbalanceReport {
    /// Whether the winding's finding carries a FAULT: a phase named at a probability of
    /// at least [`super::WINDING_FAULT_PROBABILITY`].
    pub fn names_a_short(&self) -> bool {
        self.suspect_phase.is_some() && self.phase_confidence >= super::WINDING_FAULT_PROBABILITY
    }
}

/// Where the healthy negative sequence the winding is judged against comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BaselineSource {
    /// Learned in the commissioning window, used while |I1| is within
    /// [`super::BASELINE_I1_TOLERANCE`] of its value there.
    Commissioning,
    /// The healthy log given with `--baseline`.
    File,
}

/// A fault the lamps named (the top of the signature matching while a lamp was lit), with
/// the first time it was named [s]. JSON: the pair `[fault, t_s]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// The fault.
    pub fault: Fault,
    /// When it was first named [s since the log's first row].
    pub t_s: f64,
}

impl Serialize for Detection {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.fault, self.t_s).serialize(s)
    }
}

/// What `diagnose` reports (the JSON keys of `docs/design.md`, plus `verdict`, `data_quality` and
/// `commissioning`).
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseReport {
    /// The one verdict (`fault`, `watching`, `healthy`, `could_not_judge`): the decision
    /// table over `findings` ([`super::verdict`]).
    pub verdict: Verdict,
    /// The verdict's line as `diagnose` prints it after `verdict: `.
    pub verdict_line: String,
    /// The row of the decision table that decided (`named`, `data_untrusted`, `file_misfit`,
    /// `watching`, `unexplained`, `out_of_range`, `healthy`, `nothing_judged`).
    pub verdict_rule: Rule,
    /// The finding the verdict rests on (null for healthy and for nothing judged).
    pub verdict_finding: Option<FindingReport>,
    /// Every analysis' finding: residuals, winding, rotor, operating point, data quality,
    /// parameter fit.
    pub findings: Vec<FindingReport>,
    /// What was judged, against what (`residuals against commissioning`, ...).
    pub judged: Vec<String>,
    /// What could not be judged, and why.
    pub not_judged: Vec<String>,
    /// Why the verdict is not a FAULT or healthy (empty for those): the deciding finding,
    /// then what could not be judged.
    pub verdict_withheld_because: Vec<String>,
    /// Final lamps `{"r1":bool,..}`.
    pub lamps: std::collections::BTreeMap<String, bool>,
    /// Final fault candidates, most probable first, with their estimated size: from the
    /// isolation ([`IsolationReport`]) when a fault was detected; an impossible sensor
    /// reading names its sensor outright (size null).
    pub candidates: Vec<FaultCandidate>,
    /// What the isolation concluded: the fault named, its size, the groups that cannot
    /// be separated, and one sentence.
    pub isolation: IsolationReport,
    /// The paper's matching of the final lamps against the fault signature matrix (Table
    /// 1 in voltage orientation), most probable first: the lamps' own candidates.
    pub signature_candidates: Vec<FaultCandidate>,
    /// First time a lamp lit or a sensor fault was seen [s], or null.
    pub first_detection_s: Option<f64>,
    /// Negative-sequence analysis of the currents.
    pub unbalance: UnbalanceReport,
    /// The rotor: broken bars from the current's sidebands (`super::rotor`).
    pub rotor: super::RotorReport,
    /// Faults ever named while the lamps were lit, with the time first named.
    pub detections: Vec<Detection>,
    /// Analyses skipped for lack of a column, with the reason.
    pub skipped: Vec<String>,
    /// Angle source used (JSON: its command-line name, [`super::angle_source_name`]).
    #[serde(serialize_with = "serialize_angle_source")]
    pub angle_source: AngleSource,
    /// Commissioning window asked for, if any [s].
    pub commission: Option<(f64, f64)>,
    /// What commissioning did (state, window used, range covered).
    pub commissioning: CommissioningReport,
    /// What the data-quality stage found and did.
    pub data_quality: DataQuality,
    /// Rows replayed.
    pub rows: u64,
    /// Largest |normalised residual| while evaluating, r1..r4.
    pub max_abs_residual: [f32; 4],
    /// Timeline (one point per `timeline_step_s`).
    pub timeline: Vec<TimelinePoint>,
}

/// The analyses a log with `channels` cannot feed, with the column they need (the report's
/// `skipped`).
fn skipped_analyses(channels: Channels) -> Vec<String> {
    let mut skipped = Vec::new();
    if !channels.voltages {
        skipped.push(
            "residuals r1..r4 and fault signatures: need the voltages va_V, vb_V, vc_V (Vqs)"
                .to_string(),
        );
    } else if !(channels.speed || channels.encoder) {
        skipped.push(
            "residuals r1..r4 and fault signatures: need the speed (wm_rad_s or enc_count)"
                .to_string(),
        );
    }
    skipped
}

/// The final lamps' matching against the signature matrix: the faults with a probability,
/// most probable first (the report's `signature_candidates`).
fn signature_candidates(out: &MonitorOutput) -> Vec<FaultCandidate> {
    let mut candidates: Vec<FaultCandidate> = Fault::ALL
        .iter()
        .zip(out.diagnosis.probabilities)
        .filter(|(_, p)| *p > 0.0)
        .map(|(f, p)| FaultCandidate {
            fault: *f,
            probability: p,
            change: None,
            phase: None,
        })
        .collect();
    candidates.sort_by(|a, b| b.probability.total_cmp(&a.probability));
    candidates
}

/// Outside the commissioned range at the end (`note`: where the point moved), a deviation no
/// single fault explains is the new operating point's, said calmly (the verdict withholds a
/// judgement).
fn note_moved_point(isolation: &mut IsolationReport, note: &str) {
    if isolation.state == monitor_core::IsolationState::Unknown {
        isolation.verdict = format!(
            "Not judged as a fault: the operating point moved outside the commissioned range ({note}), where the healthy baseline does not hold; the deviation there ({:.0} standard deviations) fits no single fault, as a new load would not. Commission over this load to judge it.",
            isolation.deviation_sigma
        );
    }
}

/// The final lamps, `{"r1": bool, ..}`.
fn final_lamps(out: &MonitorOutput) -> std::collections::BTreeMap<String, bool> {
    (0..4)
        .map(|k| {
            (
                format!("r{}", k + 1),
                out.lamps.get(k).copied().unwrap_or(false),
            )
        })
        .collect()
}

impl Replay {
    /// The isolation's report at the end, with the candidates the report lists (the lamps'
    /// own for a sensor's impossible reading): the moved point's sentence, one phase's
    /// sensor from the zero sequence.
    fn final_isolation(
        &self,
        out: &MonitorOutput,
        unbalance: &UnbalanceReport,
        detected: bool,
        signature_candidates: &[FaultCandidate],
    ) -> (IsolationReport, Vec<FaultCandidate>) {
        let (mut isolation, mut isolated) = self.isolation.report(detected);
        if let Some(note) = self.commission.moved_note(out) {
            note_moved_point(&mut isolation, &note);
        }
        isolation::refine_single_phase(
            &mut isolation,
            &mut isolated,
            unbalance.current_sensor_phase.as_ref(),
            unbalance.voltage_sensor_phase.as_ref(),
        );
        if out.sensor_fault.any() {
            (isolation, signature_candidates.to_vec())
        } else {
            (isolation, isolated)
        }
    }

    /// Ends the replay and builds the report (`data_quality` left at its default for the
    /// caller to fill).
    pub fn finish(mut self) -> DiagnoseReport {
        self.isolation.flush();
        let out = self.output();
        self.close_sequences(&out);
        let skipped = skipped_analyses(self.channels);
        let unbalance = self.unbalance_report();
        let signature_candidates = signature_candidates(&out);
        let detected = self.detected();
        let (isolation, candidates) =
            self.final_isolation(&out, &unbalance, detected, &signature_candidates);
        let lamps = final_lamps(&out);
        let rotor = super::rotor::rotor_report(self.seq_front.rotor(), &self.params);
        let found = self.findings(
            &findings::ResidualInputs {
                out: &out,
                isolation: &isolation,
                candidates: &candidates,
                detected,
                skipped: &skipped,
            },
            &unbalance,
            &rotor,
        );
        let mut report = DiagnoseReport {
            verdict: Verdict::CouldNotJudge,
            verdict_line: String::new(),
            verdict_rule: Rule::NothingJudged,
            verdict_finding: None,
            findings: found,
            judged: Vec::new(),
            not_judged: Vec::new(),
            verdict_withheld_because: Vec::new(),
            lamps,
            candidates,
            isolation,
            signature_candidates,
            first_detection_s: self.first_detection,
            unbalance,
            rotor,
            detections: self.detections,
            skipped,
            angle_source: self.opts.angle_source,
            commission: self.opts.commission,
            commissioning: self.commission.report(self.k_sigma),
            data_quality: DataQuality::default(),
            rows: self.rows,
            max_abs_residual: self.max_abs,
            timeline: self.timeline,
        };
        report.conclude();
        report
    }

    /// Closes the sequence analysis' last window (the front's, then the book's, with the
    /// monitor's speed in `out`).
    fn close_sequences(&mut self, out: &MonitorOutput) {
        if self.seq_front.finish() {
            self.book.take(&mut self.seq_front);
            self.book
                .close(self.monitor.as_ref().map(|_| out.operating.wr_rad_s));
        }
    }
}

/// The timeline point of an output at `t` of `replay`, with what the panel shows
/// ([`Replay::panel`]).
pub(super) fn timeline_point(
    replay: &Replay,
    t: f64,
    out: &MonitorOutput,
    range_note: Option<String>,
) -> TimelinePoint {
    let top = out.top();
    TimelinePoint {
        t_s: t,
        residuals: out.residuals,
        lamps: out.lamps,
        top: top.map(|(f, _)| f),
        top_probability: top.map(|(_, p)| p).unwrap_or(0.0),
        speed_rad_s: out.speed_rad_s,
        evaluating: out.evaluating,
        commissioning: matches!(out.commissioning, CommissioningState::Learning(_)),
        quasi_steady: out.quasi_steady,
        negative_sequence_ratio: out.unbalance.negative_sequence_ratio,
        range_note,
        panel: replay.panel(out),
    }
}
