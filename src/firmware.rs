//! The STM32G474RE firmware: hardware tasks around the hardware-free logic in the library.
//!
//! Tasks and priorities:
//! - `sample_task` (`firmware/sample_task.rs`) on an interrupt executor (UART4 vector, NVIC
//!   priority P1, above thread mode): TIM1 TRGO triggers ADC1 (va, vb, vc) and ADC2 (ia, ib,
//!   ic) eight times per sample of [`SETTINGS`]; each ADC fills a DMA ring of two halves of
//!   eight sequences (`drive_monitor::acquisition`), so every sample wakes the task
//!   (half- and full-transfer interrupts). The task sums the sequences, runs
//!   `acquisition::PwmFilter` (an inverter's in-band ripple out), takes the encoder counts
//!   TIM4 latched at the same triggers (its capture on TIM1's TRGO, copied by DMA1 channel 3
//!   into a ring beside the ADCs') and runs `SamplePath::on_frame` (scaling and `Monitor::update`). Every wait for
//!   ADC data has a timeout (`drive_monitor::liveness::AdcWait`): when it expires (an ADC
//!   overrun, a DMA transfer error, a stopped trigger) or the DMA lapped the reader, the
//!   acquisition is recovered by `drive_monitor::recovery::recover` on the registers
//!   (`firmware/acquisition.rs`): trigger, ADCs and DMA stopped (`DMAEN` cleared), `OVR`,
//!   `EOC`, `EOS` and `TEIF` cleared, DMA re-armed, ADCs and trigger restarted, in the
//!   reference manual's order. Every `status_every` samples the task hands thread mode a
//!   small `MonitorStatus`.
//! - `main` in thread mode: the start (`drive_monitor::startup::start` on the registers of
//!   `firmware/startup_hw.rs`: the freeze, the watchdog, why the previous run ended, the
//!   clock with its bounded waits, the self-check; the safe mode, `firmware/safe_mode.rs`,
//!   when the boot gave up), the flash records, then every 50 ms thread mode's period
//!   (`drive_monitor::app::period`: button, commissioning procedure, the watch on the sample
//!   counter, the watchdog petted only while samples flow, the run marked up, panel, the
//!   commissioning action carried out), its commands sent to the sample task, and a status
//!   line every 100 ms.
//! - The fault path (`firmware/failure.rs`: the panic handlers, `core`'s and defmt's, the
//!   HardFault, NMI and default handlers; `drive_monitor::fault_path`): a guard, the reason
//!   into the reset record (RAM that survives the reset), "monitor failed" on the panel, no
//!   log, then the watchdog's reset, or a software reset when the watchdog does not run yet.
//!   An NMI from an ECC double error in a record page is latched instead, and the boot
//!   falls back (`drive_monitor::flash_ecc`, `firmware/flash.rs`).
//!
//! Communication: `COMMANDS` (Channel, thread -> sample task), `STATUS` (Signal, latest
//! status, sample task -> thread, 100 Hz), `TRIM` (Signal, the start-up offset trim, once).

mod acquisition;
mod commands;
mod failure;
mod flash;
mod logs;
mod reset_ram;
mod safe_mode;
mod sample_task;
mod stack;
mod startup_hw;
mod supply;
mod vcp;

use core::sync::atomic::{AtomicU32, Ordering};

use defmt::{error, info};
use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::exti::{self, ExtiInput};
use embassy_stm32::flash::Flash;
use embassy_stm32::gpio::{Level, Output, Pull, Speed};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::mode::Async;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, dma, interrupt, peripherals, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_time::{with_deadline, Duration, Instant, Timer};

use drive_monitor::app::{
    period, status_line, BoardCounters, Command, MonitorStatus, PeriodInput, SamplePath, Settings,
    Supervisor, ThreadHw, ThreadState, Tick, PANEL_PERIOD_MS, WATCHDOG_TIMEOUT_MS,
};
use drive_monitor::board::{self, pins::Board, Lamp, LAMP_COUNT};
use drive_monitor::boot::BootMachine;
use drive_monitor::offset_trim::TrimResult;
use drive_monitor::panel::PanelLamps;
use drive_monitor::reset_record::{BootPhase, ResetRecord, RESET_RECORD_LEN};
use drive_monitor::startup::{self, BootFacts};
use drive_monitor::supply::{BorCheck, BorGate};
use monitor_core::Isolation;
use reset_ram::{mark_phase, set_phase};

