//! The fault isolation of a replay: the core's [`Isolator`] fed from the monitor's
//! outputs, its baseline learned over the commissioning window, and what `diagnose`
//! reports about it (JSON `isolation`, the candidates' `change`).
//!
//! The isolator works on a steady operating point: the positive-sequence voltage and current
//! vectors of the replay's sequence analysis (one angle from a PLL on the voltages, so the
//! point does not depend on the monitor's frame, which a speed-sensor or rotor-parameter
//! fault detunes), the PLL's frequency and the monitor's electrical speed (encoder),
//! averaged once the monitor has settled, with no sensor fault, and isolated (or, while
//! commissioning learns, added to the baseline) on the core's schedule
//! ([`monitor_core::isolation::Follower`]: the same code the firmware runs; the firmware
//! feeds it the monitor's own outputs, [`SteadyPoint::from_output`]).

use super::events::IsolationEvent;
use monitor_core::isolation::{Candidate, Follower, Named, Step, DEFAULT_SPREAD};
use monitor_core::sequence::SinglePhaseGain;
use monitor_core::{
    CommissioningState, Fault, Isolation, IsolationState, Isolator, MonitorOutput, Phase,
    SteadyPoint,
};
use serde::{Serialize, Serializer};
use std::fmt;

/// A reported isolation older than this at the log's end says so [s].
pub const STALE_S: f64 = 1.0;

/// A candidate is listed from this probability on.
pub const LIST_FROM: f32 = 0.01;

/// What the isolation names, as the reports say it: one fault, or the friction class
/// (`b/bl`: B and Bl scale the same term of the torque balance and cannot be separated,
/// and to the paper's model a load change is a Bl change). Serialised as its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IsolationName {
    /// One fault (never B or Bl alone: they are the friction class).
    Fault(Fault),
    /// The friction class B/Bl.
    Friction,
}

impl IsolationName {
    /// The name the isolation should give for `fault`: its own, the friction class for B
    /// and Bl.
    pub fn expected(fault: Fault) -> Self {
        match fault {
            Fault::B | Fault::Bl => IsolationName::Friction,
            f => IsolationName::Fault(f),
        }
    }

    /// The name of the core's conclusion.
    pub fn of(named: &Named) -> Self {
        match named {
            Named::Fault(c) => IsolationName::Fault(c.fault),
            Named::Friction { .. } => IsolationName::Friction,
        }
    }

    /// The fault's name ([`Fault::name`]) or `b/bl`.
    pub fn name(self) -> &'static str {
        match self {
            IsolationName::Fault(f) => f.name(),
            IsolationName::Friction => "b/bl",
        }
    }

    /// The name back from its text ([`IsolationName::name`]); `None` for any other text.
    pub fn from_name(s: &str) -> Option<Self> {
        if s == "b/bl" {
            Some(IsolationName::Friction)
        } else {
            Fault::from_name(s).map(IsolationName::Fault)
        }
    }
}

impl fmt::Display for IsolationName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for IsolationName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A name the isolation gave, with the first time it gave it [s]. Serialised as the pair
/// `[name, t_s]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NameGiven {
    /// What was named.
    pub name: IsolationName,
    /// When it was first named [s] (the replay's time, or as the caller shifts it).
    pub t_s: f64,
}

impl Serialize for NameGiven {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.name, self.t_s).serialize(s)
    }
}

/// Serialises an [`IsolationState`] by its report name ([`state_name`]).
pub(crate) fn serialize_state<S: Serializer>(
    state: &IsolationState,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.serialize_str(state_name(*state))
}

/// Follows the monitor's outputs and isolates (the core's [`Follower`] schedule).
pub(super) struct IsolationTracker {
    follower: Option<Follower>,
    first_named: Option<NameGiven>,
    /// Every name given, with the first time it was given [s].
    names: Vec<NameGiven>,
    /// The monitor has evaluated once (settled, voltage present).
    running: bool,
    /// Time of the last isolation and of the last sample [s].
    last_t: f64,
    end_t: f64,
    /// The operating point of the last isolation.
    last_point: SteadyPoint,
    /// A lamp lit while lamps counted.
    lamps_lit: bool,
    /// The operating points kept since a deviation, and their joint isolation.
    evidence: monitor_core::isolation::Evidence,
    /// What is known of the load ([`super::LoadModel`]).
    load: super::LoadModel,
    /// Names and load moves, with times.
    events: super::events::EventLog,
    /// The log's temperature channel (`t_winding_c`), when it has one.
    temperature: super::temperature::TemperatureChannel,
}

