//! The ADC's register rules that embassy-stm32 does not keep for the firmware, written once
//! for the board's registers and the host's register-level model (`tests/sil/recovery`):
//!
//! - **`ADC_CR`'s set-only bits** (RM0440, "ADC control register"; ST's LL masks them as
//!   `ADC_CR_BITS_PROPERTY_RS`): `ADEN`, `ADDIS`, `ADSTART`, `JADSTART`, `ADSTP`, `JADSTP` and
//!   `ADCAL` are set by software and cleared by hardware. A read-modify-write that sets one
//!   of them writes the others back as read: an `ADSTART` read as 1 and written back while
//!   `ADSTP` is set, an `ADEN` rewritten. [`cr_setting`] writes one such bit and none of the
//!   others, keeping the ordinary bits (`ADVREGEN`, `DEEPPWD`, `ADCALDIF`) as read.
//! - **The common prescaler** (`ADC12_CCR.PRESC`): written only while both ADCs of the pair
//!   are disabled. embassy-stm32 0.6's `Adc::new` writes it for each ADC it creates, and
//!   enables that ADC; [`create_pair`] disables ADC1 before ADC2's `Adc::new`, so both
//!   writes find both ADCs disabled, and reads the prescaler back against
//!   [`crate::clock::ADC_PRESC`] (the ADC clock the acquisition's timing is computed on).
//! - **`DMAEN`** may change only with no regular and no injected conversion ongoing
//!   (`ADSTART = 0` and `JADSTART = 0`): the recovery waits for both
//!   (`recovery::RegisterAcquisition`).
//! - **The first conversion after more than 1 ms idle** may be wrong (the G4's errata):
//!   [`IdleDiscard`] drops the first sample after a start or a restart that idled longer.
//! - **VREFINT's start-up** (`tstart_vrefint`, up to 12 us after `VREFEN`):
//!   `supply::measure_now` waits [`VREFINT_START_US`] before its conversions.
//!
//! Two constants live here because the modules on both sides of the acquisition use them
//! and this module is below both: [`POLL_LIMIT`], the bound of every wait on an ADC or DMA
//! register (the pair's set-up here, the recovery's waits in `recovery`), and [`CHANNELS`],
//! the regular sequence's length of each ADC (`acquisition`'s geometry and the recovery's
//! re-arming of the encoder latch, one count per sequence).

/// Polls of a register the firmware's bounded waits on the ADCs and the DMA allow (the
/// pair's set-up here, the recovery's steps in `recovery::poll_until`): each poll a few
/// cycles, about 1 ms at 170 MHz, far above the 1-2 conversion times an `ADSTP` or a DMA
/// disable takes.
pub const POLL_LIMIT: u32 = 50_000;

/// Channels per ADC, the length of each ADC's regular sequence (`ADC_SQR1.L` + 1): ADC1
/// va, vb, vc; ADC2 ia, ib, ic. `acquisition::CHANNELS` is this constant.
pub const CHANNELS: usize = 3;

/// `ADC_CR.ADEN` (bit 0): enable (set-only).
pub const ADEN: u32 = 1 << 0;
/// `ADC_CR.ADDIS` (bit 1): disable (set-only).
pub const ADDIS: u32 = 1 << 1;
/// `ADC_CR.ADSTART` (bit 2): start the regular conversions (set-only).
pub const ADSTART: u32 = 1 << 2;
/// `ADC_CR.JADSTART` (bit 3): start the injected conversions (set-only).
pub const JADSTART: u32 = 1 << 3;
/// `ADC_CR.ADSTP` (bit 4): stop the regular conversions (set-only).
pub const ADSTP: u32 = 1 << 4;
/// `ADC_CR.JADSTP` (bit 5): stop the injected conversions (set-only).
pub const JADSTP: u32 = 1 << 5;
/// `ADC_CR.ADVREGEN` (bit 28): the ADC's voltage regulator (an ordinary bit).
pub const ADVREGEN: u32 = 1 << 28;
/// `ADC_CR.ADCAL` (bit 31): calibrate (set-only).
pub const ADCAL: u32 = 1 << 31;
/// The set-only bits of `ADC_CR` (ST's `ADC_CR_BITS_PROPERTY_RS`).
pub const CR_SET_ONLY: u32 = ADEN | ADDIS | ADSTART | JADSTART | ADSTP | JADSTP | ADCAL;

/// The value to write to `ADC_CR` to set the set-only bit `bit`, `read` being its value
/// now: the ordinary bits as read, no other set-only bit (as ST's LL does).
pub const fn cr_setting(read: u32, bit: u32) -> u32 {
    (read & !CR_SET_ONLY) | bit
}

/// How long VREFINT's buffer needs after `VREFEN` before a conversion of it is valid
/// [us] (the datasheet's `tstart_vrefint`, at most 12 us).
pub const VREFINT_START_US: u32 = 12;

/// The idle time after which the first conversion may be wrong [us] (the G4's errata).
pub const IDLE_ERRATUM_US: u32 = 1_000;

/// Drops the first sample after a start or a restart of the conversions that followed
/// more than [`IDLE_ERRATUM_US`] without one: its first conversion may be wrong (errata).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IdleDiscard {
    pending: u32,
}

