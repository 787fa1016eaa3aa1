//! The start's registers (`crate::startup::StartupHw`, whose sequence is
//! `crate::startup::start`): the debug freeze, the watchdog, the reset flags, the crystal,
//! the PLL and the clock security system.

use super::{pac, Bus, Registers};
use crate::debug_halt::FreezeRegisters;
use crate::watchdog::IwdgSetting;

impl<B: Bus> Registers<B> {
    /// `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR` as they are.
    pub fn read_freeze(self) -> FreezeRegisters {
        let d = self.dbgmcu();
        FreezeRegisters {
            apb1fzr1: d.apb1lfzr().read().0,
            apb2fzr: d.apb2fzr().read().0,
        }
    }

    /// `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR` written whole.
    pub fn write_freeze(self, regs: FreezeRegisters) {
        let d = self.dbgmcu();
        d.apb1lfzr()
            .write_value(pac::dbgmcu::regs::Apb1lfzr(regs.apb1fzr1));
        d.apb2fzr()
            .write_value(pac::dbgmcu::regs::Apb2fzr(regs.apb2fzr));
    }

    /// `key` written to `IWDG_KR`.
    pub fn iwdg_key(self, key: u16) {
        self.iwdg()
            .kr()
            .write(|w| w.set_key(pac::iwdg::vals::Key::from_bits(key)));
    }

    /// `IWDG_PR` and `IWDG_RLR` written.
    pub fn iwdg_setting(self, setting: IwdgSetting) {
        let iwdg = self.iwdg();
        iwdg.pr()
            .write(|w| w.set_pr(pac::iwdg::vals::Pr::from_bits(setting.pr)));
        iwdg.rlr().write(|w| w.set_rl(setting.rlr));
    }

    /// `IWDG_SR.PVU` or `RVU`: a new value on its way to the LSI domain.
    pub fn iwdg_updating(self) -> bool {
        let sr = self.iwdg().sr().read();
        sr.pvu() || sr.rvu()
    }

    /// `RCC_CSR` (the reset flags).
    pub fn reset_flags(self) -> u32 {
        self.rcc().csr().read().0
    }

    /// Clears the reset flags (`RCC_CSR.RMVF`).
    pub fn clear_reset_flags(self) {
        self.rcc().csr().modify(|w| w.set_rmvf(true));
    }

    /// `RCC_CR.HSEON`.
    pub fn hse_on(self, on: bool) {
        self.rcc().cr().modify(|w| w.set_hseon(on));
    }

    /// `RCC_CR.HSERDY`.
    pub fn hse_ready(self) -> bool {
        self.rcc().cr().read().hserdy()
    }

    /// `RCC_PLLCFGR` written whole (`crate::clock::pll_cfgr`).
    pub fn pll_configure(self, pllcfgr: u32) {
        self.rcc()
            .pllcfgr()
            .write_value(pac::rcc::regs::Pllcfgr(pllcfgr));
    }

    /// `RCC_CR.PLLON`.
    pub fn pll_on(self, on: bool) {
        self.rcc().cr().modify(|w| w.set_pllon(on));
    }

    /// `RCC_CR.PLLRDY`.
    pub fn pll_ready(self) -> bool {
        self.rcc().cr().read().pllrdy()
    }

    /// `RCC_CR.CSSON`.
    pub fn set_css(self, on: bool) {
        self.rcc().cr().modify(|w| w.set_csson(on));
    }
}
