//! The register layer (`drive_monitor::regs`) held to RM0440: every method runs on a
//! memory of the test's own standing behind each peripheral (the layer's [`Bus`]), and the
//! words it wrote are read back at RM0440's addresses and bits, written out here (the
//! peripheral's base from RM0440's memory map, the register's offset and the field's bits
//! from its register description; the Cortex-M4's from the Armv7-M Architecture Reference
//! Manual), never taken from the layer or stm32-metapac. Each write is also checked to
//! touch no other word (a register written by read-modify-write keeps its other bits; a
//! write-only or write-1-to-clear register holds exactly the word written), and each read
//! is answered from that memory. So a wrong block, register, bit or value in the layer
//! fails here; and `src/firmware/*`, which calls the layer, names no register itself
//! ([`the_firmware_files_name_no_register`]).

#![allow(unsafe_code)]

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;

use drive_monitor::board::Lamp;
use drive_monitor::debug_halt::FreezeRegisters;
use drive_monitor::recovery::AdcFlags;
use drive_monitor::regs::{self, Bus, Registers};
use drive_monitor::self_check::{self, registers as table, CheckId, EncoderExpected};
use drive_monitor::watchdog::IwdgSetting;

// RM0440's addresses: the peripherals' bases ("Memory map and register boundary addresses").
const DBGMCU: u32 = 0xE004_2000;
const IWDG: u32 = 0x4000_3000;
const TIM4: u32 = 0x4000_0800;
const DMA1: u32 = 0x4002_0000;
const RCC: u32 = 0x4002_1000;
const FLASH: u32 = 0x4002_2000;
const GPIOA: u32 = 0x4800_0000;
const GPIOB: u32 = 0x4800_0400;
const ADC1: u32 = 0x5000_0000;
const ADC2: u32 = 0x5000_0100;
const ADC12_COMMON: u32 = 0x5000_0300;
/// `VREFINT_CAL`, the factory's calibration half-word in system memory (DS12288).
const VREFINT_CAL: u32 = 0x1FFF_75AA;
// The Cortex-M4's System Control Block (Armv7-M ARM, B3.2.2).
const SCB_CFSR: u32 = 0xE000_ED28;
const SCB_HFSR: u32 = 0xE000_ED2C;
const SCB_BFAR: u32 = 0xE000_ED38;

