//! The start of every run, on the registers, before and around embassy-stm32's `init`:
//! written once here over [`StartupHw`] (the firmware implements it on the STM32G474's
//! registers in `src/firmware/startup_hw.rs`, one register access a method; the host tests
//! on a register model), so every step below runs in `cargo test`.
//!
//! In this order ([`start`]):
//! 1. **The debug freeze** (`debug_halt::FROZEN`): `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR`
//!    written whole, the values `Freeze::registers_after` computes from what they held.
//! 2. **The watchdog**, started with the boot's timeout (`watchdog::BOOT_SETTING`): start
//!    key, unlock, `PR`, `RLR`, a bounded wait for the update, reload.
//! 3. **Why the previous run ended**: the reset flags (then cleared), the reset record (then
//!    erased) and the boot block (`crate::boot_block`: the phase mark, the failed boots in
//!    a row, whether RAM survived).
//! 4. **The stack**: the previous run's overflow in its guard words, then painted.
//! 5. **The phase mark** [`BootPhase::Clock`], then the clock: the crystal's bounded start
//!    (`clock::HSE_STARTUP_TIMEOUT_MS`; not tried after a clock failure), the PLL's bounded
//!    lock from it ([`PLL_LOCK_POLLS`]; the HSI's when the crystal's does not lock), then
//!    `init` with the source that worked and the clock security system with the crystal.
//!    A PLL that locks from neither, or [`SAFE_MODE_AFTER`](crate::boot_block::SAFE_MODE_AFTER) failed boots in a row, make
//!    the **safe mode** ([`SafeModeReason`]): `init` on the reset clock, no sampling.
//! 6. **The self-check** of the boot's registers (`crate::self_check`, [`CheckId::BOOT`])
//!    and the brown-out level.
//!
//! What it found is a [`BootFacts`]: the firmware logs its [`BootFacts::notes`], puts it into
//! the supervisor ([`BootFacts::configure`]) and the reset log.

use crate::app::{AppError, Settings, Supervisor};
use crate::boot::{self, Booted};
use crate::boot_block::{BootBlock, BootHistory, BOOT_BLOCK_LEN};
use crate::clock::{self, ClockSource};
use crate::debug_halt::{FreezeRegisters, FROZEN};
use crate::flash_record::RecordStore;
use crate::reset_record::{BootPhase, PreviousRun, ResetSource, RESET_RECORD_LEN};
use crate::self_check::registers::FLASH_OPTR;
use crate::self_check::{self, CheckId, Findings, CRYSTAL_DID_NOT_START, PLL_DID_NOT_LOCK};
use crate::supply::BorCheck;
use crate::watchdog::{self, IwdgSetting};

/// Polls of `RCC_CR.PLLRDY`, [`PLL_POLL_US`] apart, before the PLL counts as not locking:
/// 2 ms, far beyond the PLL's lock time in the datasheet.
pub const PLL_LOCK_POLLS: u32 = 200;
/// The wait between two polls of the PLL [us] (at the 16 MHz reset clock).
pub const PLL_POLL_US: u32 = 10;
/// Polls of the watchdog's update flags (`IWDG_SR.PVU`, `RVU`) before the boot goes on:
/// the new values reach the LSI domain within a few LSI periods (48 us each).
pub const IWDG_UPDATE_POLLS: u32 = 100_000;

