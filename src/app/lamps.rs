//! The panel's inputs from the board's latest status and isolation: the FAULT lamp by the
//! one verdict's decision table (`monitor_core::verdict`, shared with the host's `diagnose`,
//! timeline and HMI: [`panel_glance`]), the blink code of the fault it names, the amber
//! "operating point moved" state.

use super::*;
use monitor_core::verdict::{
    Decision, FaultName, FindingSource, Glance, NamedFault as Name, Size, Verdict,
};

/// The isolation as the panel reads it: the latest one in force
/// ([`Supervisor::isolation`]) and whether it judges against a baseline learned in
/// commissioning (else against the motor record's nominal values).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PanelIsolation<'a> {
    /// The latest isolation (`None`: none yet, or no isolator for this machine).
    pub latest: Option<&'a Isolation>,
    /// Its baseline was learned in commissioning (this run or the stored record's).
    pub learned: bool,
}

impl PanelIsolation<'_> {
    /// What the isolation names as the panel counts it: with the learned thresholds in force
    /// (`commissioned`), a learned isolation's name only (a nominal one would judge the
    /// motor against the record's values, not the commissioned motor); without them, any.
    fn named(&self, commissioned: bool) -> Option<Named> {
        self.latest
            .filter(|_| self.learned || !commissioned)
            .and_then(Isolation::named)
    }
}

/// The moment's evidence as the decision table reads it (`monitor_core::verdict::Glance`):
/// the core's lamps, its sensor flags, the isolation's name (a Table 1 fault with its size
/// and probability), whether the learned thresholds are in force, the range watch's "moved",
/// and shorted turns with the core's phase confidence. The board knows no load model: as the
/// host's `diagnose` by default, it reads the load as an unknown input, so the friction
/// class is the load's move (the operating point "moved"), not a name.
///
/// In the range state (`status.clip_range`: clipping persists in steady running,
/// [`crate::clip_watch`]) the data cannot carry a verdict: the blocks the monitor judges
/// are the few that did not clip, at the operating points where the readings stayed inside
/// the front end. The glance is then the data's quality alone (untrusted, the decision
/// table's "could not judge"), nothing detected or named, so the FAULT lamp stays dark; the
/// panel's residual lamps still show the core's.
pub fn panel_glance(status: &MonitorStatus, isolation: PanelIsolation<'_>) -> Glance {
    if status.clip_range {
        return Glance {
            sensor_fault: true,
            commissioned: status.commissioned,
            ..Glance::default()
        };
    }
    let named = isolation.named(status.commissioned);
    let friction = matches!(named, Some(Named::Friction { .. }));
    Glance {
        lamps_lit: status.fault_detected,
        sensor_fault: status.sensor_fault.any(),
        named: named.filter(|_| !friction).as_ref().map(Name::of_isolation),
        commissioned: status.commissioned,
        moved: status.moved || friction,
        // Shorted turns count where the lamps are judged (a start's or a step's transient
        // unbalances the currents for a while).
        winding: status
            .winding
            .filter(|_| status.evaluating && status.quasi_steady)
            .map(|(phase, ratio)| Name {
                fault: FaultName::ShortedTurns,
                size: Size::OfPositiveSequence(ratio),
                phase: Some(phase),
                confidence: status.winding_confidence,
            }),
    }
}

/// The decision table's verdict on the board's latest `status` and `isolation`
/// ([`panel_glance`]); the status line prints it (`call=`: `healthy`, `fault`, `watching`,
/// `could_not_judge`).
pub fn panel_call(status: &MonitorStatus, isolation: PanelIsolation<'_>) -> Decision {
    panel_glance(status, isolation).decide()
}

/// The blink code of the FAULT the table called (`None` for no FAULT): the named Table 1
/// fault's, or shorted turns' phase code.
fn fault_code(glance: &Glance, d: Decision) -> Option<u8> {
    if d.verdict != Verdict::Fault {
        return None;
    }
    let finding = d.by.and_then(|k| glance.findings().get(k).copied())?;
    let named = finding.named()?;
    match (finding.source, named.fault, named.phase) {
        (FindingSource::Winding, _, Some(p)) => Some(winding_code(p.index() as u8)),
        (_, FaultName::Table1(f), _) => Some(blink_code(f.index() as u8)),
        _ => None,
    }
}