// The registers' offsets and bits (RM0440's register descriptions).
const DBGMCU_APB1FZR1: u32 = DBGMCU + 0x08;
const DBGMCU_APB2FZR: u32 = DBGMCU + 0x10;
const IWDG_KR: u32 = IWDG;
const IWDG_PR: u32 = IWDG + 0x04;
const IWDG_RLR: u32 = IWDG + 0x08;
const IWDG_SR: u32 = IWDG + 0x0C;
const RCC_CR: u32 = RCC;
const RCC_PLLCFGR: u32 = RCC + 0x0C;
const RCC_CIFR: u32 = RCC + 0x1C;
const RCC_CICR: u32 = RCC + 0x20;
const RCC_CSR: u32 = RCC + 0x94;
const HSEON: u32 = 1 << 16;
const HSERDY: u32 = 1 << 17;
const CSSON: u32 = 1 << 19;
const PLLON: u32 = 1 << 24;
const PLLRDY: u32 = 1 << 25;
const RMVF: u32 = 1 << 23;
const CSSC: u32 = 1 << 8;
const FLASH_ECCR: u32 = FLASH + 0x18;
const FLASH_OPTR: u32 = FLASH + 0x20;
const ECCC: u32 = 1 << 30;
const ECCD: u32 = 1 << 31;
const DBANK: u32 = 1 << 22;
// ADC_x (RM0440, "ADC registers (for each ADC)").
const ADC_ISR: u32 = 0x00;
const ADC_CR: u32 = 0x08;
const ADC_CFGR: u32 = 0x0C;
const ADC_SMPR2: u32 = 0x18;
const ADC_JSQR: u32 = 0x4C;
const ADC_JDR1: u32 = 0x80;
const EOC: u32 = 1 << 2;
const EOS: u32 = 1 << 3;
const OVR: u32 = 1 << 4;
const JEOC: u32 = 1 << 5;
const JEOS: u32 = 1 << 6;
const ADEN: u32 = 1 << 0;
const ADSTART: u32 = 1 << 2;
const JADSTART: u32 = 1 << 3;
const ADVREGEN: u32 = 1 << 28;
const DMAEN: u32 = 1 << 0;
const DMACFG: u32 = 1 << 1;
const ADC12_CCR: u32 = ADC12_COMMON + 0x08;
const VREFEN: u32 = 1 << 22;
// DMA1: ISR, IFCR, then 20 bytes a channel from CCR1 at 0x08 (CCR, CNDTR, CPAR, CMAR).
const DMA_ISR: u32 = DMA1;
const DMA_IFCR: u32 = DMA1 + 0x04;
const fn dma_ccr(channel: u32) -> u32 {
    DMA1 + 0x08 + 20 * (channel - 1)
}
const fn dma_cndtr(channel: u32) -> u32 {
    DMA1 + 0x0C + 20 * (channel - 1)
}
const EN: u32 = 1 << 0;
const TEIE: u32 = 1 << 3;
/// A channel's four flags in `DMA_ISR`/`IFCR`: GIF, TCIF, HTIF, TEIF from bit 4 (channel - 1).
const fn dma_flag(channel: u32, bit: u32) -> u32 {
    1 << (4 * (channel - 1) + bit)
}
const GIF: u32 = 0;
const TCIF: u32 = 1;
const HTIF: u32 = 2;
const TEIF: u32 = 3;
// TIM4 (general-purpose timer).
const TIM4_SMCR: u32 = TIM4 + 0x08;
const TIM4_DIER: u32 = TIM4 + 0x0C;
const TIM4_CCMR1: u32 = TIM4 + 0x18;
const TIM4_CCMR2: u32 = TIM4 + 0x1C;
const TIM4_CCER: u32 = TIM4 + 0x20;
const TIM4_CCR3: u32 = TIM4 + 0x3C;
const CC3DE: u32 = 1 << 11;
// GPIO.
const GPIO_MODER: u32 = 0x00;
const GPIO_BSRR: u32 = 0x18;

/// A sentinel in registers a method must write whole (it shows any write).
const SENTINEL: u32 = 0xDEAD_BEEF;

/// Memory standing behind every peripheral: 4 KiB windows, made when first touched.
struct Memory {
    windows: RefCell<BTreeMap<u32, *mut [u32; 1024]>>,
}

impl Memory {
    fn new() -> Self {
        Memory {
            windows: RefCell::new(BTreeMap::new()),
        }
    }

    /// The memory at `address` (its window made if needed).
    fn ptr(&self, address: u32) -> *mut u8 {
        let base = address & !0xFFF;
        let window = *self
            .windows
            .borrow_mut()
            .entry(base)
            .or_insert_with(|| Box::into_raw(Box::new([0u32; 1024])));
        // SAFETY: `address - base` is within the 4 KiB window.
        unsafe { window.cast::<u8>().add((address - base) as usize) }
    }

    fn word(&self, address: u32) -> u32 {
        // SAFETY: an aligned word of a window.
        unsafe { self.ptr(address).cast::<u32>().read_volatile() }
    }

    fn set(&self, address: u32, value: u32) {
        // SAFETY: as `word`.
        unsafe { self.ptr(address).cast::<u32>().write_volatile(value) }
    }

    /// Every word of every window, by address.
    fn words(&self) -> BTreeMap<u32, u32> {
        let bases: Vec<u32> = self.windows.borrow().keys().copied().collect();
        bases
            .into_iter()
            .flat_map(|b| (0..1024).map(move |i| b + 4 * i))
            .map(|a| (a, self.word(a)))
            .collect()
    }

    /// The words `f` changed: (address, before, after).
    fn changes(&self, f: impl FnOnce()) -> Vec<(u32, u32, u32)> {
        let before = self.words();
        f();
        let after = self.words();
        after
            .iter()
            .filter(|(a, v)| before.get(a).copied().unwrap_or(0) != **v)
            .map(|(a, v)| (*a, before.get(a).copied().unwrap_or(0), *v))
            .collect()
    }