/// The registers the start touches, one access a method (module docs).
pub trait StartupHw {
    /// What `init` hands back (embassy-stm32's peripherals on the board).
    type Peripherals;
    /// `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR` as they are.
    fn read_freeze(&mut self) -> FreezeRegisters;
    /// `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR` written whole.
    fn write_freeze(&mut self, regs: FreezeRegisters);
    /// A key written to `IWDG_KR` ([`watchdog::KEY_START`], ...).
    fn iwdg_key(&mut self, key: u16);
    /// `IWDG_PR` and `IWDG_RLR` written (unlocked by [`watchdog::KEY_UNLOCK`] first).
    fn iwdg_setting(&mut self, setting: IwdgSetting);
    /// `IWDG_SR.PVU` or `RVU`: a new value on its way to the LSI domain.
    fn iwdg_updating(&mut self) -> bool;
    /// `RCC_CSR` (the reset flags).
    fn reset_flags(&mut self) -> u32;
    /// Clears the reset flags (`RCC_CSR.RMVF`).
    fn clear_reset_flags(&mut self);
    /// The reset record's RAM.
    fn read_reset_record(&mut self) -> [u8; RESET_RECORD_LEN];
    /// Overwrites the reset record's RAM.
    fn write_reset_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]);
    /// The boot block's RAM (`crate::boot_block`).
    fn read_boot_block(&mut self) -> [u8; BOOT_BLOCK_LEN];
    /// Overwrites the boot block's RAM.
    fn write_boot_block(&mut self, bytes: &[u8; BOOT_BLOCK_LEN]);
    /// Whether the previous run's stack overflowed (`stack::overflowed` on its guard
    /// words), then paints the stack for this run.
    fn check_and_paint_stack(&mut self) -> bool;
    /// `RCC_CR.HSEON`.
    fn hse_on(&mut self, on: bool);
    /// `RCC_CR.HSERDY`.
    fn hse_ready(&mut self) -> bool;
    /// `RCC_PLLCFGR` written whole ([`clock::pll_cfgr`]).
    fn pll_configure(&mut self, pllcfgr: u32);
    /// `RCC_CR.PLLON`.
    fn pll_on(&mut self, on: bool);
    /// `RCC_CR.PLLRDY`.
    fn pll_ready(&mut self) -> bool;
    /// A busy wait of `us` microseconds at the 16 MHz reset clock.
    fn delay_us(&mut self, us: u32);
    /// embassy-stm32's `init`: with the PLL from `clock` at 170 MHz, or (`None`, the safe
    /// mode) on the reset clock.
    fn init(&mut self, clock: Option<ClockSource>) -> Self::Peripherals;
    /// `RCC_CR.CSSON`.
    fn set_css(&mut self, on: bool);
    /// The register at `address` (the self-check's reads, `FLASH_OPTR`).
    fn read_word(&mut self, address: u32) -> u32;
}

/// Why the boot entered the safe mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SafeModeReason {
    /// [`SAFE_MODE_AFTER`](crate::boot_block::SAFE_MODE_AFTER) or more runs in a row failed before they were up.
    BootLoop {
        /// The failed boots in a row.
        failed_boots: u8,
    },
    /// The PLL locked neither from the crystal nor from the HSI.
    PllDidNotLock,
}

impl SafeModeReason {
    /// The code the FAULT lamp blinks in the safe mode (`panel::PanelLamps::safe_mode`).
    pub const fn code(self) -> u8 {
        match self {
            SafeModeReason::BootLoop { .. } => 1,
            SafeModeReason::PllDidNotLock => 2,
        }
    }
}

/// What the start found (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BootFacts {
    /// Why the previous run ended.
    pub previous: PreviousRun,
    /// What the reset flags say reset the MCU.
    pub reset_source: ResetSource,
    /// The boot block's history: the reset's kind, the failed boots in a row.
    pub history: BootHistory,
    /// The previous run's stack reached the bottom of RAM.
    pub stack_overflowed: bool,
    /// The PLL's source (`None`: the safe mode, the 16 MHz reset clock without the PLL).
    pub clock: Option<ClockSource>,
    /// The self-check's findings (the boot's registers, the clock's fallbacks).
    pub findings: Findings,
    /// The brown-out level in the option bytes.
    pub bor: BorCheck,
    /// The safe mode, and why (`None`: a normal run).
    pub safe_mode: Option<SafeModeReason>,
}

