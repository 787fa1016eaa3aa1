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

mod boot_composition;
mod clipping;
mod commissioning;
mod conversions;
mod drift;
mod evidence;
mod flash_pause;
mod hal_restart;
mod isolation;
mod liveness;
mod moved;
mod recovery;
mod reference_gain;
mod same_state;
mod startup;
mod thread;

use drive_monitor::app::{
    panel_input, period, AcquisitionPause, Command, MonitorStatus, PeriodInput, SamplePath,
    Settings, Supervisor, ThreadState, Tick, PANEL_PERIOD_MS, WATCHDOG_TIMEOUT_MS,
};
use drive_monitor::board::Lamp;
use drive_monitor::board::{self, RECORD_PAGE_SIZE};
use drive_monitor::boot_block::BootHistory;
use drive_monitor::clock::ClockSource;
use drive_monitor::commissioning::{Failure, RunEnd};
use drive_monitor::flash_record::{self, CalibrationRecord, RecordPage, RecordStore, RECORD_LEN};
use drive_monitor::liveness::AdcWait;
use drive_monitor::offset_trim::TrimResult;
use drive_monitor::panel::{self, Mode, PanelLamps};
use drive_monitor::recovery::{Faults, StepTimeout};
use drive_monitor::reset_record::{
    PreviousRun, ResetCause, ResetRecord, ResetSource, RESET_RECORD_LEN,
};
use drive_monitor::sampling::RawFrame;
use drive_monitor::self_check::Findings;
use drive_monitor::startup::{boot_board, BootFacts};
use drive_monitor::supply::BorCheck;
use monitor_core::{Abc, Calibration, CommissioningFailure, Fault, RunStage};
use monitor_io::params::ParamFile;
use monitor_sim::{simulate_to_vec, FaultSpec, LoadStep, Scenario};
use thread::RigThread;

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

/// The commissioning record's two pages (`page`: the first, `page_b`: the second), with
/// fault injection.
#[derive(Clone, Debug)]
struct FakeFlash {
    page: Vec<u8>,
    page_b: Vec<u8>,
    fault: Option<FlashFault>,
    power_lost: bool,
    writes: u32,
}

#[derive(Debug, PartialEq)]
struct FlashError;

impl FakeFlash {
    fn erased() -> Self {
        Self {
            page: vec![0xFF; RECORD_PAGE_SIZE as usize],
            page_b: vec![0xFF; RECORD_PAGE_SIZE as usize],
            fault: None,
            power_lost: false,
            writes: 0,
        }
    }

