//! Software in the loop: the firmware's own logic (ADC quantization, sample path, core,
//! status hand-over, supervisor with its commissioning procedure and liveness watch, flash
//! record, reset record, panel) driven sample by sample by the simulator in `sim-host`, with
//! the lamps, the watchdog and the flash asserted.
//!
//! The rig is the firmware without hardware: a sample period is 100 us of board time; the
//! sample task's work per period is `SamplePath::on_frame` (or, when the source delivers
//! nothing, the wait for ADC data with its timeout and restarts); every 100 samples it hands
//! over a status; every 50 ms thread mode runs `Supervisor::tick` and carries out its
//! action on a fake flash page; a watchdog model resets the "MCU" 500 ms after the last pet.
//! A reset (watchdog, power loss) keeps what survives on a board: the flash page, the
//! no-init RAM of the reset record and the watchdog-reset flag.
//!
//! At every thread tick the rig checks that RAM (the core's thresholds), flash (the record
//! the next boot would load) and the panel (the RUN lamp's mode) agree.

use drive_monitor::app::{
    carry_out, panel_input, MonitorStatus, SamplePath, Settings, Supervisor, Tick, PANEL_PERIOD_MS,
    WATCHDOG_TIMEOUT_MS,
};
use drive_monitor::board::{self, RECORD_PAGE_SIZE};
use drive_monitor::commissioning::{Failure, RunEnd};
use drive_monitor::flash_record::{self, CalibrationRecord, RecordStore, RECORD_LEN};
use drive_monitor::liveness::AdcWait;
use drive_monitor::panel::{self, Lamp, Mode, PanelLamps};
use drive_monitor::reset_record::{PreviousRun, ResetCause, ResetRecord, RESET_RECORD_LEN};
use drive_monitor::sampling::RawFrame;
use monitor_core::{Abc, Calibration, CommissioningFailure, Fault, RunStage};
use sim_host::params::ParamFile;
use sim_host::sim::{simulate_to_vec, FaultSpec, LoadStep, Scenario};

const FS: u32 = board::DEFAULT_SAMPLE_RATE_HZ;
const PERIODS_PER_MS: u64 = FS as u64 / 1000;
/// The rig's settings: the firmware's, with 1 s of learning to keep the tests short.
const SETTINGS: Settings = Settings {
    commissioning_duration_s: 1.0,
    ..Settings::DEFAULT
};

/// A flash fault to inject into the next record write.
#[derive(Clone, Copy, Debug)]
enum FlashFault {
    /// Power is lost after this many bytes of the record were written.
    PowerLossAfter(usize),
    /// The write reports an error and writes nothing.
    WriteFails,
}

/// The record page, with fault injection.
#[derive(Clone, Debug)]
struct FakeFlash {
    page: Vec<u8>,
    fault: Option<FlashFault>,
    power_lost: bool,
    writes: u32,
}

#[derive(Debug)]
struct FlashError;

impl FakeFlash {
    fn erased() -> Self {
        Self {
            page: vec![0xFF; RECORD_PAGE_SIZE as usize],
            fault: None,
            power_lost: false,
            writes: 0,
        }
    }

    fn holding(rec: &CalibrationRecord) -> Self {
        let mut f = Self::erased();
        f.page[..RECORD_LEN].copy_from_slice(&rec.encode().unwrap());
        f
    }

    /// The calibration the next boot would put into force (a valid record the core
    /// accepts), the flash side of "RAM, flash and panel agree".
    fn usable(&self) -> Option<Calibration> {
        CalibrationRecord::decode(&self.page)
            .ok()
            .map(Calibration::from)
            .filter(Calibration::is_valid)
    }
}

impl RecordStore for FakeFlash {
    type Error = FlashError;
    fn read(&mut self, buf: &mut [u8; RECORD_LEN]) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        buf.copy_from_slice(&self.page[..RECORD_LEN]);
        Ok(())
    }
    fn erase(&mut self) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        self.page.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, bytes: &[u8; RECORD_LEN]) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        self.writes += 1;
        match self.fault.take() {
            None => {
                self.page[..RECORD_LEN].copy_from_slice(bytes);
                Ok(())
            }
            Some(FlashFault::PowerLossAfter(n)) => {
                self.page[..n].copy_from_slice(&bytes[..n]);
                self.power_lost = true;
                Err(FlashError)
            }
            Some(FlashFault::WriteFails) => Err(FlashError),
        }
    }
}