/// One thing the boot's log says, in its order ([`BootFacts::notes`]); the firmware spells
/// each (`src/firmware/logs.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BootNote {
    /// The clock in force (`None`: the safe mode's reset clock).
    Clock(Option<ClockSource>),
    /// What reset the MCU, and why the previous run ended.
    PreviousRun(ResetSource, PreviousRun),
    /// The previous run's stack reached the bottom of RAM.
    StackOverflowed,
    /// Failed boots in a row so far (logged from the second on).
    FailedBoots(u8),
    /// A register that did not hold what the firmware wrote.
    Mismatch(CheckId),
    /// The brown-out level.
    BrownOut(BorCheck),
    /// The safe mode.
    SafeMode(SafeModeReason),
}

impl BootFacts {
    /// What the boot's log says, in order.
    pub fn notes(&self) -> impl Iterator<Item = BootNote> + '_ {
        let head = [
            Some(BootNote::Clock(self.clock)),
            Some(BootNote::PreviousRun(self.reset_source, self.previous)),
            self.stack_overflowed.then_some(BootNote::StackOverflowed),
            (self.history.failed_boots > 1)
                .then_some(BootNote::FailedBoots(self.history.failed_boots)),
        ];
        let tail = [
            Some(BootNote::BrownOut(self.bor)),
            self.safe_mode.map(BootNote::SafeMode),
        ];
        head.into_iter()
            .flatten()
            .chain(self.findings.mismatched().map(BootNote::Mismatch))
            .chain(tail.into_iter().flatten())
    }

    /// Puts what the panel marks into the `supervisor`: the clock on the HSI, the
    /// brown-out level below the goal.
    pub fn configure(&self, supervisor: &mut Supervisor) {
        supervisor.set_clock_fallback(self.clock != Some(ClockSource::Hse));
        supervisor.set_bor_below_goal(!self.bor.allows_flash_writes());
    }
}

/// The boot composition (`crate::boot::boot`: the machine of the motor record in
/// `motor_page`, the commissioning record in `store`, the supervisor for `settings` after
/// the previous run `facts` read) with the panel's marks from `facts`
/// ([`BootFacts::configure`]). The firmware and the host's software-in-the-loop rig boot
/// through it.
///
/// # Errors
/// As `crate::boot::boot`.
pub fn boot_board<S: RecordStore>(
    facts: &BootFacts,
    motor_page: &[u8],
    store: &mut S,
    settings: &Settings,
) -> Result<Booted<S::Error>, AppError> {
    let mut booted = boot::boot(motor_page, store, settings, facts.previous, 0)?;
    facts.configure(&mut booted.supervisor);
    Ok(booted)
}

/// The start (module docs): returns `init`'s peripherals and what it found.
pub fn start<H: StartupHw>(hw: &mut H) -> (H::Peripherals, BootFacts) {
    freeze_and_watch(hw);
    let (previous, reset_source, history) = previous_run(hw);
    let stack_overflowed = hw.check_and_paint_stack();
    let block = history.block().in_phase(BootPhase::Clock);
    hw.write_boot_block(&block.encode());
    let (clock, clock_findings, safe_mode) = if history.safe_mode() {
        let reason = SafeModeReason::BootLoop {
            failed_boots: history.failed_boots,
        };
        (None, 0, Some(reason))
    } else {
        choose_clock(hw, previous.clock_failed())
    };
    let peripherals = hw.init(clock);
    if clock.is_some_and(clock::css_on) {
        hw.set_css(true);
    }
    hw.write_boot_block(&block.in_phase(BootPhase::Boot).encode());
    let expected = self_check::expectation(clock.unwrap_or(ClockSource::Hsi), None);
    let findings = self_check::run(&CheckId::BOOT, &expected, |a| hw.read_word(a));
    let facts = BootFacts {
        previous,
        reset_source,
        history,
        stack_overflowed,
        clock,
        findings: findings.with(clock_findings),
        bor: BorCheck::of_optr(hw.read_word(FLASH_OPTR)),
        safe_mode,
    };
    (peripherals, facts)
}