/// With the load an unknown input, B and Bl are not candidates (their change is the load's
/// move): their probabilities are set to zero and they go last, so that no list, group or
/// sentence offers them (the others keep their probabilities). Applied after the name is
/// decided ([`IsolationTracker::report`]).
fn without_friction(iso: &mut Isolation) {
    for c in iso.candidates.iter_mut() {
        if matches!(c.fault, Fault::B | Fault::Bl) {
            c.probability = 0.0;
        }
    }
    iso.candidates
        .sort_by(|a, b| b.probability.total_cmp(&a.probability));
}

/// The candidates `diagnose` lists for `iso` when `detected` (most probable first, those
/// from [`LIST_FROM`] on; an unknown fault's three nearest only; none without a deviation).
fn listed_candidates(iso: &Isolation, detected: bool) -> Vec<FaultCandidate> {
    if !detected || iso.state == IsolationState::NoDeviation {
        return Vec::new();
    }
    let listed = if iso.state == IsolationState::Unknown {
        3
    } else {
        iso.candidates.len()
    };
    iso.candidates
        .iter()
        .take(listed)
        .filter(|c| c.probability >= LIST_FROM)
        .map(FaultCandidate::from)
        .collect()
}

/// `n` is the friction class while the load is an unknown input: a load move, not a name
/// ([`super::LoadModel::Unknown`]).
fn load_reading(load: super::LoadModel, n: &Named) -> bool {
    load == super::LoadModel::Unknown && matches!(n, Named::Friction { .. })
}

/// What the report concludes from ([`IsolationTracker::concluded`]).
struct Concluded {
    /// The isolation judged (joint or single, the load's move read as no deviation).
    iso: Isolation,
    /// The joint fit and its number of points, where it is the one judged.
    joint: Option<(Isolation, usize)>,
    /// The friction class was read as the load's move.
    load_moved: bool,
}

/// How far a parameter file's values may be off the machine's (nameplate estimates are
/// 10-30 % off): against the nominal parameters (no commissioning), a change this small or
/// smaller, with every lamp dark, is the file's own error as much as a fault, and is not
/// named; with lamps lit it is no FAULT (the one rule, `monitor_core::isolation::fault_call`).
/// The core's constant, re-exported.
pub use monitor_core::isolation::NOMINAL_UNCERTAINTY;

impl IsolationTracker {
    /// A tracker for the nominal machine (`None`: a machine the isolator rejects, then
    /// nothing is isolated and the report says so), of a log with a temperature column
    /// (`temperature_column`) or without; `load`: what is known of the load.
    pub(super) fn new(
        isolator: Option<Isolator>,
        temperature_column: bool,
        load: super::LoadModel,
    ) -> Self {
        IsolationTracker {
            follower: isolator.map(Follower::new),
            first_named: None,
            names: Vec::new(),
            running: false,
            last_t: 0.0,
            end_t: 0.0,
            last_point: SteadyPoint::default(),
            lamps_lit: false,
            evidence: monitor_core::isolation::Evidence::default(),
            load,
            events: super::events::EventLog::default(),
            temperature: super::temperature::TemperatureChannel::new(temperature_column),
        }
    }

    /// After the monitor's output for the sample at `t` (`dt_s` after the previous one);
    /// `point`: the steady-state vectors at this sample (module docs); `counts`: lamps and
    /// detections count now (the learned thresholds are in force, or none were asked for);
    /// `temperature_c`: the log's temperature reading, if it has the column.
    pub(super) fn after(
        &mut self,
        t: f64,
        dt_s: f64,
        out: &MonitorOutput,
        point: &SteadyPoint,
        counts: bool,
        temperature_c: Option<f64>,
    ) {
        self.end_t = t;
        let Some(follower) = self.follower.as_mut() else {
            return;
        };
        let learning = matches!(out.commissioning, CommissioningState::Learning(_));
        // Running: the monitor evaluates its lamps, or its commissioning has learned a
        // block (it learns on running, quasi-steady blocks only, and does not evaluate
        // meanwhile: a window that opens before the first evaluation would otherwise teach
        // the isolation nothing).
        let learned_blocks =
            matches!(out.commissioning, CommissioningState::Learning(f) if f > 0.0);
        self.running |= out.evaluating || learned_blocks;
        let usable = self.running && !out.sensor_fault.any() && (learning || counts);
        self.lamps_lit |= counts && out.fault_detected;
        let learned = follower.learned();
        if learned {
            // Load moves are measured from the commissioned point, and recorded at every
            // quasi-steady output (the isolation does not run outside the learned range).
            self.events.seed(&follower.isolator().baseline().at);
            if usable && out.quasi_steady {
                self.events.point(t, point);
            }
        }
        self.temperature
            .put_in_force(follower, t, temperature_c, learning);
        // Quasi-steady by the vectors themselves (the monitor's gate follows its own frame,
        // which a sensor fault can detune).
        if let Step::Isolated(result) = follower.observe(point, dt_s as f32, usable, learning) {
            let lag = follower.measured_rise_k().map(|_| follower.probe_lag_k());
            self.temperature.after_isolation(t, &result, lag);
            self.evidence.after(follower, &result);
            if let Some((p, _)) = follower.averaged() {
                self.events.point(t, &p);
            }
            if let Some(n) = self.name_of(&result, learned) {
                self.give_name(t, n);
            }
            self.last_t = t;
            self.last_point = *point;
        }
    }

