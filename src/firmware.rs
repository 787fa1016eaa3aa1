//! The STM32G474RE firmware: hardware tasks around the hardware-free logic in the library.
//!
//! Tasks and priorities:
//! - `sample_task` on an interrupt executor (UART4 vector, NVIC priority P1, above thread
//!   mode): TIM1 TRGO triggers ADC1 (va, vb, vc) and ADC2 (ia, ib, ic) at the sample rate;
//!   each ADC fills a DMA ring of two samples, so every sample wakes the task (half- and
//!   full-transfer interrupts). The task reads the encoder counter (TIM4), builds the
//!   `Sample` and runs `Monitor::update` on it. Overruns (the DMA lapped the reader) are
//!   counted, logged, and the two rings are resynchronised with the trigger stopped.
//! - `main` in thread mode: boot (clocks, watchdog, flash record), then a 50 ms loop that
//!   pets the watchdog, watches the button, drives the commissioning state machine and
//!   the panel, and logs a status line every 100 ms.
//!
//! Communication: `COMMANDS` (Channel, thread -> sample task), `STATUS` (Signal, latest
//! output, sample task -> thread, 100 Hz), `LEARN` (Channel, learning finished/failed).

use core::sync::atomic::{AtomicU32, Ordering};

use defmt::{error, info, warn};
use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::adc::{Adc, AdcChannel, AdcConfig, Exten, RingBufferedAdc, SampleTime};
use embassy_stm32::exti::{self, ExtiInput};
use embassy_stm32::flash::Flash;
use embassy_stm32::gpio::{Level, Output, Pull, Speed};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{MasterMode, RoundTo, Timer as HwTimer};
use embassy_stm32::timer::qei::{Config as QeiConfig, Qei};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{bind_interrupts, dma, interrupt, pac, peripherals, triggers, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_time::{with_timeout, Duration, Instant, Ticker, Timer};

use drive_monitor::app::{Command, SamplePath};
use drive_monitor::board::{self, pins::Board, CurrentCode, VoltageCode};
use drive_monitor::commissioning::{Action, CommissioningProcedure, Event};
use drive_monitor::flash_record::{CalibrationRecord, RECORD_LEN};
use drive_monitor::panel::{self, Lamp, Mode, PanelInput, PanelLamps};
use drive_monitor::sampling::RawFrame;
use monitor_core::{Fault, MonitorOutput};

bind_interrupts!(struct Irqs {
    DMA1_CHANNEL1 => dma::InterruptHandler<peripherals::DMA1_CH1>;
    DMA1_CHANNEL2 => dma::InterruptHandler<peripherals::DMA1_CH2>;
    EXTI15_10 => exti::InterruptHandler<interrupt::typelevel::EXTI15_10>;
});

/// Sample rate, Hz (must divide 1 MHz; TIM1 at 170 MHz divides it exactly for 10 kHz).
const SAMPLE_RATE_HZ: u32 = board::DEFAULT_SAMPLE_RATE_HZ;
/// Samples per DMA half buffer: 1, so every sample is processed as it arrives and the
/// encoder is read within microseconds of the conversion.
const SAMPLES_PER_HALF: usize = 1;
/// ADC channels per ADC.
const CHANNELS: usize = 3;
/// DMA ring length per ADC, in 16-bit words (two halves).
const RING_LEN: usize = 2 * SAMPLES_PER_HALF * CHANNELS;
/// Status to thread mode every this many samples (10 kHz / 100 = 100 Hz).
const STATUS_EVERY: u32 = 100;
/// Independent watchdog timeout, us. The thread loop pets it every 50 ms.
const WATCHDOG_TIMEOUT_US: u32 = 500_000;
/// Panel refresh period, ms.
const PANEL_PERIOD_MS: u64 = 50;

/// Latest state from the sample task.
#[derive(Clone, Copy)]
struct Status {
    output: MonitorOutput,
    samples: u32,
    max_update_cycles: u32,
}

/// Outcome of a learning run, from the sample task.
#[derive(Clone, Copy)]
enum LearnEvent {
    Done(CalibrationRecord),
    Failed,
}

static COMMANDS: Channel<CriticalSectionRawMutex, Command, 4> = Channel::new();
static STATUS: Signal<CriticalSectionRawMutex, Status> = Signal::new();
static LEARN: Channel<CriticalSectionRawMutex, LearnEvent, 2> = Channel::new();
static OVERRUNS: AtomicU32 = AtomicU32::new(0);
static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();

#[interrupt]
#[allow(unsafe_code)]
unsafe fn UART4() {
    // SAFETY: UART4 is not used as a UART; its vector is dedicated to this executor,
    // which is started once in `main` before the interrupt is enabled.
    unsafe { EXECUTOR_HIGH.on_interrupt() }
}

/// Everything the sample task owns.
struct SampleHw {
    adc1: Peri<'static, peripherals::ADC1>,
    adc2: Peri<'static, peripherals::ADC2>,
    dma1: Peri<'static, peripherals::DMA1_CH1>,
    dma2: Peri<'static, peripherals::DMA1_CH2>,
    tim1: Peri<'static, peripherals::TIM1>,
    v: board::pins::VoltagePins,
    i: board::pins::CurrentPins,
    tim4: Peri<'static, peripherals::TIM4>,
    enc_a: Peri<'static, peripherals::PB6>,
    enc_b: Peri<'static, peripherals::PB7>,
}

fn now_us() -> u32 {
    Instant::now().as_micros() as u32
}

#[embassy_executor::task]
async fn sample_task(hw: SampleHw, mut path: SamplePath) {
    static RING1: static_cell::StaticCell<[u16; RING_LEN]> = static_cell::StaticCell::new();
    static RING2: static_cell::StaticCell<[u16; RING_LEN]> = static_cell::StaticCell::new();
    let ring1 = RING1.init([0; RING_LEN]);
    let ring2 = RING2.init([0; RING_LEN]);

    let qei = Qei::new(hw.tim4, hw.enc_a, hw.enc_b, QeiConfig::default());

    // Sample trigger: TIM1 update event -> TRGO -> both ADCs (rising edge).
    let trigger = HwTimer::new(hw.tim1);
    trigger.set_frequency(Hertz(SAMPLE_RATE_HZ), RoundTo::Slower);
    trigger.set_master_mode(MasterMode::UPDATE);

    // 24.5 ADC cycles sampling time: enough for a low-impedance isolated amplifier output.
    let st = SampleTime::CYCLES24_5;
    let adc1 = Adc::new(hw.adc1, AdcConfig::default());
    let mut adc1: RingBufferedAdc<'static, peripherals::ADC1> = adc1.into_ring_buffered(
        hw.dma1,
        ring1,
        Irqs,
        [
            (hw.v.a.degrade_adc(), st),
            (hw.v.b.degrade_adc(), st),
            (hw.v.c.degrade_adc(), st),
        ]
        .into_iter(),
        triggers::TIM1_TRGO,
        Exten::RISING_EDGE,
    );
    let adc2 = Adc::new(hw.adc2, AdcConfig::default());
    let mut adc2: RingBufferedAdc<'static, peripherals::ADC2> = adc2.into_ring_buffered(
        hw.dma2,
        ring2,
        Irqs,
        [
            (hw.i.a.degrade_adc(), st),
            (hw.i.b.degrade_adc(), st),
            (hw.i.c.degrade_adc(), st),
        ]
        .into_iter(),
        triggers::TIM1_TRGO,
        Exten::RISING_EDGE,
    );
    adc1.start();
    adc2.start();
    path.sampler_mut().resync(now_us());
    trigger.start();
    info!("sampling at {=u32} Hz", SAMPLE_RATE_HZ);

    let mut half1 = [0u16; SAMPLES_PER_HALF * CHANNELS];
    let mut half2 = [0u16; SAMPLES_PER_HALF * CHANNELS];
    let mut samples: u32 = 0;
    let mut max_cycles: u32 = 0;
    loop {
        let r1 = adc1.read(&mut half1).await;
        let r2 = adc2.read(&mut half2).await;
        if r1.is_err() || r2.is_err() {
            // Samples were lost: count, log, resynchronise both rings with the trigger
            // stopped so that ADC1 and ADC2 restart on the same conversion.
            let n = OVERRUNS.fetch_add(1, Ordering::Relaxed) + 1;
            warn!(
                "ADC DMA overrun #{=u32} (adc1 {} adc2 {})",
                n,
                r1.is_err(),
                r2.is_err()
            );
            trigger.stop();
            Timer::after_micros(20).await;
            adc1.clear();
            adc2.clear();
            path.sampler_mut().resync(now_us());
            trigger.start();
            continue;
        }
        while let Ok(cmd) = COMMANDS.try_receive() {
            if path.command(cmd).is_err() {
                warn!("core rejected a command");
            }
        }
        let encoder_count = qei.count();
        for (v, i) in half1
            .chunks_exact(CHANNELS)
            .zip(half2.chunks_exact(CHANNELS))
        {
            let (&[va, vb, vc], &[ia, ib, ic]) = (v, i) else {
                continue;
            };
            let raw = RawFrame {
                v: [VoltageCode(va), VoltageCode(vb), VoltageCode(vc)],
                i: [CurrentCode(ia), CurrentCode(ib), CurrentCode(ic)],
                encoder_count,
            };
            let t0 = cortex_m::peripheral::DWT::cycle_count();
            let result = path.on_frame(&raw);
            let dt = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(t0);
            max_cycles = max_cycles.max(dt);
            samples = samples.wrapping_add(1);
            if let Some(rec) = result.learned {
                let _ = LEARN.try_send(LearnEvent::Done(rec));
            } else if result.learning_failed {
                let _ = LEARN.try_send(LearnEvent::Failed);
            }
            if samples.is_multiple_of(STATUS_EVERY) {
                STATUS.signal(Status {
                    output: result.output,
                    samples,
                    max_update_cycles: max_cycles,
                });
            }
        }
    }
}

