//! The board: analog front-end scaling, encoder, sample rate and the pin map.
//!
//! Everything that depends on how the NUCLEO-G474RE is wired to the drive lives in this
//! one file. The scaling part is plain arithmetic and builds on the host (it is tested
//! there); the pin assignment at the bottom only exists for `target_os = "none"`.
//!
//! # Analog front end (default: isolated measurement board)
//!
//! Each of the six channels is an isolated amplifier whose output spans the STM32's
//! 0..3.3 V ADC input range linearly:
//!
//! | quantity | range at the motor | ADC input | code |
//! |---|---|---|---|
//! | phase-to-neutral voltage `va, vb, vc` | -400 V .. +400 V | 0 .. 3.3 V | 0 .. 4095 |
//! | phase current `ia, ib, ic` | -10 A .. +10 A | 0 .. 3.3 V | 0 .. 4095 |
//!
//! So zero volts / zero amperes sit at mid-scale, code 2047.5, and
//! `x = (code - offset) * PER_LSB`. The constants below derive the factors from these
//! ranges; change the ranges here (and only here) for another front end. Codes 0 and
//! 4095 mean the input is at or beyond the rail: the true value is unknown. Such a code,
//! or any conversion beyond its channel's linear range, makes the sample **clipped**: the
//! core holds it out and names no sensor (`acquisition::sum_clipped`,
//! `crate::sampling::RawFrame::clips`); clipping that persists in steady running is the
//! range state (`crate::clip_watch`).
//!
//! # Pin map (NUCLEO-G474RE, Arduino/Morpho headers)
//!
//! | function | pin | peripheral | notes |
//! |---|---|---|---|
//! | `va` | PA0 (A0) | ADC1_IN1 | ADC1 rank 1 |
//! | `vb` | PA1 (A1) | ADC1_IN2 | ADC1 rank 2 |
//! | `vc` | PC0 (A5) | ADC1_IN6 | ADC1 rank 3 |
//! | `ia` | PC1 (A4) | ADC2_IN7 | ADC2 rank 1, converted together with `va` |
//! | `ib` | PC2 (CN7-35) | ADC2_IN8 | ADC2 rank 2, together with `vb` |
//! | `ic` | PC3 (CN7-37) | ADC2_IN9 | ADC2 rank 3, together with `vc` |
//! | encoder A / B | PB6 / PB7 | TIM4_CH1 / TIM4_CH2 | quadrature x4, 1024 lines |
//! | sample trigger | (internal) | TIM1 TRGO | both ADCs, rising edge |
//! | RUN lamp | PA5 | LD2 (green, on board) | [`Lamp::Run`] |
//! | r1 lamp | PB14 | GPIO out | [`Lamp::R1`] (not PB8: that is BOOT0) |
//! | r2 lamp | PB9 | GPIO out | [`Lamp::R2`] |
//! | r3 lamp | PB10 | GPIO out | [`Lamp::R3`] |
//! | r4 lamp | PB12 | GPIO out | [`Lamp::R4`] |
//! | FAULT lamp | PB13 | GPIO out | [`Lamp::Fault`], also blinks the top candidate |
//! | commissioning button | PC13 | B1 (blue, on board), EXTI13 | pressed = high (pull-down) |
//! | defmt log | SWD (ST-LINK) | RTT | |
//! | boot report | PA2 | USART2 TX | the ST-LINK's virtual COM port, 115 200 8N1 |
//!
//! The lamp rows repeat the lamp table below (`panel_lamps!`, the one definition of each
//! lamp's pin, label and meaning, from which [`Lamp`], the firmware's lamp pins and the
//! panic handler's pins are generated); a test (`tests/firmware/panel_docs.rs`) checks that these
//! rows and docs/firmware.md's pin map agree with it. The LEDs other than LD2 are external:
//! pin -> 330 ohm -> LED anode, cathode to GND (about 4 mA at 3.3 V). The commissioning
//! record lives in the last 2 KiB flash page, see [`RECORD_FLASH_OFFSET`].

