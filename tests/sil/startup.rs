//! Start-up: the offset trim with the motor off, and the time base's tolerance (the
//! internal oscillator's +-1 %) measured on the monitor's frequency and speed.

use super::*;
use drive_monitor::offset_trim::{ChannelTrim, TRIM_SAMPLES};

/// `duration_s` of the motor off: every code at the front end's zero plus `offset` (codes
/// per channel: va, vb, vc, ia, ib, ic) and 0..2 codes of noise.
fn motor_off(duration_s: f64, offset: [i32; 6]) -> Vec<RawFrame> {
    let n = (duration_s * f64::from(FS)) as usize;
    let q = *SamplePath::for_board(FS).unwrap().sampler();
    let at_zero = q.quantize(Abc::default(), Abc::default(), 0);
    (0..n)
        .map(|k| shifted(&at_zero, offset, (k % 3) as i32))
        .collect()
}

/// `raw` with `offset` (+ `noise`) added to each channel's code.
fn shifted(raw: &RawFrame, offset: [i32; 6], noise: i32) -> RawFrame {
    let add = |code: u16, d: i32| (i32::from(code) + d + noise).clamp(0, 4095) as u16;
    let mut out = *raw;
    for (k, c) in out.v.iter_mut().enumerate() {
        c.0 = add(c.0, offset[k]);
    }
    for (k, c) in out.i.iter_mut().enumerate() {
        c.0 = add(c.0, offset[3 + k]);
    }
    out
}

#[test]
fn the_offset_trim_measures_the_zero_with_the_motor_off_and_puts_it_into_force() {
    let offset = [3, -2, 0, 12, -7, 0];
    // One trim window and a half: the start-up trim, no standstill re-trim after it (which
    // would put the next window's zeros into force: `tests/sil/drift.rs`).
    let off = motor_off(0.15, offset);
    // The expected zero of each channel: the mean of the codes the rig sends in the
    // trim's window.
    let window = &off[..TRIM_SAMPLES as usize];
    let mean = |f: &dyn Fn(&RawFrame) -> u16| {
        window.iter().map(|r| f64::from(f(r))).sum::<f64>() / window.len() as f64
    };
    let expected_ia = mean(&|r| r.i[0].0);
    let expected_vb = mean(&|r| r.v[1].0);
    // Then the motor starts, its codes carrying the same offsets.
    let running: Vec<RawFrame> = steady_frames(2.5)
        .iter()
        .map(|r| shifted(r, offset, 0))
        .collect();
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    rig.run(&off, |_, _| {}).unwrap();
    rig.run(&running, |_, _| {}).unwrap();
    assert_eq!(rig.trims.len(), 1);
    assert_eq!(
        rig.trims[0].kind,
        drive_monitor::offset_trim::TrimKind::StartUp
    );
    let fe = *rig.path.sampler().front_end();
    assert!((f64::from(fe.current[0].offset_code) - expected_ia).abs() < 1e-3);
    assert!((f64::from(fe.voltage[1].offset_code) - expected_vb).abs() < 1e-3);
    // The zero reads zero now: within half a code of the noise.
    let quiet = rig.path.sampler().clone().build(&off[0]);
    assert!(
        quiet.i_abc.a.abs() < 1.5 * board::AMP_PER_LSB,
        "{:?}",
        quiet.i_abc
    );
    assert!(rig.trims[0]
        .voltage
        .iter()
        .all(|c| matches!(c, ChannelTrim::Trimmed(_))));
    // No sensor is flagged, and the running machine is healthy.
    let last = rig.last().status;
    assert!(!last.sensor_fault.any() && !last.fault_detected, "{last:?}");
}

#[test]
fn an_offset_out_of_bound_is_not_used_and_flags_the_sensor() {
    // ib's zero 300 codes off (a sensor without supply, a broken amplifier).
    let off = motor_off(1.0, [0, 0, 0, 0, 300, 0]);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&off, |_, _| {}).unwrap();
    let trim = rig.trims[0];
    assert!(matches!(trim.current[1], ChannelTrim::OutOfBound(x) if x > 2300.0));
    assert!(trim.current_fault() && !trim.voltage_fault());
    // Not used: ib keeps the nominal zero; the sensor is flagged from the next status on
    // and the FAULT lamp is steady (input invalid).
    let fe = *rig.path.sampler().front_end();
    assert_eq!(fe.current[1].offset_code, board::MID_SCALE_CODE);
    let after: Vec<&Seen> = rig.seen.iter().filter(|s| s.t_ms >= 200).collect();
    assert!(after.iter().all(|s| s.status.sensor_fault.current));
    assert!(after.iter().all(|s| s.tick.lamps.fault), "steady");
}