use drive_monitor::flash_ecc::CheckedFlash;
use flash::{read_motor_page, BoardFlash, Driver};
use sample_task::{sample_task, SampleHw};

// Every defmt frame carries the time since boot in microseconds (embassy-time's clock; what
// embassy-time's `defmt-timestamp-uptime` feature defines, written here so the build's
// features stay as they are). Frames logged before `init` would read 0; none are.
defmt::timestamp!("{=u64:us}", embassy_time::Instant::now().as_micros());

bind_interrupts!(struct Irqs {
    DMA1_CHANNEL1 => acquisition::AdcDmaInterrupt<peripherals::DMA1_CH1, 0>;
    DMA1_CHANNEL2 => acquisition::AdcDmaInterrupt<peripherals::DMA1_CH2, 1>;
    DMA1_CHANNEL3 => acquisition::AdcDmaInterrupt<peripherals::DMA1_CH3, 2>;
    EXTI15_10 => exti::InterruptHandler<interrupt::typelevel::EXTI15_10>;
});

// SAFETY: the DMA channels' vectors run `acquisition::AdcDmaInterrupt`, which calls
// embassy's `dma::InterruptHandler` for the channel every time except with `TEIF` set,
// when the channel is off (the hardware cleared `EN`) and the recovery owns it: the ring
// drivers get every interrupt of a running channel, which is what the binding promises.
#[allow(unsafe_code)]
unsafe impl
    interrupt::typelevel::Binding<
        interrupt::typelevel::DMA1_CHANNEL1,
        dma::InterruptHandler<peripherals::DMA1_CH1>,
    > for Irqs
{
}
// SAFETY: as above, for channel 2.
#[allow(unsafe_code)]
unsafe impl
    interrupt::typelevel::Binding<
        interrupt::typelevel::DMA1_CHANNEL2,
        dma::InterruptHandler<peripherals::DMA1_CH2>,
    > for Irqs
{
}
// SAFETY: as above, for channel 3 (the encoder latch's ring).
#[allow(unsafe_code)]
unsafe impl
    interrupt::typelevel::Binding<
        interrupt::typelevel::DMA1_CHANNEL3,
        dma::InterruptHandler<peripherals::DMA1_CH3>,
    > for Irqs
{
}

/// The firmware's settings: the sample rate (10 kHz; it must divide 1 MHz, and TIM1 at
/// 170 MHz divides it exactly for 10 kHz), the commissioning time and stall time. The
/// rate goes through `SamplePath::for_board`, that is `app::board_monitor_config`, the
/// same configuration function the host tests use.
const SETTINGS: Settings = Settings::DEFAULT;
const _: () = assert!(SETTINGS.validate().is_ok(), "SETTINGS out of range");
/// Longest wait for a command slot in the queue, ms (the sample task empties it at every
/// sample).
const COMMAND_SEND_TIMEOUT_MS: u64 = 100;

/// What the sample task hands thread mode.
#[derive(Clone, Copy)]
struct Status {
    monitor: MonitorStatus,
    max_update_cycles: u32,
}

static COMMANDS: Channel<CriticalSectionRawMutex, Command, 4> = Channel::new();
static STATUS: Signal<CriticalSectionRawMutex, Status> = Signal::new();
/// The start-up offset trim's result (sample task -> thread mode, once).
static TRIM: Signal<CriticalSectionRawMutex, TrimResult> = Signal::new();
/// The start-up check of the ADC's reference, from the sample task to thread mode.
static REFERENCE: Signal<CriticalSectionRawMutex, board::ReferenceCheck> = Signal::new();
/// The sample task paused the acquisition for a flash erase (`true`: stopped), to thread
/// mode (`app::AcquisitionPause`).
static PAUSED: Signal<CriticalSectionRawMutex, bool> = Signal::new();
/// Thread mode has finished with the flash: the sample task resumes the acquisition.
static RESUME: Signal<CriticalSectionRawMutex, ()> = Signal::new();
/// The longest the sample task stays paused for the flash [ms] (an erase takes about
/// 22 ms, the record's write about 1 ms); it resumes then whatever thread mode says.
const PAUSE_LIMIT_MS: u32 = 100;
/// The longest thread mode waits for the sample task to pause [ms] (it pauses between two
/// halves, 300 us apart).
const PAUSE_WAIT_MS: u64 = 10;
static OVERRUNS: AtomicU32 = AtomicU32::new(0);
static RESTARTS: AtomicU32 = AtomicU32::new(0);
static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();
#[interrupt]
#[allow(unsafe_code)]
unsafe fn UART4() {
    // SAFETY: UART4 is not used as a UART; its vector is dedicated to this executor,
    // which is started once in `main` before the interrupt is enabled.
    unsafe { EXECUTOR_HIGH.on_interrupt() }
}