/// Resolution of the STM32G4 ADC in bits (12-bit mode).
pub const ADC_BITS: u32 = 12;
/// Largest ADC code: `2^ADC_BITS - 1 = 4095`.
pub const ADC_MAX_CODE: u16 = (1 << ADC_BITS) - 1;
/// ADC reference voltage on the NUCLEO-G474RE (VREF+ tied to VDDA = 3.3 V).
pub const ADC_VREF_V: f32 = 3.3;
/// Code of a zero-volt / zero-ampere input for a bipolar front end that maps
/// `-full_scale..+full_scale` onto `0..ADC_MAX_CODE`: `4095 / 2 = 2047.5`.
pub const MID_SCALE_CODE: f32 = ADC_MAX_CODE as f32 / 2.0;

/// Full-scale phase voltage of the voltage channels, volts (the front end maps
/// `-VOLTAGE_FULL_SCALE_V..+VOLTAGE_FULL_SCALE_V` onto 0..3.3 V).
pub const VOLTAGE_FULL_SCALE_V: f32 = 400.0;
/// Full-scale phase current of the current channels, amperes.
pub const CURRENT_FULL_SCALE_A: f32 = 10.0;

/// The core's sensor limits on the board (`MonitorConfig::limits`, `v_max` and `i_max`) over
/// the front end's full scale: 2.5. A reading from a 12-bit code lies at most 4095 codes
/// from its channel's zero (twice the full scale) times the reference's correction (at most
/// 1.1, `app::SamplePath::set_reference_gain`): 2.2 times the full scale, so no finite
/// reading is ever out of the core's range. A reading at or beyond the front end's linear
/// range is a clip, which the per-conversion check flags and the core holds out without
/// naming a sensor (`acquisition::sum_clipped`, `crate::clip_watch`); with the limits at the
/// full scale, a rail code read through a start-up offset trim or the reference's
/// correction (10.2 A on the 10 A front end) named the current sensor at every
/// direct-on-line start.
pub const LIMIT_OVER_FULL_SCALE: f32 = 2.5;

/// Volts at the motor per ADC code: `2 * 400 V / 4095 LSB = 0.195 36 V/LSB`.
pub const VOLT_PER_LSB: f32 = 2.0 * VOLTAGE_FULL_SCALE_V / ADC_MAX_CODE as f32;
/// Amperes at the motor per ADC code: `2 * 10 A / 4095 LSB = 4.884 mA/LSB`.
pub const AMP_PER_LSB: f32 = 2.0 * CURRENT_FULL_SCALE_A / ADC_MAX_CODE as f32;

/// The isolated amplifier's output headroom [ADC codes]: its output stage is linear only
/// up to about 50 mV from its supply rails (a rail-to-rail output stage's swing; check the
/// part fitted), 62 codes at 3.3 V / 4095. A conversion within it of the record's full
/// scale counts as clipped (`motor_source::linear_ranges`): an isolated amplifier clips
/// before the ADC's rail.
pub const AMPLIFIER_HEADROOM_CODES: f32 = 62.0;

/// Sample (trigger) rate of the six channels by default, hertz.
pub const DEFAULT_SAMPLE_RATE_HZ: u32 = 10_000;
/// Encoder lines per mechanical revolution.
pub const ENCODER_LINES: u32 = 1024;
/// Encoder counts per mechanical revolution with x4 quadrature decoding:
/// `4 * 1024 = 4096`.
pub const ENCODER_COUNTS_PER_REV: u32 = 4 * ENCODER_LINES;

/// Kernel clock of the encoder timer TIM4, Hz: the APB1 timer clock
/// ([`crate::clock::TIMER_HZ`], 170 MHz).
pub const ENCODER_TIMER_HZ: u32 = crate::clock::TIMER_HZ;