impl IdleDiscard {
    /// The conversions (re)started after `idle_us` without one.
    pub fn on_start(&mut self, idle_us: u32) {
        self.pending = u32::from(idle_us > IDLE_ERRATUM_US);
    }

    /// Whether the next sample is to be dropped (then it is counted as dropped).
    pub fn drop_next(&mut self) -> bool {
        let drop = self.pending > 0;
        self.pending = self.pending.saturating_sub(1);
        drop
    }
}

/// The set-up of the pair ADC1/ADC2 as [`create_pair`] drives it: ADC `i` is 0 (ADC1) or
/// 1 (ADC2). The firmware implements it with embassy-stm32's `Adc::new` and the registers,
/// the host tests with a model that checks the rules (module docs).
pub trait AdcPairSetup {
    /// The HAL's `Adc::new` for ADC `i`: writes the common prescaler, calibrates and
    /// enables the ADC.
    fn create(&mut self, i: usize);
    /// `ADC_CR` of ADC `i`.
    fn cr(&mut self, i: usize) -> u32;
    /// Writes `ADC_CR` of ADC `i`.
    fn write_cr(&mut self, i: usize, value: u32);
    /// The common prescaler's field `ADC12_CCR.PRESC` as read.
    fn prescaler(&mut self) -> u32;
}

/// Why the pair's set-up did not end as it should.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairError {
    /// ADC1 did not disable within [`POLL_LIMIT`] polls.
    NotDisabled,
    /// The common prescaler read back is not [`crate::clock::ADC_PRESC`] (the value read).
    Prescaler(u32),
}

/// Creates ADC1 and ADC2 with the common prescaler written only while both are disabled:
/// ADC1's `Adc::new` (ADC2 not created yet), ADC1 disabled (`ADDIS`, a bounded wait for
/// `ADEN = 0`), ADC2's `Adc::new`, the prescaler read back. ADC1 is enabled again by the
/// ring's set-up (`into_ring_buffered`).
///
/// # Errors
/// [`PairError`] when ADC1 did not disable or the prescaler is not the clock's.
pub fn create_pair(setup: &mut impl AdcPairSetup) -> Result<(), PairError> {
    setup.create(0);
    let cr = setup.cr(0);
    if cr & ADEN != 0 && cr & (ADSTART | JADSTART) == 0 {
        setup.write_cr(0, cr_setting(cr, ADDIS));
    }
    if !(0..POLL_LIMIT).any(|_| setup.cr(0) & ADEN == 0) {
        return Err(PairError::NotDisabled);
    }
    setup.create(1);
    match setup.prescaler() {
        p if p == crate::clock::ADC_PRESC => Ok(()),
        p => Err(PairError::Prescaler(p)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_only_bit_is_written_alone_and_the_ordinary_bits_kept() {
        // Enabled, converting, regulator on: stopping writes ADSTP and the regulator only.
        let read = ADVREGEN | ADEN | ADSTART;
        assert_eq!(cr_setting(read, ADSTP), ADVREGEN | ADSTP);
        assert_eq!(cr_setting(ADVREGEN | ADEN, ADSTART), ADVREGEN | ADSTART);
    }

    /// `ADC_CR`'s bits where RM0440 puts them: `ADEN` 0, `ADDIS` 1, `ADSTART` 2, `JADSTART`
    /// 3, `ADSTP` 4, `JADSTP` 5, `ADVREGEN` 28, `ADCAL` 31; the set-only ones are ST's
    /// `ADC_CR_BITS_PROPERTY_RS`, 0x8000_003F.
    #[test]
    fn the_control_registers_bits_are_rm0440s() {
        assert_eq!(
            [ADEN, ADDIS, ADSTART, JADSTART, ADSTP, JADSTP],
            [0x01, 0x02, 0x04, 0x08, 0x10, 0x20]
        );
        assert_eq!((ADVREGEN, ADCAL), (0x1000_0000, 0x8000_0000));
        assert_eq!(CR_SET_ONLY, 0x8000_003F);
        // Every set-only bit read as 1 (no real state has them all; each is to be dropped),
        // the regulator on and ADCALDIF (bit 30) set: JADSTP is written with bits 28 and 30
        // as read, and alone of the set-only bits.
        assert_eq!(cr_setting(0xD000_003F, 0x20), 0x5000_0020);
    }

    /// The errata's condition is a conversion more than 1 ms after the previous one: 1 ms
    /// exactly drops nothing, 1 ms and 1 us does.
    #[test]
    fn an_idle_of_exactly_one_millisecond_drops_nothing() {
        let mut d = IdleDiscard::default();
        d.on_start(1_000);
        assert!(!d.drop_next());
        d.on_start(1_001);
        assert!(d.drop_next());
    }

    #[test]
    fn only_a_long_idle_drops_a_sample_and_only_one() {
        let mut d = IdleDiscard::default();
        assert!(!d.drop_next());
        d.on_start(900);
        assert!(!d.drop_next());
        d.on_start(2_000);
        assert!(d.drop_next());
        assert!(!d.drop_next());
    }
}