    /// The name the isolation gives after `result` (`learned`: a learned baseline is in
    /// force): a fault one point cannot name may be named from several (evidence across
    /// operating points). The joint fit's fault goes before the friction class of the last
    /// point (a load that moved is, to the paper's model, a Bl change); against the nominal
    /// parameters with every lamp dark a change within their uncertainty is not named, nor,
    /// with the load unknown, the friction class.
    fn name_of(&self, result: &Isolation, learned: bool) -> Option<Named> {
        let joint = self
            .evidence
            .joint_beside(result)
            .and_then(|(j, _)| j.named());
        joint
            .or(result.named())
            .filter(|n| learned || self.lamps_lit || !within_nominal_uncertainty(n))
            .filter(|n| !load_reading(self.load, n))
    }

    /// Books the name `n` given at `t` [s]: the first name, and each name the first time it
    /// is given (with its event).
    fn give_name(&mut self, t: f64, n: Named) {
        let given = NameGiven {
            name: IsolationName::of(&n),
            t_s: t,
        };
        self.first_named.get_or_insert(given);
        if !self.names.iter().any(|g| g.name == given.name) {
            self.names.push(given);
            let (change, p) = match n {
                Named::Fault(c) => (c.change, c.probability),
                Named::Friction {
                    probability, bl, ..
                } => (bl.change, probability),
            };
            self.events.named(t, given.name, change, p);
        }
    }

    /// Every name the isolation gave so far (a fault or the friction class), each with the
    /// first time it was given [s], in that order.
    pub(super) fn names(&self) -> &[NameGiven] {
        &self.names
    }

    /// The isolation named a fault other than the friction class at some point (a load
    /// change is, to the paper's model, a Bl change: that is left to the lamps and the
    /// commissioned range).
    pub(super) fn named_a_fault(&self) -> bool {
        self.first_named
            .is_some_and(|g| g.name != IsolationName::Friction)
    }

    /// How far the current of the last isolation is from the one the learned baseline was
    /// learned at: `|I| / |I_learned| - 1` (0.3: 30 % more current); `None` without a
    /// learned baseline or its point.
    /// The tracked winding temperature rise [K] when a learned baseline is in force and it
    /// is at least [`REPORTED_RISE_K`] either way.
    pub(super) fn winding_rise_k(&self) -> Option<f32> {
        let f = self.follower.as_ref().filter(|f| f.learned())?;
        let rise = f.isolator().winding_rise_k();
        (rise.abs() >= REPORTED_RISE_K).then_some(rise)
    }

    /// The sentence of a winding that warmed (a tracked rise of at least
    /// [`REPORTED_RISE_K`]) when the isolation finds no deviation from the warm machine.
    fn heating_sentence(&self, state: IsolationState) -> Option<String> {
        let rise = self
            .winding_rise_k()
            .filter(|_| state == IsolationState::NoDeviation)?;
        let withdrawn = self.first_named.map_or(String::new(), |g| {
            format!(
                " ({} was named at {:.2} s while the tracked temperature lagged, and withdrawn.)",
                g.name, g.t_s
            )
        });
        Some(format!(
            "The windings warmed by {rise:.0} K since commissioning (Rs and Rr {} together, copper 0.393 %/K): heating, not a fault; the warm machine's steady-state equations fit{}.{withdrawn}",
            pct(rise * monitor_core::isolation::COPPER_ALPHA_PER_K),
            if self.lamps_lit { "; the lamps lit because their residuals were learned on the cold machine" } else { "" }
        ))
    }

    /// The lamps' detections, and any name given on the way, are explained by the
    /// winding's heating: the last isolation found no deviation from the machine at its
    /// tracked (warmer) temperature, which has risen by at least [`REPORTED_RISE_K`] (a
    /// name given while the tracking lagged a fast warming was withdrawn since).
    pub(super) fn heating_explains_lamps(&self) -> bool {
        self.winding_rise_k().is_some_and(|r| r > 0.0)
            && self
                .concluded()
                .is_some_and(|c| c.iso.state == IsolationState::NoDeviation)
    }

