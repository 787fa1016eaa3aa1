//! Evidence across operating points on the board: the supervisor keeps the steady points
//! since a deviation began and fits them jointly (`monitor_core::isolation::Evidence`, the
//! code the host's replay runs), so a fault that one operating point cannot name is named
//! on the panel and the status line as the host names it.
//!
//! The case is the one `crates/monitor-studies/tests/studies/operating_points.rs` measures on the host: the 3 hp
//! motor (220 V, 60 Hz) at rated load, Ls +50 % at 4.5 s, the viscous load stepped to 0.7
//! of Bl at 8 s and to 0.5 at 11 s. At rated load an Ls change moves the residuals where an
//! Rr change and a small speed-sensor error do, so the single point shares it among the
//! three; the points at three load levels part them.

use super::*;
use drive_monitor::app::isolation_summary;
use monitor_core::motor_record::MotorRecord;
use monitor_core::reference::MOTOR_3HP;
use monitor_replay::{IsolationName, ReplayOptions};
use monitor_sim::SensorSpec;
use monitor_studies::experiment::simulate_and_replay;

/// The 3 hp machine as a motor record: the board's front end with a 25 A current full
/// scale (its rated current is about 12 A peak) and the board's encoder.
fn record_3hp() -> MotorRecord {
    MotorRecord {
        motor: MOTOR_3HP.motor,
        supply: MOTOR_3HP.supply,
        current_full_scale_a: 25.0,
        voltage_full_scale_v: board::VOLTAGE_FULL_SCALE_V,
        current_offset_counts: [board::MID_SCALE_CODE; 3],
        voltage_offset_counts: [board::MID_SCALE_CODE; 3],
        encoder_lines: board::ENCODER_LINES as u16,
        encoder_reversed: false,
        encoder_pull_up: true,
    }
}

/// The log: `operating_points.rs`'s, sampled at the board's rate and 10 s longer (the blink
/// code is read from the last 9 s).
fn scenario(fault: Option<(Fault, f64)>) -> Scenario {
    let mut sc = Scenario::steady(24.0, f64::from(FS));
    sc.sensors = SensorSpec::default();
    sc.seed = 21;
    sc.load.steps = [(8.0, 0.7), (11.0, 0.5)]
        .map(|(t_s, k)| LoadStep {
            t_s,
            torque_nm: None,
            bl_scale: Some(k),
        })
        .to_vec();
    if let Some((f, change)) = fault {
        sc.faults.push(FaultSpec::at_change(f, 4.5, change));
    }
    sc
}

/// The board with the 3 hp record in its motor-record page (the firmware's boot
/// composition, `drive_monitor::boot`), commissioned at 1.5 s, through the whole log; returns the rig.
fn board_run(sc: &Scenario) -> Rig {
    let rec = record_3hp();
    let survivors = Survivors::power_on(FakeFlash::erased()).with_motor_page(&rec.to_bytes());
    let mut rig = Rig::boot(survivors);
    let frames = frames_with(&ParamFile::reference_3hp(), &rig.path, sc);
    rig.run_commissioning(&frames);
    rig
}

/// What the host's replay names for the same log (commissioned over 1.5-3.5 s).
fn host_named(sc: &Scenario) -> (Option<IsolationName>, Option<f32>) {
    let p = ParamFile::reference_3hp();
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(1.5, 3.5)),
        ..Default::default()
    };
    let r = simulate_and_replay(&p, &p, sc, opts, |_, _| {})
        .expect("runs")
        .finish();
    (r.isolation.named, r.isolation.named_change)
}

/// Ls +-50 %: the board names what the host names. Where the host names `ls` with its size,
/// the board names the same (its status line `iso=ls`, its size within 15 % of the truth)
/// and the FAULT lamp blinks Ls's code (3); where the host names nothing (issue 48: the
/// joint fit's probability for ls stays under the name's 0.9 on this log, with the tracked
/// temperature's lag allowed for), the board names no fault and its FAULT lamp stays dark.
/// Before the board kept the evidence, it named the friction class (the last load step,
/// -50 % of Bl) and the panel showed "operating point moved".
#[test]
fn ls_on_the_3hp_motor_is_named_on_the_board_as_on_the_host_once_the_load_has_moved() {
    let mut wrong = Vec::new();
    for change in [0.5, -0.5] {
        let sc = scenario(Some((Fault::Ls, change)));
        let (host, host_change) = host_named(&sc);
        let rig = board_run(&sc);
        let iso = rig.supervisor.isolation().copied();
        let board = iso.and_then(|i| i.named()).map(|n| match n {
            monitor_core::Named::Fault(c) => (IsolationName::Fault(c.fault), c.change),
            monitor_core::Named::Friction { bl, .. } => (IsolationName::Friction, bl.change),
        });
        let (label, size, _) = isolation_summary(iso.as_ref());
        let trace: Vec<bool> = rig
            .seen
            .iter()
            .filter(|s| s.t_ms >= 15_000)
            .map(|s| s.tick.lamps.fault)
            .collect();
        let code = panel::read_blink_code(&trace, PANEL_PERIOD_MS);
        eprintln!(
            "ls {change:+}: host {host:?} {host_change:?}; board {board:?}, iso={label} iso_change={size:.3}, code {code:?}"
        );
        // The board names the fault the host names, or (where the joint fit's calibrated
        // probability stays under the name's 0.9, issue 48) no fault on either, the FAULT
        // lamp dark.
        let board_fault = board
            .map(|(n, _)| n)
            .filter(|n| *n != IsolationName::Friction);
        // The board names ls at the end with its size, or blinked ls's code on the way
        // (its last point may read the load's move as the friction class, amber); it never
        // blinks another fault's code.
        let ls_code = Fault::Ls.index() as u8 + 1;
        let ok = match host {
            Some(IsolationName::Fault(Fault::Ls)) => {
                let named_ls = board_fault == host
                    && label == "ls"
                    && (f64::from(size) - change).abs() <= 0.15 * change.abs();
                (named_ls || code == Some(ls_code)) && code.is_none_or(|c| c == ls_code)
            }
            None => board_fault.is_none() && code.is_none(),
            Some(_) => false,
        };
        if !ok {
            wrong.push(format!(
                "ls {change:+}: host {host:?} {host_change:?}, board {board:?} iso={label} {size}, code {code:?}, candidates {:?}, {}",
                iso.map(|i| i.candidates.map(|c| (c.fault, c.probability))),
                trace.iter().map(|&b| if b { '#' } else { '.' }).collect::<String>()
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn the_load_steps_alone_name_no_fault_on_the_board() {
    let rig = board_run(&scenario(None));
    let named = rig.supervisor.isolation().and_then(|i| i.named_fault());
    assert!(named.is_none(), "{named:?}");
}
