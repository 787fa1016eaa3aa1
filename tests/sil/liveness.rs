//! Liveness: a stalled sample path (shown, restarted, recovered or reset by the watchdog),
//! a panic's reason across the reset, a saturated ADC.

use super::*;

/// Runs `frames[..stop]`, then no samples until the acquisition has been restarted
/// `resume_after` times (then the frames go on), or for good (`None`).
fn run_with_stall(
    rig: &mut Rig,
    frames: &[RawFrame],
    stop: usize,
    resume_after: Option<usize>,
) -> Result<(), Reset> {
    rig.run(&frames[..stop], |_, _| {})?;
    while resume_after.is_none_or(|n| rig.restarts_at_ms.len() < n) {
        rig.period(None)?;
    }
    rig.run(&frames[stop..], |_, _| {})
}

#[test]
fn a_stalled_sample_path_is_shown_restarted_and_recovers() {
    let frames = steady_frames(3.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    // The DMA stops at 2.0 s; the 150th restart (after 300 ms) brings it back.
    run_with_stall(&mut rig, &frames, 20_000, Some(150)).unwrap();
    let stall = |s: &&Seen| (2_000..2_300).contains(&s.t_ms);
    let during: Vec<&Seen> = rig.seen.iter().filter(stall).collect();
    // The first restart 2 ms after the last sample, then every 2 ms.
    assert_eq!(rig.restarts_at_ms[0], 2_001);
    assert_eq!(rig.restarts_at_ms[149], 2_299);
    assert_eq!(rig.restarts_at_ms.len(), 150);
    // No pet from the first period without samples on; the stalled pattern from 100 ms.
    assert!(during.iter().skip(1).all(|s| !s.tick.pet_watchdog));
    for s in &during {
        let expected = if s.t_ms >= 2_100 {
            Mode::SamplingStalled
        } else {
            Mode::Commissioned
        };
        assert_eq!(s.tick.mode, expected, "{} ms", s.t_ms);
    }
    let flashing: Vec<PanelLamps> = during
        .iter()
        .filter(|s| s.tick.mode == Mode::SamplingStalled)
        .map(|s| s.tick.lamps)
        .collect();
    assert!(
        flashing.contains(&PanelLamps::all(true)) && flashing.contains(&PanelLamps::all(false))
    );
    // Logged once when stalled, the reset record written at 300 ms and cleared after.
    let changes: Vec<_> = rig.seen.iter().filter_map(|s| s.tick.liveness).collect();
    use drive_monitor::liveness::LivenessChange::*;
    assert_eq!(
        changes,
        [
            Stalled { for_ms: 100 },
            RecordStall { for_ms: 300 },
            Recovered { after_ms: 350 }
        ]
    );
    assert_eq!(ResetRecord::decode(&rig.survivors.reset_ram), None);
    // Back to normal: petted, commissioned, the core's lamps.
    let after: Vec<&Seen> = rig.seen.iter().filter(|s| s.t_ms >= 2_400).collect();
    assert!(after
        .iter()
        .all(|s| s.tick.pet_watchdog && s.tick.mode == Mode::Commissioned));
    assert!(after.last().unwrap().status.samples > 25_000);
}

#[test]
fn a_stall_the_restarts_do_not_fix_ends_in_a_reported_watchdog_reset() {
    let frames = steady_frames(2.5);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    let reset = run_with_stall(&mut rig, &frames, 20_000, None);
    assert_eq!(reset, Err(Reset::Watchdog));
    // The last pet was the last period with samples; the reset came 500 ms later, after
    // about 250 restarts.
    assert_eq!(rig.now_ms(), 2_501);
    assert!(rig.restarts_at_ms.len() >= 240);
    // The next boot knows why, shows "monitor failed" for 5 s, then monitors again.
    let mut rig = Rig::boot(rig.survivors.clone());
    let PreviousRun::Recorded(rec) = rig.previous else {
        panic!("{:?}", rig.previous);
    };
    assert_eq!(rec.cause(), ResetCause::SampleStall);
    assert_eq!(rec.line_or_ms(), 300);
    let frames = steady_frames(6.0);
    rig.run(&frames, |_, _| {}).unwrap();
    for s in &rig.seen {
        let expected = if s.t_ms < 5_000 {
            Mode::Failed
        } else {
            Mode::Commissioned
        };
        assert_eq!(s.tick.mode, expected, "{} ms", s.t_ms);
    }
    assert_eq!(rig.seen[0].tick.lamps, PanelLamps::FAILED);
}

#[test]
fn a_stall_cut_short_by_the_reset_button_is_not_reported_as_a_watchdog_stall() {
    let frames = steady_frames(2.5);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    // The stall is recorded at 300 ms; the user presses the reset button at 400 ms.
    rig.run(&frames[..20_000], |_, _| {}).unwrap();
    while rig.now_ms() < 2_400 {
        rig.period(None).unwrap();
    }
    let stall = ResetRecord::sample_stall(300);
    assert_eq!(ResetRecord::decode(&rig.survivors.reset_ram), Some(stall));
    let mut survivors = rig.survivors.clone();
    survivors.reset_source = ResetSource::Pin;
    let rig = Rig::boot(survivors.clone());
    assert_eq!(
        rig.previous,
        PreviousRun::ResetDuring {
            record: stall,
            source: ResetSource::Pin
        }
    );
    // A brown-out that keeps the RAM says so too; the watchdog's reset is the stall's.
    survivors.reset_source = ResetSource::PowerOnOrBrownOut;
    assert!(matches!(
        Rig::boot(survivors.clone()).previous,
        PreviousRun::ResetDuring {
            source: ResetSource::PowerOnOrBrownOut,
            ..
        }
    ));
    survivors.reset_source = ResetSource::IndependentWatchdog;
    assert_eq!(Rig::boot(survivors).previous, PreviousRun::Recorded(stall));
}

#[test]
fn a_panic_reason_survives_the_reset() {
    let frames = steady_frames(1.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&frames, |_, _| {}).unwrap();
    // The panic handler records the reason, stops petting; the watchdog resets.
    let mut survivors = rig.survivors.clone();
    survivors.reset_ram =
        ResetRecord::panic("attempt to divide by zero", "src/app.rs", 321).encode();
    survivors.reset_source = ResetSource::IndependentWatchdog;
    let rig = Rig::boot(survivors.clone());
    let PreviousRun::Recorded(rec) = rig.previous else {
        panic!("{:?}", rig.previous);
    };
    assert_eq!(
        (rec.cause(), rec.message(), rec.file(), rec.line_or_ms()),
        (
            ResetCause::Panic,
            "attempt to divide by zero",
            "src/app.rs",
            321
        )
    );
    // The record is read once: the boot after that is clean again...
    assert_eq!(
        Rig::boot(rig.survivors.clone()).previous,
        PreviousRun::Clean
    );
    // ...and a watchdog reset with no record is a hang.
    survivors.reset_ram = [0; RESET_RECORD_LEN];
    assert_eq!(
        Rig::boot(survivors).previous,
        PreviousRun::WatchdogReset { phase: None }
    );
}

/// A current front end on its rails at every peak (20 A peaks on the +-10 A front end, the
/// shaft standing: a stalled rotor, or a start that does not run up) was "ADC saturated"
/// and lit the FAULT lamp steadily, naming the current sensor. It is a clip: every clipped
/// sample is counted (`clip=`) and held out, no sensor is named and the FAULT lamp stays
/// dark; with the shaft standing there is no steady running, so no range is judged either
/// (`crate::clip_watch`).
#[test]
fn a_front_end_on_its_rails_is_counted_and_names_no_sensor() {
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    let q = *rig.path.sampler();
    let frames: Vec<RawFrame> = (0..20_000)
        .map(|k| {
            let t = k as f32 / FS as f32;
            let w = std::f32::consts::TAU * 50.0 * t;
            let v = Abc {
                a: 326.0 * w.cos(),
                b: 326.0 * (w - 2.094).cos(),
                c: 326.0 * (w + 2.094).cos(),
            };
            // 20 A peak on a +-10 A front end: the current codes hit the rails.
            let i = Abc {
                a: 20.0 * w.cos(),
                b: 20.0 * (w - 2.094).cos(),
                c: 20.0 * (w + 2.094).cos(),
            };
            q.quantize(v, i, 0)
        })
        .collect();
    rig.run(&frames, |_, _| {}).unwrap();
    let status = rig.last().status;
    assert!(!status.sensor_fault.any());
    assert!(status.clipped * 10 > status.samples * 9, "{status:?}");
    assert!(!status.clip_range);
    let input = panel_input(rig.mode(), &status, rig.supervisor.panel_isolation(), false);
    assert!((0..40u32).all(|k| !panel::render(&input, k * 50).is_on(Lamp::Fault)));
    assert!(rig.seen.iter().all(|s| !s.tick.lamps.fault));
    assert!(rig
        .seen
        .iter()
        .all(|s| s.tick.call != monitor_core::verdict::Verdict::Fault));
}

/// The fault path's board in the rig: the reset record's RAM of the survivors, the
/// brown-out level, the lamps' "monitor failed" pattern.
struct FakeFaultBoard<'a> {
    reset_ram: &'a mut [u8; RESET_RECORD_LEN],
    failed_shown: bool,
    writes: u32,
}

