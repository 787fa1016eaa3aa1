//! The supply and the set-up on the registers: the ADCs' set-up deadline on SysTick
//! (`drive_monitor::setup_guard`), VREFINT on ADC1's injected channel
//! (`drive_monitor::supply::ReferenceAdc`) and the brown-out level of the option bytes.

use core::sync::atomic::{AtomicU8, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use drive_monitor::setup_guard::{self, SetupStep, SETUP_DEADLINE_MS};
use drive_monitor::supply::{BorLevel, ReferenceAdc};
use drive_monitor::{adc_rules, clock};
use embassy_stm32::pac;
use embassy_stm32::pac::adc::vals::{Exten, SampleTime};

use super::reset_ram;

/// The set-up step running (`SetupStep::number`), 0 when no set-up runs: what the SysTick
/// exception reads when the deadline runs out.
static SETUP_STEP: AtomicU8 = AtomicU8::new(0);

/// The ADCs' set-up under its deadline ([`setup_guard`]): SysTick counts
/// [`SETUP_DEADLINE_MS`] once; if it runs out while a step is marked, its exception
/// writes the step into the reset record and resets the MCU.
pub(super) struct SetupGuard {
    syst: SYST,
}

impl SetupGuard {
    /// Arms the deadline (SysTick from HCLK / 8, its exception enabled) with `first`
    /// marked. SysTick's exception priority is 0, its reset value, above the sample
    /// executor's P1.
    pub(super) fn arm(mut syst: SYST, first: SetupStep) -> Self {
        SETUP_STEP.store(first.number(), Ordering::SeqCst);
        // 20 ms fits SysTick's 24 bits at 170 MHz / 8 (a host test checks the value).
        let reload =
            setup_guard::systick_reload(clock::HCLK_HZ, SETUP_DEADLINE_MS).unwrap_or(0xFF_FFFF);
        syst.set_clock_source(SystClkSource::External);
        syst.set_reload(reload);
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();
        Self { syst }
    }

    /// Marks the step that begins now.
    pub(super) fn step(&self, step: SetupStep) {
        SETUP_STEP.store(step.number(), Ordering::SeqCst);
    }

    /// The set-up finished: nothing is marked, SysTick stops.
    pub(super) fn disarm(mut self) {
        SETUP_STEP.store(0, Ordering::SeqCst);
        self.syst.disable_interrupt();
        self.syst.disable_counter();
    }
}

/// SysTick: the set-up deadline ran out. With a step marked, its record (with the
/// brown-out level) into the reset record, then a software reset; else nothing (the
/// guard was disarmed as the counter wrapped).
#[cortex_m_rt::exception]
fn SysTick() {
    if let Some(record) = setup_guard::on_deadline(SETUP_STEP.load(Ordering::SeqCst)) {
        reset_ram::record(record, bor_level());
        cortex_m::peripheral::SCB::sys_reset();
    }
}

/// The brown-out level in force (`FLASH_OPTR.BOR_LEV`; `None` for a reserved value).
pub(super) fn bor_level() -> Option<BorLevel> {
    BorLevel::from_optr(pac::FLASH.optr().read().0)
}

/// ADC1's VREFINT channel (RM0440, "ADC1 connectivity": ADC1_IN18).
const VREFINT_CHANNEL: u8 = 18;

/// Sets ADC1's injected sequence to one conversion of VREFINT, software-triggered, with
/// 247.5 cycles of sampling time (5.8 us; VREFINT needs at least 4 us, datasheet
/// `t_S_vrefint`); the VREFINT buffer is switched on by the measurement
/// (`supply::measure_now`, then its start-up time). Call with ADC1
/// enabled and `ADSTART = JADSTART = 0` (after `into_ring_buffered`, before the ring
/// starts): `SMPR2` and `JSQR` are writable only then. The regular sequence's sample
/// times are `SMPR1` and channels 10..17 of `SMPR2`; channel 18's field is this one's.
pub(super) fn configure_reference() {
    let adc = pac::ADC1;
    adc.smpr2()
        .modify(|w| w.set_smp(usize::from(VREFINT_CHANNEL - 10), SampleTime::CYCLES247_5));
    adc.jsqr().write(|w| {
        w.set_jl(0);
        w.set_jexten(Exten::DISABLED);
        w.set_jsq(0, VREFINT_CHANNEL);
    });
}

/// VREFINT on ADC1's injected channel ([`ReferenceAdc`]). An injected conversion started
/// while a regular one runs interrupts it; the regular one restarts after it (RM0440,
/// "Injected channel management"), so once per measurement one voltage sample is taken
/// up to 6.1 us later: 0.1 degree of a 50 Hz period.
pub(super) struct HwReference;

impl ReferenceAdc for HwReference {
    fn calibration(&self) -> u16 {
        pac::VREFINTCAL.data().read()
    }

    fn enable(&mut self) {
        pac::ADC12_COMMON.ccr().modify(|w| w.set_vrefen(true));
    }

    fn wait_us(&mut self, us: u32) {
        cortex_m::asm::delay(us.saturating_mul(clock::HCLK_HZ / 1_000_000));
    }

    fn start(&mut self) {
        // JADSTART written alone (`adc_rules::cr_setting`: no other set-only bit written
        // back), in a critical section: the sample task's recovery writes ADC1_CR too
        // (ADSTP, ADSTART), and its read and write must not interleave with this one.
        cortex_m::interrupt::free(|_| {
            let cr = pac::ADC1.cr().read().0;
            let value = adc_rules::cr_setting(cr, adc_rules::JADSTART);
            pac::ADC1.cr().write_value(pac::adc::regs::Cr(value));
        });
    }

    fn result(&mut self) -> Option<u16> {
        let adc = pac::ADC1;
        if !adc.isr().read().jeos() {
            return None;
        }
        let code = adc.jdr(0).read().jdata();
        // Write 1 to clear JEOS and JEOC only; the regular flags stay as they are.
        adc.isr().write(|w| {
            w.set_jeos(true);
            w.set_jeoc(true);
        });
        Some(code)
    }
}
