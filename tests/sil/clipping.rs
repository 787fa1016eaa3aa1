//! Clipping on the board's panel and status line (issue 74): a direct-on-line start's
//! inrush clips the 10 A current front end, and those samples are held out of the
//! residuals and counted (`clip=`) with no FAULT and no sensor named; clipping that
//! persists in steady running (a front end whose range the running current exceeds) is
//! the range state (`clip_range=true`, the panel's range mark, the verdict "could not
//! judge"), not a sensor FAULT either. The rig's frames are quantized by the record's
//! front end: a reading beyond its full scale sits on a rail, the clip the board's
//! per-conversion check also sees (`tests/sil/conversions.rs` runs that check).

use super::*;
use drive_monitor::app::{status_line, BoardCounters};
use drive_monitor::motor_source;
use monitor_core::motor_record::MotorRecord;
use monitor_core::status_line::parse;
use monitor_core::verdict::Verdict;

/// No tick of `rig` lit the FAULT lamp, named a sensor or called a FAULT.
fn no_fault_named(rig: &Rig) {
    for s in &rig.seen {
        assert!(!s.tick.lamps.fault, "{} ms: the FAULT lamp lit", s.t_ms);
        assert!(
            !s.status.sensor_fault.any(),
            "{} ms: a sensor named: {:?}",
            s.t_ms,
            s.status.sensor_fault
        );
        assert_ne!(s.tick.call, Verdict::Fault, "{} ms", s.t_ms);
    }
}

/// The status line of `seen`'s status and call, as the firmware writes it, read back.
fn line_of(seen: &Seen) -> String {
    let line = status_line(
        &seen.status,
        None,
        0.0,
        (seen.tick.mode.name(), seen.tick.call.name()),
        0,
        BoardCounters::default(),
        (3.3, 4),
    );
    format!("INFO  {line}")
}

/// The DOL start of the healthy 2.2 kW machine at rated load clips the 10 A front end
/// during its inrush (hundreds of samples, none after the run-up): counted on the status
/// line, held out, no FAULT lamp, no sensor named, never the range state.
#[test]
fn a_dol_starts_inrush_clips_are_counted_and_name_nothing() {
    let frames = steady_frames(8.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&frames, |_, _| {}).unwrap();
    let clipped = rig.last().status.clipped;
    let after_start = rig
        .seen
        .iter()
        .find(|s| s.t_ms >= 1_500)
        .expect("a tick after the start")
        .status
        .clipped;
    assert!(clipped > 100, "{clipped} clipped samples");
    assert_eq!(after_start, clipped, "clipped after the run-up");
    assert!(rig.last().status.clipped_current == clipped);
    no_fault_named(&rig);
    assert!(rig.seen.iter().all(|s| !s.status.clip_range));
    let line = line_of(rig.last());
    let read = parse(&line).expect("the status line");
    assert_eq!(
        (read.clipped, read.clip_range, read.sensors),
        (Some(clipped), Some(false), Some([false; 3]))
    );
    println!("the start clipped {clipped} samples");
}

/// The same machine behind a 6 A front end (the record's current full scale; its running
/// current peaks at about 6.8 A): it clips around every current peak in steady running.
/// The range state is set 6 s into steady running (three windows of 2 s after the run-up)
/// and holds; no FAULT lamp, no sensor named; the verdict "could not judge", the status
/// line's `clip_range=true`, the RUN lamp's range mark (steady from 7.5 s to 9.5 s of every
/// 10 s).
#[test]
fn clipping_that_persists_in_steady_running_is_the_range_state_not_a_fault() {
    let rec = MotorRecord {
        current_full_scale_a: 6.0,
        ..motor_source::default_record()
    };
    let path = motor_source::sample_path(&rec, FS).unwrap();
    let frames = frames_with(
        &ParamFile::reference_2p2kw(),
        &path,
        &Scenario::steady(16.0, f64::from(FS)),
    );
    let survivors = Survivors::power_on(FakeFlash::erased()).with_motor_page(&rec.to_bytes());
    let mut rig = Rig::boot(survivors);
    rig.run(&frames, |_, _| {}).unwrap();
    let last = rig.last().status;
    assert!(
        last.clipped * 10 > last.samples,
        "{} of {} samples clipped",
        last.clipped,
        last.samples
    );
    let set = rig
        .seen
        .iter()
        .find(|s| s.status.clip_range)
        .map(|s| s.t_ms)
        .expect("the range state");
    assert!((6_000..=10_000).contains(&set), "set at {set} ms");
    no_fault_named(&rig);
    let after: Vec<&Seen> = rig.seen.iter().filter(|s| s.t_ms >= set).collect();
    assert!(after.iter().all(|s| s.status.clip_range));
    assert!(after.iter().all(|s| s.tick.call == Verdict::CouldNotJudge));
    // The RUN lamp's range mark: lit from 7.5 s to 9.5 s of every 10 s, dark 0.5 s either
    // side (from the state's start, 8.05 s, into the next period's 0.5 s gap).
    let (mut lit, mut gap) = (0, 0);
    for s in &after {
        let phase = s.t_ms % 10_000;
        if (7_500..9_500).contains(&phase) {
            assert!(s.tick.lamps.run, "{} ms: the mark is dark", s.t_ms);
            lit += 1;
        } else if (7_000..7_500).contains(&phase) || phase >= 9_500 {
            assert!(!s.tick.lamps.run, "{} ms: the mark's gap is lit", s.t_ms);
            gap += 1;
        }
    }
    assert!(
        lit >= 20 && gap >= 10,
        "{lit} ticks in the mark, {gap} in its gaps"
    );
    let line = line_of(rig.last());
    let read = parse(&line).expect("the status line");
    assert_eq!(read.clip_range, Some(true));
    assert_eq!(read.call, Some(Verdict::CouldNotJudge));
    assert_eq!(read.sensors, Some([false; 3]));
    println!(
        "range state at {set} ms, {} of {} samples clipped",
        last.clipped, last.samples
    );
}

/// The same start with the readings corrected for a reference 2 % above commissioning's
/// (`Command::ReferenceGain`: a rail code now reads 10.2 A) names nothing either: a reading
/// at a rail is a clip, whatever the scaling makes of it.
#[test]
fn a_clip_read_beyond_the_full_scale_names_nothing() {
    let frames = steady_frames(3.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.path.command(Command::ReferenceGain(1.02)).unwrap();
    rig.run(&frames, |_, _| {}).unwrap();
    assert!(rig.last().status.clipped > 100);
    no_fault_named(&rig);
}