/// Length of the timer input filter `ICxF = 0..=15` in timer clocks, with `f_DTS = f_CK_INT`
/// (`CKD = 0`): `N` consecutive equal samples at `f_SAMPLING` (STM32G4 reference manual
/// RM0440, `TIMx_CCMR1_Input`, `IC1F`): 0, fCK_INT x 2/4/8, fDTS/2 x 6/8, fDTS/4 x 6/8,
/// fDTS/8 x 6/8, fDTS/16 x 5/6/8, fDTS/32 x 5/6/8.
pub const INPUT_FILTER_CLOCKS: [u32; 16] = [
    0, 2, 4, 8, 12, 16, 24, 32, 48, 64, 80, 96, 128, 160, 192, 256,
];

/// The encoder inputs' filter setting `ICxF` (0..=15): the longest filter whose delay is at
/// most a quarter of the shortest time between two quadrature edges, `1 / (4 x lines x
/// max_rev_per_s)`, on a timer clocked at `timer_hz`. A longer filter would swallow real
/// edges at `max_rev_per_s`; this one rejects any glitch shorter than its delay. 0 (no
/// filter) when even the shortest is too long or the inputs are not valid.
pub fn encoder_input_filter(lines: u16, max_rev_per_s: f32, timer_hz: u32) -> u8 {
    let edges_per_s = 4.0 * f32::from(lines) * max_rev_per_s;
    if !(edges_per_s > 0.0 && edges_per_s.is_finite()) || timer_hz == 0 {
        return 0;
    }
    let budget_clocks = timer_hz as f32 / edges_per_s / 4.0;
    INPUT_FILTER_CLOCKS
        .iter()
        .rposition(|&n| n as f32 <= budget_clocks)
        .map_or(0, |k| k as u8)
}

/// Offset of the commissioning record's first page from the start of flash (0x0800_0000),
/// bytes: the last 2 KiB page of bank 2 (dual-bank mode), `0x0807_F800`. `memory.x` gives
/// the linker bank 1 alone, so code can never land in bank 2, and writing bank 2 while
/// code runs from bank 1 does not stall instruction fetches.
pub const RECORD_FLASH_OFFSET: u32 = 0x0007_F800;
/// Size of the flash page that holds the record (erase granularity, dual-bank mode).
pub const RECORD_PAGE_SIZE: u32 = 2048;
/// Offset of the motor record (`monitor_core::motor_record`, written by `sim-host
/// board-record`) from the start of flash, bytes: the 2 KiB page before the commissioning
/// record, `0x0807_F000`, also kept out of the linker's reach by `memory.x`.
pub const MOTOR_RECORD_FLASH_OFFSET: u32 = RECORD_FLASH_OFFSET - RECORD_PAGE_SIZE;
/// Offset of the commissioning record's second page (`flash_record::RecordPage::B`: the
/// two copies in turn), bytes: the page before the motor record's, `0x0807_E800`.
pub const RECORD_B_FLASH_OFFSET: u32 = MOTOR_RECORD_FLASH_OFFSET - RECORD_PAGE_SIZE;
/// Offset of the reset log (`reset_record::log`: the counts and the last ends of a run,
/// [`LOG_PAGES`] pages of 2 KiB) from the start of flash, bytes: the pages before the
/// record's second, `0x0807_6800`..`0x0807_E800` for 16, bank 2 like the records.
pub const RESET_LOG_FLASH_OFFSET: u32 = RECORD_B_FLASH_OFFSET - LOG_PAGES * RECORD_PAGE_SIZE;
/// The reset log's pages of 2 KiB (`reset_record::log::PAGES` is this number: the flash
/// map owns it, so the log's pages and the records' cannot disagree).
pub const LOG_PAGES: u32 = 16;
/// The start of bank 2 (dual-bank mode) from the start of flash, bytes: `0x0804_0000`.
/// Everything from here on is data (the records, the reset log), never code.
pub const BANK2_OFFSET: u32 = 0x0004_0000;
// The reset log's pages end where the records begin (the commissioning record's second
// page, then the motor record's, then the first), each page the records' size, all in bank 2:
// raising [`LOG_PAGES`] moves the log down, never over a record (`reset_record::log`
// asserts that its pages are the records' size).
const _: () = assert!(
    RESET_LOG_FLASH_OFFSET + LOG_PAGES * RECORD_PAGE_SIZE == RECORD_B_FLASH_OFFSET
        && RECORD_B_FLASH_OFFSET + RECORD_PAGE_SIZE == MOTOR_RECORD_FLASH_OFFSET
        && MOTOR_RECORD_FLASH_OFFSET + RECORD_PAGE_SIZE == RECORD_FLASH_OFFSET
        && RESET_LOG_FLASH_OFFSET >= BANK2_OFFSET,
    "the reset log's pages must end where the records begin, in bank 2"
);