/// Steps 1 and 2: the debug freeze, then the watchdog with the boot's timeout.
fn freeze_and_watch<H: StartupHw>(hw: &mut H) {
    let after = FROZEN.registers_after(hw.read_freeze());
    hw.write_freeze(after);
    hw.iwdg_key(watchdog::KEY_START);
    hw.iwdg_key(watchdog::KEY_UNLOCK);
    hw.iwdg_setting(watchdog::BOOT_SETTING);
    let mut polls = 0;
    while hw.iwdg_updating() && polls < IWDG_UPDATE_POLLS {
        polls += 1;
    }
    hw.iwdg_key(watchdog::KEY_RELOAD);
}

/// Step 3: the previous run's end (the reset record, then erased; a watchdog reset with
/// none placed by the boot block's phase mark), the reset's source (the flags, then
/// cleared) and the boot block's history.
fn previous_run<H: StartupHw>(hw: &mut H) -> (PreviousRun, ResetSource, BootHistory) {
    let source = ResetSource::from_csr(hw.reset_flags());
    hw.clear_reset_flags();
    let left = BootBlock::decode(&hw.read_boot_block());
    let previous =
        PreviousRun::at_boot(&hw.read_reset_record(), source).hung_in(left.and_then(|b| b.phase));
    hw.write_reset_record(&[0; RESET_RECORD_LEN]);
    let history = BootHistory::of(left, source, &previous);
    (previous, source, history)
}

/// Step 5's clock: the crystal's bounded start (not after a clock failure), the PLL's
/// bounded lock from it, else from the HSI. Returns the source (`None`: the PLL locked
/// from neither: the safe mode), the findings of the fallbacks and the safe mode's reason.
fn choose_clock<H: StartupHw>(
    hw: &mut H,
    crystal_failed: bool,
) -> (Option<ClockSource>, u32, Option<SafeModeReason>) {
    let source = clock::boot_source(crystal_failed, || start_crystal(hw));
    let mut findings = if source == ClockSource::Hsi {
        CRYSTAL_DID_NOT_START
    } else {
        0
    };
    if pll_locks(hw, source) {
        return (Some(source), findings, None);
    }
    if source == ClockSource::Hse {
        // The crystal runs but the PLL does not lock from it: off, and the HSI instead.
        findings |= PLL_DID_NOT_LOCK;
        hw.hse_on(false);
        if pll_locks(hw, ClockSource::Hsi) {
            return (Some(ClockSource::Hsi), findings, None);
        }
    }
    (None, findings, Some(SafeModeReason::PllDidNotLock))
}

/// The crystal started with a bounded wait (`clock::HSE_STARTUP_TIMEOUT_MS`, a
/// millisecond a poll): [`ClockSource::Hse`], or, switched off again, [`ClockSource::Hsi`].
/// embassy-stm32's `init` waits for `HSERDY` without a bound, so it is handed the crystal
/// only once it runs.
pub fn start_crystal<H: StartupHw>(hw: &mut H) -> ClockSource {
    hw.hse_on(true);
    for _ in 0..clock::HSE_STARTUP_TIMEOUT_MS {
        if hw.hse_ready() {
            return ClockSource::Hse;
        }
        hw.delay_us(1_000);
    }
    if hw.hse_ready() {
        return ClockSource::Hse;
    }
    hw.hse_on(false);
    ClockSource::Hsi
}

/// Whether the PLL locks from `source` within [`PLL_LOCK_POLLS`]: configured as `init`
/// will configure it ([`clock::pll_cfgr`]), switched on, polled, switched off again (a
/// bounded wait too); `init` then sets it up itself and waits without a bound, which a
/// PLL that locked once does not need.
pub fn pll_locks<H: StartupHw>(hw: &mut H, source: ClockSource) -> bool {
    hw.pll_configure(clock::pll_cfgr(source));
    hw.pll_on(true);
    let mut locked = false;
    for _ in 0..PLL_LOCK_POLLS {
        if hw.pll_ready() {
            locked = true;
            break;
        }
        hw.delay_us(PLL_POLL_US);
    }
    hw.pll_on(false);
    for _ in 0..PLL_LOCK_POLLS {
        if !hw.pll_ready() {
            break;
        }
        hw.delay_us(PLL_POLL_US);
    }
    locked
}
