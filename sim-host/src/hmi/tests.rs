//! The live HMI's three sources, tested through the library (`sim_host::hmi`): the live
//! simulation with its keys, a replay of a small simulated log through the data-quality stage
//! and the core, and the firmware's status lines (the board's own writer). The binary's own
//! tests (`hmi --stdin`, `--help`, a log replay's options) are in `sim-host/tests/cli/hmi.rs`;
//! a real terminal in `sim-host/tests/cli/hmi_tmux.rs`.

use crate::hmi::live::LiveSim;
use crate::hmi::log_replay::LogReplay;
use crate::hmi::status_line::{self, StdinStatus};
use crate::hmi::{Controls, HmiState, Key, Source, Speed};
use monitor_core::Fault;
use monitor_io::log::Log;
use monitor_io::params::ParamFile;
use monitor_replay::ReplayOptions;
use monitor_sim::simulate_to_vec;
use monitor_studies::demo::MonitorState;
use monitor_studies::fault_signatures::{scenario, Protocol};

/// Runs the live source for `seconds` of simulated time, in 0.25 s steps as the screen
/// would.
fn run(live: &mut LiveSim, state: &mut HmiState, seconds: f64) {
    for _ in 0..(seconds / 0.25).round() as usize {
        live.advance(0.25, state);
    }
}

fn names(state: &HmiState) -> Vec<Fault> {
    state
        .latest
        .as_ref()
        .map(|s| s.candidates.iter().map(|(f, _)| *f).collect())
        .unwrap_or_default()
}

#[test]
fn live_simulation_commissions_and_a_key_injects_a_fault() {
    let mut live = LiveSim::demo_motor().expect("reference motor");
    let mut state = live.initial_state();
    run(&mut live, &mut state, 2.0);
    let s = state.latest.clone().expect("readings");
    assert!(
        (s.t_s - 1.95).abs() < 1e-6,
        "one reading every 50 ms: {}",
        s.t_s
    );
    assert!(
        s.speed_rpm > 1700.0 && s.speed_rpm < 1800.0,
        "{}",
        s.speed_rpm
    );
    assert_eq!(s.state, MonitorState::Healthy, "{:?}", s.state);
    assert!(!s.learned);
    assert!(s.iqs_a.is_some_and(|x| x > 0.0) && s.vqs_v.is_some_and(|x| x > 100.0));
    assert!(
        s.supply_hz.is_some_and(|f| (f - 60.0).abs() < 0.5),
        "{:?}",
        s.supply_hz
    );
    // The strip chart holds the readings so far.
    assert_eq!(state.history.len(), 40);

    // c: commissioning with progress, then the learned thresholds in force.
    assert!(live.key(Key::Char('c'), &mut state));
    run(&mut live, &mut state, 1.0);
    let progress = match state.latest.as_ref().map(|s| &s.state) {
        Some(MonitorState::Commissioning(x)) => *x,
        other => panic!("not commissioning: {other:?}"),
    };
    assert!(progress > 0.0 && progress < 1.0, "{progress}");
    assert!(state
        .events
        .iter()
        .any(|e| e.contains("commissioning run 1 started")));
    run(&mut live, &mut state, 3.5);
    let s = state.latest.clone().expect("readings");
    assert!(
        s.learned && s.state == MonitorState::Healthy,
        "{:?}",
        s.state
    );
    assert!(!s.fault_lamp && names(&state).is_empty());

    // 6: the paper's Enable_F_Bl switch, Bl +50 %: r2..r4 light, b and bl named. To the
    // paper's model a Bl change is a load change, and the load current has left the
    // commissioned range: the amber "operating point moved" state, the FAULT lamp off
    // (issue 28).
    assert!(live.key(Key::Char('6'), &mut state));
    assert_eq!(live.controls().faults, vec![(Fault::Bl, 0.5)]);
    assert!(matches!(&state.controls, Controls::Live(c) if c.faults.len() == 1));
    run(&mut live, &mut state, 3.0);
    let s = state.latest.clone().expect("readings");
    assert_eq!(s.lamps, [false, true, true, true], "{:?}", s.residuals);
    assert!(!s.fault_lamp);
    let n = names(&state);
    assert!(n.contains(&Fault::Bl) && n.contains(&Fault::B), "{n:?}");
    assert!(
        matches!(
            &s.state,
            MonitorState::Moved(monitor_api::replay::MovedWhy::OutsideRange { departures })
                if departures.iter().any(|d| d.quantity == monitor_api::replay::RangeQuantity::Load)
        ),
        "{:?}",
        s.state
    );
    // A lit residual lies outside its learned band.
    let bands = s.bands.expect("bands");
    for (k, (r, (c, h))) in s.residuals.iter().zip(bands).enumerate().skip(1) {
        assert!((r - c).abs() > h, "r{}: {r} in {c}±{h}", k + 1);
    }

    // 6 again clears it: the lamps go out once the load is back.
    assert!(live.key(Key::Char('6'), &mut state));
    assert!(live.controls().faults.is_empty());
    run(&mut live, &mut state, 4.0);
    let s = state.latest.clone().expect("readings");
    assert_eq!(s.lamps, [false; 4], "{:?} {:?}", s.residuals, s.state);
}

