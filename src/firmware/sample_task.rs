//! The sample task (on the high-priority interrupt executor): the acquisition's set-up
//! (encoder, trigger, the two ring-buffered ADCs, the start-up check of the ADC's
//! reference) under the set-up deadline and the reset record, then per sample the wait for
//! both ADCs' data, the recovery when none came or the DMA lapped the reader, thread mode's
//! commands and the sample path on the readings (`SamplePath::on_frame`), with a status for
//! thread mode every `status_every` samples.

use core::sync::atomic::Ordering;

use defmt::{error, info, warn};
use drive_monitor::acquisition::{self as geometry, HALF_LEN, RING_LEN};
use drive_monitor::adc_rules::{self, IdleDiscard, PairError};
use drive_monitor::app::{Command, FrameBuilder, SamplePath};
use drive_monitor::board;
use drive_monitor::clock;
use drive_monitor::clock::ClockSource;
use drive_monitor::liveness::AdcWait;
use drive_monitor::motor_source::EncoderSetup;
use drive_monitor::recovery::{self, RecoveryCounts, StepTimeout};
use drive_monitor::regs::{self, MCU};
use drive_monitor::reset_record::{BootPhase, ResetRecord, RESET_RECORD_LEN};
use drive_monitor::ring_read::{self, Half, HalfBuffers};
use drive_monitor::self_check::{self, CheckId, EncoderExpected};
use drive_monitor::setup_guard::SetupStep;
use embassy_stm32::adc::{Adc, AdcChannel, Exten, RingBufferedAdc, SampleTime};
use embassy_stm32::dma::{self, ReadableRingBuffer, TransferOptions};
use embassy_stm32::gpio::Pull;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{MasterMode, RoundTo, Timer as HwTimer};
use embassy_stm32::timer::qei::{Config as QeiConfig, Qei};
use embassy_stm32::{peripherals, triggers, Peri};
use embassy_time::{with_timeout, Duration};

use super::acquisition::{self, HwAcquisition};
use super::logs;
use super::reset_ram::{self, mark_phase, set_phase, write_reset_record};
use super::supply;
use super::{
    Irqs, Status, COMMANDS, OVERRUNS, PAUSED, PAUSE_LIMIT_MS, REFERENCE, RESTARTS, RESUME,
    SETTINGS, STATUS, TRIM,
};

/// Everything the sample task owns.
pub(super) struct SampleHw {
    pub(super) adc1: Peri<'static, peripherals::ADC1>,
    pub(super) adc2: Peri<'static, peripherals::ADC2>,
    pub(super) dma1: Peri<'static, peripherals::DMA1_CH1>,
    pub(super) dma2: Peri<'static, peripherals::DMA1_CH2>,
    /// The encoder latch's DMA channel (TIM4's capture at the trigger).
    pub(super) dma3: Peri<'static, peripherals::DMA1_CH3>,
    pub(super) tim1: Peri<'static, peripherals::TIM1>,
    pub(super) v: board::pins::VoltagePins,
    pub(super) i: board::pins::CurrentPins,
    pub(super) tim4: Peri<'static, peripherals::TIM4>,
    pub(super) enc_a: Peri<'static, peripherals::PB6>,
    pub(super) enc_b: Peri<'static, peripherals::PB7>,
    /// The encoder's direction, filter and pull-ups from the motor record.
    pub(super) encoder: EncoderSetup,
    /// SysTick: the ADC set-up's deadline (`supply::SetupGuard`).
    pub(super) syst: cortex_m::peripheral::SYST,
    /// The supply frequency of the machine monitored [Hz] (the filter's gain is restored
    /// there: `geometry::PwmFilter`).
    pub(super) supply_hz: f32,
    /// The six channels' linear ranges from the motor record (the clip check).
    pub(super) ranges: geometry::LinearRanges,
    /// The clock the start chose (the self-check's expectation).
    pub(super) clock: Option<ClockSource>,
}

