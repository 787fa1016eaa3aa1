//! What the isolation concluded, as a typed value ([`IsolationSaid`], JSON
//! `isolation.said`): the verdict `diagnose` reports ([`IsolationTracker::said`]), with the
//! numbers its sentence is spelled from at the door (`monitor_words`).

use super::{Concluded, IsolationTracker, STALE_S};
use crate::events::IsolationEvent;
use crate::isolation_name::NameGiven;
use crate::range::RangeDeparture;
use monitor_core::isolation::Named;
use monitor_core::{Fault, Isolation, IsolationState, Phase};
use serde::Serialize;

/// A current this far from the learned point (relative) is said in the verdict when no
/// fault is named: the widening for the parameter file's error is then why.
pub const MOVED_SAID_FROM: f32 = 0.05;

/// A current this far (relative) from the commissioned point's is another operating point:
/// an unexplained deviation there is not reported as a possible fault.
pub const MOVED_FAR: f32 = 0.5;

/// One of the nearest faults the isolation lists where it names none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Nearest {
    /// The fault (JSON: its name).
    pub fault: Fault,
    /// Its estimated relative change.
    pub change: f32,
    /// Its probability.
    pub probability: f32,
}

/// The core's conclusion at the operating point judged (JSON `{"kind": ..}`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CoreSaid {
    /// The lamps lit, but the steady-state equations deviate by only `deviation` spreads.
    LitWithoutDeviation {
        /// The deviation [standard deviations].
        deviation: f32,
    },
    /// The steady-state equations fit the nominal machine: nothing to isolate.
    NoDeviation,
    /// No usable operating point was isolated.
    NotJudged,
    /// The operating point moved far ([`MOVED_FAR`]) from the commissioned one: the
    /// deviation is not judged as a fault.
    MovedFar {
        /// The current's relative distance from the learned point.
        moved: f32,
        /// The deviation [standard deviations].
        deviation: f32,
        /// The nearest single faults.
        nearest: Vec<Nearest>,
    },
    /// A change no single fault explains.
    Unknown {
        /// The deviation [standard deviations].
        deviation: f32,
        /// The nearest single faults.
        nearest: Vec<Nearest>,
        /// The current's distance from the learned point, where it is
        /// [`MOVED_SAID_FROM`] or more.
        away: Option<f32>,
    },
    /// One fault, with its size.
    Fault {
        /// The fault.
        fault: Fault,
        /// Its estimated relative change.
        change: f32,
        /// Its probability.
        probability: f32,
    },
    /// The friction class B/Bl.
    Friction {
        /// The class's probability.
        probability: f32,
        /// B's change for the same torque.
        b_change: f32,
        /// Bl's change.
        bl_change: f32,
    },
    /// More than one fault fits, none alone.
    Several {
        /// The nearest single faults.
        nearest: Vec<Nearest>,
        /// As in [`CoreSaid::Unknown`].
        away: Option<f32>,
    },
}

/// The joint fit over several operating points a name rests on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct JointEvidence {
    /// Operating points since the change.
    pub points: usize,
    /// Anchored: the torque against the load measured just before the change took part.
    pub anchored: bool,
}

/// The last isolation is older than [`STALE_S`] at the log's end.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stale {
    /// When it was made [s].
    pub judged_at_s: f64,
    /// How long the operating point was not steady at the end [s].
    pub unsteady_s: f64,
}

/// Which sensor of one phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorKind {
    /// A current sensor.
    Current,
    /// A voltage sensor.
    Voltage,
}

/// Why nothing was isolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NotIsolatedWhy {
    /// The parameter file's machine cannot be used by the isolation.
    MachineUnusable,
    /// No settled, quasi-steady operating point with voltage was evaluated.
    NoSteadyPoint,
}

/// What the isolation concluded (JSON `isolation.said`, `{"kind": ..}` with its numbers):
/// the door spells it as `isolation.verdict`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IsolationSaid {
    /// Nothing could be isolated.
    NotIsolated {
        /// Why.
        why: NotIsolatedWhy,
    },
    /// The nearest fault is within the parameter file's own uncertainty: not named.
    WithinFileError {
        /// The fault.
        fault: Fault,
        /// Its change.
        change: f32,
        /// Its probability.
        probability: f32,
        /// A lamp lit.
        lamps_lit: bool,
    },
    /// The core's conclusion, made longer than [`STALE_S`] before the log's end.
    Stale {
        /// The conclusion.
        core: CoreSaid,
        /// When, and how long the end was not steady.
        stale: Stale,
    },
    /// The windings warmed since commissioning: heating, not a fault.
    Heating {
        /// The tracked rise [K].
        rise_k: f32,
        /// A lamp lit (their residuals were learned on the cold machine).
        lamps_lit: bool,
        /// A name given while the tracked temperature lagged, and withdrawn.
        withdrawn: Option<NameGiven>,
    },
    /// Against the file's nominal values, the change is what warmer (or cooler) windings
    /// give.
    FileHeating {
        /// The rise above the file's temperature [K] (negative: cooler).
        rise_k: f32,
    },
    /// The load moved (the friction class read with the load an unknown input).
    LoadMoved {
        /// The last load move: when [s], the active current before and after [A].
        last: Option<(f64, f32, f32)>,
    },
    /// The core's conclusion, with the joint fit it rests on where there is one.
    Concluded {
        /// The conclusion.
        core: CoreSaid,
        /// The joint fit over the operating points since the change.
        joint: Option<JointEvidence>,
    },
    /// One phase's sensor named by the zero sequence, with its own gain error.
    SensorPhase {
        /// Which sensor.
        sensor: SensorKind,
        /// Its phase.
        phase: Phase,
        /// Its gain error.
        gain_error: f32,
        /// Where the conclusion was stale.
        stale: Option<Stale>,
    },
    /// An unexplained deviation outside the commissioned range: not judged as a fault.
    OutsideRange {
        /// What left the range.
        departures: Vec<RangeDeparture>,
        /// The deviation [standard deviations].
        deviation: f32,
    },
}