/// The six lamp outputs, in [`Lamp::ALL`] order.
struct PanelPins {
    pins: [Output<'static>; LAMP_COUNT],
}

impl PanelPins {
    fn new(pins: [Peri<'static, embassy_stm32::gpio::AnyPin>; LAMP_COUNT]) -> Self {
        Self {
            pins: pins.map(|p| Output::new(p, Level::Low, Speed::Low)),
        }
    }

    fn show(&mut self, lamps: &PanelLamps) {
        for (pin, lamp) in self.pins.iter_mut().zip(Lamp::ALL) {
            pin.set_level(Level::from(lamps.is_on(lamp)));
        }
    }
}

/// The independent watchdog at its running timeout (`WATCHDOG_TIMEOUT_MS`, 500 ms): it
/// runs since the start (`drive_monitor::startup`, the boot's 1 s); embassy's driver writes
/// the shorter timeout.
fn start_watchdog(
    iwdg: Peri<'static, peripherals::IWDG>,
) -> IndependentWatchdog<'static, peripherals::IWDG> {
    let mut wdg = IndependentWatchdog::new(iwdg, WATCHDOG_TIMEOUT_MS * 1000);
    wdg.unleash();
    wdg.pet();
    wdg
}

/// The boot composition (`drive_monitor::startup::boot_board`, the function the host's SIL
/// rig boots through) on the flash's record pages with what the start found (`facts`): the
/// machine, its sample path, isolator and encoder set-up, the stored calibration and the
/// supervisor with the panel's marks, each failure with its fallback, logged. A plain
/// function, so that what it builds on its way is on the stack, not kept in the main
/// task's future.
fn boot_board(flash: &mut BoardFlash, facts: &BootFacts) -> (BootMachine, SamplePath, Supervisor) {
    let page = read_motor_page(flash);
    let booted = match startup::boot_board(facts, &page, flash, &SETTINGS) {
        Ok(b) => b,
        // The built-in default at the constant sample rate: a host test (`app::tests`)
        // builds the same path, so this cannot happen, and if it did nothing could be
        // monitored.
        #[allow(clippy::panic)]
        Err(_) => panic!("monitor configuration rejected"),
    };
    logs::log_boot(&booted);
    (booted.machine, booted.path, booted.supervisor)
}

/// The start (`drive_monitor::startup::start`: the freeze, the watchdog, why the previous
/// run ended, the stack, the clock with its bounded waits, the self-check; or the safe
/// mode), the flash records and the boot report, then the sample task on the high-priority
/// executor and thread mode's periods ([`Thread::run`]).
#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let (p, facts) = startup::start(&mut startup_hw::StartRegisters);
    reset_ram::FINDINGS.store(facts.findings.0, Ordering::Relaxed);
    info!("drive-monitor {} starting", env!("CARGO_PKG_VERSION"));
    logs::log_facts(&facts);
    if let Some(reason) = facts.safe_mode {
        safe_mode::run(p, &facts, reason).await
    }
    let cp = core_peripherals();
    let b = Board::take(p);
    let wdg = start_watchdog(b.iwdg);
    let dual_bank = dual_bank_flash();
    let flash = dual_bank.then(|| Flash::new_blocking(b.flash));
    let mut thread = Thread::new(PanelPins::new(b.lamps), flash, wdg, facts.bor);
    vcp::report_boot(&mut thread.hw.flash.store, b.vcp, &facts);
    let mut button = ExtiInput::new(b.button, b.button_exti, Pull::Down, Irqs);