/// The encoder: TIM4 in quadrature mode on PB6/PB7 with the motor record's pull-ups,
/// input filter and direction (`motor_source::encoder_setup`).
fn start_encoder(
    tim4: Peri<'static, peripherals::TIM4>,
    a: Peri<'static, peripherals::PB6>,
    b: Peri<'static, peripherals::PB7>,
    setup: &EncoderSetup,
) -> Qei<'static, peripherals::TIM4> {
    let pull = if setup.pull_up { Pull::Up } else { Pull::None };
    let qei_config = QeiConfig {
        ch1_pull: pull,
        ch2_pull: pull,
        ..QeiConfig::default()
    };
    let qei = Qei::new(tim4, a, b, qei_config);
    // The input filter on both inputs and the direction (input A's polarity), from the
    // motor record (`motor_source::encoder_setup`), and the count latched at the sample
    // trigger (`drive_monitor::regs`' `encoder_setup`).
    MCU.encoder_setup(setup.input_filter, setup.invert_a);
    qei
}

/// The encoder latch's ring: DMA1 channel 3 on TIM4's channel-3 request, from `CCR3` into
/// `ring` (one count per trigger: `geometry::LATCH_LEN`), circular, not started.
fn latch_ring(
    dma: Peri<'static, peripherals::DMA1_CH3>,
    ring: &'static mut [u16; geometry::LATCH_LEN],
) -> ReadableRingBuffer<'static, u16> {
    use embassy_stm32::timer::{Ch3, Dma as TimerDma};
    let request = TimerDma::<peripherals::TIM4, Ch3>::request(&*dma);
    let ccr3 = MCU.latch_source();
    // Circular with the half- and full-transfer interrupts (the ring buffer sets them).
    let options = TransferOptions::default();
    #[allow(unsafe_code)]
    // SAFETY: `ccr3` is TIM4's capture register, a peripheral address valid for the whole
    // run; `ring` is 'static and only this ring buffer writes it.
    unsafe {
        ReadableRingBuffer::new(dma::Channel::new(dma, Irqs), request, ccr3, ring, options)
    }
}

/// 24.5 ADC cycles sampling time (`drive_monitor::acquisition::SAMPLE_TIME_HALF_CYCLES`,
/// checked below): with 12.5 cycles of approximation 870 ns a conversion at the 42.5 MHz
/// ADC clock, 2.6 us a sequence of three, within the 12.5 us between the oversampling's
/// triggers. The documented front end (docs/firmware.md, "Voltage and current sensing")
/// drives each pin through a 1 kohm / 10 nF anti-alias filter (100 nF for an inverter-fed
/// motor); the datasheet's bound on
/// the source resistance, R_AIN < t_S / (f_ADC C_ADC ln(2^(N+2))) - R_ADC, with C_ADC
/// 5 pF and R_ADC 1 kohm, is about 11 kohm at 24.5 cycles.
const SAMPLE_TIME: SampleTime = regs::acquisition::SAMPLE_TIME;
const _: () = assert!(
    geometry::ring_fits(SETTINGS.sample_rate_hz, geometry::SAMPLES_PER_HALF as u32),
    "the DMA ring does not cover the worst-case latency at the sample rate"
);
const _: () = assert!(
    geometry::fits(SETTINGS.sample_rate_hz),
    "the oversampled acquisition does not fit the sample rate"
);

/// ADC1's regular sequence va, vb, vc on TIM1's TRGO into its DMA ring.
fn ring_voltages(
    adc: Adc<'static, peripherals::ADC1>,
    dma: Peri<'static, peripherals::DMA1_CH1>,
    v: board::pins::VoltagePins,
    ring: &'static mut [u16; RING_LEN],
) -> RingBufferedAdc<'static, peripherals::ADC1> {
    let st = SAMPLE_TIME;
    let sequence = [
        (v.a.degrade_adc(), st),
        (v.b.degrade_adc(), st),
        (v.c.degrade_adc(), st),
    ];
    let (trigger, edge) = (triggers::TIM1_TRGO, Exten::RISING_EDGE);
    adc.into_ring_buffered(dma, ring, Irqs, sequence.into_iter(), trigger, edge)
}

