//! The same state for the same log (issue "One verdict from all the evidence"): the board's
//! sample path and panel (this rig) and the host's replay (`diagnose`'s timeline and the
//! HMI's panel, `monitor_replay::Replay::panel`) run one simulated log, commissioned over
//! the same stretch, with load steps of +10 % and +40 % and a fault; at every half second
//! away from the changes they show the same verdict (`call=` on the board, the panel's call
//! on the host), the FAULT lamp lit on both or neither, and a load step is never a FAULT.

use super::*;
use monitor_core::verdict::Verdict;
use monitor_replay::{diagnose_rows, MonitorState, ReplayOptions};

/// Seconds after a change (a load step, the fault) in which the two may still differ: the
/// board's statuses come every 100 samples and its isolation every 0.1 s, the host's every
/// row.
const SETTLE_S: f64 = 1.5;

#[test]
fn the_board_and_the_host_show_the_same_state_for_the_same_log() {
    let mut scenario = Scenario::steady(24.0, f64::from(FS));
    scenario.load.steps = vec![
        LoadStep {
            t_s: 6.0,
            torque_nm: None,
            bl_scale: Some(1.1),
        },
        LoadStep {
            t_s: 9.0,
            torque_nm: None,
            bl_scale: Some(1.4),
        },
        LoadStep {
            t_s: 12.0,
            torque_nm: None,
            bl_scale: Some(1.0),
        },
    ];
    scenario
        .faults
        .push(FaultSpec::parametric(Fault::Rr, 16.0, 0.5));
    let changes = [6.0, 9.0, 12.0, 16.0];
    // The board: commissioned by the button at 1.5 s.
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run_commissioning(&frames(&scenario));
    let learned_until = rig
        .seen
        .iter()
        .find(|s| s.t_ms > 2_000 && s.tick.mode == Mode::Commissioned)
        .map(|s| f64::from(s.t_ms) / 1e3)
        .expect("commissioned"); // ok: test
                                 // The host: the same log, commissioned over the same stretch.
    let params = ParamFile::reference_2p2kw();
    let rows = simulate_to_vec(&params, &scenario).expect("simulation"); // ok: test
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(1.5, learned_until)),
        timeline_step: monitor_replay::TimelineStep::of(0.05),
        ..ReplayOptions::default()
    };
    let host = diagnose_rows(&params, scenario.sensors.channels(), &rows, opts).expect("replay"); // ok: test
    let mut compared = 0;
    let mut differ = Vec::new();
    let mut t = learned_until + SETTLE_S;
    while t < scenario.duration_s - 0.1 {
        let near_change = changes.iter().any(|c| t >= *c && t < c + SETTLE_S);
        let board = rig
            .seen
            .iter()
            .min_by_key(|s| (f64::from(s.t_ms) / 1e3 - t).abs().to_bits());
        let point = host
            .timeline
            .iter()
            .min_by_key(|p| (p.t_s - t).abs().to_bits());
        if let (false, Some(b), Some(h)) = (near_change, board, point) {
            compared += 1;
            let host_call = h.panel.call;
            let host_moved = matches!(h.panel.state, MonitorState::Moved(_));
            // (The board's FAULT lamp blinks its code: its call says whether it is lit.)
            let board_fault = b.tick.call == Verdict::Fault;
            // Where the board's range watch says "moved" with no FAULT (the amber RUN
            // pattern), the host shows the amber state too.
            let board_amber = b.status.moved && !board_fault;
            let same = b.tick.call == host_call
                && board_fault == h.panel.fault_lamp
                && (!board_amber || host_moved);
            if !same {
                differ.push(format!(
                    "{t:.1} s: board {:?} lamp {} moved {}, host {:?} lamp {} {:?}",
                    b.tick.call,
                    b.tick.lamps.fault,
                    b.status.moved,
                    host_call,
                    h.panel.fault_lamp,
                    h.panel.state
                ));
            }
            // A load step is never a FAULT on either.
            if t < 16.0 {
                assert!(
                    !board_fault && !h.panel.fault_lamp,
                    "{t:.1} s: a FAULT for a load step"
                );
            }
        }
        t += 0.5;
    }
    assert!(compared >= 20, "{compared} points compared");
    // Agreement at nearly every point (a point where one side's isolation is a block ahead
    // of the other's may differ).
    assert!(
        differ.len() * 10 <= compared,
        "{} of {compared} points differ:\n{}",
        differ.len(),
        differ.join("\n")
    );
    // The fault is named on both: a FAULT at the end.
    let end = rig.last();
    assert_eq!(end.tick.call, Verdict::Fault, "board at the end");
    assert_eq!(host.verdict, Verdict::Fault, "{:?}", host.verdict_finding);
}
