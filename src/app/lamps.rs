//! The panel's inputs from the board's latest status and isolation: the FAULT lamp by the
//! one rule for a FAULT (`monitor_core::isolation::fault_call`, shared with the host's
//! `diagnose` and HMI), the blink code, the amber "operating point moved" state.

use super::*;
use monitor_core::isolation::{fault_call, FaultCall, Sighting};

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
    /// The isolation when its baseline is learned.
    fn learned(&self) -> Option<&Isolation> {
        self.latest.filter(|_| self.learned)
    }
}

/// The one rule's call (`monitor_core::isolation::fault_call`) on the board's latest
/// `status` and `isolation`: detected when the core's lamps (or a sensor flag) detect, or
/// when the isolation names a fault (not the friction class, which a load change is to the
/// paper's model) against a learned baseline while commissioned; commissioned when the
/// learned thresholds are in force ([`MonitorStatus::commissioned`], the RUN lamp's 1 Hz
/// blink); the size of what the isolation names. The status line prints it (`call=`).
pub fn panel_call(status: &MonitorStatus, isolation: PanelIsolation<'_>) -> FaultCall {
    let named = isolation.latest.and_then(Isolation::named);
    let named_fault = isolation.learned && matches!(named, Some(Named::Fault(_)));
    fault_call(&Sighting {
        detected: status.fault_detected || (named_fault && status.commissioned),
        sensor_fault: status.sensor_fault.any(),
        named_change: named.map(|n| n.change()),
        commissioned: status.commissioned,
    })
}

/// The blink code for the FAULT lamp: the isolated fault's (the friction class's 5,
/// [`NOT_NAMED_CODE`] when a learned isolation names nothing); without a learned
/// baseline the fault a FAULT against the nominal values was called for (a name beyond the
/// file's uncertainty), else the lamps' top candidate, as the paper's method gives it.
fn fault_code(status: &MonitorStatus, isolation: PanelIsolation<'_>, call: FaultCall) -> u8 {
    let code = |n: Named| match n {
        Named::Fault(c) => blink_code(c.fault.index() as u8),
        Named::Friction { .. } => blink_code(Fault::B.index() as u8),
    };
    match isolation.learned() {
        Some(iso) => iso.named().map_or(NOT_NAMED_CODE, code),
        None => match isolation.latest.and_then(Isolation::named) {
            Some(n) if call.is_fault() && !status.commissioned => code(n),
            _ => status
                .top
                .map_or(NOT_NAMED_CODE, |(f, _)| blink_code(f.index() as u8)),
        },
    }
}