    /// The address a pointer into the windows stands for.
    fn address_of(&self, p: *const ()) -> Option<u32> {
        let p = p as usize;
        self.windows.borrow().iter().find_map(|(base, w)| {
            let start = *w as usize;
            (start..start + 4096)
                .contains(&p)
                .then(|| base + (p - start) as u32)
        })
    }
}

impl Drop for Memory {
    fn drop(&mut self) {
        for w in self.windows.borrow().values() {
            // SAFETY: each window came from `Box::into_raw`, freed once.
            drop(unsafe { Box::from_raw(*w) });
        }
    }
}

// SAFETY: every address gets a 4 KiB window from its 4 KiB boundary, which holds any of the
// STM32G474's register blocks the layer asks for; the windows live as long as the memory.
unsafe impl Bus for &Memory {
    fn at(self, address: usize) -> *mut () {
        self.ptr(address as u32).cast()
    }
}

fn layer(mem: &Memory) -> Registers<&Memory> {
    Registers::new(mem)
}

/// `f` on a fresh memory prepared by `prepare` (address, value) changes exactly `want`
/// (address, value after).
#[track_caller]
fn writes(prepare: &[(u32, u32)], f: impl FnOnce(Registers<&Memory>), want: &[(u32, u32)]) {
    let mem = Memory::new();
    for &(a, v) in prepare {
        mem.set(a, v);
    }
    let changed: Vec<(u32, u32)> = mem
        .changes(|| f(layer(&mem)))
        .into_iter()
        .map(|(a, _, v)| (a, v))
        .collect();
    let want: Vec<(u32, u32)> = want.to_vec();
    let hex = |v: &[(u32, u32)]| {
        v.iter()
            .map(|(a, v)| format!("{a:#010x}={v:#010x}"))
            .collect::<Vec<_>>()
    };
    assert_eq!(hex(&changed), hex(&want));
}

/// `f` reads `want` from a memory holding `prepared`.
#[track_caller]
fn reads<T: PartialEq + std::fmt::Debug>(
    prepared: &[(u32, u32)],
    f: impl FnOnce(Registers<&Memory>) -> T,
    want: T,
) {
    let mem = Memory::new();
    for &(a, v) in prepared {
        mem.set(a, v);
    }
    let got = mem.changes(|| assert_eq!(f(layer(&mem)), want));
    assert!(got.is_empty(), "a read wrote: {got:x?}");
}