/// A GPIO port of the STM32G474 (`A` = GPIOA, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Port {
    /// GPIOA.
    A,
    /// GPIOB.
    B,
    /// GPIOC.
    C,
    /// GPIOD.
    D,
    /// GPIOE.
    E,
    /// GPIOF.
    F,
    /// GPIOG.
    G,
}

/// A GPIO pin: port and pin number (0..=15), written `PA5` as in the datasheet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpioPin {
    /// The port.
    pub port: Port,
    /// The pin number within the port, 0..=15.
    pub number: u8,
}

impl GpioPin {
    /// The pin named `name` (`"PA5"`, `"PB12"`: `P`, port letter A..G, number 0..=15), or
    /// `None` for anything else. A `const fn`, so the lamp table's names are checked when
    /// the firmware is compiled.
    pub const fn parse(name: &str) -> Option<GpioPin> {
        let (port, digits) = match name.as_bytes() {
            [b'P', port, digits @ ..] => (*port, digits),
            _ => return None,
        };
        let port = match port {
            b'A' => Port::A,
            b'B' => Port::B,
            b'C' => Port::C,
            b'D' => Port::D,
            b'E' => Port::E,
            b'F' => Port::F,
            b'G' => Port::G,
            _ => return None,
        };
        let number = match digits {
            [d @ b'0'..=b'9'] => *d - b'0',
            [b'1', d @ b'0'..=b'5'] => 10 + (*d - b'0'),
            _ => return None,
        };
        Some(GpioPin { port, number })
    }
}

impl core::fmt::Display for GpioPin {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let port = match self.port {
            Port::A => 'A',
            Port::B => 'B',
            Port::C => 'C',
            Port::D => 'D',
            Port::E => 'E',
            Port::F => 'F',
            Port::G => 'G',
        };
        write!(f, "P{port}{}", self.number)
    }
}

/// Number of panel lamps.
pub const LAMP_COUNT: usize = 6;

/// Generates [`Lamp`] (with its pin, label and meaning) and, for the target, the macro that
/// takes the lamp pins out of the HAL's peripheral set, from one table.
macro_rules! panel_lamps {
    ($($lamp:ident = $index:literal: $pin:ident, $label:literal, $meaning:literal;)*) => {
        /// One lamp of the panel. Its pin, label and meaning are defined once, in the lamp
        /// table of `board.rs`; the patterns it shows are [`crate::panel`]'s.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Lamp {
            $(
                #[doc = $meaning]
                $lamp = $index,
            )*
        }

        impl Lamp {
            /// All lamps, in the order of the panel (RUN, r1..r4, FAULT).
            pub const ALL: [Lamp; LAMP_COUNT] = [$(Lamp::$lamp),*];

            /// The pin that drives the lamp (high = lit).
            pub const fn pin(self) -> GpioPin {
                match self {
                    $(Lamp::$lamp => match GpioPin::parse(stringify!($pin)) {
                        Some(pin) => pin,
                        // Unreachable: `LAMP_PINS_ARE_VALID` rejects a bad name at compile time.
                        None => GpioPin { port: Port::A, number: 0 },
                    },)*
                }
            }

            /// The lamp's name on the panel (`RUN`, `r1`..`r4`, `FAULT`).
            pub const fn label(self) -> &'static str {
                match self {
                    $(Lamp::$lamp => $label,)*
                }
            }

            /// What a lit lamp means (the patterns are in [`crate::panel`]).
            pub const fn meaning(self) -> &'static str {
                match self {
                    $(Lamp::$lamp => $meaning,)*
                }
            }
        }

        /// Every name in the lamp table is a pin (a compile-time check).
        const LAMP_PINS_ARE_VALID: bool = $(GpioPin::parse(stringify!($pin)).is_some() &&)* true;
        const _: () = assert!(LAMP_PINS_ARE_VALID, "a lamp pin in board.rs is not a pin name");

        /// `take_lamp_pins!(p)`: the lamp pins out of `embassy_stm32::Peripherals` `p`, in
        /// [`Lamp::ALL`] order, as `[Peri<'static, AnyPin>; LAMP_COUNT]`.
        #[cfg(target_os = "none")]
        macro_rules! take_lamp_pins {
            ($p:ident) => {
                [$($p.$pin.into()),*]
            };
        }
    };
}

