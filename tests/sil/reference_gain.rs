//! VDDA, the ADC's reference, stored at commissioning and every reading corrected by its
//! drift since (`supply::ReferenceGain`, `SamplePath::set_reference_gain`): a 3 % drift
//! within the reference's band (3.2..3.4 V, so nothing is flagged) no longer moves every
//! reading by 3 %.

use super::startup::FakeReference;
use super::*;
use drive_monitor::supply::measure_now;

/// VDDA at commissioning and after the drift [V].
const AT_COMMISSIONING: f32 = 3.30;
const DRIFTED: f32 = 3.21;
/// The drift begins at this frame (1.5 s).
const DRIFT_AT: usize = 15_000;

/// The frames an ADC whose reference has drifted from 3.30 V to 3.21 V reads: the same
/// input, the swing around the zero `3.30 / 3.21` larger (the front end's swing is not
/// ratiometric), the zero where it was (the board's front end biases it at VDDA / 2,
/// `board::ZERO_BIAS`).
fn drifted(raw: &RawFrame) -> RawFrame {
    let zero = drive_monitor::board::MID_SCALE_CODE;
    let scale = |c: u16| {
        let swing = (f32::from(c) - zero) * AT_COMMISSIONING / DRIFTED;
        (zero + swing).round().clamp(0.0, 4095.0) as u16
    };
    let mut out = *raw;
    for c in out.v.iter_mut() {
        c.0 = scale(c.0);
    }
    for c in out.i.iter_mut() {
        c.0 = scale(c.0);
    }
    out
}

/// Boots on a commissioning record holding `vdda_v`, runs 4.5 s with the reference
/// drifting at 1.5 s; the filtered V_qs before the drift and at the end, and the rig.
fn run(vdda_v: Option<f32>) -> (f32, f32, Rig) {
    let record = CalibrationRecord {
        vdda_v,
        ..old_record()
    };
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&record)));
    let mut adc = FakeReference::at(AT_COMMISSIONING);
    let start = measure_now(&mut adc);
    rig.supervisor.observe_reference(start, 0);
    rig.reference = Some(adc);
    let frames: Vec<RawFrame> = steady_frames(4.5)
        .iter()
        .enumerate()
        .map(|(k, f)| if k < DRIFT_AT { *f } else { drifted(f) })
        .collect();
    let mut before = 0.0;
    rig.run(&frames, |rig, k| {
        if k == DRIFT_AT {
            before = rig.path.status().operating.vqs;
            if let Some(adc) = rig.reference.as_mut() {
                adc.vdda = DRIFTED;
            }
        }
    })
    .unwrap();
    let after = rig.path.status().operating.vqs;
    (before, after, rig)
}

#[test]
fn a_drift_of_the_reference_since_commissioning_is_corrected() {
    let (before, after, rig) = run(Some(AT_COMMISSIONING));
    // The gain handed to the sample task: 3.21 / 3.30 (measured by VREFINT's codes).
    let gain = rig.path.reference_gain();
    assert!((gain - DRIFTED / AT_COMMISSIONING).abs() < 0.002, "{gain}");
    let moved = (after - before) / before;
    assert!(moved.abs() < 0.003, "V_qs {before} -> {after}: {moved}");
    // Within the band: nothing flagged.
    assert!(rig.seen.iter().all(|s| !s.status.sensor_fault.voltage));
    // The control, a record without VDDA (as before version 4): every reading 2.8 % high.
    let (before, after, rig) = run(None);
    assert_eq!(rig.path.reference_gain(), 1.0);
    let moved = (after - before) / before;
    assert!(moved > 0.025, "V_qs {before} -> {after}: {moved}");
}

/// A commissioning run stores the VDDA it learned at.
#[test]
fn a_commissioning_run_stores_the_reference_it_learned_at() {
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    let mut adc = FakeReference::at(3.287);
    let start = measure_now(&mut adc);
    rig.supervisor.observe_reference(start, 0);
    rig.reference = Some(adc);
    rig.run_commissioning(&steady_frames(4.0));
    let stored = CalibrationRecord::decode(&rig.survivors.flash.page).unwrap();
    let v = stored.vdda_v.expect("VDDA stored");
    assert!((v - 3.287).abs() < 0.005, "{v}");
    assert_eq!(rig.paused_for_flash, 1, "the store paused the acquisition");
}

/// A gain beyond the reference's band (0.9..=1.1: a VDDA 10 % off, whose readings are
/// flagged anyway), or not finite, is ignored: the correction in force stays.
#[test]
fn a_gain_beyond_the_band_is_ignored() {
    let mut path = SamplePath::for_board(FS).unwrap();
    for gain in [0.9, 1.1, 0.97] {
        path.set_reference_gain(gain);
        assert_eq!(path.reference_gain(), gain);
    }
    for gain in [0.89, 1.11, 0.5, 2.0, f32::NAN, f32::INFINITY, -1.0] {
        path.set_reference_gain(gain);
        assert_eq!(path.reference_gain(), 0.97, "{gain}");
    }
}