#[test]
fn the_starts_registers_are_rm0440s() {
    // The debug freeze: both registers read and written whole.
    reads(
        &[
            (DBGMCU_APB1FZR1, 0x1234_5678),
            (DBGMCU_APB2FZR, 0x0001_0800),
        ],
        |r| r.read_freeze(),
        FreezeRegisters {
            apb1fzr1: 0x1234_5678,
            apb2fzr: 0x0001_0800,
        },
    );
    writes(
        &[],
        |r| {
            r.write_freeze(FreezeRegisters {
                apb1fzr1: 1 << 12,
                apb2fzr: 1 << 11 | 1 << 16,
            })
        },
        &[
            (DBGMCU_APB1FZR1, 1 << 12),
            (DBGMCU_APB2FZR, 1 << 11 | 1 << 16),
        ],
    );
    // The watchdog: its keys into KR, the prescaler and the reload, the update flags.
    for key in [0xCCCC, 0x5555, 0xAAAA] {
        writes(
            &[(IWDG_KR, SENTINEL)],
            |r| r.iwdg_key(key),
            &[(IWDG_KR, u32::from(key))],
        );
    }
    writes(
        &[(IWDG_PR, SENTINEL), (IWDG_RLR, SENTINEL)],
        |r| r.iwdg_setting(IwdgSetting { pr: 3, rlr: 0x0ABC }),
        &[(IWDG_PR, 3), (IWDG_RLR, 0x0ABC)],
    );
    for (sr, updating) in [(0, false), (0b001, true), (0b010, true), (0b100, false)] {
        reads(&[(IWDG_SR, sr)], |r| r.iwdg_updating(), updating);
    }
    // The reset flags and their clear.
    reads(&[(RCC_CSR, 0x2400_0000)], |r| r.reset_flags(), 0x2400_0000);
    writes(
        &[(RCC_CSR, 0x0C00_0001)],
        |r| r.clear_reset_flags(),
        &[(RCC_CSR, 0x0C00_0001 | RMVF)],
    );
    // RCC_CR: each bit alone, the others (HSION, HSIRDY) kept.
    let cr = 0x0000_0500;
    type Set = for<'a> fn(Registers<&'a Memory>, bool);
    let bits: [(u32, Set); 3] = [
        (HSEON, |r, on| r.hse_on(on)),
        (PLLON, |r, on| r.pll_on(on)),
        (CSSON, |r, on| r.set_css(on)),
    ];
    for (on, f) in bits {
        writes(&[(RCC_CR, cr)], |r| f(r, true), &[(RCC_CR, cr | on)]);
        writes(&[(RCC_CR, cr | on)], |r| f(r, false), &[(RCC_CR, cr)]);
    }
    type Get = for<'a> fn(Registers<&'a Memory>) -> bool;
    let flags: [(u32, Get); 2] = [(HSERDY, |r| r.hse_ready()), (PLLRDY, |r| r.pll_ready())];
    for (ready, f) in flags {
        reads(&[(RCC_CR, !ready)], f, false);
        reads(&[(RCC_CR, ready)], f, true);
    }
    writes(
        &[(RCC_PLLCFGR, SENTINEL)],
        |r| r.pll_configure(0x0100_5533),
        &[(RCC_PLLCFGR, 0x0100_5533)],
    );
    // The self-check's reads: the word at the address asked for.
    reads(
        &[(FLASH_OPTR, 0xFFEF_F8AA)],
        |r| r.read_word(FLASH_OPTR),
        0xFFEF_F8AA,
    );
    reads(&[(TIM4_CCER, 0x111)], |r| r.read_word(TIM4_CCER), 0x111);
}

#[test]
fn the_supplys_registers_are_rm0440s() {
    reads(&[(FLASH_OPTR, 0xFFEF_F8AA)], |r| r.optr(), 0xFFEF_F8AA);
    reads(&[(FLASH_OPTR, !DBANK)], |r| r.dual_bank(), false);
    reads(&[(FLASH_OPTR, DBANK)], |r| r.dual_bank(), true);
    // VREFINT (ADC1_IN18): SMP18 in SMPR2's bits 26:24 = 110 (247.5 cycles), the other
    // channels' fields kept; JSQR: JL = 0 (one conversion), JEXTEN = 00 (software), JSQ1 =
    // 18 in bits 13:9, the rest 0.
    writes(
        &[
            (ADC1 + ADC_SMPR2, 0x0000_0249),
            (ADC1 + ADC_JSQR, 0xFFFF_FFFF),
        ],
        |r| r.configure_reference(),
        &[
            (ADC1 + ADC_SMPR2, 0x0000_0249 | 0b110 << 24),
            (ADC1 + ADC_JSQR, 18 << 9),
        ],
    );
    // The calibration half-word at 0x1FFF_75AA (the upper half of the word at ..A8).
    reads(
        &[(VREFINT_CAL - 2, 0x0677_1111)],
        |r| r.vrefint_calibration(),
        0x0677,
    );
    writes(
        &[(ADC12_CCR, 0b0010 << 18)],
        |r| r.vrefint_enable(),
        &[(ADC12_CCR, 0b0010 << 18 | VREFEN)],
    );
    // JADSTART written alone: ADEN and ADSTART (set-only) not written back, ADVREGEN kept.
    writes(
        &[(ADC1 + ADC_CR, ADVREGEN | ADSTART | ADEN)],
        |r| r.start_injected(),
        &[(ADC1 + ADC_CR, ADVREGEN | JADSTART)],
    );
    // The injected result: nothing before JEOS; then JDR1, and JEOS | JEOC written (1 clears).
    reads(
        &[(ADC1 + ADC_ISR, !JEOS), (ADC1 + ADC_JDR1, 0x5DC)],
        |r| r.injected_result(),
        None,
    );
    let mem = Memory::new();
    mem.set(ADC1 + ADC_ISR, JEOS | JEOC | EOC);
    mem.set(ADC1 + ADC_JDR1, 0x5DC);
    assert_eq!(layer(&mem).injected_result(), Some(0x5DC));
    assert_eq!(mem.word(ADC1 + ADC_ISR), JEOS | JEOC);
    // ADC2's registers are not ADC1's.
    assert_eq!(mem.word(ADC2 + ADC_ISR), 0);
}

