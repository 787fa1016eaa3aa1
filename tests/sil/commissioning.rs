//! Commissioning through the firmware's own path: a run that detects a fault afterwards, a
//! run the quasi-steady gate stalls, a cancel, power loss and a failed flash write, and
//! unusable records at boot.

use super::*;

#[test]
fn commission_then_detect_rs_fault_on_the_panel() {
    let mut scenario = Scenario::steady(6.5, f64::from(FS));
    scenario
        .faults
        .push(FaultSpec::parametric(Fault::Rs, 4.0, 0.5));
    let frames = frames(&scenario);
    assert!(frames.len() >= 64_000, "{} samples", frames.len());

    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    assert_eq!(rig.previous, PreviousRun::Clean);
    let mut before_fault = None;
    rig.run(&frames, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
        if k == 39_500 {
            before_fault = Some(*rig.last());
        }
    })
    .unwrap();
    assert_eq!(rig.seen[0].tick.mode, Mode::NotCommissioned);
    // Learning shows on the panel, then the stored record is in force.
    assert!(rig.seen.iter().any(|s| s.tick.mode == Mode::Commissioning));
    assert_eq!(rig.ended, [RunEnd::Commissioned { run: 1 }]);
    assert_eq!(rig.survivors.flash.writes, 1);

    // Commissioned before the fault, no residual lamp, no fault lamp.
    let seen = before_fault.unwrap();
    assert_eq!(
        seen.tick.mode,
        Mode::Commissioned,
        "commissioning did not finish"
    );
    assert_eq!(
        seen.status.residual_lamps, [false; 4],
        "false alarm: {seen:?}"
    );
    for l in [Lamp::R1, Lamp::R2, Lamp::R3, Lamp::R4, Lamp::Fault] {
        assert!(!seen.tick.lamps.is_on(l), "{l:?} lit before the fault");
    }
    assert!(
        rig.seen.iter().all(|s| s.tick.pet_watchdog),
        "samples flowed"
    );

    // After the fault: detected, the residual LEDs are the core's lamps, and the fault
    // LED blinks the top candidate's code.
    let status = rig.last().status;
    assert!(status.fault_detected, "Rs +50 % not detected: {status:?}");
    assert!(status.residual_lamps.iter().any(|l| *l));
    let iso = rig.supervisor.isolation().copied();
    eprintln!("isolation: {iso:?}");
    let input = panel_input(rig.mode(), &status, rig.supervisor.panel_isolation(), false);
    let now = panel::render(&input, 0);
    for (lamp, lit) in Lamp::RESIDUALS.into_iter().zip(status.residual_lamps) {
        assert_eq!(now.is_on(lamp), lit);
    }
    // The blink code is the fault the isolation named, Rs (code 1), with its size.
    let named = iso.and_then(|i| i.named_fault()).expect("Rs +50 % named");
    assert_eq!(named.fault, Fault::Rs, "{iso:?}");
    assert!((named.change - 0.5).abs() < 0.1, "size {}", named.change);
    let trace: Vec<bool> = (0..400u32)
        .map(|t| panel::render(&input, t * 50).is_on(Lamp::Fault))
        .collect();
    assert_eq!(panel::read_blink_code(&trace, 50), Some(1));

    // The stored record brings the next boot up commissioned.
    let rig2 = Rig::boot(Survivors::power_on(rig.survivors.flash.clone()));
    assert_eq!(
        rig2.path.monitor().calibration(),
        rig.path.monitor().calibration()
    );
    assert!(rig2.supervisor.latest().commissioned);
}