/// The panel's inputs ([`PanelInput`], the panel's whole interface) for the latest status
/// in `mode` and the latest `isolation`: the residual lamps; the FAULT lamp for a FAULT of
/// the one rule only ([`panel_call`]: not for a named fault below 5 %, watched, nor,
/// not commissioned, for lamps whose isolation names nothing beyond the file's +-30 %), with
/// its blink code (the isolated fault's, as `fault_code` picks it); "input invalid" when a
/// sensor fault is flagged with no residual lamp lit; shorted turns' own code while nothing
/// else is shown; the amber "operating point moved" state (the panel's module docs).
pub fn panel_input(
    mode: Mode,
    status: &MonitorStatus,
    isolation: PanelIsolation<'_>,
    commissioning_failed: bool,
) -> PanelInput {
    let call = panel_call(status, isolation);
    let named = isolation.learned().and_then(Isolation::named);
    let named_fault =
        matches!(named, Some(Named::Fault(_))) && named.is_some_and(|n| n.stands_clear());
    // The amber "operating point moved" state: no FAULT lamp for the lamps (panel docs).
    let moved = status.moved && !named_fault && !status.sensor_fault.any();
    let other_fault = !moved && call.is_fault();
    // Shorted turns blink their own code while nothing else is shown.
    let (fault_detected, fault_code) = match status.winding {
        Some((phase, _)) if !other_fault && !status.sensor_fault.any() => {
            (true, winding_code(phase.index() as u8))
        }
        _ => (other_fault, fault_code(status, isolation, call)),
    };
    PanelInput {
        mode,
        residual_lamps: status.residual_lamps,
        fault_detected,
        input_invalid: status.sensor_fault.any() && !status.residual_lamps.iter().any(|l| *l),
        fault_code,
        commissioning_failed,
        default_motor: false,
        moved,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::panel::{read_blink_code, render, Lamp};

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
            ..MonitorStatus::default()
        }
    }

    #[test]
    fn the_code_is_the_isolated_fault_and_a_named_fault_shows_when_commissioned() {
        let mut status = commissioned();
        let m = Mode::Commissioned;
        // Named, commissioned, lamps quiet: shown with the fault's code.
        let rr = isolation(Fault::Rr, 0.9, 0.3);
        assert_eq!(code(&panel_input(m, &status, learned(&rr), false)), Some(2));
        // The lamps detect, the isolation is not sure (p < 0.5): "not named".
        status.fault_detected = true;
        let unsure = isolation(Fault::Rs, 0.4, 0.3);
        let inp = panel_input(m, &status, learned(&unsure), false);
        assert_eq!(code(&inp), Some(NOT_NAMED_CODE));
        // No isolation: the lamps' top candidate, or "not named".
        let none = PanelIsolation::default();
        assert_eq!(
            code(&panel_input(m, &status, none, false)),
            Some(NOT_NAMED_CODE)
        );
        status.top = Some((Fault::Lr, 0.5));
        assert_eq!(code(&panel_input(m, &status, none, false)), Some(4));
        status.top = None;
        // Bl (or B) named: the friction class, code 5; a load change alone does not light
        // the lamp.
        let bl = isolation(Fault::Bl, 0.7, 0.3);
        assert_eq!(code(&panel_input(m, &status, learned(&bl), false)), Some(5));
        status.fault_detected = false;
        assert!(dark(&panel_input(m, &status, learned(&bl), false)));
        // Shorted turns blink their phase's code (11, 12, 13) while nothing else is shown;
        // a lamp fault keeps its own code.
        for (k, phase) in Phase::ALL.into_iter().enumerate() {
            status.winding = Some((phase, 0.05));
            let inp = panel_input(m, &status, none, false);
            assert_eq!(code(&inp), Some(11 + k as u8), "{phase:?}");
        }
        status.fault_detected = true;
        status.top = Some((Fault::Rs, 0.5));
        assert_eq!(code(&panel_input(m, &status, none, false)), Some(1));
    }

    /// The one rule's (a): a named fault below 5 % is watched; the FAULT lamp stays dark
    /// though the core's lamps detect, and the status line says `call=watching`.
    #[test]
    fn a_small_name_is_watched_with_the_fault_lamp_dark() {
        let mut status = commissioned();
        status.residual_lamps = [false, true, true, true];
        status.fault_detected = true;
        status.top = Some((Fault::B, 0.5));
        for (fault, change) in [(Fault::Rr, 0.03), (Fault::Rs, -0.049), (Fault::Bl, 0.005)] {
            let iso = isolation(fault, 0.9, change);
            let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
            assert!(dark(&inp), "{fault:?} {change}");
            assert_eq!(inp.residual_lamps, [false, true, true, true]);
            assert!(!inp.moved, "watching is not the amber state");
            let call = panel_call(&status, learned(&iso));
            assert_eq!((call, call.name()), (FaultCall::Watching, "watching"));
        }
        // The same names at 5 % and more are a FAULT with their codes.
        for (fault, change, blink) in [(Fault::Rr, 0.05, 2), (Fault::Bl, 0.3, 5)] {
            let iso = isolation(fault, 0.9, change);
            let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
            assert_eq!(code(&inp), Some(blink), "{fault:?}");
            assert_eq!(panel_call(&status, learned(&iso)), FaultCall::Fault);
        }
        // A sensor fault beside a small name stays a FAULT (steady: input invalid).
        status.sensor_fault.current = true;
        status.residual_lamps = [false; 4];
        let iso = isolation(Fault::Rr, 0.9, 0.01);
        let inp = panel_input(Mode::Commissioned, &status, learned(&iso), false);
        assert!(inp.input_invalid && render(&inp, 0).is_on(Lamp::Fault));
        assert_eq!(panel_call(&status, learned(&iso)), FaultCall::Fault);
    }

    /// The one rule's (b): not commissioned, lamps lit against the motor record's nominal
    /// values are a FAULT only for a name beyond the file's +-30 %.
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
            let call = panel_call(&status, nominal(&iso));
            assert_eq!(call, FaultCall::NotCommissioned, "rs {change:+}");
            assert_eq!(call.name(), "not-commissioned");
        }
        // Nothing named, or no isolation at all: no judgement either.
        let unsure = isolation(Fault::Rs, 0.4, 0.5);
        for iso in [nominal(&unsure), PanelIsolation::default()] {
            assert!(dark(&panel_input(m, &status, iso, false)));
            assert_eq!(panel_call(&status, iso), FaultCall::NotCommissioned);
        }
        // Beyond +-30 %: a FAULT, with the named fault's code (not the lamps' top).
        for (fault, change, blink) in [(Fault::Rs, 0.5, 1), (Fault::Rr, -0.4, 2)] {
            let iso = isolation(fault, 0.9, change);
            let inp = panel_input(m, &status, nominal(&iso), false);
            assert_eq!(code(&inp), Some(blink), "{fault:?} {change}");
            assert_eq!(panel_call(&status, nominal(&iso)), FaultCall::Fault);
        }
        // The isolation alone (lamps quiet) lights nothing while not commissioned.
        let quiet = MonitorStatus::default();
        let iso = isolation(Fault::Rs, 0.9, 0.5);
        assert!(dark(&panel_input(m, &quiet, nominal(&iso), false)));
        assert_eq!(panel_call(&quiet, nominal(&iso)), FaultCall::Clear);
    }
}
