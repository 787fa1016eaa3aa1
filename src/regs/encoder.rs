//! The encoder's timer, TIM4, beyond embassy-stm32's `Qei::new` (which sets the encoder
//! mode, TI1/TI2 and enables channels 1 and 2): the motor record's input filter and
//! direction, and the count latched at the sample trigger on channel 3.

use super::{pac, Bus, Registers};
use pac::timer::vals::{CcmrInputCcs, FilterValue, Ts};

impl<B: Bus> Registers<B> {
    /// The input filter `filter` (`ICxF`, 0..=15) on both inputs and input A's polarity
    /// inverted with `invert_a` (`CC1P`); then the latch: channel 3 captures the counter on
    /// TRC, the internal trigger ITR0 (TIM1's TRGO, RM0440 "TIMx internal trigger
    /// connection"; the encoder mode does not use the trigger input), rising edge, each
    /// capture raising a DMA request (`CC3DE`) that copies `CCR3` into the latch's ring.
    pub fn encoder_setup(self, filter: u8, invert_a: bool) {
        let t = self.tim4();
        let filter = FilterValue::from_bits(filter);
        t.ccmr_input(0).modify(|w| {
            w.set_icf(0, filter);
            w.set_icf(1, filter);
        });
        t.ccer().modify(|w| w.set_ccp(0, invert_a));
        t.smcr().modify(|w| w.set_ts(Ts::ITR0));
        t.ccmr_input(1).modify(|w| w.set_ccs(0, CcmrInputCcs::TRC));
        t.ccer().modify(|w| {
            w.set_ccp(2, false);
            w.set_cce(2, true);
        });
        t.dier().modify(|w| w.set_ccde(2, true));
    }

    /// `TIM4_CCR3`, the latch ring's DMA source.
    pub fn latch_source(self) -> *mut u16 {
        self.tim4().ccr(2).as_ptr().cast::<u16>()
    }
}