#[test]
fn timeout_while_the_gate_is_closed_cancels_and_keeps_the_old_record() {
    // Healthy, but the load steps by +-30 % every 0.4 s from 1.4 s to 6 s: the operating
    // point never settles, the quasi-steady gate stays closed, no block is learned.
    let mut scenario = Scenario::steady(7.0, f64::from(FS));
    scenario.load.steps = (0..12)
        .map(|k| LoadStep {
            t_s: 1.4 + 0.4 * f64::from(k),
            torque_nm: None,
            bl_scale: Some(if k % 2 == 0 { 0.7 } else { 1.3 }),
        })
        .chain([LoadStep {
            t_s: 6.2,
            torque_nm: None,
            bl_scale: Some(1.0),
        }])
        .collect();
    let frames = frames(&scenario);
    let old = old_record();
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old)));
    assert!(rig.supervisor.latest().commissioned);
    rig.run(&frames, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
    })
    .unwrap();
    // The run started and learned nothing while the load stepped.
    let learning: Vec<&Seen> = rig
        .seen
        .iter()
        .filter(|s| s.status.run.stage == RunStage::Learning)
        .collect();
    assert!(!learning.is_empty());
    assert!(learning.iter().all(|s| s.status.run.blocks_learned == 0));
    // Because the gate was closed, not for want of a running motor (no sensor fault; the
    // same motor without the steps learns in the other tests).
    assert!(learning.iter().all(|s| !s.quasi_steady));
    assert!(learning.iter().all(|s| !s.status.sensor_fault.any()));
    // Cancelled for want of progress, 3 s after the start, while the gate was closed.
    assert_eq!(
        rig.ended,
        [RunEnd::Failed {
            run: Some(1),
            why: Failure::Stalled
        }]
    );
    let cancelled_at = rig
        .seen
        .iter()
        .find(|s| s.tick.run_ended.is_some())
        .unwrap()
        .t_ms;
    assert!((4_450..=4_700).contains(&cancelled_at), "{cancelled_at} ms");
    assert_eq!(
        rig.path.monitor().commissioning().stage,
        RunStage::Failed(CommissioningFailure::Cancelled)
    );
    // RAM, flash and panel: the old record, commissioned, plus the failure flicker.
    assert_eq!(rig.path.monitor().calibration(), Some(old.into()));
    assert_eq!(rig.survivors.flash.usable(), Some(old.into()));
    assert_eq!(rig.survivors.flash.writes, 0, "nothing was written");
    assert_eq!(rig.mode(), Mode::Commissioned);
    assert_eq!(
        rig.supervisor.procedure().last_failure(),
        Some(Failure::Stalled)
    );
    let input = panel_input(
        Mode::Commissioned,
        &rig.last().status,
        Default::default(),
        true,
    );
    let flicker: Vec<bool> = (0..10u32)
        .map(|t| panel::render(&input, t * 25).fault)
        .collect();
    assert!(flicker.contains(&true) && flicker.contains(&false));
    // The core did not learn on after the cancel (the old wall-clock timeout let it).
    assert!(rig
        .seen
        .iter()
        .all(|s| s.status.run.stage != RunStage::Done));
}

#[test]
fn the_button_cancels_a_learning_run() {
    let frames = steady_frames(4.0);
    let old = old_record();
    // 3 s of learning this time.
    let settings = Settings {
        commissioning_duration_s: 3.0,
        ..SETTINGS
    };
    let mut rig = Rig::boot_with(settings, Survivors::power_on(FakeFlash::holding(&old)));
    rig.run(&frames, |rig, k| {
        // Pressed at 1.5 s; again at 2.0 s, within the guard time: ignored; at 2.6 s: cancel.
        if k == PRESS_AT || k == 20_000 || k == 26_000 {
            rig.press();
        }
    })
    .unwrap();
    assert_eq!(rig.ended, [RunEnd::CancelledByUser { run: 1 }]);
    let at = |ms: u32| rig.seen.iter().find(|s| s.t_ms == ms).unwrap();
    assert_eq!(
        at(2_400).tick.mode,
        Mode::Commissioning,
        "the 2 s press did not cancel"
    );
    assert_eq!(at(2_750).tick.mode, Mode::Commissioned);
    assert_eq!(rig.path.monitor().calibration(), Some(old.into()));
    assert_eq!(rig.survivors.flash.usable(), Some(old.into()));
    assert_eq!(rig.supervisor.procedure().last_failure(), None);
    // (The direct-on-line start's inrush saturates the +-10 A front end: the FAULT lamp
    // is steady on for the first second, the current sensor named.)
    assert!(
        rig.seen
            .iter()
            .filter(|s| s.t_ms >= 1_500)
            .all(|s| !s.tick.lamps.fault),
        "a cancel is not shown as a failure"
    );
}