impl IsolationTracker {
    /// What a winding that warmed says (a tracked rise of at least
    /// `REPORTED_RISE_K`) when the isolation finds no deviation from the warm machine.
    fn heating_said(&self, state: IsolationState) -> Option<IsolationSaid> {
        let rise_k = self
            .winding_rise_k()
            .filter(|_| state == IsolationState::NoDeviation)?;
        Some(IsolationSaid::Heating {
            rise_k,
            lamps_lit: self.lamps_lit,
            withdrawn: self.first_named,
        })
    }

    /// Against the parameter file's nominal values (not commissioned), a change that
    /// heating explains ([`IsolationTracker::heating_explains`]).
    fn file_heating_said(&self, iso: &Isolation) -> Option<IsolationSaid> {
        if self.follower.as_ref().is_none_or(|f| f.learned()) {
            return None;
        }
        let rise_k = self.heating_explains(false, iso)?;
        Some(IsolationSaid::FileHeating { rise_k })
    }

    /// Where the last point reads as the friction class with the load an unknown input
    /// ([`crate::options::LoadModel::Unknown`]): the load moved.
    fn load_moved_said(&self) -> IsolationSaid {
        let last = self.events.events().iter().rev().find_map(|e| match e {
            IsolationEvent::LoadMoved { t_s, from_a, to_a } => Some((*t_s, *from_a, *to_a)),
            IsolationEvent::Named { .. } => None,
        });
        IsolationSaid::LoadMoved { last }
    }

    /// What the report says of `c` (`in_file_error`: the name within the parameter file's
    /// uncertainty, not given; `detected`: a lamp lit or a sensor fault was seen; `moved`:
    /// the current's change from the learned point).
    pub(super) fn said(
        &self,
        c: &Concluded,
        in_file_error: Option<Named>,
        detected: bool,
        moved: Option<f32>,
    ) -> IsolationSaid {
        let iso = &c.iso;
        if let Some(Named::Fault(c)) = in_file_error {
            IsolationSaid::WithinFileError {
                fault: c.fault,
                change: c.change,
                probability: c.probability,
                lamps_lit: self.lamps_lit,
            }
        } else if self.end_t - self.last_t > STALE_S {
            IsolationSaid::Stale {
                core: core_said(iso, detected, moved),
                stale: Stale {
                    judged_at_s: self.last_t,
                    unsteady_s: self.end_t - self.last_t,
                },
            }
        } else if let Some(warm) = self.heating_said(iso.state) {
            warm
        } else if let Some(warm) = self.file_heating_said(iso) {
            warm
        } else if c.load_moved {
            self.load_moved_said()
        } else {
            IsolationSaid::Concluded {
                core: core_said(iso, detected, moved),
                joint: c.joint.map(|(_, points)| JointEvidence {
                    points,
                    anchored: self.evidence.anchored(),
                }),
            }
        }
    }
}

/// The core's conclusion of `iso`; `moved`: the current's relative distance from the
/// learned point ([`super::IsolationReport::moved_from_learned`]).
fn core_said(iso: &Isolation, detected: bool, moved: Option<f32>) -> CoreSaid {
    let away = moved.filter(|m| m.abs() >= MOVED_SAID_FROM);
    let nearest = || -> Vec<Nearest> {
        iso.candidates
            .iter()
            .take(3)
            .map(|c| Nearest {
                fault: c.fault,
                change: c.change,
                probability: c.probability,
            })
            .collect()
    };
    match (iso.state, iso.named()) {
        (IsolationState::NoDeviation, _) if detected => CoreSaid::LitWithoutDeviation {
            deviation: iso.deviation,
        },
        (IsolationState::NoDeviation, _) => CoreSaid::NoDeviation,
        (IsolationState::NotJudged, _) => CoreSaid::NotJudged,
        // Far from the commissioned point the learned baseline does not hold: the deviation
        // is the operating point's, not evidence of a fault (the verdict says the same).
        (IsolationState::Unknown, _) if moved.is_some_and(|m| m.abs() >= MOVED_FAR) => {
            CoreSaid::MovedFar {
                moved: moved.unwrap_or(0.0),
                deviation: iso.deviation,
                nearest: nearest(),
            }
        }
        (IsolationState::Unknown, _) => CoreSaid::Unknown {
            deviation: iso.deviation,
            nearest: nearest(),
            away,
        },
        (_, Some(Named::Fault(c))) => CoreSaid::Fault {
            fault: c.fault,
            change: c.change,
            probability: c.probability,
        },
        (_, Some(Named::Friction { probability, b, bl })) => CoreSaid::Friction {
            probability,
            b_change: b.change,
            bl_change: bl.change,
        },
        (_, None) => CoreSaid::Several {
            nearest: nearest(),
            away,
        },
    }
}
