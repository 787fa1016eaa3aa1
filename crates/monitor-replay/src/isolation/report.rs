//! What `diagnose` reports of the isolation (JSON `isolation`, the candidates).

use super::said::{IsolationSaid, NotIsolatedWhy, SensorKind};
use super::{serialize_state, IsolationName, IsolationTracker, NameGiven, LIST_FROM};
use crate::events::IsolationEvent;
use crate::windows::SensorPhaseReport;
use monitor_core::isolation::{Candidate, DEFAULT_SPREAD};
use monitor_core::{Fault, Isolation, IsolationState, Phase};
use serde::Serialize;

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

/// One phase's sensor: the isolation sees a gain error `g` on one of three phases as the
/// positive sequence's `g/3`; where the zero sequence names the phase (`current`,
/// `voltage`: [`SensorPhaseReport`]), the sensor candidates and the named fault get that
/// phase and the sensor's own gain error, and the verdict says so.
pub(crate) fn refine_single_phase(
    report: &mut IsolationReport,
    candidates: &mut [FaultCandidate],
    current: Option<&SensorPhaseReport>,
    voltage: Option<&SensorPhaseReport>,
) {
    let of = |fault: Fault| match fault {
        Fault::CurrentSensor => current.map(|g| (g, SensorKind::Current)),
        Fault::VoltageSensor => voltage.map(|g| (g, SensorKind::Voltage)),
        _ => None,
    };
    for c in candidates.iter_mut() {
        if let Some((g, _)) = of(c.fault) {
            c.change = Some(g.gain_error);
            c.phase = Some(g.phase);
        }
    }
    let Some((g, sensor)) = (match report.named {
        Some(IsolationName::Fault(f)) => of(f),
        _ => None,
    }) else {
        return;
    };
    report.named_change = Some(g.gain_error);
    let stale = match &report.said {
        IsolationSaid::Stale { stale, .. } => Some(*stale),
        _ => None,
    };
    report.said = IsolationSaid::SensorPhase {
        sensor,
        phase: g.phase,
        gain_error: g.gain_error,
        stale,
    };
}

/// Faults that cannot be separated here, and why (JSON `isolation.groups`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct IsolationGroup {
    /// The faults (JSON: their names).
    pub faults: Vec<Fault>,
    /// Why they cannot be separated (JSON `why`; the door spells it as `reason`).
    #[serde(rename = "why")]
    pub reason: GroupWhy,
}

/// Why a group of candidates cannot be separated (JSON `{"kind": ..}`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum GroupWhy {
    /// B and Bl scale the same load term of the torque balance.
    FrictionClass,
    /// Rr and a speed-sensor gain error change the steady-state currents alike.
    RotorResistanceAndSpeedSensor {
        /// The directions' angle [deg].
        separation_deg: f32,
    },
    /// The current and voltage sensors both scale the measured impedance.
    CurrentAndVoltageSensors {
        /// The directions' angle [deg].
        separation_deg: f32,
    },
    /// Their directions in the residual space are this close at this point.
    CloseDirections {
        /// The directions' angle [deg].
        separation_deg: f32,
    },
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
    /// The probability that the named fault is the fault (for `b/bl`: the class's), or
    /// null: a calibrated probability (docs/isolation.md, "How often a name is right").
    pub named_probability: Option<f32>,
    /// What it concluded, with its numbers (JSON `said`; the door spells it as `verdict`).
    #[serde(rename = "said")]
    pub said: IsolationSaid,
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
    /// a fault"); without a learned baseline, the rise above the parameter file's
    /// temperature that explains the change where heating does
    /// ([`IsolationReport::heating_explains`]); absent (JSON) below [`REPORTED_RISE_K`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub winding_rise_k: Option<f32>,
    /// The windings' heating explains the change from the baseline: against commissioning,
    /// the warm machine's steady-state equations fit (a tracked rise of [`REPORTED_RISE_K`]
    /// or more); against the parameter file, heating (Rs and Rr together) is the most
    /// probable explanation, more than any fault or the unknown fault, within the healthy
    /// scatter.
    pub heating_explains: bool,
    /// What happened, with times: each name the first time it was given (with its size and
    /// probability) and each load move ([`IsolationEvent`]), at most [`crate::events::MAX_EVENTS`].
    pub events: Vec<IsolationEvent>,
    /// How many events came after [`crate::events::MAX_EVENTS`] and are not listed.
    pub events_dropped: usize,
    /// The log's temperature channel (JSON keys `winding_temperature_c`, `measured_rise_k`,
    /// `temperature_channel`, present only for a log with the column).
    #[serde(flatten)]
    pub temperature: crate::temperature::TemperatureReport,
    /// Rs and Rr read apart at the isolation's steady points (absent in JSON where no
    /// point could carry it: no voltage, no speed, too little slip).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resistances: Option<super::resistances::ResistanceReading>,
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
    pub(super) fn detection_limits(&self) -> Vec<DetectionLimit> {
        let Some(f) = self.follower.as_ref() else {
            return Vec::new();
        };
        let iso = f.isolator();
        let at = iso.baseline().at;
        Fault::ALL
            .into_iter()
            .filter(|fault| *fault != Fault::B)
            .filter(|fault| *fault != Fault::Bl || self.load != crate::options::LoadModel::Unknown)
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
    pub(super) fn not_judged(why: NotIsolatedWhy, learned: bool) -> Self {
        IsolationReport {
            state: IsolationState::NotJudged,
            named: None,
            named_change: None,
            named_probability: None,
            said: IsolationSaid::NotIsolated { why },
            groups: Vec::new(),
            deviation_sigma: 0.0,
            unknown_probability: 0.0,
            separation_deg: 0.0,
            residuals: [0.0; 3],
            spread: DEFAULT_SPREAD.to_array(),
            judged_at_s: 0.0,
            moved_from_learned: None,
            winding_rise_k: None,
            heating_explains: false,
            temperature: Default::default(),
            baseline: baseline_name(learned),
            first_named: None,
            events: Vec::new(),
            events_dropped: 0,
            resistances: None,
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
pub(super) fn baseline_name(learned: bool) -> IsolationBaseline {
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

/// The groups of candidates that cannot be separated: the friction class whenever it is
/// among the candidates, and the top two when their probabilities are within a factor 3
/// of each other.
pub(super) fn groups(iso: &Isolation) -> Vec<IsolationGroup> {
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
            reason: GroupWhy::FrictionClass,
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

fn pair_reason(a: Fault, b: Fault, separation_deg: f32) -> GroupWhy {
    let pair = |x: Fault, y: Fault| (a == x && b == y) || (a == y && b == x);
    if pair(Fault::Rr, Fault::SpeedSensor) {
        GroupWhy::RotorResistanceAndSpeedSensor { separation_deg }
    } else if pair(Fault::CurrentSensor, Fault::VoltageSensor) {
        GroupWhy::CurrentAndVoltageSensors { separation_deg }
    } else {
        GroupWhy::CloseDirections { separation_deg }
    }
}