/// What survives a reset on the board.
#[derive(Clone, Debug)]
struct Survivors {
    flash: FakeFlash,
    reset_ram: [u8; RESET_RECORD_LEN],
    watchdog_reset: bool,
}

impl Survivors {
    fn power_on(flash: FakeFlash) -> Self {
        Self {
            flash,
            // Power-on RAM content: anything.
            reset_ram: [0x5A; RESET_RECORD_LEN],
            watchdog_reset: false,
        }
    }
}

/// Why a run of the rig stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reset {
    Watchdog,
    PowerLoss,
}

/// One thread-mode period as the rig saw it.
#[derive(Clone, Copy, Debug)]
struct Seen {
    t_ms: u32,
    tick: Tick,
    status: MonitorStatus,
    /// The core's quasi-steady gate at the tick (a peek the firmware does not need).
    quasi_steady: bool,
}

/// The firmware without hardware.
struct Rig {
    settings: Settings,
    survivors: Survivors,
    previous: PreviousRun,
    path: SamplePath,
    supervisor: Supervisor,
    periods: u64,
    pending_status: Option<MonitorStatus>,
    button: bool,
    last_pet_ms: u32,
    adc: AdcWait,
    waited_us: u32,
    restarts_at_ms: Vec<u32>,
    seen: Vec<Seen>,
    ended: Vec<RunEnd>,
}

impl Rig {
    fn boot(survivors: Survivors) -> Self {
        Self::boot_with(SETTINGS, survivors)
    }

    fn boot_with(settings: Settings, mut survivors: Survivors) -> Self {
        let previous = PreviousRun::at_boot(&survivors.reset_ram, survivors.watchdog_reset);
        survivors.reset_ram = [0; RESET_RECORD_LEN];
        survivors.watchdog_reset = false;
        survivors.flash.power_lost = false;
        let mut path = SamplePath::for_board(settings.sample_rate_hz).unwrap();
        let mut installed = None;
        if let Ok(rec) = flash_record::load(&mut survivors.flash) {
            // A record the core rejects leaves the default thresholds (logged on the board).
            if path
                .command(drive_monitor::app::Command::SetCalibration(rec))
                .is_ok()
            {
                installed = Some(rec);
            }
        }
        let mut supervisor = Supervisor::new(&settings, previous, 0, path.status());
        if let Some(rec) = installed {
            supervisor.restore_isolation(&rec);
        }
        Rig {
            settings,
            survivors,
            previous,
            path,
            supervisor,
            periods: 0,
            pending_status: None,
            button: false,
            last_pet_ms: 0,
            adc: AdcWait::new(settings.sample_rate_hz),
            waited_us: 0,
            restarts_at_ms: Vec::new(),
            seen: Vec::new(),
            ended: Vec::new(),
        }
    }

    fn now_ms(&self) -> u32 {
        (self.periods / PERIODS_PER_MS) as u32
    }

    fn press(&mut self) {
        self.button = true;
    }

    /// One sample period: the sample task gets `raw` (or nothing: the source is stopped),
    /// then thread mode runs if its period is due. `Err` when the MCU reset.
    fn period(&mut self, raw: Option<&RawFrame>) -> Result<(), Reset> {
        match raw {
            Some(raw) => {
                self.waited_us = 0;
                self.adc.data();
                self.path.on_frame(raw);
                if self
                    .path
                    .samples()
                    .is_multiple_of(self.settings.status_every())
                {
                    self.pending_status = Some(self.path.status());
                }
            }
            None => {
                self.waited_us += 1_000_000 / FS;
                if self.waited_us >= self.adc.timeout_us() {
                    // The wait timed out: the sample task restarts the acquisition.
                    self.adc.timed_out();
                    self.waited_us = 0;
                    self.restarts_at_ms.push(self.now_ms());
                    let now_us = (self.periods * 1_000_000 / u64::from(FS)) as u32;
                    self.path.sampler_mut().resync(now_us);
                }
            }
        }
        self.periods += 1;
        let now_ms = self.now_ms();
        if self
            .periods
            .is_multiple_of(PERIODS_PER_MS * u64::from(PANEL_PERIOD_MS))
        {
            self.thread_tick(now_ms)?;
        }
        if now_ms.wrapping_sub(self.last_pet_ms) > WATCHDOG_TIMEOUT_MS {
            self.survivors.watchdog_reset = true;
            return Err(Reset::Watchdog);
        }
        Ok(())
    }