    let (machine, path, mut supervisor) = boot_board(&mut thread.hw.flash.store, &facts);
    let boot = Instant::now();
    let hw = SampleHw {
        adc1: b.adc1,
        adc2: b.adc2,
        dma1: b.adc1_dma,
        dma2: b.adc2_dma,
        dma3: b.encoder_dma,
        tim1: b.trigger_timer,
        v: b.voltage,
        i: b.current,
        tim4: b.encoder_timer,
        enc_a: b.encoder_a,
        enc_b: b.encoder_b,
        encoder: machine.encoder,
        syst: cp.SYST,
        supply_hz: machine.record.supply.f_hz as f32,
        ranges: machine.ranges,
        clock: facts.clock,
    };
    spawn_sample_task(hw, path);
    thread.run(&mut supervisor, &mut button, boot).await
}

/// The Cortex-M core peripherals, with the cycle counter running (for the per-sample cost
/// shown in the log); their SysTick is the ADC set-up's deadline.
fn core_peripherals() -> cortex_m::Peripherals {
    let mut cp = match cortex_m::Peripherals::take() {
        Some(cp) => cp,
        // Taken once, here (embassy-stm32 takes none of them).
        #[allow(clippy::panic)]
        None => panic!("core peripherals taken twice"),
    };
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();
    cp
}

/// Whether the option bytes select dual-bank flash, which the record pages need. The flash
/// driver (built for dual-bank) panics on single-bank option bytes: the firmware checks
/// first and runs without the records instead (the built-in motor, not commissioned),
/// saying so in the log.
fn dual_bank_flash() -> bool {
    mark_phase(BootPhase::Flash);
    let dual_bank = drive_monitor::regs::MCU.dual_bank();
    if !dual_bank {
        error!("option bytes: single-bank flash (DBANK = 0); the records need dual-bank: set DBANK with STM32CubeProgrammer. Running with the built-in motor, not commissioned");
    }
    dual_bank
}

/// Starts the high-priority executor (UART4's vector at NVIC priority P1, above thread
/// mode) and spawns the sample task on it with its hardware `hw` and the sample `path`.
fn spawn_sample_task(hw: SampleHw, path: SamplePath) {
    interrupt::UART4.set_priority(Priority::P1);
    let high = EXECUTOR_HIGH.start(interrupt::UART4);
    set_phase(BootPhase::Boot);
    match sample_task(hw, path) {
        Ok(task) => high.spawn(task),
        // A task that is spawned once, at boot: the pool cannot be full.
        #[allow(clippy::panic)]
        Err(_) => panic!("sample task not spawned"),
    }
}

/// Thread mode's hardware (`drive_monitor::app::ThreadHw`): the lamps, the record pages
/// behind the brown-out gate, the acquisition's pause, the watchdog, VREFINT.
struct ThreadBoard {
    lamps: PanelPins,
    /// The record pages, erases and writes refused below the brown-out goal.
    flash: BorGate<BoardFlash>,
    pause: commands::SampleTaskPause,
    wdg: IndependentWatchdog<'static, peripherals::IWDG>,
    reference: supply::HwReference,
}

impl ThreadHw for ThreadBoard {
    type Store = BorGate<BoardFlash>;
    type Pause = commands::SampleTaskPause;
    type Reference = supply::HwReference;

    fn pet_watchdog(&mut self) {
        self.wdg.pet();
    }

    fn store_and_pause(&mut self) -> (&mut Self::Store, &mut Self::Pause) {
        (&mut self.flash, &mut self.pause)
    }

    fn reference(&mut self) -> Option<&mut Self::Reference> {
        Some(&mut self.reference)
    }

    fn show(&mut self, lamps: &PanelLamps) {
        self.lamps.show(lamps);
    }

    fn write_record(&mut self, record: Option<ResetRecord>) {
        match record {
            Some(r) => reset_ram::record(r, supply::bor_level()),
            None => reset_ram::write_reset_record(&[0; RESET_RECORD_LEN]),
        }
    }

    fn mark_up(&mut self, long: bool) {
        reset_ram::mark_up(long);
    }
}

/// What thread mode owns besides the supervisor: its hardware, its state across periods
/// and the log's.
struct Thread {
    hw: ThreadBoard,
    state: ThreadState,
    /// The sample task's longest `Monitor::update` so far, in CPU cycles (from its status).
    max_update_cycles: u32,
    /// The brown-out level found at boot (the status line's `bor=`).
    bor: BorCheck,
}

