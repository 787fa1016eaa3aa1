//! A register model of what `drive_monitor::startup::start` touches on the STM32G474: the
//! registers by address (the bit positions written out here from RM0440, not taken from the
//! firmware), the IWDG's key protocol, the reset flags, the crystal and the PLL on a clock,
//! and the RAM that survives a reset (the reset record, the boot block, the stack's guard).

use std::collections::HashMap;

use drive_monitor::boot_block::BOOT_BLOCK_LEN;
use drive_monitor::clock::ClockSource;
use drive_monitor::debug_halt::FreezeRegisters;
use drive_monitor::reset_record::RESET_RECORD_LEN;
use drive_monitor::startup::StartupHw;
use drive_monitor::watchdog::IwdgSetting;

// RM0440's addresses and bits, the model's own copy.
pub const DBGMCU_APB1FZR1: u32 = 0xE004_2008;
pub const DBGMCU_APB2FZR: u32 = 0xE004_2010;
pub const RCC_CR: u32 = 0x4002_1000;
pub const FLASH_OPTR: u32 = 0x4002_2020;
pub const CSSON: u32 = 1 << 19;
/// The factory option bytes with the brown-out level at 4 and `nSWBOOT0` (bit 26) at 0
/// (what the firmware wants, what `cargo fw bor` writes).
pub const OPTR_GOOD: u32 = (0xFFEF_F8AA | (4 << 8)) & !(1 << 26);
/// `RCC_CSR`'s flags.
pub const IWDGRSTF: u32 = 1 << 29;
pub const PINRSTF: u32 = 1 << 26;
pub const BORRSTF: u32 = 1 << 27;

/// `PLLRDY` clears this long after `PLLON` is cleared [us].
pub const PLL_OFF_US: u64 = 20;

/// One step the model saw, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    WriteFreeze,
    WatchdogRunning,
    ResetFlagsCleared,
    BootBlock,
    Init,
    Css(bool),
}

/// The IWDG: started by its key, `PR`/`RLR` writable only after the unlock key.
#[derive(Clone, Copy, Debug, Default)]
pub struct Iwdg {
    pub running: bool,
    pub unlocked: bool,
    pub setting: Option<IwdgSetting>,
    pub reloads: u32,
    /// Writes of `PR`/`RLR` while locked (ignored by the hardware).
    pub locked_writes: u32,
    /// Polls of `SR` a new `PR`/`RLR` takes to reach the LSI domain (`PVU`/`RVU` set).
    pub update_polls: u32,
    /// `SR` polls while the update was on its way, and in all.
    pub polls_updating: u32,
    pub polls: u32,
    /// A reload key written while the update was still on its way.
    pub reloads_while_updating: u32,
}

/// The board (module docs).
#[derive(Clone, Debug)]
pub struct Board {
    pub regs: HashMap<u32, u32>,
    pub iwdg: Iwdg,
    pub csr: u32,
    pub reset_ram: [u8; RESET_RECORD_LEN],
    pub boot_block: [u8; BOOT_BLOCK_LEN],
    /// The boot block as it was when `init` was called (a hang there leaves it so).
    pub block_at_init: Option<[u8; BOOT_BLOCK_LEN]>,
    /// The previous run's stack reached its guard.
    pub stack_overflowed: bool,
    pub painted: bool,
    /// The crystal is ready this long after `HSEON` [us] (`None`: never).
    pub crystal_ready_after_us: Option<u64>,
    pub hse_on_at_us: Option<u64>,
    /// The PLL locks from the crystal / from the HSI (this long after `PLLON` [us]).
    pub pll_from_hse_us: Option<u64>,
    pub pll_from_hsi_us: Option<u64>,
    pub pllcfgr: u32,
    pub pll_on_at_us: Option<u64>,
    /// `CSSON` writes have no effect (a remedy that did not take).
    pub css_stuck_off: bool,
    /// `SR` polls a new watchdog setting takes to reach the LSI domain.
    pub iwdg_update_polls: u32,
    /// When the PLL was switched off [us] (`PLLRDY` clears [`PLL_OFF_US`] later).
    pub pll_off_at_us: Option<u64>,
    /// `PLLRDY` was still set when `init` was called.
    pub pll_ready_at_init: bool,
    pub now_us: u64,
    pub ops: Vec<Op>,
    pub init_with: Option<Option<ClockSource>>,
}

