//! Where the firmware writes registers under embassy-stm32, why, and the version of the
//! HAL that was read for it. Each entry relies on the HAL's internals as they are in
//! embassy-stm32 [`EMBASSY_STM32_CHECKED`]: a new version may own a register the firmware
//! writes, or do in another order what the firmware works around. `tests/under_the_hal.rs`
//! fails when `Cargo.lock` holds another version (read the HAL's source for each entry
//! again, then change the pin) and when a firmware file reaches the registers (`pac::`)
//! without an entry here.
//!
//! | file | registers | why | relies on (embassy-stm32 0.6) |
//! |---|---|---|---|
//! | `src/firmware.rs` | `DBGMCU_APB1FZR1`/`APB2FZR`, `IWDG_KR`/`PR`/`RLR`, before `init` | the freeze on a debug halt (`debug_halt`) and the watchdog from the first instruction (`watchdog`): the HAL has neither | `IndependentWatchdog::new` reprograms a running IWDG (unlock, `PR`, `RLR`); `init` leaves `DBGMCU`'s freeze bits alone |
//! | `src/firmware.rs` | `RCC_CR.HSEON`/`HSERDY`, before `init` | the crystal's bounded start and the HSI fallback (`clock::ClockSource`): the HAL waits for `HSERDY` without a bound | `init` switches `HSEON` off and on again and waits: a crystal that started once starts again |
//! | `src/firmware.rs` | `FLASH_OPTR` (read) | `DBANK` before the flash driver, which panics on single-bank option bytes | the driver's dual-bank build |
//! | `src/firmware/acquisition.rs` | `ADC_ISR`, `ADC_CR` (whole-register writes, `adc_rules::cr_setting`), `ADC_CFGR.DMAEN`/`DMACFG`, `DMA_ISR`/`IFCR`, `DMA_CCR.EN`/`TEIE`, `DMA_CNDTR` | the acquisition's first start and its recovery (`recovery`): the ring-buffered ADC offers no stop, flag clear or reload, and its `start` writes `ADEN` back with `ADSTART` | `RingBufferedAdc::{stop, clear}` (`clear` reads the ring position from `CNDTR`), `read` not starting a ring whose channel has `EN` and `CIRC` set (`is_running`), `configure_dma` setting `DMAEN`; the DMA interrupt handler panics when it runs with `TEIF` set (`AdcDmaInterrupt` runs first) |
//! | `src/firmware/acquisition.rs` | `ADC_CR.ADDIS`, `ADC12_CCR.PRESC` (read) | the common prescaler written with both ADCs disabled (`adc_rules::create_pair`) | `Adc::new` writes `PRESC` and enables its ADC; `into_ring_buffered` enables it again |
//! | `src/firmware/supply.rs` | `ADC1_SMPR2`, `ADC1_JSQR`, `ADC12_CCR.VREFEN`, `ADC1_CR.JADSTART`, `ADC1_JDR1`/`ISR.JEOS`, `FLASH_OPTR` (read) | VREFINT on ADC1's injected channel (`supply`), the brown-out level | the ring-buffered ADC uses the regular group only and leaves the injected group, `SMPR2`'s channel 18 and `VREFEN` alone |
//! | `src/firmware/sample_task.rs` | `TIM4_CCMR1.IC1F`/`IC2F`, `TIM4_CCER.CC1P` | the encoder's input filter and direction (`motor_source`) | `Qei::new` leaves the filter at 0 and the polarity non-inverted and does not write them later |
//! | `src/firmware/sample_task.rs` | `TIM4_SMCR.TS` (ITR0), `TIM4_CCMR2.CC3S` (TRC), `TIM4_CCER.CC3E`, `TIM4_DIER.CC3DE`, `TIM4_CCR3` as a DMA source (`ReadableRingBuffer::new` on DMA1 channel 3) | the encoder count latched at the trigger (`acquisition::LATCH_LEN`): the HAL's encoder driver has no capture | `Qei::new` uses channels 1 and 2 and the encoder slave mode only; ITR0 of TIM4 is TIM1's `TRGO` (RM0440's internal trigger table: check on the board, the latch's counts then step with the shaft) |
//! | `src/firmware/logs.rs` | `RCC_CSR` (read, `RMVF`) | the reset's cause (`reset_record`) | `init` does not clear the reset flags |
//! | `src/firmware/failure.rs` | `GPIOx_MODER`/`BSRR`, `FLASH_ECCR` | the fault path's lamps without the HAL's drivers, the record pages' ECC errors (`fault_path`, `flash_ecc`) | nothing of the HAL's state: these run when the HAL may be mid-operation |

/// The embassy-stm32 version whose source the entries above were checked against.
pub const EMBASSY_STM32_CHECKED: &str = "0.6.0";
