//! The panel's amber "operating point moved" state (issue 28): after commissioning, a load
//! step beyond the commissioned range with no fault keeps the FAULT lamp off and
//! triple-flashes the RUN lamp; a fault the isolation names still blinks its code.

use super::*;

/// The RUN lamp's rising edges per 2 s over the ticks in `window` [ms] (the 1 Hz blink
/// gives 2, the "moved" triple flash 3).
fn run_flashes_per_2s(rig: &Rig, window: std::ops::Range<u32>) -> f64 {
    let run: Vec<bool> = rig
        .seen
        .iter()
        .filter(|s| window.contains(&s.t_ms))
        .map(|s| s.tick.lamps.run)
        .collect();
    let edges = run.windows(2).filter(|w| !w[0] && w[1]).count();
    let span_ms = run.len() as f64 * f64::from(PANEL_PERIOD_MS);
    edges as f64 * 2000.0 / span_ms
}

/// Commissions on healthy running, then runs `scenario`'s events; the rig after it.
fn commissioned_then(scenario: &Scenario) -> Rig {
    let frames = frames(scenario);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run_commissioning(&frames);
    rig
}

/// A +30 % load step (Bl x 1.3) at 5 s with no fault: the lamps may light, the FAULT lamp
/// stays off, the RUN lamp triple-flashes, the status says moved.
#[test]
fn a_load_step_with_no_fault_is_the_moved_state_not_a_fault() {
    let mut scenario = Scenario::steady(12.0, f64::from(FS));
    scenario.load.steps = vec![LoadStep {
        t_s: 5.0,
        torque_nm: None,
        bl_scale: Some(1.3),
    }];
    let rig = commissioned_then(&scenario);
    // The supervisor hands out the range the run learned (the one "moved" is judged on).
    assert!(
        rig.supervisor.range().commissioned().is_learned(),
        "no commissioned range: {:?}",
        rig.supervisor.range()
    );
    let before: Vec<&Seen> = rig
        .seen
        .iter()
        .filter(|s| (3_500..5_000).contains(&s.t_ms))
        .collect();
    assert!(
        before.iter().all(|s| !s.status.moved),
        "moved before the step"
    );
    let after: Vec<&Seen> = rig.seen.iter().filter(|s| s.t_ms >= 7_000).collect();
    let moved = after.iter().filter(|s| s.status.moved).count();
    assert!(
        moved * 10 >= after.len() * 9,
        "moved in {moved} of {} ticks after the step; range {:?}, point {:?}",
        after.len(),
        rig.supervisor.range().commissioned(),
        rig.last().status.operating_point()
    );
    assert!(
        rig.seen
            .iter()
            .filter(|s| s.t_ms >= 3_000)
            .all(|s| !s.tick.lamps.fault),
        "the FAULT lamp lit"
    );
    let lit = after
        .iter()
        .any(|s| s.status.residual_lamps.iter().any(|l| *l));
    let flashes = run_flashes_per_2s(&rig, 7_000..u32::MAX);
    assert!(
        (flashes - 3.0).abs() < 0.5,
        "{flashes} RUN flashes per 2 s (lamps lit: {lit})"
    );
    // Before the step: the commissioned 1 Hz blink (500 ms on, 500 ms off).
    let blink = rig
        .seen
        .iter()
        .filter(|s| (3_500..5_000).contains(&s.t_ms))
        .all(|s| s.tick.lamps.run == (s.t_ms % 1000 < 500));
    assert!(blink, "not the 1 Hz blink before the step");
}

/// A fault the isolation names (Rr +50 % at 5 s, at the commissioned load) still lights
/// the FAULT lamp with its blink code, and the RUN lamp keeps the commissioned 1 Hz blink:
/// the amber state is only for an operating point that moved with no fault named. (Rr
/// +50 % together with the +30 % load step is not named by the board's isolation, which
/// judges one fault at a time; the panel then shows the amber state, as the host does.)
#[test]
fn a_named_fault_still_lights_the_fault_lamp() {
    let mut scenario = Scenario::steady(20.0, f64::from(FS));
    scenario
        .faults
        .push(FaultSpec::parametric(Fault::Rr, 5.0, 0.5));
    let rig = commissioned_then(&scenario);
    let trace: Vec<bool> = rig
        .seen
        .iter()
        .filter(|s| s.t_ms >= 8_000)
        .map(|s| s.tick.lamps.fault)
        .collect();
    let code = panel::read_blink_code(&trace, PANEL_PERIOD_MS);
    assert_eq!(code, Some(Fault::Rr.index() as u8 + 1));
    let flashes = run_flashes_per_2s(&rig, 8_000..u32::MAX);
    assert!((flashes - 2.0).abs() < 0.5, "{flashes} RUN flashes per 2 s");
}