    /// The isolation the report concludes from: the joint fit over the operating points
    /// kept where it names a fault the last point alone does not, else the last point;
    /// with the load an unknown input, a reading of the friction class is the load's move
    /// (state [`IsolationState::NoDeviation`]). `None` before any point was isolated.
    fn concluded(&self) -> Option<Concluded> {
        let single = self.follower.as_ref().and_then(|f| f.last().copied())?;
        let joint = self.evidence.joint_beside(&single).map(|(j, n)| (*j, n));
        let mut iso = joint.map_or(single, |(j, _)| j);
        let load_moved = iso.named().is_some_and(|n| load_reading(self.load, &n));
        if load_moved {
            iso.state = IsolationState::NoDeviation;
        }
        if self.load == super::LoadModel::Unknown {
            without_friction(&mut iso);
        }
        Some(Concluded {
            iso,
            joint,
            load_moved,
        })
    }

    /// The verdict sentence `s` with the evidence it was drawn from, where the joint fit over
    /// the operating points kept (`joint`: its isolation and the number of points) named it.
    fn with_evidence(&self, s: String, joint: Option<(Isolation, usize)>) -> String {
        match joint {
            Some((_, n)) if self.evidence.anchored() => format!(
                "{} (from {n} operating point{} since the change: the stator-voltage equations, which need no load model, and the torque against the load measured just before the change)",
                s.trim_end_matches('.'),
                if n == 1 { "" } else { "s" }
            ),
            Some((_, n)) => format!(
                "{} (from {n} operating points together: the stator-voltage equations only, which need no load model)",
                s.trim_end_matches('.')
            ),
            None => s,
        }
    }

    /// The verdict where the last point reads as the friction class with the load an unknown
    /// input ([`super::LoadModel::Unknown`]): the load moved.
    fn load_moved_sentence(&self) -> String {
        let last = self.events.events().iter().rev().find_map(|e| match e {
            IsolationEvent::LoadMoved { t_s, from_a, to_a } => Some((*t_s, *from_a, *to_a)),
            IsolationEvent::Named { .. } => None,
        });
        let what = last.map_or(String::new(), |(t, a0, a1)| {
            format!(
                " (at {t:.2} s the active current went from {a0:.2} to {a1:.2} A, {})",
                pct(a1 / a0 - 1.0)
            )
        });
        format!(
            "The load moved{what}: an operating-point change, not a fault; the stator-voltage equations, with the load as an unknown input, fit the machine. (A change of the machine's friction B cannot be told from a load change without a load model: for the paper's fixed viscous load, where a Bl change is a fault, give --load viscous.)"
        )
    }

    /// With the load an unknown input ([`super::LoadModel::Unknown`]), the lamps' detections
    /// are the load's move: the last isolation reads the friction class (the load), the
    /// operating points since name no fault, and no fault was ever named.
    pub(super) fn load_explains_lamps(&self) -> bool {
        let last = self.follower.as_ref().and_then(|f| f.last().copied());
        let friction = last
            .and_then(|i| i.named())
            .is_some_and(|n| load_reading(self.load, &n));
        friction && self.evidence.named().is_none() && !self.named_a_fault()
    }

    fn moved_from_learned(&self) -> Option<f32> {
        let f = self.follower.as_ref().filter(|f| f.learned())?;
        let at = f.isolator().baseline().at;
        let (i0, i1) = (
            at.i.d.hypot(at.i.q),
            self.last_point.i.d.hypot(self.last_point.i.q),
        );
        let r = i1 / i0 - 1.0;
        (i0 > 0.0 && r.is_finite()).then_some(r)
    }

    /// The report's sentence on `c` (`in_file_error`: the name within the parameter file's
    /// uncertainty, not given; `detected`: a lamp lit or a sensor fault was seen; `moved`:
    /// the current's change from the learned point).
    fn verdict(
        &self,
        c: &Concluded,
        in_file_error: Option<Named>,
        detected: bool,
        moved: Option<f32>,
    ) -> String {
        let iso = &c.iso;
        if let Some(Named::Fault(c)) = in_file_error {
            format!(
                "The nearest fault, {} {} (p {:.2}), is within the parameter file's own uncertainty (+/-{:.0} %) while every lamp stayed dark: not named. Commission on the healthy machine to judge changes this small.",
                c.fault,
                pct(c.change),
                c.probability,
                100.0 * NOMINAL_UNCERTAINTY
            )
        } else if self.end_t - self.last_t > STALE_S {
            format!(
                "{} (judged at {:.2} s; the operating point was not steady in the last {:.1} s of the log)",
                verdict_sentence(iso, detected, moved).trim_end_matches('.'),
                self.last_t,
                self.end_t - self.last_t
            )
        } else if let Some(warm) = self.heating_sentence(iso.state) {
            warm
        } else if c.load_moved {
            self.load_moved_sentence()
        } else {
            self.with_evidence(verdict_sentence(iso, detected, moved), c.joint)
        }
    }