#[test]
fn the_internal_oscillators_tolerance_scales_the_frequency_and_speed_estimates() {
    // The time base (HSI, +-1 % over temperature and parts) clocks the trigger: a fast
    // oscillator samples faster than the firmware assumes, so everything it measures in
    // time reads slow by the same factor.
    let mut seen = Vec::new();
    for error in [-0.01, 0.0, 0.01] {
        let frames = frames(&Scenario::steady(3.0, f64::from(FS) * (1.0 + error)));
        let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
        rig.run(&frames, |_, _| {}).unwrap();
        let s = rig.last().status;
        seen.push((
            error,
            s.frame_hz,
            s.speed_rad_s,
            s.fault_detected,
            s.residuals,
        ));
    }
    for (error, f_hz, w_rad_s, fault, r) in &seen {
        eprintln!(
            "error {error:+.2}: f {f_hz:.4} Hz, wm {w_rad_s:.3} rad/s, fault {fault}, r {r:?}"
        );
    }
    let (_, f0, w0, ..) = seen[1];
    // On time, the frame's frequency is the supply's, in Hz (the core's is in rad/s).
    let supply_hz = ParamFile::reference_2p2kw().supply.f_hz;
    assert!((f64::from(f0) / supply_hz - 1.0).abs() < 2e-3, "{f0} Hz");
    for &(error, f_hz, w_rad_s, fault, _) in &seen {
        let scale = 1.0 / (1.0 + error);
        assert!(
            (f64::from(f_hz / f0) - scale).abs() < 5e-4,
            "{error}: {f_hz} vs {f0}"
        );
        assert!(
            (f64::from(w_rad_s / w0) - scale).abs() < 5e-4,
            "{error}: {w_rad_s} vs {w0}"
        );
        // A healthy machine is not flagged for the oscillator's tolerance.
        assert!(!fault, "{error}");
    }
}

#[test]
fn a_corrupt_or_old_motor_record_shows_the_default_motor_mark_on_the_panel() {
    use drive_monitor::motor_source;
    let valid = motor_source::default_record().to_bytes();
    let mut corrupt = valid;
    corrupt[20] ^= 0x10;
    let mut old = valid;
    old[4] = 0; // another version
    let erased = [0xFF; 256];
    let off = motor_off(12.5, [0; 6]);
    let pages: [(&[u8], bool); 4] = [
        (&valid, false),
        (&corrupt, true),
        (&old, true),
        (&erased, true),
    ];
    for (page, default) in pages {
        // The boot composition (`drive_monitor::boot`, as the firmware boots) on that page.
        let (machine, _, _) = drive_monitor::boot::machine(page, FS).unwrap();
        assert_eq!(machine.source.is_default(), default, "{:?}", machine.source);
        let survivors = Survivors::power_on(FakeFlash::erased()).with_motor_page(page);
        let mut rig = Rig::boot(survivors);
        rig.run(&off, |_, _| {}).unwrap();
        // The RUN lamp's longest lit stretch at the 50 ms ticks.
        let (mut on_ms, mut longest_ms) = (0, 0);
        for s in &rig.seen {
            on_ms = if s.tick.lamps.run { on_ms + 50 } else { 0 };
            longest_ms = longest_ms.max(on_ms);
            assert_eq!(s.tick.mode, Mode::NotCommissioned, "{} ms", s.t_ms);
        }
        if default {
            // Lit through 10.0..12.0 s of every 10 s (the first period starts at boot).
            assert!(rig
                .seen
                .iter()
                .filter(|s| (10_000..12_000).contains(&s.t_ms) || s.t_ms < 2_000)
                .all(|s| s.tick.lamps.run));
            assert!((1_950..=2_000).contains(&longest_ms), "{longest_ms}");
        } else {
            assert!(longest_ms <= 100, "{longest_ms}");
        }
    }
}

/// The ADC's reference (issue 43): VDDA measured through VREFINT at start-up. In band, the
/// run is the same as without the check; a sagging 3.0 V supply (every reading 10 % high)
/// flags both sensors from then on and holds the FAULT lamp steady (input invalid), as an
/// offset out of bound does.
#[test]
fn a_reference_out_of_band_flags_the_sensors() {
    let frames = steady_frames(2.0);
    let cal = 1655;
    let run = |check: Option<board::ReferenceCheck>| {
        let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
        if let Some(c) = check {
            rig.supervisor.observe_reference(c, 0);
        }
        rig.run(&frames, |_, _| {}).unwrap();
        rig.seen
            .iter()
            .filter(|s| s.t_ms >= 1_000)
            .map(|s| (s.status.sensor_fault, s.tick.lamps.fault))
            .collect::<Vec<_>>()
    };
    let control = run(None);
    assert!(!control.is_empty());
    // (Without the check the sensors are clear and the lamp dark for most of the run: the
    // flagged case is told apart.)
    let clear = control
        .iter()
        .filter(|(f, lamp)| !f.voltage && !f.current && !lamp)
        .count();
    assert!(2 * clear > control.len(), "{control:?}");
    for (vdda, bad) in [(3.3f32, false), (3.0, true)] {
        let code = (f32::from(cal) * board::VREFINT_CAL_VDDA_V / vdda).round() as u16;
        let seen = run(Some(board::ReferenceCheck::of(code, cal)));
        if bad {
            assert!(
                seen.iter().all(|(f, lamp)| f.voltage && f.current && *lamp),
                "VDDA {vdda} V"
            );
        } else {
            assert_eq!(seen, control, "VDDA {vdda} V");
        }
    }
}