/// The panel's inputs ([`PanelInput`], the panel's whole interface) for the latest status
/// in `mode` and the latest `isolation`: the residual lamps; the FAULT lamp for the decision
/// table's FAULT only ([`panel_call`]: a named fault with its size at a confidence of at
/// least 0.5; not for a name below 5 %, watched, nor, not commissioned, for lamps whose
/// isolation names nothing beyond the file's +-30 %), with the blink code of what it names;
/// "input invalid" when a sensor fault is flagged with no residual lamp lit; the amber
/// "operating point moved" state; the range state's mark (`status.clip_range`, the panel's
/// module docs).
pub fn panel_input(
    mode: Mode,
    status: &MonitorStatus,
    isolation: PanelIsolation<'_>,
    commissioning_failed: bool,
) -> PanelInput {
    let glance = panel_glance(status, isolation);
    let d = glance.decide();
    let code = fault_code(&glance, d);
    // The amber "operating point moved" state: no FAULT, and the load's move explains the
    // lamps (panel docs).
    let moved = glance.moved && code.is_none() && !status.sensor_fault.any();
    PanelInput {
        mode,
        residual_lamps: status.residual_lamps,
        fault_detected: code.is_some(),
        input_invalid: status.sensor_fault.any() && !status.residual_lamps.iter().any(|l| *l),
        fault_code: code.unwrap_or(NOT_NAMED_CODE),
        commissioning_failed,
        default_motor: false,
        clock_fallback: false,
        bor_below_goal: false,
        moved,
        clip_range: status.clip_range,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::board::Lamp;
    use crate::panel::{read_blink_code, render};

    /// An isolation that names `fault` with probability `p` and a change of `change` (the
    /// rest unknown).
    fn isolation(fault: Fault, p: f32, change: f32) -> Isolation {
        let mut iso = Isolation {
            state: monitor_core::IsolationState::Isolated,
            ..Isolation::default()
        };
        let k = iso
            .candidates
            .iter()
            .position(|c| c.fault == fault)
            .unwrap_or(0); // ok: test
        iso.candidates.swap(0, k);
        iso.candidates[0].probability = p;
        iso.candidates[0].change = change;
        iso.unknown_probability = 1.0 - p;
        iso
    }

    fn learned(iso: &Isolation) -> PanelIsolation<'_> {
        PanelIsolation {
            latest: Some(iso),
            learned: true,
        }
    }

    fn nominal(iso: &Isolation) -> PanelIsolation<'_> {
        PanelIsolation {
            latest: Some(iso),
            learned: false,
        }
    }

    /// The blink code the FAULT lamp shows over 20 s, `None` when it stays dark.
    fn code(inp: &PanelInput) -> Option<u8> {
        let trace: Vec<bool> = (0..400u32)
            .map(|k| render(inp, k * 50).is_on(Lamp::Fault))
            .collect();
        read_blink_code(&trace, 50)
    }

    fn dark(inp: &PanelInput) -> bool {
        (0..400u32).all(|k| !render(inp, k * 50).is_on(Lamp::Fault))
    }

    fn commissioned() -> MonitorStatus {
        MonitorStatus {
            commissioned: true,
            evaluating: true,
            quasi_steady: true,
            ..MonitorStatus::default()
        }
    }

    #[test]
    fn the_code_is_the_named_fault_and_a_detection_without_a_name_is_no_fault() {
        let mut status = commissioned();
        let m = Mode::Commissioned;
        // Named, commissioned, lamps quiet: shown with the fault's code.
        let rr = isolation(Fault::Rr, 0.9, 0.3);
        assert_eq!(code(&panel_input(m, &status, learned(&rr), false)), Some(2));
        // The lamps detect, the isolation is not sure (p < 0.5): watched, the lamp dark.
        status.fault_detected = true;
        let unsure = isolation(Fault::Rs, 0.4, 0.3);
        let inp = panel_input(m, &status, learned(&unsure), false);
        assert!(dark(&inp));
        assert_eq!(
            panel_call(&status, learned(&unsure)).verdict,
            Verdict::Watching
        );
        // No isolation: the lamps' own top candidate names no size: no FAULT.
        let none = PanelIsolation::default();
        status.top = Some((Fault::Lr, 0.5));
        assert!(dark(&panel_input(m, &status, none, false)));
        status.top = None;
        // Bl (or B) named: the friction class is the load's move: amber, never a FAULT.
        let bl = isolation(Fault::Bl, 0.7, 0.3);
        let inp = panel_input(m, &status, learned(&bl), false);
        assert!(dark(&inp) && inp.moved);
        status.fault_detected = false;
        // Shorted turns blink their phase's code (11, 12, 13) at a confidence of 0.5 or
        // more, and are watched below it.
        for (k, phase) in Phase::ALL.into_iter().enumerate() {
            status.winding = Some((phase, 0.05));
            status.winding_confidence = 0.8;
            let inp = panel_input(m, &status, none, false);
            assert_eq!(code(&inp), Some(11 + k as u8), "{phase:?}");
            status.winding_confidence = 0.3;
            assert!(dark(&panel_input(m, &status, none, false)), "{phase:?}");
            // A transient (a start, a step) unbalances the currents: no winding then.
            status.winding_confidence = 0.8;
            status.quasi_steady = false;
            assert!(dark(&panel_input(m, &status, none, false)), "{phase:?}");
            status.quasi_steady = true;
        }
        // A named lamp fault more confident than the winding keeps its own code.
        status.fault_detected = true;
        status.winding_confidence = 0.6;
        let rs = isolation(Fault::Rs, 0.9, 0.5);
        assert_eq!(code(&panel_input(m, &status, learned(&rs), false)), Some(1));
    }

    /// A named fault below 5 % is watched: the FAULT lamp stays dark though the core's lamps
    /// detect, and the status line says `call=watching`.
    #[test]
    fn a_small_name_is_watched_with_the_fault_lamp_dark() {
        let mut status = commissioned();
        status.residual_lamps = [false, true, true, true];
        status.fault_detected = true;
        status.top = Some((Fault::B, 0.5));
        for (fault, change) in [(Fault::Rr, 0.03), (Fault::Rs, -0.049)] {
            let iso = isolation(fault, 0.9, change);
            let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
            assert!(dark(&inp), "{fault:?} {change}");
            assert_eq!(inp.residual_lamps, [false, true, true, true]);
            assert!(!inp.moved, "watching is not the amber state");
            let call = panel_call(&status, learned(&iso)).verdict;
            assert_eq!((call, call.name()), (Verdict::Watching, "watching"));
        }
        // The same name at 5 % and more is a FAULT with its code.
        let iso = isolation(Fault::Rr, 0.9, 0.05);
        let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
        assert_eq!(code(&inp), Some(2));
        assert_eq!(panel_call(&status, learned(&iso)).verdict, Verdict::Fault);
        // A sensor's impossible readings beside a small name: the data cannot be judged,
        // the lamp steady ("input invalid"), no blink code.
        status.sensor_fault.current = true;
        status.residual_lamps = [false; 4];
        let iso = isolation(Fault::Rr, 0.9, 0.01);
        let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
        assert!(inp.input_invalid && render(&inp, 0).is_on(Lamp::Fault));
        assert_eq!(code(&inp), None);
        assert_eq!(
            panel_call(&status, learned(&iso)).verdict,
            Verdict::CouldNotJudge
        );
    }

    /// The range state (clipping persists in steady running): could not judge, whatever the
    /// lamps and the isolation say; the FAULT lamp dark (no blink code, no steady "input
    /// invalid"), no amber state, the RUN lamp's range mark; the residual lamps as the core's.
    #[test]
    fn the_range_state_could_not_judge_and_lights_no_fault() {
        let mut status = commissioned();
        status.residual_lamps = [false, true, true, true];
        status.fault_detected = true;
        status.moved = true;
        let rr = isolation(Fault::Rr, 0.9, 0.3);
        let inp = panel_input(Mode::Commissioned, &status, learned(&rr), false);
        assert_eq!(code(&inp), Some(2), "the control: a FAULT named");
        status.clip_range = true;
        let inp = panel_input(Mode::Commissioned, &status, learned(&rr), false);
        assert!(dark(&inp) && !inp.input_invalid && !inp.moved && inp.clip_range);
        assert_eq!(inp.residual_lamps, [false, true, true, true]);
        assert_eq!(
            panel_call(&status, learned(&rr)).verdict,
            Verdict::CouldNotJudge
        );
        assert!(render(&inp, 8_000).is_on(Lamp::Run) && !render(&inp, 9_700).is_on(Lamp::Run));
    }

    /// Not commissioned, lamps lit against the motor record's nominal values are a FAULT
    /// only for a name beyond the file's +-30 %; else the file does not fit.
    #[test]
    fn uncommissioned_lamps_need_a_name_beyond_the_files_uncertainty() {
        let status = MonitorStatus {
            residual_lamps: [true, true, false, true],
            fault_detected: true,
            top: Some((Fault::Lr, 0.5)),
            ..MonitorStatus::default()
        };
        let m = Mode::NotCommissioned;
        for change in [0.3, -0.24, 0.1, 0.02] {
            let iso = isolation(Fault::Rs, 0.9, change);
            let inp = panel_input(m, &status, nominal(&iso), false);
            assert!(dark(&inp), "rs {change:+}");
            assert_eq!(inp.residual_lamps, [true, true, false, true]);
            let call = panel_call(&status, nominal(&iso)).verdict;
            assert_eq!(call, Verdict::CouldNotJudge, "rs {change:+}");
            assert_eq!(call.name(), "could_not_judge");
        }
        // Nothing named, or no isolation at all: no judgement either.
        let unsure = isolation(Fault::Rs, 0.4, 0.5);
        for iso in [nominal(&unsure), PanelIsolation::default()] {
            assert!(dark(&panel_input(m, &status, iso, false)));
            assert_eq!(panel_call(&status, iso).verdict, Verdict::CouldNotJudge);
        }
        // Beyond +-30 %: a FAULT, with the named fault's code (not the lamps' top).
        for (fault, change, blink) in [(Fault::Rs, 0.5, 1), (Fault::Rr, -0.4, 2)] {
            let iso = isolation(fault, 0.9, change);
            let inp = panel_input(m, &status, nominal(&iso), false);
            assert_eq!(code(&inp), Some(blink), "{fault:?} {change}");
            assert_eq!(panel_call(&status, nominal(&iso)).verdict, Verdict::Fault);
        }
        // The isolation alone (lamps quiet) lights nothing while not commissioned.
        let quiet = MonitorStatus::default();
        let iso = isolation(Fault::Rs, 0.9, 0.5);
        assert!(dark(&panel_input(m, &quiet, nominal(&iso), false)));
        assert_eq!(panel_call(&quiet, nominal(&iso)).verdict, Verdict::Healthy);
    }
}