/// A power loss during the store's write: the new copy in the other page is torn, the old
/// record in its page untouched (the two pages in turn, `flash_record`). Power back: RAM,
/// flash and panel say "commissioned" with the old record.
#[test]
fn power_loss_during_the_flash_write_keeps_the_old_record() {
    let frames = steady_frames(3.0);
    let mut flash = FakeFlash::holding(&old_record());
    // The other page was erased and 16 of the 104 bytes written when the power went.
    flash.fault = Some(FlashFault::PowerLossAfter(16));
    let mut rig = Rig::boot(Survivors::power_on(flash));
    let reset = rig.run(&frames, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
    });
    assert_eq!(reset, Err(Reset::PowerLoss));
    // Power back: the torn copy is rejected, the old one is in force everywhere.
    let survivors = Survivors::power_on(rig.survivors.flash.clone());
    assert_eq!(
        CalibrationRecord::decode(&survivors.flash.page_b),
        Err(flash_record::RecordError::Crc)
    );
    assert_eq!(
        CalibrationRecord::decode(&survivors.flash.page),
        Ok(old_record())
    );
    let mut rig = Rig::boot(survivors);
    assert_eq!(rig.previous, PreviousRun::Clean);
    rig.run(&frames[..5_000], |_, _| {}).unwrap();
    let old = Some(Calibration::from(old_record()));
    assert_eq!(rig.path.monitor().calibration(), old);
    assert_eq!(rig.survivors.flash.usable(), old);
    assert_eq!(rig.mode(), Mode::Commissioned);
}

#[test]
fn a_failed_flash_write_puts_what_the_flash_holds_into_force() {
    let frames = steady_frames(3.5);
    let mut flash = FakeFlash::holding(&old_record());
    flash.fault = Some(FlashFault::WriteFails);
    let mut rig = Rig::boot(Survivors::power_on(flash));
    rig.run(&frames, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
    })
    .unwrap();
    // The other page was erased, the write failed: the old record in flash, in RAM and on
    // the panel; the run did not store what it learned.
    assert_eq!(
        rig.ended,
        [RunEnd::Failed {
            run: Some(1),
            why: Failure::Core(CommissioningFailure::NotStored)
        }]
    );
    let old = Some(Calibration::from(old_record()));
    assert_eq!(rig.path.monitor().calibration(), old);
    assert_eq!(rig.survivors.flash.usable(), old);
    assert_eq!(rig.mode(), Mode::Commissioned);
    // The FAULT lamp flickers at 10 Hz (on in the first half of every 100 ms; the rig's
    // ticks fall on both halves).
    let last_second: Vec<&Seen> = rig.seen.iter().rev().take(20).collect();
    assert!(last_second.iter().all(|s| !s.status.fault_detected));
    for s in last_second {
        assert_eq!(s.tick.lamps.fault, s.t_ms % 100 < 50, "{} ms", s.t_ms);
    }
}

#[test]
fn a_corrupt_or_unusable_record_at_boot_means_not_commissioned_everywhere() {
    let frames = steady_frames(2.0);
    let good = old_record().encode().unwrap();
    let mut flipped = FakeFlash::erased();
    flipped.page[..RECORD_LEN].copy_from_slice(&good);
    flipped.page[20] ^= 0x04;
    // CRC-valid, but outside the core's range (|mean| > 1).
    let unusable = FakeFlash::holding(&CalibrationRecord {
        mean: [5.0, 0.0, 0.0, 0.0],
        spread: [0.1; 4],
        isolation: None,
        vdda_v: None,
    });
    for flash in [flipped, unusable, FakeFlash::erased()] {
        let mut rig = Rig::boot(Survivors::power_on(flash));
        rig.run(&frames, |_, _| {}).unwrap();
        assert_eq!(rig.path.monitor().calibration(), None);
        assert_eq!(rig.survivors.flash.usable(), None);
        assert!(rig
            .seen
            .iter()
            .all(|s| s.tick.mode == Mode::NotCommissioned));
    }
    // The intact record: commissioned everywhere, from the first period on.
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    rig.run(&frames, |_, _| {}).unwrap();
    assert!(rig.seen.iter().all(|s| s.tick.mode == Mode::Commissioned));
}