#[test]
fn the_acquisitions_adc_registers_are_rm0440s() {
    for (i, base, other) in [(0, ADC1, ADC2), (1, ADC2, ADC1)] {
        reads(
            &[(base + ADC_ISR, OVR), (other + ADC_ISR, !0)],
            |r| r.adc_flags(i),
            AdcFlags {
                ovr: true,
                eoc: false,
                eos: false,
            },
        );
        // Each flag alone, and every bit but it.
        for (flag, eoc) in [(EOC, true), (EOS, false)] {
            let alone = AdcFlags {
                ovr: false,
                eoc,
                eos: !eoc,
            };
            reads(&[(base + ADC_ISR, flag)], |r| r.adc_flags(i), alone);
            let others = AdcFlags {
                ovr: true,
                eoc: !eoc,
                eos: eoc,
            };
            reads(&[(base + ADC_ISR, !flag)], |r| r.adc_flags(i), others);
        }
        let all = AdcFlags {
            ovr: true,
            eoc: true,
            eos: true,
        };
        writes(
            &[(base + ADC_ISR, SENTINEL)],
            |r| r.adc_clear(i, all),
            &[(base + ADC_ISR, OVR | EOC | EOS)],
        );
        let ovr = AdcFlags {
            ovr: true,
            eoc: false,
            eos: false,
        };
        writes(
            &[(base + ADC_ISR, SENTINEL)],
            |r| r.adc_clear(i, ovr),
            &[(base + ADC_ISR, OVR)],
        );
        reads(
            &[(base + ADC_CR, 0x1000_0005)],
            |r| r.adc_cr(i),
            0x1000_0005,
        );
        writes(
            &[(base + ADC_CR, SENTINEL)],
            |r| r.adc_cr_write(i, ADVREGEN | ADSTART),
            &[(base + ADC_CR, ADVREGEN | ADSTART)],
        );
        let cfgr = 0x8000_3000;
        writes(
            &[(base + ADC_CFGR, cfgr)],
            |r| r.adc_dma_circular(i),
            &[(base + ADC_CFGR, cfgr | DMAEN | DMACFG)],
        );
        writes(
            &[(base + ADC_CFGR, cfgr | DMAEN | DMACFG)],
            |r| r.adc_dma_off(i),
            &[(base + ADC_CFGR, cfgr | DMACFG)],
        );
    }
    // PRESC in ADC12_CCR's bits 21:18.
    reads(
        &[(ADC12_CCR, 0b0010 << 18 | VREFEN | 0b11 << 16)],
        |r| r.adc_prescaler(),
        0b0010,
    );
    // The regular conversions' sampling time, 24.5 cycles: SMP = 011, 49 half cycles in the
    // acquisition's geometry; VREFINT's 247.5: 110.
    assert_eq!(regs::acquisition::SAMPLE_TIME.to_bits(), 0b011);
    assert_eq!(drive_monitor::acquisition::SAMPLE_TIME_HALF_CYCLES, 49);
    assert_eq!(regs::supply::VREFINT_SAMPLE_TIME.to_bits(), 0b110);
}

