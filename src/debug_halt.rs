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