    fn thread_tick(&mut self, now_ms: u32) -> Result<(), Reset> {
        let status = self.pending_status.take();
        let button = std::mem::take(&mut self.button);
        let tick = self.supervisor.tick(now_ms, status, button);
        let used = *self.supervisor.latest();
        self.check_agreement(now_ms, &tick, &used);
        self.seen.push(Seen {
            t_ms: now_ms,
            tick,
            status: used,
            quasi_steady: self.path.monitor().output().quasi_steady,
        });
        if tick.pet_watchdog {
            self.last_pet_ms = now_ms;
        }
        self.ended.extend(tick.run_ended);
        match tick.liveness {
            Some(drive_monitor::liveness::LivenessChange::RecordStall { for_ms }) => {
                self.survivors.reset_ram = ResetRecord::sample_stall(for_ms).encode();
            }
            Some(drive_monitor::liveness::LivenessChange::Recovered { .. }) => {
                self.survivors.reset_ram = [0; RESET_RECORD_LEN];
            }
            _ => {}
        }
        let (command, _stored) = carry_out(tick.action, &mut self.survivors.flash);
        if self.survivors.flash.power_lost {
            return Err(Reset::PowerLoss);
        }
        if let Some(cmd) = command {
            // The sample task applies commands between two samples; a refused one is
            // logged on the board.
            let _ = self.path.command(cmd);
        }
        Ok(())
    }

    /// RAM, flash and panel agree (checked at every thread tick, before its action).
    fn check_agreement(&self, now_ms: u32, tick: &Tick, status: &MonitorStatus) {
        let ram = self.path.monitor().calibration();
        let run = self.path.monitor().commissioning();
        let flash = self.survivors.flash.usable();
        if !matches!(run.stage, RunStage::AwaitingStorage(_)) {
            assert_eq!(ram, flash, "{now_ms} ms: RAM and flash disagree ({run:?})");
        }
        assert_eq!(
            status.commissioned,
            ram.is_some(),
            "{now_ms} ms: the status is not the core's"
        );
        let expected = if status.run.stage.is_active() {
            Mode::Commissioning
        } else if status.commissioned {
            Mode::Commissioned
        } else {
            Mode::NotCommissioned
        };
        if !matches!(tick.mode, Mode::Failed | Mode::SamplingStalled) {
            assert_eq!(tick.mode, expected, "{now_ms} ms: the panel disagrees");
        }
    }

    /// Runs the frames from index `from` on; `at(rig, k)` may act before frame `k`.
    fn run(
        &mut self,
        frames: &[RawFrame],
        mut at: impl FnMut(&mut Rig, usize),
    ) -> Result<(), Reset> {
        for (k, raw) in frames.iter().enumerate() {
            at(self, k);
            self.period(Some(raw))?;
        }
        Ok(())
    }

    fn last(&self) -> &Seen {
        self.seen.last().expect("a thread tick")
    }

    fn mode(&self) -> Mode {
        self.last().tick.mode
    }
}

fn frames(scenario: &Scenario) -> Vec<RawFrame> {
    let params = ParamFile::reference_2p2kw();
    let rows = simulate_to_vec(&params, scenario).expect("simulation");
    let q = *SamplePath::for_board(FS).unwrap().sampler();
    let mut theta_counts = 0.0f64;
    let dt = 1.0 / f64::from(FS);
    rows.iter()
        .map(|row| {
            let v = row.v_abc.unwrap_or([0.0; 3]);
            let i = row.i_abc;
            let count = match row.enc_count {
                Some(c) => c as u32,
                None => {
                    theta_counts += row.wm_rad_s.unwrap_or(0.0) * dt / std::f64::consts::TAU
                        * f64::from(board::ENCODER_COUNTS_PER_REV);
                    theta_counts.floor() as i64 as u32
                }
            };
            q.quantize(
                Abc {
                    a: v[0] as f32,
                    b: v[1] as f32,
                    c: v[2] as f32,
                },
                Abc {
                    a: i[0] as f32,
                    b: i[1] as f32,
                    c: i[2] as f32,
                },
                count,
            )
        })
        .collect()
}