    /// The report, and the candidates for `diagnose` (most probable first, those from
    /// [`LIST_FROM`] on) when `detected` (a lamp lit or a sensor fault was seen).
    pub(super) fn report(&self, detected: bool) -> (IsolationReport, Vec<FaultCandidate>) {
        let learned = self.follower.as_ref().is_some_and(Follower::learned);
        let Some(concluded) = self.concluded() else {
            let why = if self.follower.is_none() {
                "the parameter file's machine cannot be used by the isolation"
            } else {
                "no settled, quasi-steady operating point with voltage was evaluated"
            };
            return (IsolationReport::not_judged(why, learned), Vec::new());
        };
        let iso = concluded.iso;
        let candidates = listed_candidates(&iso, detected);
        let moved = self.moved_from_learned();
        let in_file_error = iso
            .named()
            .filter(|n| !learned && !self.lamps_lit && within_nominal_uncertainty(n));
        let named = iso.named().filter(|_| in_file_error.is_none());
        let report = IsolationReport {
            state: iso.state,
            named: named.map(|n| IsolationName::of(&n)),
            named_change: named.map(|n| match n {
                Named::Fault(c) => c.change,
                Named::Friction { bl, .. } => bl.change,
            }),
            verdict: self.verdict(&concluded, in_file_error, detected, moved),
            moved_from_learned: moved,
            winding_rise_k: self.winding_rise_k(),
            temperature: self.temperature.report(),
            judged_at_s: self.last_t,
            groups: groups(&iso),
            deviation_sigma: iso.deviation,
            unknown_probability: iso.unknown_probability,
            separation_deg: iso.separation_deg,
            residuals: iso.residuals.to_array(),
            spread: self
                .follower
                .as_ref()
                .map_or(DEFAULT_SPREAD, |f| f.isolator().baseline().spread)
                .to_array(),
            baseline: baseline_name(learned),
            first_named: self.first_named,
            events: self.events.events().to_vec(),
            events_dropped: self.events.dropped(),
            detection_limits: if learned && iso.state == IsolationState::NoDeviation {
                self.detection_limits()
            } else {
                Vec::new()
            },
        };
        (report, candidates)
    }
}

/// A fault candidate (`diagnose --json` key `candidates`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FaultCandidate {
    /// The fault (JSON: its name, [`Fault::name`]).
    pub fault: Fault,
    /// Probability, [0, 1].
    pub probability: f32,
    /// Estimated relative change (0.48 = +48 %); for a sensor its gain error; null where
    /// only the lamps named it (a sensor reading that is impossible).
    pub change: Option<f32>,
    /// The phase of a single-phase sensor fault (JSON `a|b|c`), else null.
    pub phase: Option<Phase>,
}

impl From<&Candidate> for FaultCandidate {
    fn from(c: &Candidate) -> Self {
        FaultCandidate {
            fault: c.fault,
            probability: c.probability,
            change: Some(c.change),
            phase: None,
        }
    }
}

/// One phase's sensor gain error found from the zero sequence
/// ([`monitor_core::sequence::single_phase_gain`]; JSON `unbalance.current_sensor_phase`,
/// `unbalance.voltage_sensor_phase`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SensorPhaseReport {
    /// The phase (JSON `a`, `b` or `c`).
    pub phase: Phase,
    /// The sensor's gain error (0.2: it reads 20 % high).
    pub gain_error: f32,
    /// |3 I0| / |I1|: the zero sequence the error leaves in the measured set.
    pub zero_sequence_ratio: f32,
}

impl From<&SinglePhaseGain> for SensorPhaseReport {
    fn from(g: &SinglePhaseGain) -> Self {
        SensorPhaseReport {
            phase: g.phase,
            gain_error: g.gain_error,
            zero_sequence_ratio: g.zero_sequence_ratio,
        }
    }
}