impl Board {
    /// A board at power-on: RAM garbage, the power-on flag, a crystal and a PLL that
    /// work, the option bytes as the firmware wants them.
    pub fn power_on() -> Self {
        let mut regs = HashMap::new();
        regs.insert(FLASH_OPTR, OPTR_GOOD);
        Board {
            regs,
            iwdg: Iwdg::default(),
            csr: BORRSTF | PINRSTF,
            reset_ram: [0x5A; RESET_RECORD_LEN],
            boot_block: [0xA5; BOOT_BLOCK_LEN],
            block_at_init: None,
            stack_overflowed: false,
            painted: false,
            crystal_ready_after_us: Some(2_000),
            hse_on_at_us: None,
            pll_from_hse_us: Some(40),
            pll_from_hsi_us: Some(40),
            pllcfgr: 0,
            pll_on_at_us: None,
            css_stuck_off: false,
            iwdg_update_polls: 3,
            pll_off_at_us: None,
            pll_ready_at_init: false,
            now_us: 0,
            ops: Vec::new(),
            init_with: None,
        }
    }

    /// The board after a reset with flags `csr`: RAM and the option bytes kept, the
    /// registers back to their reset values, the watchdog stopped.
    pub fn reset(&self, csr: u32) -> Self {
        let mut next = Board::power_on();
        next.regs.insert(FLASH_OPTR, self.reg(FLASH_OPTR));
        next.csr = csr | PINRSTF;
        next.reset_ram = self.reset_ram;
        next.boot_block = self.boot_block;
        next.crystal_ready_after_us = self.crystal_ready_after_us;
        next.pll_from_hse_us = self.pll_from_hse_us;
        next.pll_from_hsi_us = self.pll_from_hsi_us;
        next.iwdg_update_polls = self.iwdg_update_polls;
        next
    }

    pub fn reg(&self, address: u32) -> u32 {
        self.regs.get(&address).copied().unwrap_or(0)
    }

    pub fn position(&self, op: Op) -> usize {
        self.ops
            .iter()
            .position(|o| *o == op)
            .unwrap_or_else(|| panic!("{op:?} not in {:?}", self.ops))
    }

    fn pll_source(&self) -> u32 {
        self.pllcfgr & 0b11
    }

    /// The PLL runs and has locked from its source.
    fn pll_locked(&self) -> bool {
        let Some(t0) = self.pll_on_at_us else {
            return false;
        };
        // PLLSRC: 3 the crystal (which must run), 2 the HSI16.
        let lock = match self.pll_source() {
            3 if self.crystal_runs() => self.pll_from_hse_us,
            2 => self.pll_from_hsi_us,
            _ => None,
        };
        lock.is_some_and(|after| self.now_us >= t0 + after)
    }

    fn crystal_runs(&self) -> bool {
        match (self.hse_on_at_us, self.crystal_ready_after_us) {
            (Some(t0), Some(after)) => self.now_us >= t0 + after,
            _ => false,
        }
    }
}

impl StartupHw for Board {
    type Peripherals = ();