    fn page_mut(&mut self, page: RecordPage) -> &mut Vec<u8> {
        match page {
            RecordPage::A => &mut self.page,
            RecordPage::B => &mut self.page_b,
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
        flash_record::load(&mut self.clone())
            .ok()
            .map(Calibration::from)
            .filter(Calibration::is_valid)
    }
}

impl RecordStore for FakeFlash {
    type Error = FlashError;
    fn read(&mut self, page: RecordPage, buf: &mut [u8; RECORD_LEN]) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        buf.copy_from_slice(&self.page_mut(page)[..RECORD_LEN]);
        Ok(())
    }
    fn erase(&mut self, page: RecordPage) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        self.page_mut(page).fill(0xFF);
        Ok(())
    }
    fn write(&mut self, page: RecordPage, bytes: &[u8; RECORD_LEN]) -> Result<(), FlashError> {
        if self.power_lost {
            return Err(FlashError);
        }
        self.writes += 1;
        match self.fault.take() {
            None => {
                self.page_mut(page)[..RECORD_LEN].copy_from_slice(bytes);
                Ok(())
            }
            Some(FlashFault::PowerLossAfter(n)) => {
                self.page_mut(page)[..n].copy_from_slice(&bytes[..n]);
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
    /// The motor record's flash page as the firmware reads it at boot.
    motor_page: Vec<u8>,
    reset_ram: [u8; RESET_RECORD_LEN],
    /// What the reset flags of `RCC_CSR` say at the next boot.
    reset_source: ResetSource,
}

impl Survivors {
    /// Power on with `flash` as the commissioning page and the built-in machine's motor
    /// record on its page (so the panel shows no default-motor mark).
    fn power_on(flash: FakeFlash) -> Self {
        Self {
            flash,
            motor_page: motor_page(&drive_monitor::motor_source::default_record().to_bytes()),
            // Power-on RAM content: anything.
            reset_ram: [0x5A; RESET_RECORD_LEN],
            reset_source: ResetSource::PowerOnOrBrownOut,
        }
    }

    /// The same with `bytes` at the start of the motor record's page.
    fn with_motor_page(self, bytes: &[u8]) -> Self {
        Self {
            motor_page: motor_page(bytes),
            ..self
        }
    }
}

/// A motor-record flash page (2 KiB) holding `bytes`, erased after them.
fn motor_page(bytes: &[u8]) -> Vec<u8> {
    let mut page = vec![0xFF; RECORD_PAGE_SIZE as usize];
    page[..bytes.len()].copy_from_slice(bytes);
    page
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
    /// The ADCs, DMA channels and trigger: the firmware's register sequence over a
    /// register-level model of the hardware (`recovery::AdcDmaModel`).
    acq: recovery::ModelAcq,
    /// What the sample task runs when a wait timed out: the firmware's
    /// `drive_monitor::recovery::recover`, or another sequence to compare with.
    restart: fn(&mut recovery::ModelAcq) -> Result<Faults, StepTimeout>,
    /// The results of the restarts.
    recoveries: Vec<Result<Faults, StepTimeout>>,
    /// The start-up offset trim's result.
    trims: Vec<TrimResult>,
    seen: Vec<Seen>,
    ended: Vec<RunEnd>,
    /// VREFINT on ADC1's injected channel, when the test gives one: thread mode polls it
    /// through `Supervisor::poll_reference` at every tick, as the firmware does.
    reference: Option<startup::FakeReference>,
    /// The reference verdict's changes, with the tick's time [ms].
    reference_changes: Vec<(u32, drive_monitor::supply::ReferenceChange)>,
    /// The flash stores that paused the acquisition (`app::carry_out`).
    paused_for_flash: u32,
    /// Thread mode's state across periods (`app::period`).
    thread: ThreadState,
    /// The offset trim's result, handed to thread mode at its next period.
    pending_trim: Option<TrimResult>,
    /// The runs marked up (`false`) and long up (`true`), in order.
    marked_up: Vec<bool>,
}

/// The sample task's pause around a flash store on the rig: the firmware's
/// `recovery::pause` and `recovery::resume` on the register model.
struct ModelPause<'a> {
    acq: &'a mut recovery::ModelAcq,
    paused: &'a mut u32,
}

impl AcquisitionPause for ModelPause<'_> {
    fn pause(&mut self) -> bool {
        *self.paused += 1;
        drive_monitor::recovery::pause(self.acq).is_ok()
    }
    fn resume(&mut self) {
        drive_monitor::recovery::resume(self.acq);
    }
}

impl Rig {
    fn boot(survivors: Survivors) -> Self {
        Self::boot_with(SETTINGS, survivors)
    }