/// Healthy running at the rated viscous load: run-up, then steady.
fn steady_frames(duration_s: f64) -> Vec<RawFrame> {
    frames(&Scenario::steady(duration_s, f64::from(FS)))
}

/// A record from an earlier commissioning (a plausible healthy calibration).
fn old_record() -> CalibrationRecord {
    CalibrationRecord {
        mean: [0.0, 0.001, -0.001, 0.0],
        spread: [0.004; 4],
        isolation: None,
    }
}

const PRESS_AT: usize = 15_000; // 1.5 s: after the run-up and the core's settling

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
    let input = panel_input(rig.mode(), &status, iso.as_ref(), false);
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

/// Table 1 faults through the firmware's own path: commissioned, then the fault at +50 %
/// (the current and voltage sensors at +20 %: +50 % drives the board's front end past its
/// full scale, which is a sensor fault, the steady lamp, tested below); the FAULT lamp the
/// supervisor drives blinks the isolated fault's code (the friction class for Bl), and the
/// isolation's size is within 20 % of the truth (relative), both as thread mode has them.
#[test]
fn the_fault_lamp_blinks_the_isolated_fault_and_the_size_is_right() {
    let cases = [
        (Fault::Rr, false, 0.5),
        (Fault::Ls, false, 0.5),
        (Fault::Lr, false, 0.5),
        (Fault::Bl, false, 0.5),
        (Fault::CurrentSensor, true, 0.2),
        (Fault::VoltageSensor, true, 0.2),
        (Fault::SpeedSensor, true, 0.5),
    ];
    let mut wrong = Vec::new();
    for (fault, sensor, change) in cases {
        // Long enough for two periods of blink code 9 after the fault is named.
        let mut scenario = Scenario::steady(20.0, f64::from(FS));
        scenario.faults.push(if sensor {
            FaultSpec::sensor_gain(fault, 4.0, change)
        } else {
            FaultSpec::parametric(fault, 4.0, change)
        });
        let frames = frames(&scenario);
        let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
        rig.run(&frames, |rig, k| {
            if k == PRESS_AT {
                rig.press();
            }
        })
        .unwrap();
        assert_eq!(rig.ended, [RunEnd::Commissioned { run: 1 }], "{fault:?}");
        let trace: Vec<bool> = rig
            .seen
            .iter()
            .filter(|s| s.t_ms >= 5_000)
            .map(|s| s.tick.lamps.fault)
            .collect();
        let code = panel::read_blink_code(&trace, PANEL_PERIOD_MS);
        let want = if fault == Fault::Bl {
            5
        } else {
            fault.index() as u8 + 1
        };
        let iso = rig.supervisor.isolation().copied();
        let size = iso.and_then(|i| i.named()).map(|n| match n {
            monitor_core::Named::Fault(c) => (c.fault, c.change),
            monitor_core::Named::Friction { bl, .. } => (Fault::Bl, bl.change),
        });
        let size_ok =
            size.is_some_and(|(f, c)| f == fault && (f64::from(c) - change).abs() <= 0.2 * change);
        if code != Some(want) || !size_ok {
            let t: String = trace.iter().map(|&b| if b { '#' } else { '.' }).collect();
            let st = rig.last().status;
            wrong.push(format!(
                "{fault:?}: code {code:?} (want {want}), named {size:?}, state {:?}, sensor {:?}, lamps {:?} {t}",
                iso.map(|i| i.state),
                st.sensor_fault,
                st.residual_lamps
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// The isolation baseline learned in a commissioning run is stored with its calibration
/// (record version 2) and put back into force at the next boot: a fault after a reset is
/// isolated against the machine's own baseline, so the panel blinks the isolated fault
/// and its size is right. Before, the baseline was lost at a reset and the panel fell back
/// to the lamps' top candidate until the next commissioning.
#[test]
fn the_isolation_baseline_survives_a_reset() {
    let frames_healthy = frames(&Scenario::steady(5.0, f64::from(FS)));
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&frames_healthy, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
    })
    .unwrap();
    assert_eq!(rig.ended, [RunEnd::Commissioned { run: 1 }]);
    let stored = CalibrationRecord::decode(&rig.survivors.flash.page).unwrap();
    let learned = rig.supervisor.isolation_baseline();
    let b = stored
        .isolation
        .expect("the run's isolation baseline is in the record");
    assert_eq!(Some(b), learned, "the record holds the baseline in force");
    for (s, floor) in b
        .spread
        .to_array()
        .iter()
        .zip(monitor_core::isolation::LEARNED_SPREAD_FLOOR.to_array())
    {
        assert!(*s >= floor && *s < 10.0 * floor, "{b:?}");
    }

    // Reset; Rr +50 % from 2 s on, no new commissioning.
    let mut scenario = Scenario::steady(14.0, f64::from(FS));
    scenario
        .faults
        .push(FaultSpec::parametric(Fault::Rr, 2.0, 0.5));
    let frames_faulty = frames(&scenario);
    let mut rig = Rig::boot(Survivors::power_on(rig.survivors.flash.clone()));
    assert_eq!(rig.supervisor.isolation_baseline(), Some(b));
    rig.run(&frames_faulty, |_, _| {}).unwrap();
    let trace: Vec<bool> = rig
        .seen
        .iter()
        .filter(|s| s.t_ms >= 4_000)
        .map(|s| s.tick.lamps.fault)
        .collect();
    let code = panel::read_blink_code(&trace, PANEL_PERIOD_MS);
    assert_eq!(code, Some(Fault::Rr.index() as u8 + 1));
    let named = rig.supervisor.isolation().and_then(|i| i.named_fault());
    let c = named.expect("Rr named"); // ok: test
    assert_eq!(c.fault, Fault::Rr);
    assert!((c.change - 0.5).abs() <= 0.1, "{c:?}");
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
    let input = panel_input(Mode::Commissioned, &rig.last().status, None, true);
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

#[test]
fn power_loss_during_the_flash_write_leaves_no_record_anywhere() {
    let frames = steady_frames(3.0);
    let mut flash = FakeFlash::holding(&old_record());
    // The record page was erased and 16 of the 48 bytes written when the power went.
    flash.fault = Some(FlashFault::PowerLossAfter(16));
    let mut rig = Rig::boot(Survivors::power_on(flash));
    let reset = rig.run(&frames, |rig, k| {
        if k == PRESS_AT {
            rig.press();
        }
    });
    assert_eq!(reset, Err(Reset::PowerLoss));
    // Power back: the torn record is rejected; RAM, flash and panel say "not commissioned".
    let survivors = Survivors::power_on(rig.survivors.flash.clone());
    assert_eq!(
        CalibrationRecord::decode(&survivors.flash.page),
        Err(flash_record::RecordError::BadChecksum)
    );
    let mut rig = Rig::boot(survivors);
    assert_eq!(rig.previous, PreviousRun::Clean);
    rig.run(&frames[..5_000], |_, _| {}).unwrap();
    assert_eq!(rig.path.monitor().calibration(), None);
    assert_eq!(rig.survivors.flash.usable(), None);
    assert_eq!(rig.mode(), Mode::NotCommissioned);
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
    // The page was erased, the write failed: nothing in flash, nothing in RAM.
    assert_eq!(
        rig.ended,
        [RunEnd::Failed {
            run: Some(1),
            why: Failure::Core(CommissioningFailure::NotStored)
        }]
    );
    assert_eq!(rig.path.monitor().calibration(), None);
    assert_eq!(rig.survivors.flash.usable(), None);
    assert_eq!(rig.mode(), Mode::NotCommissioned);
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
fn a_panic_reason_survives_the_reset() {
    let frames = steady_frames(1.0);
    let mut rig = Rig::boot(Survivors::power_on(FakeFlash::erased()));
    rig.run(&frames, |_, _| {}).unwrap();
    // The panic handler records the reason, stops petting; the watchdog resets.
    let mut survivors = rig.survivors.clone();
    survivors.reset_ram =
        ResetRecord::panic("attempt to divide by zero", "src/app.rs", 321).encode();
    survivors.watchdog_reset = true;
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
    assert_eq!(Rig::boot(survivors).previous, PreviousRun::WatchdogReset);
}

#[test]
fn saturated_adc_lights_the_fault_lamp_steadily() {
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
    assert!(status.sensor_fault.current);
    let input = panel_input(rig.mode(), &status, rig.supervisor.isolation(), false);
    assert!(panel::render(&input, 0).is_on(Lamp::Fault));
    assert!(
        panel::render(&input, 777).is_on(Lamp::Fault),
        "steady, not blinking"
    );
    assert!(rig.seen.iter().rev().take(10).all(|s| s.tick.lamps.fault));
}
