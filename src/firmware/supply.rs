//! The supply and the set-up on the registers: the ADCs' set-up deadline on SysTick
//! (`drive_monitor::setup_guard`), VREFINT on ADC1's injected channel
//! (`drive_monitor::supply::ReferenceAdc`) and the brown-out level of the option bytes.

use core::sync::atomic::{AtomicU8, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use drive_monitor::clock;
use drive_monitor::regs::MCU;
use drive_monitor::setup_guard::{self, SetupStep, SETUP_DEADLINE_MS};
use drive_monitor::supply::{BorLevel, ReferenceAdc};

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
    BorLevel::from_optr(MCU.optr())
}

/// Sets ADC1's injected sequence to one conversion of VREFINT
/// (`drive_monitor::regs`' `configure_reference`); the VREFINT buffer is switched on by the
/// measurement (`supply::measure_now`, then its start-up time). Call with ADC1 enabled and
/// `ADSTART = JADSTART = 0` (after `into_ring_buffered`, before the ring starts).
pub(super) fn configure_reference() {
    MCU.configure_reference();
}

/// VREFINT on ADC1's injected channel ([`ReferenceAdc`]). An injected conversion started
/// while a regular one runs interrupts it; the regular one restarts after it (RM0440,
/// "Injected channel management"), so once per measurement one voltage sample is taken
/// up to 6.1 us later: 0.1 degree of a 50 Hz period.
pub(super) struct HwReference;

impl ReferenceAdc for HwReference {
    fn calibration(&self) -> u16 {
        MCU.vrefint_calibration()
    }

    fn enable(&mut self) {
        MCU.vrefint_enable();
    }

    fn wait_us(&mut self, us: u32) {
        cortex_m::asm::delay(us.saturating_mul(clock::HCLK_HZ / 1_000_000));
    }

    fn start(&mut self) {
        // JADSTART written alone (`adc_rules::cr_setting`: no other set-only bit written
        // back), in a critical section: the sample task's recovery writes ADC1_CR too
        // (ADSTP, ADSTART), and its read and write must not interleave with this one.
        cortex_m::interrupt::free(|_| MCU.start_injected());
    }

    fn result(&mut self) -> Option<u16> {
        MCU.injected_result()
    }
}