/// VREFINT as ADC1's injected channel converts it: the code the factory's calibration word
/// `cal` gives at the supply `vdda` [V], ready at the first poll after a start, or never
/// (`converts: false`, an ADC that does not convert). The first conversion after power-up
/// samples the VREFINT buffer within its start-up time and reads half the code (VDDA
/// twice too high): `measure_now` must discard it.
pub(crate) struct FakeReference {
    pub vdda: f32,
    pub cal: u16,
    pub converts: bool,
    pending: bool,
    pub conversions: u32,
}

impl FakeReference {
    pub fn at(vdda: f32) -> Self {
        Self {
            vdda,
            cal: 1655,
            converts: true,
            pending: false,
            conversions: 0,
        }
    }
}

impl drive_monitor::supply::ReferenceAdc for FakeReference {
    fn calibration(&self) -> u16 {
        self.cal
    }
    fn enable(&mut self) {}
    fn wait_us(&mut self, _us: u32) {}
    fn start(&mut self) {
        self.pending = true;
    }
    fn result(&mut self) -> Option<u16> {
        if !(self.pending && self.converts) {
            return None;
        }
        self.pending = false;
        let settled = self.conversions > 0;
        self.conversions += 1;
        let code = f32::from(self.cal) * board::VREFINT_CAL_VDDA_V / self.vdda;
        Some(if settled { code } else { code / 2.0 }.round() as u16)
    }
}

/// The reference measured periodically (issue 43): the start-up check in band, then every
/// second while the monitor runs. A supply sagging to 3.0 V at 1.2 s flags both sensors
/// (the FAULT lamp steady: input invalid) within one period and says why; back at 3.3 V
/// at 2.6 s the flags clear within one period and the lamp goes dark again. An ADC that
/// stops converting counts as an unreadable reference after 200 ms.
#[test]
fn the_reference_is_checked_every_second_and_its_flag_clears_when_it_returns() {
    use drive_monitor::supply::{measure_now, ReferenceChange};
    let frames = steady_frames(4.5);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    let mut adc = FakeReference::at(3.3);
    let start = measure_now(&mut adc);
    assert_eq!(rig.supervisor.observe_reference(start, 0), None, "in band");
    rig.reference = Some(adc);
    rig.run(&frames, |rig, k| {
        let vdda = match k {
            k if k < 12_000 => 3.3,
            k if k < 26_000 => 3.0,
            _ => 3.3,
        };
        if let Some(adc) = rig.reference.as_mut() {
            adc.vdda = vdda;
        }
    })
    .unwrap();
    let changes = &rig.reference_changes;
    assert_eq!(changes.len(), 2, "{changes:?}");
    let (flagged_ms, cleared_ms) = (changes[0].0, changes[1].0);
    assert!(
        matches!(changes[0].1, ReferenceChange::Flagged(board::ReferenceCheck::OutOfBand(v)) if (v - 3.0).abs() < 0.01)
    );
    assert!(matches!(changes[1].1, ReferenceChange::Cleared(v) if (v - 3.3).abs() < 0.01));
    assert!((1_200..=2_250).contains(&flagged_ms), "{flagged_ms}");
    assert!((2_600..=3_650).contains(&cleared_ms), "{cleared_ms}");
    // The start-up's two (the first discarded), then one conversion a second.
    let conversions = rig.reference.as_ref().map_or(0, |a| a.conversions);
    assert!((5..=6).contains(&conversions), "{conversions}");
    // The same run without the reference's sag: outside the flagged time the board sees
    // exactly what it sees there (the start-up's own sensor checks included).
    let mut control = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    control.run(&frames, |_, _| {}).unwrap();
    assert_eq!(control.seen.len(), rig.seen.len());
    for (s, c) in rig.seen.iter().zip(&control.seen) {
        let f = s.status.sensor_fault;
        if s.t_ms >= flagged_ms && s.t_ms < cleared_ms {
            assert!(f.voltage && f.current, "{} ms", s.t_ms);
            assert!(s.tick.lamps.fault, "{} ms: input invalid", s.t_ms);
        } else {
            assert_eq!(f, c.status.sensor_fault, "{} ms", s.t_ms);
        }
    }
    assert!(!rig.last().tick.lamps.fault, "dark again");

    // An ADC that stops converting: unreadable, flagged.
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::holding(&old_record())));
    rig.supervisor.observe_reference(start, 0);
    rig.reference = Some(FakeReference {
        converts: false,
        ..FakeReference::at(3.3)
    });
    rig.run(&steady_frames(1.5), |_, _| {}).unwrap();
    assert_eq!(
        rig.reference_changes
            .iter()
            .map(|c| c.1)
            .collect::<Vec<_>>(),
        [ReferenceChange::Flagged(board::ReferenceCheck::Unreadable)]
    );
    assert!(rig.last().status.sensor_fault.voltage);
}