/// One phase's sensor: the isolation sees a gain error `g` on one of three phases as the
/// positive sequence's `g/3`; where the zero sequence names the phase (`current`,
/// `voltage`: [`SensorPhaseReport`]), the sensor candidates and the named fault get that
/// phase and the sensor's own gain error, and the verdict says so.
pub(super) fn refine_single_phase(
    report: &mut IsolationReport,
    candidates: &mut [FaultCandidate],
    current: Option<&SensorPhaseReport>,
    voltage: Option<&SensorPhaseReport>,
) {
    let of = |fault: Fault| match fault {
        Fault::CurrentSensor => current.map(|g| (g, "current")),
        Fault::VoltageSensor => voltage.map(|g| (g, "voltage")),
        _ => None,
    };
    for c in candidates.iter_mut() {
        if let Some((g, _)) = of(c.fault) {
            c.change = Some(g.gain_error);
            c.phase = Some(g.phase);
        }
    }
    let Some((g, what)) = (match report.named {
        Some(IsolationName::Fault(f)) => of(f),
        _ => None,
    }) else {
        return;
    };
    report.named_change = Some(g.gain_error);
    report.verdict = format!(
        "The phase {} {what} sensor's gain changed by {} (the zero sequence of the three readings names it; one phase's error is a third of that on the three-phase vector){}",
        g.phase.name(),
        pct(g.gain_error),
        report
            .verdict
            .find(" (judged at")
            .map_or(".".to_string(), |k| report.verdict[k..].to_string())
    );
}

/// Faults that cannot be separated here, and why (JSON `isolation.groups`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct IsolationGroup {
    /// The faults (JSON: their names).
    pub faults: Vec<Fault>,
    /// Why they cannot be separated.
    pub reason: String,
}

/// What the isolation concluded (`diagnose --json` key `isolation`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct IsolationReport {
    /// The conclusion (JSON `isolated`, `unknown`, `no_deviation` or `not_judged`).
    #[serde(serialize_with = "serialize_state")]
    pub state: IsolationState,
    /// The fault named (probability >= 0.5) or the friction class (`b/bl`), or null.
    pub named: Option<IsolationName>,
    /// The named fault's estimated relative change (for `b/bl`: Bl's), or null.
    pub named_change: Option<f32>,
    /// One sentence.
    pub verdict: String,
    /// Candidates that cannot be separated at the last operating point, with the reason.
    pub groups: Vec<IsolationGroup>,
    /// The change from the baseline in standard deviations.
    pub deviation_sigma: f32,
    /// Probability that no fault of the list explains the change.
    pub unknown_probability: f32,
    /// Angle between the top two candidates' directions [deg].
    pub separation_deg: f32,
    /// The parity residuals `[e_d, e_q, e_T]` minus the baseline.
    pub residuals: [f32; 3],
    /// The healthy spread of each residual (one standard deviation of the baseline in
    /// force): the unit of `deviation_sigma`.
    pub spread: [f32; 3],
    /// `learned in commissioning` or `nominal parameters`.
    pub baseline: IsolationBaseline,
    /// The first name given and when [s] (JSON `[name, t_s]`).
    pub first_named: Option<NameGiven>,
    /// When the reported isolation was made [s] (the last steady operating point).
    pub judged_at_s: f64,
    /// How far the stator current of the reported isolation is from the one the learned
    /// baseline was learned at, `|I| / |I_learned| - 1` (0.3: 30 % more); null without a
    /// learned baseline. Away from the learned point the isolation allows for the
    /// parameter file's error ([`monitor_core::isolation`], "Away from the learned point").
    pub moved_from_learned: Option<f32>,
    /// The winding's temperature rise since commissioning the isolation tracked [K]
    /// (Rs and Rr together, copper 0.393 %/K: [`monitor_core::isolation`], "Heating is not
    /// a fault"); absent (JSON) below [`REPORTED_RISE_K`] or without a learned baseline.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub winding_rise_k: Option<f32>,
    /// What happened, with times: each name the first time it was given (with its size and
    /// probability) and each load move ([`IsolationEvent`]), at most [`super::MAX_EVENTS`].
    pub events: Vec<IsolationEvent>,
    /// How many events came after [`super::MAX_EVENTS`] and are not listed.
    pub events_dropped: usize,
    /// The log's temperature channel (JSON keys `winding_temperature_c`, `measured_rise_k`,
    /// `temperature_channel`, present only for a log with the column).
    #[serde(flatten)]
    pub temperature: super::temperature::TemperatureReport,
    /// Where nothing deviated from a learned baseline: the smallest change of each fault
    /// the isolation would have seen at the commissioned point
    /// ([`monitor_core::Isolator::detection_limit`]), so that "healthy" says how small a
    /// fault it can rule out; absent (JSON) otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub detection_limits: Vec<DetectionLimit>,
}

/// The smallest change of one fault the isolation detects at the commissioned point
/// (`diagnose --json` `isolation.detection_limits`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct DetectionLimit {
    /// The fault (JSON: its name).
    pub fault: Fault,
    /// The smallest relative change seen (0.25: a change of +-25 %; for a sensor, of its
    /// gain).
    pub change: f32,
}

