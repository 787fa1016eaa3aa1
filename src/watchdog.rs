//! The independent watchdog from the first instruction of `main`: started before the clock
//! set-up (which waits for the crystal and the PLL), the boot composition and the ADCs'
//! set-up, with a first timeout that covers all of them ([`BOOT_TIMEOUT_MS`] against the
//! boot's budget [`BOOT_BUDGET_MS`], at the fastest LSI), then shortened to the running
//! timeout (`app::WATCHDOG_TIMEOUT_MS`, 500 ms) once thread mode runs. A HardFault inside
//! the fault path locks the core up, and only the watchdog ends that: with the watchdog
//! started first, that holds from the first instruction on.
//!
//! The IWDG counts the LSI (RM0440, "Independent watchdog"): `PR` divides it by 4 x 2^PR
//! (4..256), `RLR` (12 bits) is the count down. The LSI is 32 kHz typically, 29.5 to
//! 34 kHz over the parts and temperature (datasheet): a timeout is longest at the slowest
//! and shortest at the fastest LSI.

/// The LSI's typical frequency [Hz] (embassy-stm32 computes its timeouts with it).
pub const LSI_TYP_HZ: u32 = 32_000;
/// The LSI's fastest [Hz] (datasheet): the shortest timeout a setting gives.
pub const LSI_MAX_HZ: u32 = 34_000;

/// The boot's worst case up to the first pet of the running watchdog [ms], term by term:
/// the crystal's start-up bound (`clock::HSE_STARTUP_TIMEOUT_MS`, then the fallback to
/// HSI), the PLL's bounded lock before `init` (`startup::PLL_LOCK_POLLS`, 2 ms), the PLL's
/// lock and the clock switch in `init` (under 1 ms: 1), reading the reset record,
/// the option bytes and both record pages from flash and logging the boot report (under
/// 50 ms with the RTT buffer full and non-blocking: 50), the ADCs' set-up under its
/// deadline (`setup_guard`, 20 ms), the reference's start-up check (under 1 ms: 1) and
/// thread mode's first period (`app::PANEL_PERIOD_MS`, 50 ms).
pub const BOOT_BUDGET_MS: u32 = crate::clock::HSE_STARTUP_TIMEOUT_MS + 2 + 1 + 50 + 20 + 1 + 50;

/// The first timeout [ms] at the typical LSI: four times the boot's budget, rounded up to
/// a second.
pub const BOOT_TIMEOUT_MS: u32 = 1_000;

/// `IWDG_KR`'s start key: the watchdog (and the LSI) runs.
pub const KEY_START: u16 = 0xCCCC;
/// `IWDG_KR`'s key that unlocks `IWDG_PR` and `IWDG_RLR`.
pub const KEY_UNLOCK: u16 = 0x5555;
/// `IWDG_KR`'s reload key: the counter back to `RLR` (a pet).
pub const KEY_RELOAD: u16 = 0xAAAA;

/// An IWDG setting: `PR` (0..=6: divide by 4 x 2^PR) and `RLR` (0..=4095).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IwdgSetting {
    /// `IWDG_PR.PR`.
    pub pr: u8,
    /// `IWDG_RLR.RL`.
    pub rlr: u16,
}

impl IwdgSetting {
    /// The setting for `timeout_ms` at the typical LSI: the smallest prescaler whose 12-bit
    /// reload reaches it (`None` beyond 32.7 s, the longest).
    pub const fn for_timeout_ms(timeout_ms: u32) -> Option<IwdgSetting> {
        let mut pr = 0u8;
        while pr <= 6 {
            let divider = 4u64 << pr;
            let ticks = timeout_ms as u64 * LSI_TYP_HZ as u64 / (1_000 * divider);
            if ticks >= 1 && ticks <= 4_096 {
                return Some(IwdgSetting {
                    pr,
                    rlr: (ticks - 1) as u16,
                });
            }
            pr += 1;
        }
        None
    }

    /// The timeout this setting gives at an LSI of `lsi_hz` [ms] (rounded down).
    pub const fn timeout_ms(self, lsi_hz: u32) -> u32 {
        let divider = 4u64 << self.pr;
        ((self.rlr as u64 + 1) * divider * 1_000 / lsi_hz as u64) as u32
    }
}

/// The boot's setting ([`BOOT_TIMEOUT_MS`]); a compile-time check that it exists.
pub const BOOT_SETTING: IwdgSetting = match IwdgSetting::for_timeout_ms(BOOT_TIMEOUT_MS) {
    Some(s) => s,
    None => panic!("no IWDG setting for the boot's timeout"),
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The boot's timeout, at the fastest LSI, covers the boot's budget (the sum by hand:
    /// 100 + 2 + 1 + 50 + 20 + 1 + 50 = 224 ms), and the running timeout is shorter.
    #[test]
    fn the_first_timeout_covers_the_boot_at_the_fastest_lsi() {
        assert_eq!(BOOT_BUDGET_MS, 224);
        let shortest = BOOT_SETTING.timeout_ms(LSI_MAX_HZ);
        assert!(shortest >= BOOT_BUDGET_MS, "{shortest} ms");
        // 1 s at 32 kHz: divide by 8 (PR = 1), 4 000 ticks (4 096 at most).
        assert_eq!(BOOT_SETTING, IwdgSetting { pr: 1, rlr: 3_999 });
        assert_eq!(BOOT_SETTING.timeout_ms(LSI_TYP_HZ), 1_000);
        assert_eq!(IwdgSetting::for_timeout_ms(40_000), None);
    }
}
