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
//! - `main` in thread mode: boot (clocks, watchdog, why the previous run ended, flash
//!   record), then every 50 ms `Supervisor::tick`: button, commissioning procedure, the
//!   watch on the sample counter (the watchdog is petted only while samples flow), panel;
//!   it carries out the commissioning action (storing the record in flash) and logs a
//!   status line every 100 ms.
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
mod sample_task;
mod stack;
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
use embassy_stm32::{bind_interrupts, dma, interrupt, pac, peripherals, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_time::{with_deadline, Duration, Instant, Timer};

use drive_monitor::app::{
    carry_out, status_line, BoardCounters, Command, MonitorStatus, SamplePath, Settings,
    Supervisor, Tick, PANEL_PERIOD_MS, WATCHDOG_TIMEOUT_MS,
};
use drive_monitor::board::{self, pins::Board, Lamp, LAMP_COUNT};
use drive_monitor::boot::{self, BootMachine};
use drive_monitor::clock::{self, ClockSource};
use drive_monitor::commissioning::Action;
use drive_monitor::offset_trim::TrimResult;
use drive_monitor::panel::PanelLamps;
use drive_monitor::reset_record::{BootPhase, PreviousRun};
use drive_monitor::supply::{BorCheck, BorGate};
use drive_monitor::{debug_halt, watchdog};
use monitor_core::Isolation;
use reset_ram::set_phase;

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

/// Starts the board's 24 MHz crystal (HSE) on the registers and waits for it at most
/// `clock::HSE_STARTUP_TIMEOUT_MS` (the core runs on the 16 MHz HSI after reset: 16 000
/// cycles a millisecond): embassy-stm32's clock set-up waits for `HSERDY` without a bound,
/// so it is handed the crystal only once it runs. A crystal that did not start is
/// switched off again and the clock falls back to the HSI (`ClockSource::Hsi`).
fn start_crystal() -> ClockSource {
    pac::RCC.cr().modify(|w| w.set_hseon(true));
    for _ in 0..clock::HSE_STARTUP_TIMEOUT_MS {
        if pac::RCC.cr().read().hserdy() {
            return ClockSource::Hse;
        }
        cortex_m::asm::delay(clock::HSI_HZ / 1_000);
    }
    if pac::RCC.cr().read().hserdy() {
        return ClockSource::Hse;
    }
    pac::RCC.cr().modify(|w| w.set_hseon(false));
    ClockSource::Hsi
}

fn clock_config(source: ClockSource) -> embassy_stm32::Config {
    use embassy_stm32::rcc::*;
    let mut config = embassy_stm32::Config::default();
    // 24 MHz HSE / 6 (or 16 MHz HSI / 4) * 85 / 2 = 170 MHz SYSCLK (the G474's maximum,
    // needs boost mode): the settings of `drive_monitor::clock`, from which every rate and
    // cycle count is derived (the registers' encodings: PLLM - 1, PLLN, PLLR / 2 - 1).
    let pll_source = match source {
        ClockSource::Hse => {
            config.rcc.hse = Some(Hse {
                freq: embassy_stm32::time::Hertz(clock::HSE_HZ),
                mode: HseMode::Oscillator,
            });
            PllSource::HSE
        }
        ClockSource::Hsi | ClockSource::HsiAfterFailure => PllSource::HSI,
    };
    config.rcc.pll = Some(Pll {
        source: pll_source,
        prediv: PllPreDiv::from_bits((source.prediv() - 1) as u8),
        mul: PllMul::from_bits(clock::PLL_MUL as u8),
        divp: None,
        divq: None,
        divr: Some(PllRDiv::from_bits((clock::PLL_RDIV / 2 - 1) as u8)),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    // The ADC12 kernel clock mux defaults to "no clock" (Adc::new would panic).
    config.rcc.mux.adc12sel = mux::Adcsel::SYS;
    config
}

/// The first thing `main` does, before the clock set-up (which waits for the crystal and
/// the PLL): what a debugger's halt freezes (`drive_monitor::debug_halt::FROZEN`: TIM1, the
/// sample trigger; TIM15, embassy-time's clock; the IWDG), then the independent watchdog
/// started with the boot's timeout (`drive_monitor::watchdog::BOOT_SETTING`, 1 s, covering
/// the boot's budget at the fastest LSI). On the registers, before embassy-stm32's `init`
/// (`firmware/under_the_hal.rs` lists why); `start_watchdog` shortens it once the boot ran.
fn start_boot_watchdog() {
    // The whole registers as `debug_halt` computes them from what they hold (the host
    // tests run the halt model on these values, not on the constant).
    let dbg = pac::DBGMCU;
    let after = debug_halt::FROZEN.registers_after(debug_halt::FreezeRegisters {
        apb1fzr1: dbg.apb1lfzr().read().0,
        apb2fzr: dbg.apb2fzr().read().0,
    });
    dbg.apb1lfzr()
        .write_value(pac::dbgmcu::regs::Apb1lfzr(after.apb1fzr1));
    dbg.apb2fzr()
        .write_value(pac::dbgmcu::regs::Apb2fzr(after.apb2fzr));
    let setting = watchdog::BOOT_SETTING;
    let iwdg = pac::IWDG;
    // Start (the LSI with it), unlock PR/RLR, the boot's timeout, reload.
    iwdg.kr().write(|w| w.set_key(pac::iwdg::vals::Key::START));
    iwdg.kr().write(|w| w.set_key(pac::iwdg::vals::Key::ENABLE));
    iwdg.pr()
        .write(|w| w.set_pr(pac::iwdg::vals::Pr::from_bits(setting.pr)));
    iwdg.rlr().write(|w| w.set_rl(setting.rlr));
    // The new values reach the LSI domain within a few LSI periods (bounded: 48 us each).
    let mut polls = 0u32;
    while (iwdg.sr().read().pvu() || iwdg.sr().read().rvu()) && polls < 100_000 {
        polls += 1;
    }
    iwdg.kr().write(|w| w.set_key(pac::iwdg::vals::Key::RESET));
}

/// The independent watchdog at its running timeout (`WATCHDOG_TIMEOUT_MS`, 500 ms): it
/// runs since [`start_boot_watchdog`]; embassy's driver writes the shorter timeout.
fn start_watchdog(
    iwdg: Peri<'static, peripherals::IWDG>,
) -> IndependentWatchdog<'static, peripherals::IWDG> {
    let mut wdg = IndependentWatchdog::new(iwdg, WATCHDOG_TIMEOUT_MS * 1000);
    wdg.unleash();
    wdg.pet();
    wdg
}

/// The boot composition (`drive_monitor::boot`, the function the host's SIL rig boots
/// through) on the flash's two record pages: the machine, its sample path, isolator and
/// encoder set-up, the stored calibration and the supervisor, each failure with its
/// fallback, logged. A plain function, so that what it builds on its way is on the stack,
/// not kept in the main task's future.
fn boot_board(
    flash: &mut BoardFlash,
    previous: PreviousRun,
) -> (BootMachine, SamplePath, Supervisor) {
    let page = read_motor_page(flash);
    let booted = match boot::boot(&page, flash, &SETTINGS, previous, 0) {
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

/// Boot in thread mode (clocks, the reason the previous run ended, the brown-out level,
/// the watchdog, the flash records), then the sample task on the high-priority executor and
/// thread mode's periods ([`Thread::run`]).
#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    start_boot_watchdog();
    // Before the clock set-up: the previous run's end (a clock failure's record keeps the
    // crystal out of this run) and the stack (its guard words, then painted).
    let (previous, reset_source) = logs::read_previous_run();
    let stack_overflowed = stack::check_and_paint();
    let source = clock::boot_source(previous.clock_failed(), start_crystal);
    let p = embassy_stm32::init(clock_config(source));
    if clock::css_on(source) {
        // The clock security system: a crystal that stops raises an NMI (`failure.rs`)
        // and the hardware switches to the HSI; embassy-stm32 leaves it off.
        pac::RCC.cr().modify(|w| w.set_csson(true));
    }
    info!("drive-monitor {} starting", env!("CARGO_PKG_VERSION"));
    logs::log_clock(source);
    logs::log_previous_run(previous, reset_source);
    logs::log_stack(stack_overflowed);
    // The brown-out level of the option bytes: reported, not written (`drive_monitor::supply`).
    let bor = supply::bor_check();
    logs::log_bor(bor);
    let cp = core_peripherals();

    let b = Board::take(p);
    let wdg = start_watchdog(b.iwdg);
    let dual_bank = dual_bank_flash();
    let flash = dual_bank.then(|| Flash::new_blocking(b.flash));
    let mut thread = Thread::new(PanelPins::new(b.lamps), flash, wdg, bor);
    vcp::report_boot(
        &mut thread.flash.store,
        bor,
        b.vcp,
        (previous, reset_source),
        source,
    );
    let mut button = ExtiInput::new(b.button, b.button_exti, Pull::Down, Irqs);

    let (machine, path, mut supervisor) = boot_board(&mut thread.flash.store, previous);
    supervisor.set_clock_fallback(source != ClockSource::Hse);
    supervisor.set_bor_below_goal(!bor.allows_flash_writes());
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
    set_phase(BootPhase::Flash);
    let dual_bank = pac::FLASH.optr().read().dbank();
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

/// What thread mode owns besides the supervisor: the lamps, the flash, the watchdog and
/// the log's state.
struct Thread {
    lamps: PanelPins,
    /// The record pages, erases and writes refused below the brown-out goal.
    flash: BorGate<BoardFlash>,
    wdg: IndependentWatchdog<'static, peripherals::IWDG>,
    /// The sample task's longest `Monitor::update` so far, in CPU cycles (from its status).
    max_update_cycles: u32,
    /// Periods since the last status line (one every second period: 100 ms).
    log_div: u32,
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
            lamps,
            flash: BorGate {
                store: BoardFlash(CheckedFlash::new(Driver(flash))),
                bor,
            },
            wdg,
            max_update_cycles: 0,
            log_div: 0,
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

    /// One period at `now_ms`: the supervisor's tick on the latest status and the button,
    /// then its consequences (watchdog, logs, the commissioning action with its command
    /// to the sample task, the lamps) and every second period the status line.
    async fn period(&mut self, supervisor: &mut Supervisor, now_ms: u32, pressed: bool) {
        let status = STATUS.try_take();
        if let Some(s) = status {
            self.max_update_cycles = s.max_update_cycles;
        }
        if let Some(trim) = TRIM.try_take() {
            supervisor.set_offset_fault(&trim);
            logs::log_trim(&trim);
        }
        check_reference(supervisor, now_ms);
        let tick = supervisor.tick(now_ms, status.map(|s| s.monitor), pressed);
        if tick.pet_watchdog {
            self.wdg.pet();
        }
        if let Some(change) = tick.liveness {
            logs::on_liveness(change);
        }
        if let Some(end) = tick.run_ended {
            logs::log_run_end(end);
        }
        if let Some(change) = tick.clip_range {
            logs::log_clip_range(change);
        }
        self.carry_out(tick.action).await;
        if let Some(gain) = tick.reference_gain {
            logs::log_reference_gain(gain);
            commands::send(Command::ReferenceGain(gain)).await;
        }
        self.lamps.show(&tick.lamps);
        self.log_div += 1;
        if self.log_div >= 2 {
            self.log_div = 0;
            self.status_line(supervisor, &tick);
        }
    }

    /// Carries out the commissioning `action` ([`carry_out`]: the record stored in flash
    /// first, logged) and sends its command to the sample task, waiting at most
    /// [`COMMAND_SEND_TIMEOUT_MS`] for a slot in the queue (else the command is dropped and
    /// logged).
    async fn carry_out(&mut self, action: Action) {
        let (command, stored) = carry_out(action, &mut self.flash, &mut commands::SampleTaskPause);
        if let Some(stored) = stored {
            logs::log_stored(&stored);
        }
        if let Some(cmd) = command {
            commands::send(cmd).await;
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

/// The checks of the ADC's reference at `now_ms`: the start-up one from the sample task
/// (`REFERENCE`, once, its VDDA logged) and the periodic one on ADC1's injected channel,
/// observed by the `supervisor`; a change of the verdict is logged.
fn check_reference(supervisor: &mut Supervisor, now_ms: u32) {
    if let Some(check) = REFERENCE.try_take() {
        if let board::ReferenceCheck::InBand(v) = check {
            info!("reference: VDDA {=f32} V", v);
        }
        if let Some(change) = supervisor.observe_reference(check, now_ms) {
            logs::log_reference(change);
        }
    }
    if let Some(change) = supervisor.poll_reference(now_ms, &mut supply::HwReference) {
        logs::log_reference(change);
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