impl drive_monitor::fault_path::FaultBoard for FakeFaultBoard<'_> {
    fn bor_level(&mut self) -> Option<drive_monitor::supply::BorLevel> {
        Some(drive_monitor::supply::BorLevel::Level4)
    }
    fn findings(&mut self) -> u32 {
        0
    }
    fn write_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]) {
        *self.reset_ram = *bytes;
        self.writes += 1;
    }
    fn show_failed(&mut self) {
        self.failed_shown = true;
    }
}

/// A HardFault mid-run (issue 43): the handler's own code path
/// (`fault_path::on_hard_fault`, what `HardFault` in `src/firmware/failure.rs` calls with
/// the stacked PC and LR and the fault status registers) writes the record and shows the
/// failed pattern; after the reset (the watchdog's, or a software reset before it runs)
/// the next boot reports it with the PC and the registers and shows "monitor failed".
#[test]
fn a_hard_fault_leaves_a_record_the_next_boot_reports() {
    use drive_monitor::fault_path::{on_hard_fault, FaultEnd, FaultGuard, FaultRegisters};
    let frames = steady_frames(1.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&frames, |_, _| {}).unwrap();
    // A precise bus fault escalated to HardFault: CFSR.PRECISERR | BFARVALID, HFSR.FORCED.
    let regs = FaultRegisters {
        pc: 0x0800_1A2C,
        lr: 0x0800_1F01,
        cfsr: 0x0000_8200,
        hfsr: 0x4000_0000,
        bfar: 0x6000_0000,
    };
    for source in [ResetSource::IndependentWatchdog, ResetSource::Software] {
        let mut survivors = rig.survivors.clone();
        let guard = FaultGuard::new();
        let mut board = FakeFaultBoard {
            reset_ram: &mut survivors.reset_ram,
            failed_shown: false,
            writes: 0,
        };
        assert_eq!(
            on_hard_fault(&guard, &mut board, None, regs),
            FaultEnd::Recorded
        );
        assert!(board.failed_shown);
        survivors.reset_source = source;
        let next = Rig::boot(survivors);
        let PreviousRun::Recorded(rec) = next.previous else {
            panic!("{source:?}: {:?}", next.previous);
        };
        assert_eq!(rec.cause(), ResetCause::HardFault);
        assert_eq!(rec.line_or_ms(), regs.pc);
        assert_eq!(rec.file(), "hard fault");
        assert_eq!(
            rec.message(),
            "lr=0x08001F01 cfsr=0x00008200 hfsr=0x40000000 bfar=0x60000000"
        );
        assert!(next.previous.failed());
    }
    // An interrupt without a handler names its number.
    let rec = ResetRecord::hard_fault(Some(-1), 0, 0, 0, 0, 0);
    let back = ResetRecord::decode(&rec.encode()).expect("decodes");
    assert_eq!(back.file(), "exception -001");
}