#[test]
fn the_acquisitions_dma_registers_are_rm0440s() {
    // ADC1's ring on DMA1 channel 1, ADC2's on channel 2, the latch's on channel 3.
    for (i, ch, other) in [(0, 1, 2), (1, 2, 1)] {
        reads(&[(DMA_ISR, dma_flag(ch, TEIF))], |r| r.dma_error(i), true);
        reads(&[(DMA_ISR, !dma_flag(ch, TEIF))], |r| r.dma_error(i), false);
        reads(
            &[(DMA_ISR, dma_flag(other, TEIF))],
            |r| r.dma_error(i),
            false,
        );
        let every =
            dma_flag(ch, GIF) | dma_flag(ch, TCIF) | dma_flag(ch, HTIF) | dma_flag(ch, TEIF);
        writes(
            &[(DMA_IFCR, SENTINEL)],
            |r| r.dma_clear(i),
            &[(DMA_IFCR, every)],
        );
        reads(&[(dma_ccr(ch), EN)], |r| r.dma_enabled(i), true);
        reads(
            &[(dma_ccr(ch), !EN), (dma_ccr(other), EN)],
            |r| r.dma_enabled(i),
            false,
        );
        writes(
            &[(dma_cndtr(ch), SENTINEL)],
            |r| r.dma_reload(i, 48),
            &[(dma_cndtr(ch), 48)],
        );
        writes(
            &[(dma_ccr(ch), 0xA6)],
            |r| r.dma_enable(i),
            &[(dma_ccr(ch), 0xA7)],
        );
    }
    let latch = 3;
    reads(&[(dma_ccr(latch), EN)], |r| r.latch_enabled(), true);
    reads(
        &[(dma_ccr(latch), !EN), (dma_ccr(1), EN)],
        |r| r.latch_enabled(),
        false,
    );
    writes(
        &[(DMA_IFCR, SENTINEL)],
        |r| r.latch_clear(),
        &[(DMA_IFCR, 0xF << 8)],
    );
    writes(
        &[(dma_cndtr(latch), SENTINEL)],
        |r| r.latch_reload(48),
        &[(dma_cndtr(latch), 48)],
    );
    writes(
        &[(dma_ccr(latch), 0xA6)],
        |r| r.latch_enable(),
        &[(dma_ccr(latch), 0xA7)],
    );
    writes(
        &[(TIM4_DIER, 0x41)],
        |r| r.latch_request(true),
        &[(TIM4_DIER, 0x41 | CC3DE)],
    );
    writes(
        &[(TIM4_DIER, 0x41 | CC3DE)],
        |r| r.latch_request(false),
        &[(TIM4_DIER, 0x41)],
    );
    // TEIE off on channels 1, 2 and 3, their other bits kept; channel 4 untouched.
    writes(
        &[
            (dma_ccr(1), 0xAF),
            (dma_ccr(2), 0xAF),
            (dma_ccr(3), 0x0F),
            (dma_ccr(4), 0x0F),
        ],
        |r| r.dma_errors_masked(),
        &[
            (dma_ccr(1), 0xAF & !TEIE),
            (dma_ccr(2), 0xAF & !TEIE),
            (dma_ccr(3), 0x0F & !TEIE),
        ],
    );
    // The DMA interrupt's first look and its acknowledgement, by register channel index.
    for n in 0..3u32 {
        let ch = n + 1;
        reads(
            &[(DMA_ISR, dma_flag(ch, TEIF))],
            |r| r.dma_channel_error(n as usize),
            true,
        );
        reads(
            &[(DMA_ISR, !dma_flag(ch, TEIF))],
            |r| r.dma_channel_error(n as usize),
            false,
        );
        writes(
            &[(DMA_IFCR, SENTINEL)],
            |r| r.dma_acknowledge_transfers(n as usize),
            &[(DMA_IFCR, dma_flag(ch, HTIF) | dma_flag(ch, TCIF))],
        );
    }
}

