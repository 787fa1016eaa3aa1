//! The firmware's defmt status line and its reader (`sim-host hmi --stdin`) agree: the
//! format string of `log_status` in `src/firmware.rs` is rendered here with known values
//! the way defmt's decoder prints them, and `sim_host::hmi::status_line::parse` must read
//! every value back; the firmware docs' "The status line" (docs/firmware.md) documents every field.

use monitor_core::verdict::Verdict;
use monitor_core::Fault;
use monitor_studies::demo::MonitorState;
use sim_host::hmi::status_line;
use std::path::PathBuf;

fn read(path: &str) -> String {
    let full = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{}: {e}", full.display()))
}

/// The format string and the argument expressions of the `info!` in `fn log_status`.
fn log_status_format() -> (String, Vec<String>) {
    let src = read("src/firmware.rs");
    let body = &src[src
        .find("fn log_status")
        .expect("fn log_status in src/firmware.rs")..];
    let call = &body[body.find("info!(").expect("info! in log_status") + "info!(".len()..];
    let open = call.find('"').expect("format string");
    let close = open
        + 1
        + call[open + 1..]
            .find('"')
            .expect("end of the format string");
    let format = call[open + 1..close].to_string();
    let args_end = call[close..].find(");").expect("end of info!") + close;
    let args = call[close + 1..args_end]
        .split(',')
        .map(|a| a.trim().to_string())
        .filter(|a| !a.is_empty())
        .collect();
    (format, args)
}

/// What defmt's decoder prints for each argument, by its expression in `log_status`.
fn value(arg: &str) -> &'static str {
    match arg {
        "s.residuals" => "[0.0123, -0.1, 0.25, -0.004]",
        "s.residual_lamps" => "[false, true, true, true]",
        "s.fault_detected" => "true",
        "call" => "fault",
        "top_name" => "b",
        "top_p" => "0.5",
        "second_name" => "bl",
        "second_p" => "0.5",
        "s.speed_rad_s" => "150.5",
        "s.zero_crossing_locked" => "None",
        "mode" => "commissioned",
        "s.run.id" => "2",
        "s.run.blocks_learned" => "4000",
        "s.run.blocks_needed" => "4000",
        "OVERRUNS.load(Ordering::Relaxed)" | "RESTARTS.load(Ordering::Relaxed)" => "0",
        "s.samples" => "123456",
        "max_update_cycles" => "2310",
        "s.operating.iqs" => "4.25",
        "s.operating.i_f" => "2.5",
        "s.operating.vqs" => "320.5",
        "s.frame_hz" => "50.02",
        "s.quasi_steady" => "true",
        "s.evaluating" => "true",
        "s.sensor_fault.current" => "false",
        "s.sensor_fault.voltage" => "true",
        "s.sensor_fault.speed" => "false",
        "mid" => "[0.001, -0.01, 0.009, 0.0]",
        "half" => "[0.006, 0.011, 0.012, 0.007]",
        "iso_name" => "rr",
        "iso_change" => "0.48",
        "iso_p" => "0.93",
        "wind_name" => "b",
        "wind_i2" => "0.041",
        "s.moved" => "true",
        "rise_k" => "54.4",
        "vdda_v" => "3.301",
        "bor" => "4",
        other => panic!(
            "log_status prints `{other}`: give it a test value here and teach \
             sim_host::hmi::status_line to read it"
        ),
    }
}

/// The format string with each `{...}` placeholder replaced by its argument's value.
fn render(format: &str, args: &[String]) -> String {
    let mut out = String::new();
    let mut rest = format;
    let mut k = 0;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let close = open + rest[open..].find('}').expect("closing brace");
        out.push_str(value(args.get(k).expect("an argument per placeholder")));
        k += 1;
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    assert_eq!(k, args.len(), "placeholders and arguments differ in number");
    out
}