/// ADC2's regular sequence ia, ib, ic on TIM1's TRGO into its DMA ring.
fn ring_currents(
    adc: Adc<'static, peripherals::ADC2>,
    dma: Peri<'static, peripherals::DMA1_CH2>,
    i: board::pins::CurrentPins,
    ring: &'static mut [u16; RING_LEN],
) -> RingBufferedAdc<'static, peripherals::ADC2> {
    let st = SAMPLE_TIME;
    let sequence = [
        (i.a.degrade_adc(), st),
        (i.b.degrade_adc(), st),
        (i.c.degrade_adc(), st),
    ];
    let (trigger, edge) = (triggers::TIM1_TRGO, Exten::RISING_EDGE);
    adc.into_ring_buffered(dma, ring, Irqs, sequence.into_iter(), trigger, edge)
}

/// The sample trigger: TIM1's update event -> TRGO -> both ADCs (rising edge),
/// `OVERSAMPLING` times per sample (`drive_monitor::acquisition`: the mean over the sample
/// period), at the rate of [`SETTINGS`]; not started yet.
fn sample_trigger(tim1: Peri<'static, peripherals::TIM1>) -> HwTimer<'static, peripherals::TIM1> {
    let trigger = HwTimer::new(tim1);
    let trigger_hz = geometry::trigger_rate_hz(SETTINGS.sample_rate_hz);
    trigger.set_frequency(Hertz(trigger_hz), RoundTo::Slower);
    trigger.set_master_mode(MasterMode::UPDATE);
    trigger
}

/// Both ADC drivers, the common prescaler written only with both ADCs disabled and read
/// back (`drive_monitor::adc_rules::create_pair`); a rule the set-up could not keep is
/// logged.
fn create_adcs(
    p1: Peri<'static, peripherals::ADC1>,
    p2: Peri<'static, peripherals::ADC2>,
) -> (
    Adc<'static, peripherals::ADC1>,
    Adc<'static, peripherals::ADC2>,
) {
    let mut pair = acquisition::HwPair {
        p1: Some(p1),
        p2: Some(p2),
        adc1: None,
        adc2: None,
    };
    match adc_rules::create_pair(&mut pair) {
        Ok(()) => {}
        Err(PairError::NotDisabled) => error!("ADC1 did not disable before ADC2's set-up"),
        Err(PairError::Prescaler(p)) => error!(
            "ADC12_CCR.PRESC reads {=u32}, not {=u32}: the ADC clock is not {=u32} Hz, the conversion times are off",
            p,
            clock::ADC_PRESC,
            clock::ADC_CLOCK_HZ
        ),
    }
    let (Some(adc1), Some(adc2)) = (pair.adc1.take(), pair.adc2.take()) else {
        // `create_pair` creates both, always.
        #[allow(clippy::panic)]
        {
            panic!("ADC drivers not created")
        }
    };
    (adc1, adc2)
}

/// Starts the acquisition: the encoder (TIM4 in quadrature mode), the trigger (TIM1 update
/// -> TRGO at the sample rate) and the two ring-buffered ADCs (ADC1 the voltages, ADC2 the
/// currents), then the trigger, the timestamps continuing from now.
fn start_acquisition(
    hw: SampleHw,
    path: &mut SamplePath,
) -> (Qei<'static, peripherals::TIM4>, HwAcquisition) {
    static RING1: static_cell::StaticCell<[u16; RING_LEN]> = static_cell::StaticCell::new();
    static RING2: static_cell::StaticCell<[u16; RING_LEN]> = static_cell::StaticCell::new();
    static LATCH: static_cell::StaticCell<[u16; geometry::LATCH_LEN]> =
        static_cell::StaticCell::new();
    let ring1 = RING1.init([0; RING_LEN]);
    let ring2 = RING2.init([0; RING_LEN]);
    let latch = latch_ring(hw.dma3, LATCH.init([0; geometry::LATCH_LEN]));

    let qei = start_encoder(hw.tim4, hw.enc_a, hw.enc_b, &hw.encoder);

    let trigger = sample_trigger(hw.tim1);

    // Every step under the set-up deadline (`drive_monitor::setup_guard`): the HAL's waits
    // on ADCAL, ADRDY and ADSTART have no bound of their own.
    let guard = supply::SetupGuard::arm(hw.syst, SetupStep::Adc1);
    let (adc1, adc2) = create_adcs(hw.adc1, hw.adc2);
    guard.step(SetupStep::Ring1);
    let adc1 = ring_voltages(adc1, hw.dma1, hw.v, ring1);
    // The ADC's reference: VDDA from VREFINT on ADC1's injected channel against the
    // factory's calibration word, once before the rings start (bounded); thread mode then
    // measures it every second.
    guard.step(SetupStep::Reference);
    supply::configure_reference();
    REFERENCE.signal(drive_monitor::supply::measure_now(&mut supply::HwReference));
    guard.step(SetupStep::Ring2);
    let adc2 = ring_currents(adc2, hw.dma2, hw.i, ring2);
    guard.step(SetupStep::Start);
    let timeout = Duration::from_micros(u64::from(
        AdcWait::new(SETTINGS.sample_rate_hz).timeout_us(),
    ));
    let mut acq =
        acquisition::new_acquisition(trigger, adc1, adc2, latch, (RING_LEN as u16, timeout));
    acquisition::start(&mut acq);
    guard.disarm();
    path.sampler_mut().resync(acq.regs.started_us);
    (qei, acq)
}

/// Runs the sample path on the readings of one DMA half (`v` from ADC1, `i` from ADC2:
/// [`geometry::SAMPLES_PER_HALF`] samples of [`geometry::OVERSAMPLING`] sequences) and the
/// encoder counts latched at the same triggers (`latched`): each sample's frame built by
/// `frames` (`app::FrameBuilder`: the sequences summed with every conversion checked for
/// clipping, the inverter's ripple filtered, the latched counts checked against the
/// maximum speed and averaged), then `SamplePath::on_frame`; hands thread mode a status
/// every `status_every` samples. `max_cycles`: the longest frame and `on_frame` of one
/// sample so far, in CPU cycles.
fn process_half(
    path: &mut SamplePath,
    frames: &mut FrameBuilder,
    (v, i): (&[u16], &[u16]),
    latched: &[u16],
    discard: &mut IdleDiscard,
    max_cycles: &mut u32,
) {
    let samples = v
        .as_chunks::<HALF_LEN>()
        .0
        .iter()
        .zip(i.as_chunks::<HALF_LEN>().0);
    for ((v, i), counts) in samples.zip(latched.as_chunks::<{ geometry::OVERSAMPLING }>().0) {
        if discard.drop_next() {
            // The first sample after a long idle (errata): dropped, its time skipped; its
            // counts still go through the encoder check.
            frames.skip(counts);
            path.sampler_mut().skip();
            continue;
        }
        let t0 = cortex_m::peripheral::DWT::cycle_count();
        let raw = frames.frame(v, i, counts);
        if let Some(trim) = path.trim_offsets(&raw) {
            TRIM.signal(trim);
        }
        path.on_frame(&raw);
        let dt = cortex_m::peripheral::DWT::cycle_count().wrapping_sub(t0);
        *max_cycles = (*max_cycles).max(dt);
        if path.samples().is_multiple_of(SETTINGS.status_every()) {
            STATUS.signal(Status {
                monitor: path.status(),
                max_update_cycles: *max_cycles,
            });
        }
    }
}

/// The sample task: sets up the acquisition, then per DMA half (`SAMPLES_PER_HALF`
/// samples, the ring's depth from the latency budget) checks that every ring runs (a DMA
/// error since the last read: the recovery now, not the HAL's restart inside `read`,
/// `recovery::before_read`), waits for both ADCs' data, bounded by [`AdcWait`]'s timeout;
/// recovers the acquisition when no data came or the DMA lapped the reader, else applies
/// thread mode's commands (a pause for a flash erase among them) and runs the sample path
/// on the half.
#[embassy_executor::task]
pub(super) async fn sample_task(hw: SampleHw, mut path: SamplePath) {
    let mut frames = FrameBuilder::new(
        SETTINGS.sample_rate_hz,
        hw.supply_hz,
        hw.ranges,
        hw.encoder.max_step_per_trigger,
    );
    // The encoder driver is kept (its timer counts); the count is read from the latch.
    let (_qei, mut acq) = set_up_acquisition(hw, &mut path);
    let mut wait = AdcWait::new(SETTINGS.sample_rate_hz);
    let mut bufs = HalfBuffers::default();
    // The ADCs idled since their set-up: the first sample is dropped (errata).
    let mut discard = IdleDiscard::default();
    discard.on_start(u32::MAX);
    let mut last_data_us = acq.regs.started_us;
    let mut max_cycles: u32 = 0;
    let mut counts = RecoveryCounts::default();
    loop {
        match ring_read::read_half(&mut acq, &mut bufs).await {
            Half::Recovered(result) => {
                RESTARTS.fetch_add(1, Ordering::Relaxed);
                after_restart(&acq, &mut path, &mut counts, result);
                restarted(&mut discard, &mut frames, &acq, last_data_us);
                continue;
            }
            half => {
                if needs_recovery(half, &mut wait) {
                    recover_acquisition(&mut acq, &mut path, &mut counts);
                    restarted(&mut discard, &mut frames, &acq, last_data_us);
                    continue;
                }
            }
        }
        if apply_commands(&mut path, &mut acq).await {
            restarted(&mut discard, &mut frames, &acq, last_data_us);
            continue;
        }
        last_data_us = embassy_time::Instant::now().as_micros() as u32;
        process_half(
            &mut path,
            &mut frames,
            (&bufs.v[..], &bufs.i[..]),
            &bufs.latched,
            &mut discard,
            &mut max_cycles,
        );
    }
}

/// After the acquisition restarted (a recovery, or a pause for a flash erase): the first
/// sample is dropped if the ADCs idled more than 1 ms since `last_data_us` (errata), and the
/// encoder check starts afresh (the shaft moved during the gap).
fn restarted(
    discard: &mut IdleDiscard,
    frames: &mut FrameBuilder,
    acq: &HwAcquisition,
    last_data_us: u32,
) {
    discard.on_start(acq.regs.started_us.wrapping_sub(last_data_us));
    frames.restart();
}

/// [`start_acquisition`] under the reset record: the HAL's ADC set-up waits on registers
/// without a bound (power-up, calibration, ADRDY, ADSTART), so the record says so if the
/// watchdog has to end it; cleared once sampling runs.
fn set_up_acquisition(
    hw: SampleHw,
    path: &mut SamplePath,
) -> (Qei<'static, peripherals::TIM4>, HwAcquisition) {
    mark_phase(BootPhase::AdcSetup);
    reset_ram::record(ResetRecord::setup(BootPhase::AdcSetup), supply::bor_level());
    let expected = EncoderExpected {
        filter: hw.encoder.input_filter,
        invert_a: hw.encoder.invert_a,
    };
    let clock = hw.clock.unwrap_or(ClockSource::Hsi);
    let started = start_acquisition(hw, path);
    write_reset_record(&[0; RESET_RECORD_LEN]);
    mark_phase(BootPhase::Sampling);
    info!("sampling at {=u32} Hz", SETTINGS.sample_rate_hz);
    // The acquisition's registers read back (the encoder's timer, the ADCs' common
    // register): each mismatch logged and carried by every later reset record.
    let expectation = self_check::expectation(clock, Some(expected));
    let findings = self_check::run(&CheckId::ACQUISITION, &expectation, |a| MCU.read_word(a));
    reset_ram::FINDINGS.fetch_or(findings.0, Ordering::Relaxed);
    findings.mismatched().for_each(logs::log_mismatch);
    started
}

/// Whether the acquisition needs the recovery after the wait for one `half`
/// (`ring_read::read_half`): read (`lapped`: the DMA lapped the reader and samples were
/// lost), or no data within the timeout (an ADC overrun, a stopped trigger: thread mode
/// shows a stall and stops petting the watchdog until samples flow again). Counts and logs
/// each cause on `wait` and the counters.
#[inline]
fn needs_recovery(half: Half, wait: &mut AdcWait) -> bool {
    match half {
        Half::Read { lapped: [l1, l2] } => {
            if let Some(n) = wait.data() {
                warn!("sampling resumed after {=u32} recoveries", n);
            }
            if l1 || l2 {
                let n = OVERRUNS.fetch_add(1, Ordering::Relaxed) + 1;
                warn!("ADC DMA ring lapped #{=u32} (adc1 {} adc2 {})", n, l1, l2);
            }
            l1 || l2
        }
        Half::TimedOut | Half::Recovered(_) => {
            let restart = wait.timed_out();
            RESTARTS.fetch_add(1, Ordering::Relaxed);
            if restart.log {
                error!(
                    "no ADC data for {=u32} us: recovering the acquisition (attempt {=u32})",
                    wait.timeout_us(),
                    restart.attempt
                );
            }
            true
        }
    }
}

/// One recovery of the acquisition, the sequence for every cause (drive_monitor::recovery):
/// trigger, ADCs and DMA stopped, OVR and TEIF cleared, DMA re-armed, ADCs and trigger
/// restarted; the timestamps continue from the restart (the gap shows). Counted in
/// `counts` and logged.
fn recover_acquisition(
    acq: &mut HwAcquisition,
    path: &mut SamplePath,
    counts: &mut RecoveryCounts,
) {
    set_phase(BootPhase::Recovery);
    let result = recovery::recover(acq);
    after_restart(acq, path, counts, result);
}

/// After a recovery's `result`: the timestamps continue from the restart, the result
/// counted in `counts` and logged.
fn after_restart(
    acq: &HwAcquisition,
    path: &mut SamplePath,
    counts: &mut RecoveryCounts,
    result: Result<recovery::Faults, StepTimeout>,
) {
    path.sampler_mut().resync(acq.regs.started_us);
    set_phase(BootPhase::Sampling);
    counts.count(result);
    match result {
        Ok(f) if f.adc_overrun || f.dma_error => warn!(
            "acquisition recovered: adc overrun {=bool}, dma error {=bool} (recoveries {=u32}, overruns {=u32}, dma errors {=u32})",
            f.adc_overrun,
            f.dma_error,
            counts.recoveries,
            counts.adc_overruns,
            counts.dma_errors
        ),
        Ok(_) => {}
        Err(StepTimeout(step)) => {
            error!("acquisition recovery stopped at {=str}: timed out", step.name())
        }
    }
}

/// Applies thread mode's queued commands to the sample path (between two samples); a
/// refused one is logged. A pause (`Command::PauseAcquisition`, before a flash erase) stops
/// the acquisition (`recovery::pause`), tells thread mode (`PAUSED`) and waits for its
/// resume (`RESUME`, at most `PAUSE_LIMIT_MS`), then starts it again (`recovery::resume`);
/// returns whether it did.
async fn apply_commands(path: &mut SamplePath, acq: &mut HwAcquisition) -> bool {
    let mut paused = false;
    while let Ok(cmd) = COMMANDS.try_receive() {
        if cmd == Command::PauseAcquisition {
            pause_for_flash(acq, path).await;
            paused = true;
            continue;
        }
        if let Err(e) = path.command(cmd) {
            warn!("core refused a command: {=str}", e.describe());
        }
    }
    paused
}

/// The acquisition paused while thread mode erases and writes the flash (module docs of
/// `drive_monitor::recovery`, `pause`): nothing converts or moves, so nothing laps;
/// resumed when thread mode says so, or after [`PAUSE_LIMIT_MS`] whatever it says.
async fn pause_for_flash(acq: &mut HwAcquisition, path: &mut SamplePath) {
    set_phase(BootPhase::Recovery);
    let paused = recovery::pause(acq);
    PAUSED.signal(paused.is_ok());
    let limit = Duration::from_millis(u64::from(PAUSE_LIMIT_MS));
    if with_timeout(limit, RESUME.wait()).await.is_err() {
        warn!(
            "flash: no resume within {=u32} ms: sampling restarted",
            PAUSE_LIMIT_MS
        );
    }
    recovery::resume(acq);
    path.sampler_mut().resync(acq.regs.started_us);
    set_phase(BootPhase::Sampling);
}
