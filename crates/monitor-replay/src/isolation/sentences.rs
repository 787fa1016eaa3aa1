//! The isolation's sentences: the verdict `diagnose` reports ([`IsolationTracker::verdict`])
//! and the phrases it is made of.

use super::{Concluded, IsolationTracker, NOMINAL_UNCERTAINTY, STALE_S};
use crate::events::IsolationEvent;
use monitor_core::isolation::Named;
use monitor_core::{Fault, Isolation, IsolationState};

impl IsolationTracker {
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

    /// Against the parameter file's nominal values (not commissioned), the sentence of a
    /// change that heating explains ([`IsolationTracker::heating_explains`]).
    fn file_heating_sentence(&self, iso: &Isolation) -> Option<String> {
        if self.follower.as_ref().is_none_or(|f| f.learned()) {
            return None;
        }
        let rise = self.heating_explains(false, iso)?;
        Some(format!(
            "The change is what windings about {:.0} K {} than the parameter file assumes give (Rs and Rr {} together, copper 0.393 %/K): heating, not a fault. Against the file's nominal values a change this small is as much the file's own error; commission on the healthy machine to judge it.",
            rise.abs(),
            if rise > 0.0 { "warmer" } else { "cooler" },
            pct(rise * monitor_core::isolation::COPPER_ALPHA_PER_K)
        ))
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
    /// input ([`crate::options::LoadModel::Unknown`]): the load moved.
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
            "The load moved{what}: an operating-point change, not a fault; the stator-voltage equations, with the load as an unknown input, fit the machine. (A change of the machine's friction B cannot be told from a load change without a load model: for the paper's fixed viscous load, where a Bl change is a fault, give {}.)",
            self.words.hint(crate::words::OptionField::Load, "viscous")
        )
    }

    /// The report's sentence on `c` (`in_file_error`: the name within the parameter file's
    /// uncertainty, not given; `detected`: a lamp lit or a sensor fault was seen; `moved`:
    /// the current's change from the learned point).
    pub(super) fn verdict(
        &self,
        c: &Concluded,
        in_file_error: Option<Named>,
        detected: bool,
        moved: Option<f32>,
    ) -> String {
        let iso = &c.iso;
        if let Some(Named::Fault(c)) = in_file_error {
            format!(
                "The nearest fault, {} {} (p {:.2}), is within the parameter file's own uncertainty (+/-{:.0} %){}: not named, a file that far off the machine moves the residuals as much. Commission on the healthy machine to judge changes this small.",
                c.fault,
                pct(c.change),
                c.probability,
                100.0 * NOMINAL_UNCERTAINTY,
                if self.lamps_lit { "" } else { " while every lamp stayed dark" }
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
        } else if let Some(warm) = self.file_heating_sentence(iso) {
            warm
        } else if c.load_moved {
            self.load_moved_sentence()
        } else {
            self.with_evidence(verdict_sentence(iso, detected, moved), c.joint)
        }
    }
}

/// A size as a signed percentage.
pub(super) fn pct(x: f32) -> String {
    format!("{:+.0} %", 100.0 * x)
}

/// A current this far from the learned point (relative) is said in the verdict when no
/// fault is named: the widening for the parameter file's error is then why.
const MOVED_SAID_FROM: f32 = 0.05;

/// A current this far (relative) from the commissioned point's is another operating point:
/// an unexplained deviation there is not reported as a possible fault.
pub const MOVED_FAR: f32 = 0.5;

/// The one-sentence verdict of the isolation; `moved`: the current's relative distance
/// from the learned point ([`super::IsolationReport::moved_from_learned`]).
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

/// The sentence's subject for fault `f`.
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