impl Thread {
    /// Thread mode's hardware: the `lamps`, the record pages in `flash` (`None`:
    /// single-bank option bytes), the watchdog `wdg` and the brown-out level `bor` found at
    /// boot (records refused below the goal).
    fn new(
        lamps: PanelPins,
        flash: Option<Flash<'static, embassy_stm32::flash::Blocking>>,
        wdg: IndependentWatchdog<'static, peripherals::IWDG>,
        bor: BorCheck,
    ) -> Self {
        Self {
            hw: ThreadBoard {
                lamps,
                flash: BorGate {
                    store: BoardFlash(CheckedFlash::new(Driver(flash))),
                    bor,
                },
                pause: commands::SampleTaskPause,
                wdg,
                reference: supply::HwReference,
            },
            state: ThreadState::default(),
            max_update_cycles: 0,
            bor,
        }
    }

    /// Thread mode's periods, every [`PANEL_PERIOD_MS`] from boot (`boot`, the clock's
    /// zero): the period's wait is the wait for the `button`, so a press at any time is
    /// seen.
    async fn run(
        &mut self,
        supervisor: &mut Supervisor,
        button: &mut ExtiInput<'static, Async>,
        boot: Instant,
    ) -> ! {
        let period = Duration::from_millis(u64::from(PANEL_PERIOD_MS));
        let mut next = Instant::now() + period;
        loop {
            let pressed = with_deadline(next, button.wait_for_rising_edge())
                .await
                .is_ok();
            if pressed {
                Timer::at(next).await;
            }
            next += period;
            let now_ms = boot.elapsed().as_millis() as u32;
            self.period(supervisor, now_ms, pressed).await;
        }
    }

    /// One period at `now_ms` (`drive_monitor::app::period` on what the sample task handed
    /// over): its events logged, its commands sent to the sample task in order (each waiting
    /// at most [`COMMAND_SEND_TIMEOUT_MS`] for a slot in the queue, else dropped and
    /// logged), and every second period the status line.
    async fn period(&mut self, supervisor: &mut Supervisor, now_ms: u32, pressed: bool) {
        let status = STATUS.try_take();
        if let Some(s) = status {
            self.max_update_cycles = s.max_update_cycles;
        }
        let reference = REFERENCE.try_take();
        if let Some(board::ReferenceCheck::InBand(v)) = reference {
            info!("reference: VDDA {=f32} V", v);
        }
        let input = PeriodInput {
            now_ms,
            status: status.map(|s| s.monitor),
            pressed,
            trim: TRIM.try_take(),
            reference,
        };
        let out = period(supervisor, &mut self.state, input, &mut self.hw);
        logs::log_period(&out);
        for cmd in out.commands.into_iter().flatten() {
            commands::send(cmd).await;
        }
        if out.status_line {
            self.status_line(supervisor, &out.tick);
        }
    }

    /// The status line ([`log_status`]) on the supervisor's latest status and isolation and
    /// the period's `tick` (the panel's mode and call).
    fn status_line(&self, supervisor: &Supervisor, tick: &Tick) {
        log_status(
            supervisor.latest(),
            supervisor.isolation(),
            supervisor
                .isolation
                .as_ref()
                .map_or(0.0, |f| f.isolator().winding_rise_k()),
            (tick.mode.name(), tick.call.name()),
            self.max_update_cycles,
            (supervisor.reference().vdda_v(), self.bor.status_number()),
        );
    }
}

/// The defmt status line (`app::status_line`, written in the core's one format,
/// `monitor_core::status_line`, which `sim-host hmi --stdin` parses with the same module):
/// residuals, lamps, the two top candidates, speed, mode, counters, the operating point, the
/// gate, the threshold bands, the isolation and the winding temperature rise (`rise_k` [K]);
/// `panel`: the panel's mode and the one verdict on the lamps (`app::panel_call`);
/// `supply`: the latest VDDA [V] and the brown-out level. Its fields are documented once,
/// in docs/firmware.md ("The status line").
fn log_status(
    s: &MonitorStatus,
    iso: Option<&Isolation>,
    rise_k: f32,
    panel: (&'static str, &'static str),
    max_update_cycles: u32,
    supply: (f32, u8),
) {
    let board = BoardCounters {
        overruns: OVERRUNS.load(Ordering::Relaxed),
        restarts: RESTARTS.load(Ordering::Relaxed),
        stack_used_bytes: stack::high_water_bytes(),
    };
    status_line(s, iso, rise_k, panel, max_update_cycles, board, supply).log_info();
}