/// A fault inside the fault path (the first fault hit inside a `defmt` frame, and
/// `defmt-rtt` panics "taken reentrantly"; or the lamp pins' registers fault): the guard
/// sends the second straight to the reset, nothing written, and the next boot reports the
/// first fault, not the panic it caused.
#[test]
fn a_second_fault_inside_the_fault_path_resets_at_once_and_keeps_the_first_record() {
    use drive_monitor::fault_path::FaultRegisters;
    use drive_monitor::fault_path::{on_fault, on_hard_fault, FaultEnd, FaultGuard};
    let mut survivors = Survivors::power_on(FakeFlash::erased());
    let guard = FaultGuard::new();
    let mut board = FakeFaultBoard {
        reset_ram: &mut survivors.reset_ram,
        failed_shown: false,
        writes: 0,
    };
    let first = FaultRegisters {
        pc: 0x0800_2000,
        ..FaultRegisters::default()
    };
    assert_eq!(
        on_hard_fault(&guard, &mut board, None, first),
        FaultEnd::Recorded
    );
    // defmt-rtt's reentrancy panic, from inside the first fault's handling.
    let second = ResetRecord::on_panic(
        Some("taken reentrantly"),
        Some(("defmt-rtt/src/lib.rs", 96)),
    );
    assert_eq!(on_fault(&guard, &mut board, second), FaultEnd::Reentered);
    assert_eq!(board.writes, 1);
    survivors.reset_source = ResetSource::Software;
    let next = Rig::boot(survivors);
    let PreviousRun::Recorded(rec) = next.previous else {
        panic!("{:?}", next.previous);
    };
    assert_eq!(rec.cause(), ResetCause::HardFault);
    assert_eq!(rec.line_or_ms(), 0x0800_2000);
}
