//! What a debugger's halt stops besides the core (`DBGMCU_APB1FZR1`, `DBGMCU_APB2FZR`;
//! RM0440, "Debug support"): by default only the core halts, and TIM1 (the sample trigger)
//! with the ADCs and the DMA it drives runs on, so the DMA laps the ring during every
//! breakpoint and every halt ends in a recovery. The firmware freezes [`FROZEN`]:
//!
//! - TIM1 (`DBG_TIM1_STOP`): no trigger, so no conversion and no DMA transfer during the
//!   halt: the ring stands where it was;
//! - TIM15 (`DBG_TIM15_STOP`), embassy-time's driver on the G474 (`time-driver-any`): the
//!   sample task's wait for data (its timeout) and thread mode's periods stand still with
//!   the samples, so the halt is no stall;
//! - the IWDG (`DBG_IWDG_STOP`): stepping does not reset the MCU.
//!
//! A breakpoint then stops sampling between two triggers and resumes without a recovery;
//! the timestamps carry on as if the halt had not been. Left: the conversion after the
//! resume follows an idle of the halt's length, which the G4's errata say may be wrong
//! (`adc_rules::IdleDiscard` cannot see a halt; one sample after a breakpoint may be off).

/// Which timers and watchdogs stop while the core is halted by a debugger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Freeze {
    /// TIM1, the sample trigger (`DBGMCU_APB2FZR.DBG_TIM1_STOP`).
    pub trigger: bool,
    /// TIM15, embassy-time's clock (`DBGMCU_APB2FZR.DBG_TIM15_STOP`).
    pub time_base: bool,
    /// The independent watchdog (`DBGMCU_APB1FZR1.DBG_IWDG_STOP`).
    pub watchdog: bool,
}

/// What the firmware freezes (module docs).
pub const FROZEN: Freeze = Freeze {
    trigger: true,
    time_base: true,
    watchdog: true,
};

/// `DBGMCU_APB2FZR.DBG_TIM1_STOP` (RM0440, "Debug MCU APB2 freeze register"): bit 11.
pub const DBG_TIM1_STOP: u32 = 1 << 11;
/// `DBGMCU_APB2FZR.DBG_TIM15_STOP`: bit 16.
pub const DBG_TIM15_STOP: u32 = 1 << 16;
/// `DBGMCU_APB1FZR1.DBG_IWDG_STOP` (RM0440, "Debug MCU APB1 freeze register 1"): bit 12.
pub const DBG_IWDG_STOP: u32 = 1 << 12;

/// The values of `DBGMCU_APB1FZR1` and `DBGMCU_APB2FZR` after the boot's write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FreezeRegisters {
    /// `DBGMCU_APB1FZR1`.
    pub apb1fzr1: u32,
    /// `DBGMCU_APB2FZR`.
    pub apb2fzr: u32,
}

impl Freeze {
    /// The freeze registers' values the firmware writes at boot for this freeze, from the
    /// values it read (`read`): each of the three stop bits set or cleared as the freeze
    /// says, every other bit as read. `src/firmware.rs` writes exactly these values (whole
    /// registers), so what a halt stops is what this computes.
    pub const fn registers_after(self, read: FreezeRegisters) -> FreezeRegisters {
        const fn bit(value: u32, mask: u32, on: bool) -> u32 {
            if on {
                value | mask
            } else {
                value & !mask
            }
        }
        FreezeRegisters {
            apb1fzr1: bit(read.apb1fzr1, DBG_IWDG_STOP, self.watchdog),
            apb2fzr: bit(
                bit(read.apb2fzr, DBG_TIM1_STOP, self.trigger),
                DBG_TIM15_STOP,
                self.time_base,
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each stop bit set or cleared as the freeze says, from either value it held, every
    /// other bit as read.
    #[test]
    fn each_stop_bit_follows_the_freeze_whatever_it_held() {
        let all = FreezeRegisters {
            apb1fzr1: u32::MAX,
            apb2fzr: u32::MAX,
        };
        let none = FreezeRegisters {
            apb1fzr1: 0,
            apb2fzr: 0,
        };
        let off = Freeze {
            trigger: false,
            time_base: false,
            watchdog: false,
        };
        assert_eq!(FROZEN.registers_after(all), all, "set stays set");
        assert_eq!(
            off.registers_after(all),
            FreezeRegisters {
                apb1fzr1: !DBG_IWDG_STOP,
                apb2fzr: !(DBG_TIM1_STOP | DBG_TIM15_STOP),
            }
        );
        assert_eq!(off.registers_after(none), none);
        assert_eq!(
            FROZEN.registers_after(none),
            FreezeRegisters {
                apb1fzr1: DBG_IWDG_STOP,
                apb2fzr: DBG_TIM1_STOP | DBG_TIM15_STOP,
            }
        );
    }
}