// The lamp table: the one place where a lamp's pin, label and meaning are written.
panel_lamps! {
    Run = 0: PA5, "RUN", "RUN: the monitor is alive; its blink pattern says what it does (LD2 on the board).";
    R1 = 1: PB14, "r1", "r1: residual r1 beyond its threshold.";
    R2 = 2: PB9, "r2", "r2: residual r2 beyond its threshold.";
    R3 = 3: PB10, "r3", "r3: residual r3 beyond its threshold.";
    R4 = 4: PB12, "r4", "r4: residual r4 beyond its threshold.";
    Fault = 5: PB13, "FAULT", "FAULT: a fault detected; blinks the top candidate's code.";
}

impl Lamp {
    /// The residual lamps r1..r4, in residual order.
    pub const RESIDUALS: [Lamp; 4] = [Lamp::R1, Lamp::R2, Lamp::R3, Lamp::R4];
}

/// Raw 12-bit code of a voltage channel, exactly as the ADC wrote it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoltageCode(pub u16);

/// Raw 12-bit code of a current channel, exactly as the ADC wrote it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CurrentCode(pub u16);

/// True when a code sits on a rail (0 or >= 4095): the input is at or beyond the
/// converter's range and the value is not known.
#[inline]
pub const fn is_saturated_code(code: u16) -> bool {
    code == 0 || code >= ADC_MAX_CODE
}

/// Linear map of one channel from ADC code to a physical unit:
/// `x = (code - offset_code) * per_lsb`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelScale {
    /// Code that corresponds to zero (volts or amperes), in LSB (may be fractional).
    pub offset_code: f32,
    /// Physical units per LSB (V/LSB or A/LSB); may be negative for an inverting stage.
    pub per_lsb: f32,
}

impl ChannelScale {
    /// Default voltage channel: zero at mid-scale, [`VOLT_PER_LSB`].
    pub const VOLTAGE: Self = Self {
        offset_code: MID_SCALE_CODE,
        per_lsb: VOLT_PER_LSB,
    };
    /// Default current channel: zero at mid-scale, [`AMP_PER_LSB`].
    pub const CURRENT: Self = Self {
        offset_code: MID_SCALE_CODE,
        per_lsb: AMP_PER_LSB,
    };

    /// Physical value of `code`: `(code - offset_code) * per_lsb`.
    #[inline]
    pub fn apply(&self, code: u16) -> f32 {
        (f32::from(code) - self.offset_code) * self.per_lsb
    }

    /// Nearest ADC code for a physical value, clamped to `0..=4095` (the inverse of
    /// [`apply`](Self::apply); used by the host tests to quantize simulated signals).
    pub fn code_of(&self, value: f32) -> u16 {
        if self.per_lsb == 0.0 || !value.is_finite() {
            return self.offset_code.clamp(0.0, ADC_MAX_CODE as f32) as u16;
        }
        let code = value / self.per_lsb + self.offset_code + 0.5;
        // `as` saturates for out-of-range floats; clamp keeps the 12-bit range.
        code.clamp(0.0, ADC_MAX_CODE as f32) as u16
    }
}

/// Scaling of all six analog channels (per-channel so a measured offset can be trimmed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontEnd {
    /// Phase voltages a, b, c.
    pub voltage: [ChannelScale; 3],
    /// Phase currents a, b, c.
    pub current: [ChannelScale; 3],
}