    fn boot_with(settings: Settings, mut survivors: Survivors) -> Self {
        let previous = PreviousRun::at_boot(&survivors.reset_ram, survivors.reset_source);
        // What the start (`drive_monitor::startup::start`, run on its own register model
        // in `tests/startup/`) hands the boot: the crystal, the brown-out level at its goal,
        // nothing found.
        let facts = BootFacts {
            previous,
            reset_source: survivors.reset_source,
            history: BootHistory::of(None, survivors.reset_source, &previous),
            stack_overflowed: false,
            clock: Some(ClockSource::Hse),
            findings: Findings::NONE,
            bor: BorCheck::of_optr(0xFFEF_F8AA | 4 << 8),
            safe_mode: None,
        };
        survivors.reset_ram = [0; RESET_RECORD_LEN];
        // The flags are cleared at boot; a boot of the rig without a reset event is the
        // reset button's.
        survivors.reset_source = ResetSource::Pin;
        survivors.flash.power_lost = false;
        // The firmware's boot composition: the machine, its sample path and isolator, the
        // stored calibration (a record the core rejects leaves the default thresholds) and
        // the supervisor with the panel's marks.
        let booted = boot_board(
            &facts,
            &survivors.motor_page,
            &mut survivors.flash,
            &settings,
        )
        .unwrap();
        let (path, supervisor) = (booted.path, booted.supervisor);
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
            acq: recovery::AdcDmaModel::running(),
            restart: drive_monitor::recovery::recover,
            recoveries: Vec::new(),
            trims: Vec::new(),
            seen: Vec::new(),
            ended: Vec::new(),
            reference: None,
            reference_changes: Vec::new(),
            paused_for_flash: 0,
            thread: ThreadState::default(),
            pending_trim: None,
            marked_up: Vec::new(),
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
                if let Some(trim) = self.path.trim_offsets(raw) {
                    // Handed to thread mode (logged, the sensor flags).
                    self.pending_trim = Some(trim);
                    self.trims.push(trim);
                }
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
                    // The wait timed out: the sample task recovers the acquisition.
                    self.adc.timed_out();
                    let result = (self.restart)(&mut self.acq);
                    self.recoveries.push(result);
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
            self.survivors.reset_source = ResetSource::IndependentWatchdog;
            return Err(Reset::Watchdog);
        }
        Ok(())
    }

    /// Thread mode's period: the firmware's own (`app::period`) on the rig's hardware.
    fn thread_tick(&mut self, now_ms: u32) -> Result<(), Reset> {
        let input = PeriodInput {
            now_ms,
            status: self.pending_status.take(),
            pressed: std::mem::take(&mut self.button),
            trim: self.pending_trim.take(),
            reference: None,
        };
        let mut hw = RigThread {
            now_ms,
            flash: &mut self.survivors.flash,
            reset_ram: &mut self.survivors.reset_ram,
            pause: ModelPause {
                acq: &mut self.acq,
                paused: &mut self.paused_for_flash,
            },
            reference: self.reference.as_mut(),
            last_pet_ms: &mut self.last_pet_ms,
            marked_up: &mut self.marked_up,
        };
        let out = period(&mut self.supervisor, &mut self.thread, input, &mut hw);
        let tick = out.tick;
        let used = *self.supervisor.latest();
        // Before the commands reach the sample path: a store's record is in flash, the core
        // still awaits it.
        self.check_agreement(now_ms, &tick, &used);
        self.seen.push(Seen {
            t_ms: now_ms,
            tick,
            status: used,
            quasi_steady: self.path.monitor().output().quasi_steady,
        });
        self.ended.extend(tick.run_ended);
        for change in out.reference_changes.into_iter().flatten() {
            self.reference_changes.push((now_ms, change));
        }
        if self.survivors.flash.power_lost {
            self.survivors.reset_source = ResetSource::PowerOnOrBrownOut;
            return Err(Reset::PowerLoss);
        }
        for cmd in out.commands.into_iter().flatten() {
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

    /// Runs the frames (one per trigger period; lost while the acquisition delivers
    /// nothing); `at(rig, k)` may act before frame `k`.
    fn run(
        &mut self,
        frames: &[RawFrame],
        mut at: impl FnMut(&mut Rig, usize),
    ) -> Result<(), Reset> {
        for (k, raw) in frames.iter().enumerate() {
            at(self, k);
            // The frame reaches the sample path only when the hardware delivers it.
            let delivered = self.acq.regs.sample();
            self.period(delivered.then_some(raw))?;
        }
        Ok(())
    }

    /// Runs `frames` with the button pressed at [`PRESS_AT`] and checks that the run
    /// commissioned.
    fn run_commissioning(&mut self, frames: &[RawFrame]) {
        self.run(frames, |rig, k| {
            if k == PRESS_AT {
                rig.press();
            }
        })
        .unwrap();
        assert_eq!(self.ended, [RunEnd::Commissioned { run: 1 }]);
    }

    fn last(&self) -> &Seen {
        self.seen.last().expect("a thread tick")
    }

    fn mode(&self) -> Mode {
        self.last().tick.mode
    }
}

fn frames(scenario: &Scenario) -> Vec<RawFrame> {
    frames_with(
        &ParamFile::reference_2p2kw(),
        &SamplePath::for_board(FS).unwrap(),
        scenario,
    )
}

/// The frames of `params`' machine in `scenario`, quantized by `path`'s front end (the
/// encoder with the board's counts per revolution).
fn frames_with(params: &ParamFile, path: &SamplePath, scenario: &Scenario) -> Vec<RawFrame> {
    let rows = simulate_to_vec(params, scenario).expect("simulation");
    let q = *path.sampler();
    let mut theta_counts = 0.0f64;
    let dt = 1.0 / scenario.sample_rate_hz;
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
        vdda_v: None,
    }
}

const PRESS_AT: usize = 15_000; // 1.5 s: after the run-up and the core's settling