/// A load step of 10-40 % on the commissioned live motor is the amber MOVED state or
/// healthy, never a FAULT (it used to turn red `FAULT b/bl +10 %` while `diagnose` called the
/// same step healthy): every reading after the step, by the one verdict's table.
#[test]
fn a_load_step_of_10_to_40_percent_is_never_a_fault_on_the_live_screen() {
    for steps in [1usize, 4] {
        let mut live = LiveSim::demo_motor().expect("reference motor");
        let mut state = live.initial_state();
        run(&mut live, &mut state, 1.5);
        assert!(live.key(Key::Char('c'), &mut state));
        run(&mut live, &mut state, 4.5);
        assert!(state.latest.as_ref().is_some_and(|s| s.learned));
        for _ in 0..steps {
            live.key(Key::Char('+'), &mut state);
        }
        let mut seen = Vec::new();
        for _ in 0..24 {
            live.advance(0.25, &mut state);
            let s = state.latest.clone().expect("readings");
            let (word, _) = crate::hmi::lamp_and_header(
                &s.state,
                s.fault_lamp,
                s.call,
                &[],
                s.isolation.as_ref(),
            );
            seen.push((word, s.call));
            assert!(
                !s.fault_lamp && word != "FAULT",
                "+{} %: {word} {:?} {:?}",
                10 * steps,
                s.call,
                s.state
            );
        }
        eprintln!("+{} %: {seen:?}", 10 * steps);
        // Settled on the new load: the amber state (or healthy once the lamps are out),
        // neither FAULT nor WATCHING.
        let settled = &seen[seen.len() - 8..];
        assert!(
            settled.iter().all(|(w, _)| w.is_empty() || *w == "MOVED"),
            "+{} %: {settled:?}",
            10 * steps
        );
    }
}