impl FrontEnd {
    /// The default isolated measurement board (+-400 V, +-10 A onto 0..3.3 V).
    pub const DEFAULT: Self = Self {
        voltage: [ChannelScale::VOLTAGE; 3],
        current: [ChannelScale::CURRENT; 3],
    };
}

impl Default for FrontEnd {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Hardware pin assignment (target only): the single place where pins are chosen.
#[cfg(target_os = "none")]
pub mod pins {
    use super::LAMP_COUNT;
    use embassy_stm32::gpio::AnyPin;
    use embassy_stm32::peripherals as p;
    use embassy_stm32::Peri;

    /// ADC1 scan sequence pins: `va`, `vb`, `vc` (ranks 1..3).
    pub struct VoltagePins {
        /// `va` on PA0.
        pub a: Peri<'static, p::PA0>,
        /// `vb` on PA1.
        pub b: Peri<'static, p::PA1>,
        /// `vc` on PC0.
        pub c: Peri<'static, p::PC0>,
    }

    /// ADC2 scan sequence pins: `ia`, `ib`, `ic` (ranks 1..3).
    pub struct CurrentPins {
        /// `ia` on PC1.
        pub a: Peri<'static, p::PC1>,
        /// `ib` on PC2.
        pub b: Peri<'static, p::PC2>,
        /// `ic` on PC3.
        pub c: Peri<'static, p::PC3>,
    }

    /// All board resources the firmware uses, split out of `embassy_stm32::Peripherals`.
    pub struct Board {
        /// ADC1 (voltages).
        pub adc1: Peri<'static, p::ADC1>,
        /// ADC2 (currents).
        pub adc2: Peri<'static, p::ADC2>,
        /// DMA channel for ADC1's ring buffer.
        pub adc1_dma: Peri<'static, p::DMA1_CH1>,
        /// DMA channel for ADC2's ring buffer.
        pub adc2_dma: Peri<'static, p::DMA1_CH2>,
        /// DMA channel for the encoder latch's ring (TIM4's capture at the trigger).
        pub encoder_dma: Peri<'static, p::DMA1_CH3>,
        /// Sample trigger timer (TRGO on update).
        pub trigger_timer: Peri<'static, p::TIM1>,
        /// Voltage inputs.
        pub voltage: VoltagePins,
        /// Current inputs.
        pub current: CurrentPins,
        /// Encoder timer.
        pub encoder_timer: Peri<'static, p::TIM4>,
        /// Encoder A (TIM4_CH1).
        pub encoder_a: Peri<'static, p::PB6>,
        /// Encoder B (TIM4_CH2).
        pub encoder_b: Peri<'static, p::PB7>,
        /// Panel lamp pins in [`super::Lamp::ALL`] order (the lamp table).
        pub lamps: [Peri<'static, AnyPin>; LAMP_COUNT],
        /// User button B1.
        pub button: Peri<'static, p::PC13>,
        /// EXTI line of the button.
        pub button_exti: Peri<'static, p::EXTI13>,
        /// Flash controller (commissioning record).
        pub flash: Peri<'static, p::FLASH>,
        /// Independent watchdog.
        pub iwdg: Peri<'static, p::IWDG>,
        /// USART2 and its TX pin PA2: the ST-LINK's virtual COM port (the boot report).
        pub vcp: (Peri<'static, p::USART2>, Peri<'static, p::PA2>),
    }