#[test]
fn the_hmi_reads_every_field_the_firmware_prints() {
    let (format, args) = log_status_format();
    let body = render(&format, &args);
    // As probe-rs prints it: the level before, the location on the next line.
    let line = format!("INFO  {body}");
    let s = status_line::parse(&line).unwrap_or_else(|| panic!("not read: {line}"));
    assert_eq!(s.residuals, [0.0123, -0.1, 0.25, -0.004]);
    assert_eq!(s.lamps, [false, true, true, true]);
    assert!(s.fault);
    assert_eq!(s.call, Some(Verdict::Fault));
    assert_eq!(s.candidates, vec![(Fault::B, 0.5), (Fault::Bl, 0.5)]);
    assert_eq!(s.wm_rad_s, Some(150.5));
    assert_eq!(s.mode.as_deref(), Some("commissioned"));
    assert_eq!(s.run, Some((2, 4000, 4000)));
    assert_eq!(
        (s.iqs_a, s.ids_a, s.vqs_v, s.supply_hz),
        (Some(4.25), Some(2.5), Some(320.5), Some(50.02))
    );
    assert_eq!((s.steady, s.evaluating), (Some(true), Some(true)));
    assert_eq!(s.sensors, Some([false, true, false]));
    assert_eq!(
        s.band,
        Some(([0.001, -0.01, 0.009, 0.0], [0.006, 0.011, 0.012, 0.007]))
    );
    assert_eq!(
        s.isolation,
        Some(status_line::FirmwareIsolation {
            named: "rr".to_string(),
            change: 0.48,
            probability: 0.93
        })
    );
    assert_eq!(s.winding, Some((monitor_core::Phase::B, 0.041)));
    assert_eq!(s.moved, Some(true));
    assert_eq!(s.winding_rise_k, Some(54.4));
    // The screen's isolation line carries the rise.
    let iso = s.snapshot(0.0).isolation.expect("iso= read");
    assert!(
        iso.text().ends_with("; windings +54 K (heating)"),
        "{}",
        iso.text()
    );
    let snap = s.snapshot(0.0);
    assert_eq!(
        snap.asymmetry.map(|a| (a.phase, a.ratio)),
        Some((monitor_core::Phase::B, 0.041))
    );
    let iso = snap
        .isolation
        .as_ref()
        .expect("the isolation on the screen");
    assert_eq!(
        (iso.named.map(|n| n.name()), iso.change),
        (Some("rr"), Some(0.48))
    );
    assert!(snap.learned && snap.fault_lamp);
    assert_eq!(snap.sensor_faults, vec![Fault::VoltageSensor]);
    assert!(matches!(snap.state, MonitorState::Fault(_)));
    // The same line with the friction class named (a load change, to the paper's model)
    // and no sensor fault: the board's "operating point moved" state, no FAULT lamp; and
    // `moved=false` keeps the fault.
    let friction = line
        .replace("iso=rr", "iso=b/bl")
        .replace("sens=false,true,false", "sens=false,false,false");
    let snap = status_line::parse(&friction).expect("read").snapshot(0.0);
    assert!(matches!(snap.state, MonitorState::Moved(_)) && !snap.fault_lamp);
    let snap = status_line::parse(&friction.replace("moved=true", "moved=false"))
        .expect("read")
        .snapshot(0.0);
    assert!(matches!(snap.state, MonitorState::Fault(_)) && snap.fault_lamp);
    // The board's verdict lights its FAULT lamp, not `fault=`: watching (a name under 5 %)
    // and could not judge (no name beyond +-30 % against the record's values; older
    // firmware's `not-commissioned`) show the lamps lit, the FAULT lamp dark and the word.
    let fixed = friction.replace("moved=true", "moved=false");
    for (call, word) in [
        ("watching", "WATCHING"),
        ("could_not_judge", "NOT JUDGED"),
        ("not-commissioned", "NOT JUDGED"),
    ] {
        let snap = status_line::parse(&fixed.replace("call=fault", &format!("call={call}")))
            .expect("read")
            .snapshot(0.0);
        assert!(matches!(snap.state, MonitorState::Fault(_)) && !snap.fault_lamp);
        let (lamp, _) = sim_host::hmi::lamp_and_header(
            &snap.state,
            snap.fault_lamp,
            snap.call,
            &snap.candidates,
            snap.isolation.as_ref(),
        );
        assert_eq!(lamp, word);
    }
}

#[test]
fn the_firmware_docs_document_every_field_of_the_status_line() {
    let (format, _) = log_status_format();
    let readme = read("docs/firmware.md");
    let start = readme
        .find("## The status line")
        .expect("docs/firmware.md section \"The status line\"");
    let section = &readme[start..];
    let section = &section[..section[4..].find("\n#").map_or(section.len(), |e| e + 4)];
    for token in format.split_whitespace() {
        let Some((key, _)) = token.split_once('=') else {
            continue;
        };
        assert!(
            section.contains(&format!("{key}=")),
            "docs/firmware.md \"The status line\" does not document `{key}=`"
        );
    }
}