/// Drive the six lamp pins.
struct PanelPins {
    pins: [Output<'static>; 6],
}

impl PanelPins {
    fn new(l: board::pins::LampPins) -> Self {
        Self {
            pins: [
                Output::new(l.run, Level::Low, Speed::Low),
                Output::new(l.r1, Level::Low, Speed::Low),
                Output::new(l.r2, Level::Low, Speed::Low),
                Output::new(l.r3, Level::Low, Speed::Low),
                Output::new(l.r4, Level::Low, Speed::Low),
                Output::new(l.fault, Level::Low, Speed::Low),
            ],
        }
    }

    fn show(&mut self, lamps: &PanelLamps) {
        for (pin, lamp) in self.pins.iter_mut().zip(Lamp::ALL) {
            pin.set_level(if lamps.is_on(lamp) {
                Level::High
            } else {
                Level::Low
            });
        }
    }
}

fn mode_name(m: Mode) -> &'static str {
    match m {
        Mode::NotCommissioned => "not-commissioned",
        Mode::Commissioning => "commissioning",
        Mode::Commissioned => "commissioned",
        Mode::CommissioningFailed => "commissioning-failed",
        Mode::Failed => "failed",
    }
}

/// Read and validate the commissioning record.
fn load_record(
    flash: &mut Flash<'static, embassy_stm32::flash::Blocking>,
) -> Option<CalibrationRecord> {
    let mut buf = [0u8; RECORD_LEN];
    if flash
        .blocking_read(board::RECORD_FLASH_OFFSET, &mut buf)
        .is_err()
    {
        warn!("flash read failed");
        return None;
    }
    match CalibrationRecord::decode(&buf) {
        Ok(rec) => Some(rec),
        Err(e) => {
            warn!("no valid commissioning record: {}", e);
            None
        }
    }
}