#[test]
fn live_simulation_steps_the_load_and_the_supply() {
    let mut live = LiveSim::demo_motor().expect("reference motor");
    let mut state = live.initial_state();
    run(&mut live, &mut state, 1.5);
    let before = state.latest.clone().expect("readings");
    for _ in 0..3 {
        live.key(Key::Char('+'), &mut state);
    }
    live.key(Key::Char('F'), &mut state);
    run(&mut live, &mut state, 1.5);
    let after = state.latest.clone().expect("readings");
    // More load: more torque current; 1 Hz more supply: the frame follows.
    assert!(
        after.iqs_a.unwrap_or(0.0) > before.iqs_a.unwrap_or(0.0) * 1.1,
        "{:?} -> {:?}",
        before.iqs_a,
        after.iqs_a
    );
    let f = after.supply_hz.unwrap_or(0.0);
    assert!((f - 61.0).abs() < 0.2, "{f}");
    match &state.controls {
        Controls::Live(c) => {
            assert!((c.load_scale - 1.3).abs() < 1e-9 && (c.supply_hz - 61.0).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // Space pauses: no new reading.
    live.key(Key::Char(' '), &mut state);
    let t = state.latest.as_ref().map(|s| s.t_s);
    live.advance(0.25, &mut state);
    assert_eq!(state.latest.as_ref().map(|s| s.t_s), t);
}

#[test]
fn a_simulated_log_replays_with_speed_pause_and_seek() {
    let params = ParamFile::reference_3hp();
    let proto = Protocol {
        duration_s: 7.5,
        fault_at_s: 5.0,
        sample_rate_hz: 5_000.0,
        ..Protocol::default()
    };
    let sc = scenario(Some((Fault::Lr, -0.5)), &proto);
    let log = Log {
        channels: sc.sensors.channels(),
        rows: simulate_to_vec(&params, &sc).expect("simulation"),
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("lr.csv");
    log.write(&path).expect("write");
    let opts = ReplayOptions {
        commission: Some(monitor_replay::CommissionWindow::of(2.0, 4.0)),
        ..ReplayOptions::default()
    };
    let mut replay = LogReplay::start(params, &path, opts, Speed::X1).expect("log opens");
    let mut state = replay.initial_state();
    replay.wait();

    // 1x: one second of wall time is one second of log.
    replay.advance(1.0, &mut state);
    assert!((replay.controls().position_s - 1.0).abs() < 1e-9);
    let s = state.latest.clone().expect("reading");
    assert!((s.t_s - 1.0).abs() < 1e-6, "{}", s.t_s);
    // 10x.
    replay.key(Key::Char('>'), &mut state);
    replay.advance(0.2, &mut state);
    assert!((replay.controls().position_s - 3.0).abs() < 1e-9);
    assert!(matches!(
        state.latest.as_ref().map(|s| &s.state),
        Some(MonitorState::Commissioning(_))
    ));
    // Pause: time stands still.
    replay.key(Key::Char(' '), &mut state);
    replay.advance(1.0, &mut state);
    assert!((replay.controls().position_s - 3.0).abs() < 1e-9);
    // Seek to the end: the lr fault is named and the verdict is in.
    replay.key(Key::End, &mut state);
    let c = replay.controls().clone();
    assert!(c.done && (c.position_s - 7.5).abs() < 0.06, "{c:?}");
    assert_eq!(c.verdict.as_deref(), Some("fault"));
    let s = state.latest.clone().expect("reading");
    assert!(s.learned && s.fault_lamp, "{:?}", s.state);
    assert!(names(&state).contains(&Fault::Lr), "{:?}", names(&state));
    assert!(
        state.history.len() > 150,
        "the strip chart's 10 s: {}",
        state.history.len()
    );
    // Seek back 5 s: inside the commissioning window again.
    replay.key(Key::Left, &mut state);
    let s = state.latest.clone().expect("reading");
    assert!(
        (s.t_s - (c.position_s - 5.0)).abs() < 0.06,
        "{} {}",
        s.t_s,
        c.position_s
    );
    assert!(
        matches!(s.state, MonitorState::Commissioning(_)),
        "{:?}",
        s.state
    );
    replay.key(Key::Home, &mut state);
    assert_eq!(replay.controls().position_s, 0.0);
    // A missing log is a one-line error before the screen starts.
    let e = LogReplay::start(params, &dir.path().join("nope.csv"), opts, Speed::Max)
        .err()
        .expect("missing log")
        .to_string();
    assert!(e.contains("nope.csv"), "{e}");
}

#[test]
fn firmware_status_lines_from_a_recorded_sample() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fw_status_sample.txt");
    let file = std::fs::File::open(&path).expect("sample");
    let mut src = StdinStatus::from_reader(file);
    let mut state = src.initial_state();
    for _ in 0..200 {
        src.advance(0.05, &mut state);
        if matches!(&state.controls, Controls::Stdin(c) if c.ended) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let Controls::Stdin(c) = &state.controls else {
        panic!("{:?}", state.controls)
    };
    assert!(c.ended);
    assert_eq!(c.status_lines, 5);
    assert_eq!(c.mode.as_deref(), Some("commissioned"));
    // The last status line (colours, one-line location) as the screen shows it.
    let s = state.latest.clone().expect("reading");
    assert!((s.t_s - 0.4).abs() < 1e-9, "{}", s.t_s);
    assert_eq!(s.lamps, [false, true, true, true]);
    assert!(s.fault_lamp && s.learned);
    assert_eq!(names(&state), vec![Fault::B, Fault::Bl]);
    assert!((s.speed_rpm - 148.2 * 60.0 / std::f32::consts::TAU).abs() < 0.01);
    assert_eq!(s.iqs_a, Some(4.12));
    assert_eq!(s.supply_hz, Some(50.01));
    let bands = s.bands.expect("bands");
    assert_eq!(bands[1], (-0.0101, 0.011));
    assert!(matches!(s.state, MonitorState::Fault(_)));
    assert_eq!(state.history.len(), 5);
    // The other log lines are events: the overrun warning among them.
    assert!(
        state
            .events
            .iter()
            .any(|e| e == "WARN ADC DMA overrun #1 (adc1 true adc2 false)"),
        "{:?}",
        state.events
    );
    assert!(
        state.events.iter().any(|e| e.contains("mode commissioned")),
        "{:?}",
        state.events
    );
}

#[test]
fn status_line_fields() {
    // Commissioning with progress from run=ID:LEARNED/NEEDED.
    let l = "INFO  r=[0.1, 0.2, 0.3, 0.4] lamps=[false, false, false, false] fault=false top=none(0.0) 2nd=none(0.0) wm=150.0rad/s mode=commissioning run=3:1000/4000";
    let s = status_line::parse(l).expect("status line").snapshot(1.0);
    assert_eq!(s.state, MonitorState::Commissioning(0.25));
    assert_eq!(s.residuals, [0.1, 0.2, 0.3, 0.4]);
    // An older firmware's line, without the operating point: those are absent, not zero.
    assert_eq!(s.iqs_a, None);
    assert_eq!(s.bands, None);
    // A decoder timestamp is the time axis.
    let t = status_line::parse(&format!("12.500000 {l}")).expect("status line");
    assert_eq!(t.timestamp_s, Some(12.5));
    // Sensor flags and a transient.
    let l2 = "r=[0.0, 0.0, 0.0, 0.0] lamps=[false, false, false, false] fault=true top=none(0.0) 2nd=none(0.0) steady=false sens=true,false,false";
    let s2 = status_line::parse(l2).expect("status line").snapshot(0.0);
    assert_eq!(s2.sensor_faults, vec![Fault::CurrentSensor]);
    assert_eq!(s2.state, MonitorState::Transient);
    // Not status lines.
    for other in [
        "INFO  sampling at 10000 Hz",
        "└─ drive_monitor::firmware::log_status @ src/firmware.rs:545",
        "r=[0.1, 0.2] lamps=[false] fault=false",
        "",
    ] {
        assert!(status_line::parse(other).is_none(), "{other}");
    }
}

/// The firmware's full status line, written by the core's writer (the one the board uses),
/// on the screen: the isolation with the rise, the winding, the sensor fault, the moved and
/// the could-not-judge states.
#[test]
fn the_firmwares_full_line_on_the_screen() {
    use monitor_core::status_line::StatusLine;
    use monitor_core::verdict::Verdict;
    let written = StatusLine {
        residuals: [0.0123, -0.1, 0.25, -0.004],
        lamps: [false, true, true, true],
        fault: true,
        call: "fault",
        top: ("b", 0.5),
        second: ("bl", 0.5),
        speed_rad_s: 150.5,
        mode: "commissioned",
        run: (2, 4000, 4000),
        quasi_steady: true,
        evaluating: true,
        sensors: (false, true, false),
        isolation: ("rr", 0.48, 0.93),
        winding: ("b", 0.041),
        moved: true,
        winding_rise_k: 54.4,
        ..StatusLine::default()
    };
    let line = format!("INFO  {written}");
    let s = status_line::parse(&line).unwrap_or_else(|| panic!("not read: {line}"));
    assert_eq!(s.call, Some(Verdict::Fault));
    assert_eq!(s.candidates, vec![(Fault::B, 0.5), (Fault::Bl, 0.5)]);
    let snap = s.snapshot(0.0);
    let iso = snap
        .isolation
        .as_ref()
        .expect("the isolation on the screen");
    assert!(
        iso.text().ends_with("; windings +54 K (heating)"),
        "{}",
        iso.text()
    );
    assert_eq!(
        (iso.named.map(|n| n.name()), iso.change),
        (Some("rr"), Some(0.48))
    );
    assert_eq!(
        snap.asymmetry.map(|a| (a.phase, a.ratio)),
        Some((monitor_core::Phase::B, 0.041))
    );
    assert!(snap.learned && snap.fault_lamp);
    assert_eq!(snap.sensor_faults, vec![Fault::VoltageSensor]);
    assert!(matches!(snap.state, MonitorState::Fault(_)));
    // The friction class named (a load change, to the paper's model) and no sensor fault:
    // the board's "operating point moved" state, no FAULT lamp; `moved=false` keeps the fault.
    let friction = line
        .replace("iso=rr", "iso=b/bl")
        .replace("sens=false,true,false", "sens=false,false,false");
    let snap = status_line::parse(&friction).expect("read").snapshot(0.0);
    assert!(matches!(snap.state, MonitorState::Moved(_)) && !snap.fault_lamp);
    let fixed = friction.replace("moved=true", "moved=false");
    let snap = status_line::parse(&fixed).expect("read").snapshot(0.0);
    assert!(matches!(snap.state, MonitorState::Fault(_)) && snap.fault_lamp);
    // The board's verdict lights its FAULT lamp, not `fault=`: watching and could not judge
    // (older firmware's `not-commissioned`) show the lamps lit, the FAULT lamp dark and the word.
    for (call, word) in [
        ("watching", "WATCHING"),
        ("could_not_judge", "NOT JUDGED"),
        ("not-commissioned", "NOT JUDGED"),
    ] {
        let snap = status_line::parse(&fixed.replace("call=fault", &format!("call={call}")))
            .expect("read")
            .snapshot(0.0);
        assert!(matches!(snap.state, MonitorState::Fault(_)) && !snap.fault_lamp);
        let (lamp, _) = crate::hmi::lamp_and_header(
            &snap.state,
            snap.fault_lamp,
            snap.call,
            &snap.candidates,
            snap.isolation.as_ref(),
        );
        assert_eq!(lamp, word);
    }
}

/// Issue 76: the state column names a fault only where the isolation names it alone, as the
/// verdict does: beside the named `rs +50 %` the lamps' three-way tie (which names `ls` and
/// `voltage_sensor` too) is not spelled; without a name the tie is the state.
#[test]
fn a_named_fault_stands_alone_in_the_state() {
    use monitor_api::replay::{FaultCandidate, IsolationName};
    use monitor_core::verdict::Verdict;
    let tie = vec![
        (Fault::Rs, 1.0 / 3.0),
        (Fault::Ls, 1.0 / 3.0),
        (Fault::VoltageSensor, 1.0 / 3.0),
    ];
    let named = crate::hmi::IsolationView {
        state: monitor_core::IsolationState::Isolated,
        named: Some(IsolationName::Fault(Fault::Rs)),
        change: Some(0.5),
        candidates: vec![FaultCandidate {
            fault: Fault::Rs,
            probability: 1.0,
            change: Some(0.5),
            phase: None,
        }],
        winding_rise_k: None,
    };
    let state = MonitorState::Fault(tie.clone());
    let header = |iso: Option<&crate::hmi::IsolationView>, call| {
        crate::hmi::lamp_and_header(&state, call == Verdict::Fault, Some(call), &tie, iso)
    };
    assert_eq!(
        header(Some(&named), Verdict::Fault),
        ("FAULT", "rs +50 %".to_string())
    );
    let unnamed = crate::hmi::IsolationView {
        named: None,
        change: None,
        ..named.clone()
    };
    assert_eq!(
        header(Some(&unnamed), Verdict::Watching),
        (
            "WATCHING",
            "(sig. rs p 0.33 / ls p 0.33 / voltage_sensor p 0.33)".to_string()
        )
    );
}

/// The lamps' signature in the header: the candidates, B and Bl as one class, or none.
#[test]
fn the_signature_is_spelled_by_the_hmi() {
    assert_eq!(
        crate::hmi::signature_text([(Fault::Rs, 1.0 / 3.0), (Fault::Ls, 1.0 / 3.0)]),
        "sig. rs p 0.33 / ls p 0.33"
    );
    assert_eq!(
        crate::hmi::signature_text([(Fault::B, 0.5), (Fault::Bl, 0.5)]),
        "sig. b/bl p 1.00"
    );
    assert_eq!(crate::hmi::signature_text([]), "sig. none");
}