    impl Board {
        /// Take the board's resources out of the HAL's peripheral set.
        pub fn take(p: embassy_stm32::Peripherals) -> Self {
            Self {
                adc1: p.ADC1,
                adc2: p.ADC2,
                adc1_dma: p.DMA1_CH1,
                adc2_dma: p.DMA1_CH2,
                encoder_dma: p.DMA1_CH3,
                trigger_timer: p.TIM1,
                voltage: VoltagePins {
                    a: p.PA0,
                    b: p.PA1,
                    c: p.PC0,
                },
                current: CurrentPins {
                    a: p.PC1,
                    b: p.PC2,
                    c: p.PC3,
                },
                encoder_timer: p.TIM4,
                encoder_a: p.PB6,
                encoder_b: p.PB7,
                lamps: take_lamp_pins!(p),
                button: p.PC13,
                button_exti: p.EXTI13,
                flash: p.FLASH,
                iwdg: p.IWDG,
                vcp: (p.USART2, p.PA2),
            }
        }
    }
}

/// Where a front end's zero (0 V, 0 A) is biased, which decides how a drift of VDDA, the
/// ADC's reference, moves its codes (`app::SamplePath::set_reference_gain`). The signal's
/// swing is the amplifier's own (volts per volt or per ampere, not a share of VDDA) in
/// both: a code is `zero + x / (per_lsb at commissioning) x (VDDA at commissioning / VDDA
/// now)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZeroBias {
    /// The zero is a voltage of its own (an amplifier's reference pin): its code moves
    /// with VDDA too, `zero x VDDA at commissioning / VDDA now`.
    Absolute,
    /// The zero is VDDA / 2 (a divider from VDDA, a mid-supply buffer): its code stays at
    /// the same share of the range whatever VDDA does; only the swing around it scales.
    /// Corrected as an absolute zero, it would move by `zero x drift`: 57 codes (11 V on the
    /// voltage channels) at a 2.8 % drift.
    HalfVdda,
}

/// The board's front end: the zero at VDDA / 2 (the isolated amplifiers' outputs level
/// shifted onto a mid-supply reference from VDDA). A front end whose zero comes from a
/// reference of its own is [`ZeroBias::Absolute`]: change it here.
pub const ZERO_BIAS: ZeroBias = ZeroBias::HalfVdda;

/// VDDA at which the factory measured `VREFINT_CAL` (STM32G474 datasheet: 3.0 V, 30 degC; the
/// calibration word is at 0x1FFF_75AA).
pub const VREFINT_CAL_VDDA_V: f32 = 3.0;

/// The band VDDA must lie in [V]: the NUCLEO's 3.3 V regulator within 3 %. VDDA is the ADC's
/// reference, so every voltage and current reading scales with it: 3.2 V read as 3.3 V is
/// every reading 3 % high.
pub const VDDA_BAND_V: (f32, f32) = (3.2, 3.4);

/// VDDA from a VREFINT reading `code` (12 bits) and the factory's `cal` word:
/// `VDDA = 3.0 V x cal / code` (RM0440, "Calculating the actual VDDA voltage using the
/// internal reference voltage"); `None` for a reading of 0 or at full scale, or a `cal`
/// of 0 or at full scale (no usable figure).
pub fn vdda_from_vrefint(code: u16, cal: u16) -> Option<f32> {
    let ok = |c: u16| c > 0 && c < ADC_MAX_CODE;
    (ok(code) && ok(cal)).then(|| VREFINT_CAL_VDDA_V * f32::from(cal) / f32::from(code))
}

/// What the reference check found at start-up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReferenceCheck {
    /// VDDA in [`VDDA_BAND_V`] [V].
    InBand(f32),
    /// VDDA outside [`VDDA_BAND_V`] [V]: every reading is scaled by `3.3 / VDDA`.
    OutOfBand(f32),
    /// No usable VREFINT reading (0 or full scale, or no calibration word).
    Unreadable,
}

impl ReferenceCheck {
    /// The check of a VREFINT reading `code` against the factory's `cal` word.
    pub fn of(code: u16, cal: u16) -> Self {
        match vdda_from_vrefint(code, cal) {
            Some(v) if (VDDA_BAND_V.0..=VDDA_BAND_V.1).contains(&v) => Self::InBand(v),
            Some(v) => Self::OutOfBand(v),
            None => Self::Unreadable,
        }
    }

    /// The readings cannot be trusted: the sensors count as faulty (the panel's "input
    /// invalid").
    pub fn distrusts_readings(self) -> bool {
        !matches!(self, Self::InBand(_))
    }
}

#[cfg(test)]
mod tests;