/// Erase the record page, write the record, read it back.
fn store_record(
    flash: &mut Flash<'static, embassy_stm32::flash::Blocking>,
    rec: &CalibrationRecord,
) -> bool {
    let Ok(bytes) = rec.encode() else {
        return false;
    };
    let from = board::RECORD_FLASH_OFFSET;
    if flash
        .blocking_erase(from, from + board::RECORD_PAGE_SIZE)
        .is_err()
    {
        return false;
    }
    if flash.blocking_write(from, &bytes).is_err() {
        return false;
    }
    load_record(flash) == Some(*rec)
}

fn clock_config() -> embassy_stm32::Config {
    use embassy_stm32::rcc::*;
    let mut config = embassy_stm32::Config::default();
    // 16 MHz HSI / 4 * 85 / 2 = 170 MHz SYSCLK (the G474's maximum, needs boost mode).
    config.rcc.pll = Some(Pll {
        source: PllSource::HSI,
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    // The ADC12 kernel clock mux defaults to "no clock" (Adc::new would panic).
    config.rcc.mux.adc12sel = mux::Adcsel::SYS;
    config
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_stm32::init(clock_config());
    info!("drive-monitor {} starting", env!("CARGO_PKG_VERSION"));
    let watchdog_reset = previous_run_reset_by_watchdog();

    // Cycle counter for the per-sample cost shown in the log.
    if let Some(mut cp) = cortex_m::Peripherals::take() {
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();
    }

    let b = Board::take(p);
    let mut wdg = IndependentWatchdog::new(b.iwdg, WATCHDOG_TIMEOUT_US);
    wdg.unleash();

    let mut lamps = PanelPins::new(b.lamps);
    let mut button = ExtiInput::new(b.button, b.button_exti, Pull::Down, Irqs);
    let mut flash = Flash::new_blocking(b.flash);

    let mut path = match SamplePath::for_board(SAMPLE_RATE_HZ) {
        Ok(p) => p,
        Err(_) => panic!("monitor configuration rejected"),
    };
    let mut procedure = CommissioningProcedure::new(CommissioningProcedure::DEFAULT_DURATION_S);
    let loaded = install_stored_calibration(&mut flash, &mut path);
    procedure.handle(Event::RecordLoaded(loaded), 0);
    info!("commissioned: {}", loaded);

    // High-priority executor for the sample path.
    interrupt::UART4.set_priority(Priority::P1);
    let high = EXECUTOR_HIGH.start(interrupt::UART4);
    let hw = SampleHw {
        adc1: b.adc1,
        adc2: b.adc2,
        dma1: b.adc1_dma,
        dma2: b.adc2_dma,
        tim1: b.trigger_timer,
        v: b.voltage,
        i: b.current,
        tim4: b.encoder_timer,
        enc_a: b.encoder_a,
        enc_b: b.encoder_b,
    };
    high.spawn(defmt::unwrap!(sample_task(hw, path)));

    let boot = Instant::now();
    let mut ticker = Ticker::every(Duration::from_millis(PANEL_PERIOD_MS));
    let mut last = Status {
        output: MonitorOutput::default(),
        samples: 0,
        max_update_cycles: 0,
    };
    let mut last_press_ms: u32 = 0;
    let mut log_div: u32 = 0;
    loop {
        wdg.pet();
        let now_ms = boot.elapsed().as_millis() as u32;

        // Button (debounced 300 ms); the wait is bounded by the panel period.
        let pressed = with_timeout(Duration::from_millis(5), button.wait_for_rising_edge())
            .await
            .is_ok();
        if pressed && now_ms.wrapping_sub(last_press_ms) > 300 {
            last_press_ms = now_ms;
            start_commissioning(&mut procedure, now_ms);
        }
        while let Ok(ev) = LEARN.try_receive() {
            wdg.pet();
            finish_learning(&mut procedure, &mut flash, ev, now_ms);
        }
        procedure.handle(Event::Tick, now_ms);

        if let Some(s) = STATUS.try_take() {
            last = s;
        }
        let mut input = PanelInput::from_output(procedure.panel_mode(), &last.output);
        if watchdog_reset && now_ms < 5_000 {
            input.mode = Mode::Failed;
        }
        lamps.show(&panel::render(&input, now_ms));

        log_div += 1;
        if log_div >= 2 {
            log_div = 0;
            log_status(&last, procedure.panel_mode());
        }
        ticker.next().await;
    }
}

/// Whether the previous run ended in a watchdog reset (a panic or a hang); clears the
/// reset flags.
fn previous_run_reset_by_watchdog() -> bool {
    let csr = pac::RCC.csr().read();
    let watchdog_reset = csr.iwdgrstf();
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    if watchdog_reset {
        error!("previous run ended in a watchdog reset (panic or hang): see its log");
    }
    watchdog_reset
}

/// Reads the commissioning record and gives it to the core; true when one was installed.
fn install_stored_calibration(
    flash: &mut Flash<'static, embassy_stm32::flash::Blocking>,
    path: &mut SamplePath,
) -> bool {
    match load_record(flash) {
        Some(rec) => match path.command(Command::SetCalibration(rec)) {
            Ok(()) => true,
            Err(_) => {
                warn!("stored calibration out of the core's range: ignored");
                false
            }
        },
        None => false,
    }
}

/// The button was pressed: starts learning unless the procedure is busy.
fn start_commissioning(procedure: &mut CommissioningProcedure, now_ms: u32) {
    info!("button: start commissioning");
    if let Action::StartLearning { duration_s } = procedure.handle(Event::ButtonPressed, now_ms) {
        if COMMANDS
            .try_send(Command::StartCommissioning { duration_s })
            .is_err()
        {
            warn!("command queue full");
        }
    }
}

/// The sample task finished learning: stores the record when the procedure asks for it.
fn finish_learning(
    procedure: &mut CommissioningProcedure,
    flash: &mut Flash<'static, embassy_stm32::flash::Blocking>,
    ev: LearnEvent,
    now_ms: u32,
) {
    let action = match ev {
        LearnEvent::Done(rec) => procedure.handle(Event::LearningDone(rec), now_ms),
        LearnEvent::Failed => procedure.handle(Event::LearningFailed, now_ms),
    };
    if let Action::Save(rec) = action {
        let ok = store_record(flash, &rec);
        info!("commissioning record stored: {}", ok);
        procedure.handle(Event::SaveDone(ok), now_ms);
    }
}

/// The defmt status line: residuals, lamps, the two top candidates, speed, mode, counters.
fn log_status(last: &Status, mode: Mode) {
    let o = &last.output;
    let top = o.top();
    let (top_name, top_p) = match top {
        Some((f, p)) => (f.name(), p),
        None => ("none", 0.0),
    };
    let second = o
        .diagnosis
        .probabilities
        .iter()
        .zip(Fault::ALL)
        .filter(|(_, f)| Some(*f) != top.map(|t| t.0))
        .fold(None::<(Fault, f32)>, |best, (p, f)| match best {
            Some((_, bp)) if bp >= *p => best,
            _ if *p > 0.0 => Some((f, *p)),
            _ => best,
        });
    let (second_name, second_p) = second.map_or(("none", 0.0), |(f, p)| (f.name(), p));
    info!(
        "r={} lamps={} fault={=bool} top={=str}({=f32}) 2nd={=str}({=f32}) wm={=f32}rad/s mode={=str} overruns={=u32} samples={=u32} max_cyc={=u32}",
        o.residuals,
        o.lamps,
        o.fault_detected,
        top_name,
        top_p,
        second_name,
        second_p,
        o.speed_rad_s,
        mode_name(mode),
        OVERRUNS.load(Ordering::Relaxed),
        last.samples,
        last.max_update_cycles,
    );
}

/// Panic: put the panel into the "monitor failed" pattern (RUN off, all others on), log
/// the reason, and stop. The watchdog is no longer petted, so the MCU resets after
/// `WATCHDOG_TIMEOUT_US`; the next boot sees the watchdog-reset flag, logs it and shows
/// the failed pattern for 5 s before monitoring again.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    // Direct register writes: the HAL objects may be in any state. GPIO clocks are
    // enabled by `embassy_stm32::init` for every port.
    use pac::gpio::vals::Moder;
    pac::GPIOA.moder().modify(|w| w.set_moder(5, Moder::OUTPUT));
    pac::GPIOA.bsrr().write(|w| w.set_br(5, true));
    for n in [8usize, 9, 10, 12, 13] {
        pac::GPIOB.moder().modify(|w| w.set_moder(n, Moder::OUTPUT));
        pac::GPIOB.bsrr().write(|w| w.set_bs(n, true));
    }
    // Only the static part of the message and the location are logged: formatting the
    // full message would pull core::fmt (float formatting alone is ~10 KiB of flash).
    let msg = info.message().as_str().unwrap_or("(formatted message)");
    match info.location() {
        Some(l) => error!(
            "MONITOR FAILED: {=str} at {=str}:{=u32}",
            msg,
            l.file(),
            l.line()
        ),
        None => error!("MONITOR FAILED: {=str}", msg),
    }
    loop {
        cortex_m::asm::nop();
    }
}

// Keep the panel's failed pattern and the handler above in step.
const _: () = assert!(!PanelLamps::FAILED.on[0] && PanelLamps::FAILED.on[5]);
