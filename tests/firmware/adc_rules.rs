//! The set-up of the ADC pair (`drive_monitor::adc_rules::create_pair`) on a model of
//! ADC1/ADC2 and their common register: embassy-stm32 0.6's `Adc::new` writes the common
//! prescaler (`ADC12_CCR.PRESC`) and enables its ADC; RM0440 allows the write only while
//! both ADCs of the pair are disabled. The model flags a prescaler write with an ADC
//! enabled, an `ADC_CR` write that carries more than one set-only bit (a read-modify-write)
//! or clears the regulator, and `ADDIS` on a disabled or converting ADC.

use drive_monitor::adc_rules::{create_pair, AdcPairSetup, PairError};

const ADEN: u32 = 1;
const ADDIS: u32 = 1 << 1;
const ADSTART: u32 = 1 << 2;
const JADSTART: u32 = 1 << 3;
const ADVREGEN: u32 = 1 << 28;
const SET_ONLY: u32 = 0b11_1111 | (1 << 31);
/// `PRESC` for /4 (RM0440: 0010).
const PRESC_DIV4: u32 = 0b0010;

#[derive(Default)]
struct Pair {
    enabled: [bool; 2],
    presc: u32,
    /// A broken ADC1 that never disables.
    stuck: bool,
    /// The prescaler another writer left (read back instead of the HAL's).
    overwritten: Option<u32>,
    /// An ADC1 its `create` leaves disabled.
    left_disabled: bool,
    /// An ADC1 found converting (`ADSTART = 1`) after its `create`.
    converting: bool,
    violations: Vec<String>,
}

impl AdcPairSetup for Pair {
    fn create(&mut self, i: usize) {
        if let Some(j) = self.enabled.iter().position(|&e| e) {
            self.violations.push(format!(
                "PRESC written by ADC{}'s set-up while ADC{} is enabled",
                i + 1,
                j + 1
            ));
        }
        self.presc = PRESC_DIV4;
        self.enabled[i] = !(i == 0 && self.left_disabled);
    }
    fn cr(&mut self, i: usize) -> u32 {
        let adstart = if i == 0 && self.converting {
            ADSTART
        } else {
            0
        };
        ADVREGEN | adstart | if self.enabled[i] { ADEN } else { 0 }
    }
    fn write_cr(&mut self, i: usize, value: u32) {
        if (value & SET_ONLY).count_ones() > 1 {
            self.violations
                .push(format!("ADC{}_CR read-modify-write", i + 1));
        }
        if value & ADVREGEN == 0 {
            self.violations
                .push(format!("ADC{}_CR: ADVREGEN cleared", i + 1));
        }
        if value & ADDIS != 0 {
            let converting = i == 0 && self.converting;
            if !self.enabled[i] || converting || value & (ADSTART | JADSTART) != 0 {
                self.violations
                    .push(format!("ADDIS on ADC{} not allowed", i + 1));
            }
            if !self.stuck {
                self.enabled[i] = false;
            }
        }
    }
    fn prescaler(&mut self) -> u32 {
        self.overwritten.unwrap_or(self.presc)
    }
}

/// Both `Adc::new` calls write the prescaler with both ADCs disabled (ADC1 disabled in
/// between, with `ADDIS` alone), and the prescaler is read back as the clock's.
#[test]
fn the_common_prescaler_is_written_with_both_adcs_disabled_and_read_back() {
    let mut pair = Pair::default();
    assert_eq!(create_pair(&mut pair), Ok(()));
    assert!(pair.violations.is_empty(), "{:?}", pair.violations);
    assert_eq!(pair.enabled, [false, true]);

    // The firmware's former order (ADC1 left enabled) breaks the rule: the model sees it.
    let mut former = Pair::default();
    former.create(0);
    former.create(1);
    assert_eq!(former.violations.len(), 1, "{:?}", former.violations);

    // A prescaler that is not the clock's is reported; an ADC1 that never disables too.
    let mut other = Pair {
        overwritten: Some(0b0001),
        ..Pair::default()
    };
    assert_eq!(create_pair(&mut other), Err(PairError::Prescaler(0b0001)));
    let mut stuck = Pair {
        stuck: true,
        ..Pair::default()
    };
    assert_eq!(create_pair(&mut stuck), Err(PairError::NotDisabled));
}

/// RM0440: software sets `ADDIS` only with `ADEN = 1` and no conversion ongoing (`ADSTART =
/// 0`, `JADSTART = 0`). An ADC1 already disabled is left so and the set-up goes on; an ADC1
/// found converting gets no `ADDIS`, stays enabled, and the set-up reports it.
#[test]
fn addis_is_written_only_to_an_enabled_adc1_that_is_not_converting() {
    let mut disabled = Pair {
        left_disabled: true,
        ..Pair::default()
    };
    assert_eq!(create_pair(&mut disabled), Ok(()));
    assert!(disabled.violations.is_empty(), "{:?}", disabled.violations);

    let mut converting = Pair {
        converting: true,
        ..Pair::default()
    };
    assert_eq!(create_pair(&mut converting), Err(PairError::NotDisabled));
    assert!(
        converting.violations.is_empty(),
        "{:?}",
        converting.violations
    );
}