impl IsolationTracker {
    /// Each fault's detection limit at the commissioned point (the friction pair as one
    /// class, `b/bl` by Bl's limit, with the load an unknown input not at all).
    fn detection_limits(&self) -> Vec<DetectionLimit> {
        let Some(f) = self.follower.as_ref() else {
            return Vec::new();
        };
        let iso = f.isolator();
        let at = iso.baseline().at;
        Fault::ALL
            .into_iter()
            .filter(|fault| *fault != Fault::B)
            .filter(|fault| *fault != Fault::Bl || self.load != super::LoadModel::Unknown)
            .filter_map(|fault| {
                iso.detection_limit(&at, fault)
                    .map(|change| DetectionLimit { fault, change })
            })
            .collect()
    }
}

/// Smallest tracked winding temperature change that is reported [K] (5 K: 2 % on Rs and Rr,
/// well above the fit's resolution, below what matters for the insulation).
pub const REPORTED_RISE_K: f32 = 5.0;

impl IsolationReport {
    fn not_judged(why: &str, learned: bool) -> Self {
        IsolationReport {
            state: IsolationState::NotJudged,
            named: None,
            named_change: None,
            verdict: format!("The fault could not be isolated: {why}."),
            groups: Vec::new(),
            deviation_sigma: 0.0,
            unknown_probability: 0.0,
            separation_deg: 0.0,
            residuals: [0.0; 3],
            spread: DEFAULT_SPREAD.to_array(),
            judged_at_s: 0.0,
            moved_from_learned: None,
            winding_rise_k: None,
            temperature: Default::default(),
            baseline: baseline_name(learned),
            first_named: None,
            events: Vec::new(),
            events_dropped: 0,
            detection_limits: Vec::new(),
        }
    }
}

/// The baseline the isolation judges against (`isolation.baseline`, JSON `learned in
/// commissioning` or `nominal parameters`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
pub enum IsolationBaseline {
    /// Learned on the healthy machine while commissioning.
    #[serde(rename = "learned in commissioning")]
    Learned,
    /// The parameter file's nominal machine with the default spreads.
    #[serde(rename = "nominal parameters")]
    Nominal,
}

/// The baseline in force: learned or nominal.
fn baseline_name(learned: bool) -> IsolationBaseline {
    if learned {
        IsolationBaseline::Learned
    } else {
        IsolationBaseline::Nominal
    }
}

/// The report's name of an isolation state.
pub fn state_name(s: IsolationState) -> &'static str {
    match s {
        IsolationState::NotJudged => "not_judged",
        IsolationState::NoDeviation => "no_deviation",
        IsolationState::Isolated => "isolated",
        IsolationState::Unknown => "unknown",
    }
}

/// A size as a signed percentage.
fn pct(x: f32) -> String {
    format!("{:+.0} %", 100.0 * x)
}

/// A current this far from the learned point (relative) is said in the verdict when no
/// fault is named: the widening for the parameter file's error is then why.
const MOVED_SAID_FROM: f32 = 0.05;

/// The one-sentence verdict of the isolation; `moved`: the current's relative distance
/// from the learned point ([`IsolationReport::moved_from_learned`]).
/// A named fault (not the friction class, which a load change moves) whose size is within
/// [`NOMINAL_UNCERTAINTY`] (`monitor_core::isolation::within_nominal_uncertainty`).
fn within_nominal_uncertainty(n: &Named) -> bool {
    matches!(n, Named::Fault(c) if monitor_core::isolation::within_nominal_uncertainty(c.change))
}

/// A current this far (relative) from the commissioned point's is another operating point:
/// an unexplained deviation there is not reported as a possible fault.
pub const MOVED_FAR: f32 = 0.5;

