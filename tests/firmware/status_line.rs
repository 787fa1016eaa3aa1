//! The firmware's status line goes through the core's one format, writer and parser
//! (`monitor_core::status_line`, which `sim-host hmi --stdin` reads with too): the line the
//! firmware builds from a status (`drive_monitor::app::status_line`) reads back with every
//! value in place, and docs/firmware.md's "The status line" documents every field.

use drive_monitor::app::{status_line, BoardCounters, MonitorStatus};
use monitor_core::status_line::{parse, FORMAT};
use monitor_core::verdict::Verdict;
use monitor_core::{CommissioningRun, Fault, Operating, Phase, SensorFlags};
use std::path::PathBuf;

fn read(path: &str) -> String {
    let full = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path);
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{}: {e}", full.display()))
}

/// A status with a value in every field the line prints.
fn status() -> MonitorStatus {
    MonitorStatus {
        samples: 123_456,
        residuals: [0.0123, -0.1, 0.25, -0.004],
        residual_lamps: [false, true, true, true],
        fault_detected: true,
        sensor_fault: SensorFlags {
            current: false,
            voltage: true,
            speed: false,
        },
        top: Some((Fault::B, 0.5)),
        second: Some((Fault::Bl, 0.5)),
        speed_rad_s: 150.5,
        zero_crossing_locked: None,
        run: CommissioningRun {
            id: 2,
            blocks_learned: 4000,
            blocks_needed: 4000,
            ..CommissioningRun::default()
        },
        operating: Operating {
            iqs: 4.25,
            i_f: 2.5,
            vqs: 320.5,
            ..Operating::default()
        },
        frame_hz: 50.02,
        quasi_steady: true,
        evaluating: true,
        bands: [(0.001, 0.006), (-0.01, 0.011), (0.009, 0.012), (0.0, 0.007)],
        winding: Some((Phase::B, 0.041)),
        moved: true,
        clipped: 17,
        encoder_rejects: 3,
        clip_range: true,
        ..MonitorStatus::default()
    }
}

#[test]
fn the_firmwares_line_reads_back_through_the_shared_module() {
    let line = status_line(
        &status(),
        None,
        54.4,
        ("commissioned", Verdict::Fault.name()),
        2310,
        BoardCounters {
            overruns: 3,
            restarts: 1,
            stack_used_bytes: 2_344,
        },
        (3.301, 4),
    );
    // As probe-rs prints it: the level before, the location on the next line.
    let text = format!("INFO  {line}");
    let s = parse(&text).unwrap_or_else(|| panic!("not read: {text}"));
    assert_eq!(s.residuals, [0.0123, -0.1, 0.25, -0.004]);
    assert_eq!(s.lamps, [false, true, true, true]);
    assert!(s.fault);
    assert_eq!(s.call, Some(Verdict::Fault));
    assert_eq!(
        s.candidates,
        [Some((Fault::B, 0.5)), Some((Fault::Bl, 0.5))]
    );
    assert_eq!(s.speed_rad_s, Some(150.5));
    assert_eq!(s.zero_crossing_locked, Some(None));
    assert_eq!(s.mode, Some("commissioned"));
    assert_eq!(s.run, Some((2, 4000, 4000)));
    assert_eq!(
        (s.overruns, s.restarts, s.samples, s.max_update_cycles),
        (Some(3), Some(1), Some(123_456), Some(2310))
    );
    assert_eq!(
        (s.iqs_a, s.ids_a, s.vqs_v, s.frame_hz),
        (Some(4.25), Some(2.5), Some(320.5), Some(50.02))
    );
    assert_eq!((s.quasi_steady, s.evaluating), (Some(true), Some(true)));
    assert_eq!(s.sensors, Some([false, true, false]));
    assert_eq!(
        s.band,
        Some(([0.001, -0.01, 0.009, 0.0], [0.006, 0.011, 0.012, 0.007]))
    );
    // No isolator: not judged.
    assert_eq!(s.isolation, Some(("not-judged", 0.0, 0.0)));
    assert_eq!(s.winding, Some((Phase::B, 0.041)));
    assert_eq!(s.moved, Some(true));
    assert_eq!(s.winding_rise_k, Some(54.4));
    assert_eq!((s.vdda_v, s.bor), (Some(3.301), Some(4)));
    assert_eq!(
        (s.clipped, s.encoder_rejects, s.stack_used_bytes),
        (Some(17), Some(3), Some(2_344))
    );
    assert_eq!(s.clip_range, Some(true));
}

#[test]
fn the_firmware_writes_the_line_with_the_shared_writer() {
    let src = read("src/firmware.rs");
    let body = &src[src.find("fn log_status").expect("fn log_status")..];
    let body = &body[..body.find("\n}\n").expect("its end")];
    assert!(
        body.contains("status_line(") && body.contains(".log_info()") && !body.contains("info!("),
        "log_status must write the core's status line (monitor_core::status_line)"
    );
}

#[test]
fn the_firmware_docs_document_every_field_of_the_status_line() {
    let readme = read("docs/firmware.md");
    let start = readme
        .find("## The status line")
        .expect("docs/firmware.md section \"The status line\"");
    let section = &readme[start..];
    let section = &section[..section[4..].find("\n#").map_or(section.len(), |e| e + 4)];
    for token in FORMAT.split_whitespace() {
        let Some((key, _)) = token.split_once('=') else {
            continue;
        };
        assert!(
            section.contains(&format!("{key}=")),
            "docs/firmware.md \"The status line\" does not document `{key}=`"
        );
    }
}
