//! The verdict of a replay by the one rule for a FAULT (`monitor_core::isolation::fault_call`,
//! shared with the panels and the board): [`verdict_of`], with the reason a detection
//! against the nominal values is no verdict ([`nominal_cannot_judge`]).

use super::isolation::{self, IsolationReport};
use super::Verdict;
use monitor_core::isolation::{fault_call, FaultCall, Sighting};

/// The one rule's view ([`Sighting`]) of a detection (`detected`, `sensor_fault`) with the
/// isolation's report: the size of its name, and whether it judges against a baseline
/// learned in commissioning.
pub(super) fn sighting(
    detected: bool,
    sensor_fault: bool,
    isolation: &IsolationReport,
) -> Sighting {
    Sighting {
        detected,
        sensor_fault,
        named_change: isolation.named.and(isolation.named_change),
        commissioned: isolation.baseline == isolation::IsolationBaseline::Learned,
    }
}

/// Why lamps lit against the parameter file's nominal values are no verdict (`None`: they
/// are, or nothing was detected). Without a baseline learned on the healthy machine the
/// residuals measure the machine against the file, and a file from a nameplate is 10-30 %
/// off ([`isolation::NOMINAL_UNCERTAINTY`]); a winding 60 K warmer than the file's
/// temperature moves Rs and Rr by 24 %. So a FAULT against the nominal machine needs a
/// name whose size stands clear of that uncertainty; a change that fits no single fault,
/// or one within it, is withheld. A sensor-fault lamp (bad samples) is no residual
/// judgement and stays a fault. The rule is the core's ([`fault_call`]'s
/// [`FaultCall::NotCommissioned`]); this gives its reason in words.
pub(super) fn nominal_cannot_judge(
    detected: bool,
    sensor_fault: bool,
    isolation: &IsolationReport,
) -> Option<String> {
    if fault_call(&sighting(detected, sensor_fault, isolation)) != FaultCall::NotCommissioned {
        return None;
    }
    let what = match isolation.named.zip(isolation.named_change) {
        Some((f, c)) => format!(
            "the nearest single fault, {f} {:+.0} %, is within the parameter file's own uncertainty (+/-{:.0} %)",
            100.0 * c,
            100.0 * isolation::NOMINAL_UNCERTAINTY
        ),
        None => "the change fits no single fault".to_string(),
    };
    Some(format!(
        "not commissioned: the lamps lit against the parameter file's nominal values and {what}; a file 10-30 % off the machine, or windings warmer than the file assumes (60 K is +24 % on Rs and Rr), move the residuals this much. Commission (--commission START:END) on the healthy machine to judge a change from it"
    ))
}

/// The verdict from the replay's findings: `withheld` the reasons a judgement is withheld
/// (returned with a watching reason added where it applies), `detected` whether a lamp or
/// the isolation detected a fault, `winding` whether shorted turns were named at a
/// probability of at least one half (`UnbalanceReport::names_a_short`), `sensor_fault`
/// whether a sensor lamp is lit.
pub(super) fn verdict_of(
    mut withheld: Vec<String>,
    detected: bool,
    winding: bool,
    sensor_fault: bool,
    isolation: &IsolationReport,
) -> (Verdict, Vec<String>) {
    // Shorted turns named at a probability of at least one half (a calibrated
    // probability, `docs/isolation.md`) are a fault whatever else could not be judged.
    if winding {
        return (Verdict::Fault, withheld);
    }
    // The one rule for a FAULT (`monitor_core::isolation::fault_call`): a named fault too
    // small to send a crew for is watched; against the nominal values a name within the
    // file's uncertainty is no judgement (its reason is already among `withheld`,
    // [`nominal_cannot_judge`]).
    let call = fault_call(&sighting(detected, sensor_fault, isolation));
    let verdict = match call {
        _ if !withheld.is_empty() => Verdict::CouldNotJudge,
        FaultCall::Watching => {
            if let Some((name, c)) = isolation.named.zip(isolation.named_change) {
                withheld.push(format!(
                    "watching: the isolation names {name} {:+.1} %, below the {:.0} % a fault needs (what a parameter file's error away from the commissioned point and a few kelvin of heating move)",
                    100.0 * c,
                    100.0 * super::super::MIN_FAULT_CHANGE
                ));
            }
            Verdict::Watching
        }
        FaultCall::Fault => Verdict::Fault,
        FaultCall::NotCommissioned => Verdict::CouldNotJudge,
        FaultCall::Clear => Verdict::Healthy,
    };
    (verdict, withheld)
}