    fn read_freeze(&mut self) -> FreezeRegisters {
        FreezeRegisters {
            apb1fzr1: self.reg(DBGMCU_APB1FZR1),
            apb2fzr: self.reg(DBGMCU_APB2FZR),
        }
    }
    fn write_freeze(&mut self, regs: FreezeRegisters) {
        self.regs.insert(DBGMCU_APB1FZR1, regs.apb1fzr1);
        self.regs.insert(DBGMCU_APB2FZR, regs.apb2fzr);
        self.ops.push(Op::WriteFreeze);
    }
    fn iwdg_key(&mut self, key: u16) {
        match key {
            0xCCCC => {
                if !self.iwdg.running {
                    self.ops.push(Op::WatchdogRunning);
                }
                self.iwdg.running = true;
            }
            0x5555 => self.iwdg.unlocked = true,
            0xAAAA => {
                self.iwdg.reloads += 1;
                if self.iwdg.update_polls > 0 {
                    self.iwdg.reloads_while_updating += 1;
                }
                self.iwdg.unlocked = false;
            }
            _ => self.iwdg.unlocked = false,
        }
    }
    fn iwdg_setting(&mut self, setting: IwdgSetting) {
        if self.iwdg.unlocked {
            self.iwdg.setting = Some(setting);
            self.iwdg.update_polls = self.iwdg_update_polls;
        } else {
            self.iwdg.locked_writes += 1;
        }
    }
    fn iwdg_updating(&mut self) -> bool {
        self.iwdg.polls += 1;
        let updating = self.iwdg.update_polls > 0;
        if updating {
            self.iwdg.polls_updating += 1;
            self.iwdg.update_polls -= 1;
        }
        updating
    }
    fn reset_flags(&mut self) -> u32 {
        self.csr
    }
    fn clear_reset_flags(&mut self) {
        self.csr = 0;
        self.ops.push(Op::ResetFlagsCleared);
    }
    fn read_reset_record(&mut self) -> [u8; RESET_RECORD_LEN] {
        self.reset_ram
    }
    fn write_reset_record(&mut self, bytes: &[u8; RESET_RECORD_LEN]) {
        self.reset_ram = *bytes;
    }
    fn read_boot_block(&mut self) -> [u8; BOOT_BLOCK_LEN] {
        self.boot_block
    }
    fn write_boot_block(&mut self, bytes: &[u8; BOOT_BLOCK_LEN]) {
        self.boot_block = *bytes;
        self.ops.push(Op::BootBlock);
    }
    fn check_and_paint_stack(&mut self) -> bool {
        let was = self.stack_overflowed && self.painted;
        self.painted = true;
        self.stack_overflowed = false;
        was
    }
    fn hse_on(&mut self, on: bool) {
        self.hse_on_at_us = on.then_some(self.now_us);
    }
    fn hse_ready(&mut self) -> bool {
        self.crystal_runs()
    }
    fn pll_configure(&mut self, pllcfgr: u32) {
        self.pllcfgr = pllcfgr;
    }
    fn pll_on(&mut self, on: bool) {
        if !on && self.pll_locked() {
            self.pll_off_at_us = Some(self.now_us);
        }
        self.pll_on_at_us = on.then_some(self.now_us);
    }
    fn pll_ready(&mut self) -> bool {
        if self.pll_on_at_us.is_none() {
            // Switched off: PLLRDY clears a little later.
            return self
                .pll_off_at_us
                .is_some_and(|t| self.now_us < t + PLL_OFF_US);
        }
        self.pll_locked()
    }
    fn delay_us(&mut self, us: u32) {
        self.now_us += u64::from(us);
    }
    fn init(&mut self, clock: Option<ClockSource>) {
        self.pll_ready_at_init = self.pll_ready();
        self.block_at_init = Some(self.boot_block);
        self.init_with = Some(clock);
        self.ops.push(Op::Init);
    }
    fn set_css(&mut self, on: bool) {
        self.ops.push(Op::Css(on));
        if self.css_stuck_off {
            return;
        }
        let cr = self.reg(RCC_CR);
        self.regs
            .insert(RCC_CR, if on { cr | CSSON } else { cr & !CSSON });
    }
    fn read_word(&mut self, address: u32) -> u32 {
        self.reg(address)
    }
}