/// The encoder's set-up on the registers `Qei::new` leaves (SMS = 0011, CC1S = CC2S =
/// 01, CC1E and CC2E), with stray bits where the layer must clear: the record's filter and
/// direction, TS = ITR0, CC3S = TRC, CC3E, CC3P clear, CC3DE; and what the self-check
/// expects of them holds.
#[test]
fn the_encoders_registers_are_rm0440s() {
    let qei = [
        (TIM4_SMCR, 0b0011 | 0b111 << 4),
        (TIM4_CCMR1, 0x0101),
        (TIM4_CCMR2, 0x0000),
        (TIM4_CCER, 0x0011 | 1 << 9),
        (TIM4_DIER, 0x0000),
    ];
    writes(
        &qei,
        |r| r.encoder_setup(6, true),
        &[
            (TIM4_SMCR, 0b0011),
            (TIM4_DIER, CC3DE),
            (TIM4_CCMR1, 0x0101 | 6 << 4 | 6 << 12),
            (TIM4_CCMR2, 0b11),
            (TIM4_CCER, 0x0011 | 1 << 1 | 1 << 8),
        ],
    );
    let mem = Memory::new();
    for (a, v) in qei {
        mem.set(a, v);
    }
    mem.set(ADC12_CCR, 0b0010 << 18 | VREFEN);
    layer(&mem).encoder_setup(11, false);
    assert_eq!(mem.word(TIM4_CCMR1), 0x0101 | 11 << 4 | 11 << 12);
    assert_eq!(mem.word(TIM4_CCER), 0x0011 | 1 << 8);
    let expected = self_check::expectation(
        drive_monitor::clock::ClockSource::Hse,
        Some(EncoderExpected {
            filter: 11,
            invert_a: false,
        }),
    );
    let found = self_check::run(&CheckId::ACQUISITION, &expected, |a| mem.word(a));
    assert!(
        found.is_clean(),
        "{:?}",
        found.mismatched().collect::<Vec<_>>()
    );
    // The latch's DMA source is TIM4_CCR3.
    let source = layer(&mem).latch_source();
    assert_eq!(mem.address_of(source.cast()), Some(TIM4_CCR3));
}

#[test]
fn the_fault_paths_registers_are_rm0440s() {
    // The lamps: each lamp's pin an output (MODER's two bits 01), the others kept; one
    // BSRR write a port, the lit lamps' set bits, the dark lamps' reset bits (bit + 16).
    let lit = [Lamp::R1, Lamp::Fault];
    let moder_a = 0xABFF_FFFF; // GPIOA's reset value
    let moder_b = 0xFFFF_FEBF; // GPIOB's
    let output = |moder: u32, pins: &[u8]| {
        pins.iter()
            .fold(moder, |m, &n| (m & !(0b11 << (2 * n))) | 0b01 << (2 * n))
    };
    // RUN on PA5 (LD2); r1 PB14, r2 PB9, r3 PB10, r4 PB12, FAULT PB13 (the board's table).
    let b_pins = [14, 9, 10, 12, 13];
    // Ports C..G carry no lamp: their registers are not written.
    let others: Vec<(u32, u32)> = (2..7u32)
        .flat_map(|port| {
            let base = GPIOA + 0x400 * port;
            [(base + GPIO_MODER, SENTINEL), (base + GPIO_BSRR, SENTINEL)]
        })
        .collect();
    let prepared: Vec<(u32, u32)> = [
        (GPIOA + GPIO_MODER, moder_a),
        (GPIOA + GPIO_BSRR, SENTINEL),
        (GPIOB + GPIO_MODER, moder_b),
        (GPIOB + GPIO_BSRR, SENTINEL),
    ]
    .into_iter()
    .chain(others)
    .collect();
    writes(
        &prepared,
        |r| r.show_lamps(|l| lit.contains(&l)),
        &[
            (GPIOA + GPIO_MODER, output(moder_a, &[5])),
            (GPIOA + GPIO_BSRR, 1 << (5 + 16)),
            (GPIOB + GPIO_MODER, output(moder_b, &b_pins)),
            (
                GPIOB + GPIO_BSRR,
                1 << 14 | 1 << 13 | 1 << (9 + 16) | 1 << (10 + 16) | 1 << (12 + 16),
            ),
        ],
    );
    assert_eq!(
        Lamp::ALL.map(|l| (l.pin().port, l.pin().number)),
        [
            (drive_monitor::board::Port::A, 5),
            (drive_monitor::board::Port::B, 14),
            (drive_monitor::board::Port::B, 9),
            (drive_monitor::board::Port::B, 10),
            (drive_monitor::board::Port::B, 12),
            (drive_monitor::board::Port::B, 13),
        ]
    );
    reads(
        &[
            (SCB_CFSR, 0x0000_8200),
            (SCB_HFSR, 0x4000_0000),
            (SCB_BFAR, 0x2002_0000),
        ],
        |r| r.fault_status(),
        regs::fault::FaultStatus {
            cfsr: 0x0000_8200,
            hfsr: 0x4000_0000,
            bfar: 0x2002_0000,
        },
    );
    reads(
        &[(RCC_CIFR, 1 << 8), (FLASH_ECCR, ECCD | 0x3_F800)],
        |r| r.nmi_sources(),
        (1 << 8, ECCD | 0x3_F800),
    );
    writes(
        &[(RCC_CICR, SENTINEL)],
        |r| r.clear_clock_failure(),
        &[(RCC_CICR, CSSC)],
    );
    writes(
        &[(FLASH_ECCR, 1 << 24 | 0x3_F800)],
        |r| r.clear_ecc(),
        &[(FLASH_ECCR, ECCD | ECCC | 1 << 24 | 0x3_F800)],
    );
}