fn verdict_sentence(iso: &Isolation, detected: bool, moved: Option<f32>) -> String {
    let away = match moved {
        Some(m) if m.abs() >= MOVED_SAID_FROM => format!(
            " The current is {} from where the baseline was learned: there the parameter file's error is allowed for, and a fault is named only if it stands out from it (commission at this load to judge here).",
            pct(m)
        ),
        _ => String::new(),
    };
    let top = |n: usize| -> Vec<String> {
        iso.candidates
            .iter()
            .take(n)
            .map(|c| format!("{} {} (p {:.2})", c.fault, pct(c.change), c.probability))
            .collect()
    };
    match (iso.state, iso.named()) {
        (IsolationState::NoDeviation, _) if detected => format!(
            "The lamps lit, but the machine's steady-state equations deviate by only {:.1} standard deviations: no fault can be isolated.",
            iso.deviation
        ),
        (IsolationState::NoDeviation, _) => {
            "The steady-state equations fit the nominal machine: nothing to isolate.".into()
        }
        (IsolationState::NotJudged, _) => "No usable operating point was isolated.".into(),
        // Far from the commissioned point the learned baseline does not hold: the deviation
        // is the operating point's, not evidence of a fault (the verdict says the same).
        (IsolationState::Unknown, _) if moved.is_some_and(|m| m.abs() >= MOVED_FAR) => format!(
            "The operating point moved far from the commissioned one (current {}): the healthy baseline learned there does not hold here, so the deviation ({:.0} standard deviations) is not judged as a fault; the nearest single faults would be {}. Commission at this load to judge it.",
            pct(moved.unwrap_or(0.0)),
            iso.deviation,
            top(3).join(", ")
        ),
        (IsolationState::Unknown, _) => format!(
            "A change of {:.0} standard deviations that no single fault explains (an unknown fault, several faults, or a parameter file that does not fit); nearest: {}.{away}",
            iso.deviation,
            top(3).join(", ")
        ),
        (_, Some(Named::Fault(c))) => format!(
            "{} changed by {} (p {:.2}).",
            fault_phrase(c.fault),
            pct(c.change),
            c.probability
        ),
        (_, Some(Named::Friction { probability, b, bl })) => format!(
            "The friction class b/bl changed by {} (p {:.2}): load friction Bl {}, or the same torque as machine friction B {}; they cannot be separated.",
            pct(bl.change),
            probability,
            pct(bl.change),
            pct(b.change)
        ),
        (_, None) => format!(
            "The change fits more than one fault and none alone: {}.{away}",
            top(3).join(", ")
        ),
    }
}

fn fault_phrase(f: Fault) -> &'static str {
    match f {
        Fault::Rs => "The stator resistance Rs",
        Fault::Rr => "The rotor resistance Rr",
        Fault::Ls => "The stator leakage inductance (Ls)",
        Fault::Lr => "The rotor leakage inductance (Lr)",
        Fault::B => "The machine friction B",
        Fault::Bl => "The load friction Bl",
        Fault::CurrentSensor => "The current sensors' gain",
        Fault::VoltageSensor => "The voltage sensors' gain",
        Fault::SpeedSensor => "The speed sensor's gain",
    }
}

/// The groups of candidates that cannot be separated: the friction class whenever it is
/// among the candidates, and the top two when their probabilities are within a factor 3
/// of each other.
fn groups(iso: &Isolation) -> Vec<IsolationGroup> {
    let mut out = Vec::new();
    if iso.state != IsolationState::Isolated && iso.state != IsolationState::Unknown {
        return out;
    }
    let listed = |f: Fault| {
        iso.candidates
            .iter()
            .any(|c| c.fault == f && c.probability >= LIST_FROM)
    };
    if listed(Fault::B) || listed(Fault::Bl) {
        out.push(IsolationGroup {
            faults: vec![Fault::B, Fault::Bl],
            reason: "both scale the load term (B + Bl) wr of the torque balance: one friction class at every operating point".into(),
        });
    }
    if let [a, b, ..] = &iso.candidates[..] {
        let friction_pair =
            matches!(a.fault, Fault::B | Fault::Bl) && matches!(b.fault, Fault::B | Fault::Bl);
        if !friction_pair && b.probability >= LIST_FROM && b.probability * 3.0 >= a.probability {
            out.push(IsolationGroup {
                faults: vec![a.fault, b.fault],
                reason: pair_reason(a.fault, b.fault, iso.separation_deg),
            });
        }
    }
    out
}

fn pair_reason(a: Fault, b: Fault, sep_deg: f32) -> String {
    let pair = |x: Fault, y: Fault| (a == x && b == y) || (a == y && b == x);
    if pair(Fault::Rr, Fault::SpeedSensor) {
        format!("in steady state the rotor circuit depends on Rr/slip only, so an Rr change and a small speed-sensor gain error change the currents alike (directions {sep_deg:.1} deg apart); only the torque balance with the assumed viscous load, a speed transient, or a load change of 20 % or more (the isolation then fits the operating points together) tells them apart")
    } else if pair(Fault::CurrentSensor, Fault::VoltageSensor) {
        format!("both scale the measured impedance V/I; only the torque balance separates them, and it is weak at light load (directions {sep_deg:.1} deg apart)")
    } else {
        format!("their directions in the residual space are {sep_deg:.1} deg apart at this operating point; a load change of 20 % or more may separate them (the isolation then fits the operating points together)")
    }
}