/// The self-check's table, read on this memory at the addresses the layer writes: the freeze
/// the start writes holds its two checks (the table and the layer name the same registers).
#[test]
fn the_self_checks_table_reads_where_the_layer_writes() {
    let mem = Memory::new();
    let r = layer(&mem);
    r.write_freeze(
        drive_monitor::debug_halt::FROZEN.registers_after(FreezeRegisters {
            apb1fzr1: 0,
            apb2fzr: 0,
        }),
    );
    r.set_css(true);
    mem.set(FLASH_OPTR, (0xFFEF_F8AA | 4 << 8) & !(1 << 26));
    let e = self_check::expectation(drive_monitor::clock::ClockSource::Hse, None);
    let found = self_check::run(&CheckId::BOOT, &e, |a| r.read_word(a));
    assert!(
        found.is_clean(),
        "{:?}",
        found.mismatched().collect::<Vec<_>>()
    );
    assert_eq!(table::RCC_CR, RCC_CR);
    assert_eq!(table::FLASH_OPTR, FLASH_OPTR);
}

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `src/firmware/*` reaches the registers only through the layer: no PAC in its code.
#[test]
fn the_firmware_files_name_no_register() {
    let mut files = vec!["src/firmware.rs".to_string()];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/firmware");
    for e in std::fs::read_dir(dir).unwrap() {
        files.push(format!(
            "src/firmware/{}",
            e.unwrap().file_name().to_string_lossy()
        ));
    }
    assert!(files.len() >= 12, "{files:?}");
    let mut found = Vec::new();
    for f in &files {
        for (n, line) in read(f).lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains("pac::") || code.contains("metapac") || code.contains(" pac,") {
                found.push(format!("{f}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "registers named outside the layer: {found:#?}"
    );
}

/// The stack's bottom is `memory.x`'s RAM origin.
#[test]
fn the_ram_start_is_the_memory_maps() {
    let memory_x = read("memory.x");
    let ram = memory_x
        .lines()
        .find(|l| l.trim_start().starts_with("RAM"))
        .expect("a RAM line in memory.x");
    let origin = ram
        .split("ORIGIN = ")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap();
    let origin = u32::from_str_radix(origin.trim().trim_start_matches("0x"), 16).unwrap();
    assert_eq!(drive_monitor::stack::RAM_START, origin);
    assert_eq!(origin, 0x2000_0000);
}

/// On the board the bus is the MCU's own addresses: `McuBus` hands back each address as it
/// is (not dereferenced here), so `MCU`'s blocks are the peripherals RM0440 places there.
#[test]
fn the_boards_bus_is_the_mcus_own_addresses() {
    for address in [
        RCC,
        FLASH,
        DMA1,
        TIM4,
        ADC1,
        ADC12_COMMON,
        GPIOB,
        DBGMCU,
        IWDG,
    ] {
        assert_eq!(regs::McuBus.at(address as usize) as usize, address as usize);
    }
}
