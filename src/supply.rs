//! The supply the readings depend on: the brown-out reset level in the option bytes and
//! the ADC's reference VDDA, watched while the firmware runs.
//!
//! **Brown-out level.** The STM32G474 holds the MCU in reset while VDD is below the
//! brown-out threshold that `FLASH_OPTR.BOR_LEV` selects (RM0440, "Power supply
//! supervisor" and "FLASH option register"). The factory setting is level 0 (about 1.7 V):
//! the firmware would keep running, and logging readings, far below the NUCLEO's 3.3 V.
//! The firmware wants [`BOR_GOAL`] (level 4, about 2.8 V falling). It does **not** program
//! the option bytes itself: an option-byte write that a reset or a power loss interrupts
//! can leave the device with default or inconsistent option bytes (read protection,
//! boot source, `DBANK`), which a board in the field should not risk on every boot for a
//! setting a user makes once. It reads the level at boot ([`BorCheck::of_optr`]), says
//! on the log and on every status line (`bor=`) which level is in force, and puts the
//! level into every reset record it writes, and warns at every boot while it is below the
//! goal; `cargo fw bor` programs level 4 once per board (`docs/firmware.md`, bring-up).
//! Until it is in force, the flash records are refused ([`BorGate`]): a sag during a
//! commissioning's erase or write would tear the record at level 0.
//!
//! **Reference.** Every reading scales with VDDA, the ADC's reference. Thread mode measures
//! it through VREFINT every [`REFERENCE_PERIOD_MS`] ([`ReferenceWatch`]) on ADC1's injected
//! channel, which leaves the regular conversions and their DMA ring alone; a VDDA outside
//! [`crate::board::VDDA_BAND_V`], or no usable reading, flags both sensors until a
//! measurement is in band again.

use crate::board::ReferenceCheck;
use crate::flash_record::RecordPage;

/// A brown-out reset level of `FLASH_OPTR.BOR_LEV` (RM0440, "FLASH option register";
/// the thresholds are the reference manual's approximate falling-edge values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum BorLevel {
    /// `000`: about 1.7 V (the factory setting).
    Level0,
    /// `001`: about 2.0 V.
    Level1,
    /// `010`: about 2.2 V.
    Level2,
    /// `011`: about 2.5 V.
    Level3,
    /// `100`: about 2.8 V.
    Level4,
}

/// The level the firmware wants: the reset releases above about 2.9 V and holds below
/// about 2.8 V. The NUCLEO's supply is 3.3 V and the reference check flags the readings
/// below 3.2 V already; below 2.8 V nothing the board measures is worth keeping, and a
/// clean reset (reported at the next boot as "power-on or brown-out") is better than a
/// run that goes on with the lamps, the flash writes and the front end out of their
/// ranges.
pub const BOR_GOAL: BorLevel = BorLevel::Level4;

impl BorLevel {
    /// All levels, lowest first.
    pub const ALL: [BorLevel; 5] = [
        BorLevel::Level0,
        BorLevel::Level1,
        BorLevel::Level2,
        BorLevel::Level3,
        BorLevel::Level4,
    ];

    /// The level's `BOR_LEV` value, 0..=4.
    pub const fn number(self) -> u8 {
        self as u8
    }

    /// The level of a `BOR_LEV` value (`None` for the reserved values 5..=7 and above).
    pub fn from_number(n: u8) -> Option<BorLevel> {
        BorLevel::ALL.get(usize::from(n)).copied()
    }

    /// The level in a value of `FLASH_OPTR` (bits 10:8).
    pub fn from_optr(optr: u32) -> Option<BorLevel> {
        BorLevel::from_number(((optr >> 8) & 0b111) as u8)
    }

    /// The approximate falling threshold [V] (RM0440).
    pub const fn falling_v(self) -> f32 {
        match self {
            BorLevel::Level0 => 1.7,
            BorLevel::Level1 => 2.0,
            BorLevel::Level2 => 2.2,
            BorLevel::Level3 => 2.5,
            BorLevel::Level4 => 2.8,
        }
    }
}

/// The boot's check of the brown-out level against [`BOR_GOAL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BorCheck {
    /// The level in force is [`BOR_GOAL`] (or higher, which the hardware does not have).
    AtGoal(BorLevel),
    /// The level in force is below [`BOR_GOAL`]: reported, not changed (module docs).
    BelowGoal(BorLevel),
    /// `BOR_LEV` holds a reserved value (5..=7).
    Reserved(u8),
}

impl BorCheck {
    /// The check of a value of `FLASH_OPTR`.
    pub fn of_optr(optr: u32) -> Self {
        match BorLevel::from_optr(optr) {
            Some(level) if level >= BOR_GOAL => BorCheck::AtGoal(level),
            Some(level) => BorCheck::BelowGoal(level),
            None => BorCheck::Reserved(((optr >> 8) & 0b111) as u8),
        }
    }

    /// The level in force, when it is one.
    pub fn level(self) -> Option<BorLevel> {
        match self {
            BorCheck::AtGoal(l) | BorCheck::BelowGoal(l) => Some(l),
            BorCheck::Reserved(_) => None,
        }
    }

    /// Whether the flash records may be erased and written: only at [`BOR_GOAL`]. Below it
    /// a supply sag during an erase or a write (the commissioning's, a few ms each) would
    /// tear the record instead of resetting the MCU first ([`BorGate`]).
    pub fn allows_flash_writes(self) -> bool {
        matches!(self, BorCheck::AtGoal(_))
    }

    /// The status line's `bor=` value: the level's number, or 255 for a reserved value.
    pub fn status_number(self) -> u8 {
        self.level().map_or(u8::MAX, BorLevel::number)
    }
}

/// A store error that says the brown-out level refused the erase or the write
/// ([`BorGate`]).
pub trait FromBorRefusal {
    /// The error for a write refused at the brown-out level `check`.
    fn bor_refused(check: BorCheck) -> Self;
}

/// A record store whose erases and writes are refused while the brown-out level is below
/// [`BOR_GOAL`] ([`BorCheck::allows_flash_writes`]): the commissioning then ends "not
/// stored", and the boot report says why (`cargo fw bor` programs the level once per
/// board). Reads pass.
#[derive(Debug)]
pub struct BorGate<S> {
    /// The store.
    pub store: S,
    /// The brown-out level found at boot.
    pub bor: BorCheck,
}

impl<S: crate::flash_record::RecordStore> crate::flash_record::RecordStore for BorGate<S>
where
    S::Error: FromBorRefusal,
{
    type Error = S::Error;
    fn read(
        &mut self,
        page: RecordPage,
        buf: &mut [u8; crate::flash_record::RECORD_LEN],
    ) -> Result<(), S::Error> {
        self.store.read(page, buf)
    }
    fn erase(&mut self, page: RecordPage) -> Result<(), S::Error> {
        if !self.bor.allows_flash_writes() {
            return Err(S::Error::bor_refused(self.bor));
        }
        self.store.erase(page)
    }
    fn write(
        &mut self,
        page: RecordPage,
        bytes: &[u8; crate::flash_record::RECORD_LEN],
    ) -> Result<(), S::Error> {
        if !self.bor.allows_flash_writes() {
            return Err(S::Error::bor_refused(self.bor));
        }
        self.store.write(page, bytes)
    }
}

/// The correction of the readings for the ADC's reference: VDDA at commissioning is kept in
/// the commissioning record (`flash_record::CalibrationRecord::vdda_v`); every measurement
/// in band afterwards gives the gain `VDDA now / VDDA at commissioning` by which every code
/// is scaled back (`SamplePath::set_reference_gain`). A 3 % drift within the band no longer
/// moves every reading by 3 %. New gains are handed to the sample task only when they differ
/// from the one in force by more than [`ReferenceGain::DEADBAND`] (a VREFINT conversion's
/// own noise, a code or two of about 1 500, does not toggle it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceGain {
    /// VDDA when the record in force was commissioned [V] (`None`: no record with it; no
    /// correction).
    commissioned_v: Option<f32>,
    /// The gain in force.
    in_force: f32,
}

impl Default for ReferenceGain {
    fn default() -> Self {
        Self {
            commissioned_v: None,
            in_force: 1.0,
        }
    }
}

impl ReferenceGain {
    /// The smallest change of the gain handed on (0.2 %).
    pub const DEADBAND: f32 = 0.002;

    /// The commissioned VDDA (`None`: no correction from now on: the gain goes back to 1);
    /// returns the gain to put into force if it changed.
    pub fn commissioned(
        &mut self,
        vdda_v: Option<f32>,
        latest: Option<ReferenceCheck>,
    ) -> Option<f32> {
        self.commissioned_v = vdda_v;
        match (vdda_v, latest) {
            (Some(_), Some(check)) => self.observe(check),
            _ => self.set(1.0),
        }
    }

    /// A measurement `check`: the gain to put into force when it moved by more than
    /// [`ReferenceGain::DEADBAND`] (measurements out of band or unreadable change nothing:
    /// the sensors are flagged then).
    pub fn observe(&mut self, check: ReferenceCheck) -> Option<f32> {
        let (Some(at), ReferenceCheck::InBand(now)) = (self.commissioned_v, check) else {
            return None;
        };
        let gain = now / at;
        if (gain - self.in_force).abs() > Self::DEADBAND {
            self.set(gain)
        } else {
            None
        }
    }

    /// The gain in force.
    pub fn in_force(&self) -> f32 {
        self.in_force
    }

    /// The VDDA of commissioning, when known [V].
    pub fn commissioned_v(&self) -> Option<f32> {
        self.commissioned_v
    }

    fn set(&mut self, gain: f32) -> Option<f32> {
        let changed = gain != self.in_force;
        self.in_force = gain;
        changed.then_some(gain)
    }
}

/// How often thread mode measures VREFINT while the monitor runs [ms]: fast enough that a
/// sagging supply is flagged within a second, rare enough that the injected conversion's
/// 6 us delay of ADC1's regular sequence (once per second, on one sample) does not matter.
pub const REFERENCE_PERIOD_MS: u32 = 1_000;

/// Longest wait for a started VREFINT conversion [ms]; a conversion takes 6.1 us
/// (247.5 + 12.5 cycles at 42.5 MHz), so one still pending after this never ran: the
/// reading counts as unusable ([`ReferenceCheck::Unreadable`]).
pub const REFERENCE_CONVERSION_TIMEOUT_MS: u32 = 200;

/// Polls of the start-up conversion before it counts as unusable: about 300 us at
/// 170 MHz, 50 times the conversion's 6.1 us.
pub const REFERENCE_POLL_LIMIT: u32 = 10_000;

/// One VREFINT conversion on ADC1's injected channel (RM0440, "Injected conversions"):
/// the firmware implements it on the registers (`JADSTART`, `JEOS`, `JDR1`), the host tests
/// with a fake.
pub trait ReferenceAdc {
    /// The factory's calibration word `VREFINT_CAL`: the reading of VREFINT at
    /// VDDA = 3.0 V ([`crate::board::vdda_from_vrefint`]).
    fn calibration(&self) -> u16;
    /// Switches the VREFINT buffer on (`ADC12_CCR.VREFEN`); its output is valid only after
    /// its start-up time ([`crate::adc_rules::VREFINT_START_US`]).
    fn enable(&mut self);
    /// Waits `us` microseconds (on the board a bounded busy wait on the CPU clock).
    fn wait_us(&mut self, us: u32);
    /// Starts one conversion (`JADSTART = 1`; a conversion in progress is left alone).
    fn start(&mut self);
    /// The result when the conversion has finished (`JEOS` set: `JDR1` read, `JEOS`
    /// cleared), else `None`.
    fn result(&mut self) -> Option<u16>;
}

/// One conversion: started, then at most [`REFERENCE_POLL_LIMIT`] polls for its result.
fn convert_now(adc: &mut impl ReferenceAdc) -> Option<u16> {
    adc.start();
    (0..REFERENCE_POLL_LIMIT).find_map(|_| adc.result())
}

/// One measurement now, each conversion waited for at most [`REFERENCE_POLL_LIMIT`]
/// polls: the start-up check, before the sample path runs. It switches the VREFINT buffer
/// on (`VREFEN`) and waits its start-up time (datasheet `tstart_vrefint`, up to
/// [`crate::adc_rules::VREFINT_START_US`]) before the first conversion: converted earlier,
/// the buffer's output is not valid (the former check converted right after `VREFEN` and
/// kept the second conversion, which sampled 6-12 us after it). The first conversion is
/// still discarded (the ADC's own first after an idle, `adc_rules`), the second is the
/// measurement.
pub fn measure_now(adc: &mut impl ReferenceAdc) -> ReferenceCheck {
    adc.enable();
    adc.wait_us(crate::adc_rules::VREFINT_START_US);
    if convert_now(adc).is_none() {
        return ReferenceCheck::Unreadable;
    }
    match convert_now(adc) {
        Some(code) => ReferenceCheck::of(code, adc.calibration()),
        None => ReferenceCheck::Unreadable,
    }
}

/// A change of the reference's verdict, for the log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReferenceChange {
    /// The reference is out of band or unreadable: the sensors are flagged from now on.
    Flagged(ReferenceCheck),
    /// The reference is back in band (VDDA [V]): the flags it set are cleared.
    Cleared(f32),
}

/// Where the periodic measurement stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum WatchPhase {
    /// Waiting for the start-up check (nothing is measured before it).
    NotStarted,
    /// The next conversion starts at this time [ms].
    Idle { next_ms: u32 },
    /// A conversion was started at this time [ms].
    Converting { since_ms: u32 },
}

/// The periodic reference check (module docs): a measurement every `period_ms`, the
/// sensors flagged while the latest is out of band or unreadable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceWatch {
    period_ms: u32,
    phase: WatchPhase,
    latest: Option<ReferenceCheck>,
}

impl ReferenceWatch {
    /// A watch measuring every `period_ms` (at least 1 ms) once the start-up check came
    /// ([`ReferenceWatch::observe`]).
    pub fn new(period_ms: u32) -> Self {
        Self {
            period_ms: period_ms.max(1),
            phase: WatchPhase::NotStarted,
            latest: None,
        }
    }

    /// Whether the latest measurement distrusts the readings (out of band or unreadable).
    pub fn flags_sensors(&self) -> bool {
        self.latest.is_some_and(|c| c.distrusts_readings())
    }

    /// The latest VDDA [V] (0 before the start-up check and when unreadable).
    pub fn vdda_v(&self) -> f32 {
        match self.latest {
            Some(ReferenceCheck::InBand(v) | ReferenceCheck::OutOfBand(v)) => v,
            _ => 0.0,
        }
    }

    /// The latest measurement (`None` before the start-up check).
    pub fn latest(&self) -> Option<ReferenceCheck> {
        self.latest
    }

    /// The latest VDDA when it is in band [V] (what a commissioning run stores).
    pub fn in_band_v(&self) -> Option<f32> {
        match self.latest {
            Some(ReferenceCheck::InBand(v)) => Some(v),
            _ => None,
        }
    }

    /// A measurement's result at `now_ms` (the start-up check, or a periodic one): the
    /// verdict and the next measurement's time; a change of the verdict is returned.
    pub fn observe(&mut self, check: ReferenceCheck, now_ms: u32) -> Option<ReferenceChange> {
        let was = self.flags_sensors();
        self.latest = Some(check);
        self.phase = WatchPhase::Idle {
            next_ms: now_ms.wrapping_add(self.period_ms),
        };
        match (was, check) {
            (true, ReferenceCheck::InBand(v)) => Some(ReferenceChange::Cleared(v)),
            (false, c) if c.distrusts_readings() => Some(ReferenceChange::Flagged(c)),
            _ => None,
        }
    }

    /// One thread-mode period at `now_ms`: starts a due conversion, or takes the result of
    /// the one running (a result still missing after
    /// [`REFERENCE_CONVERSION_TIMEOUT_MS`] counts as unreadable). Returns a change of the
    /// verdict.
    pub fn poll(&mut self, now_ms: u32, adc: &mut impl ReferenceAdc) -> Option<ReferenceChange> {
        match self.phase {
            WatchPhase::NotStarted => None,
            WatchPhase::Idle { next_ms } => {
                // Due when `now` has reached `next` (wrapping time: the difference's sign).
                if now_ms.wrapping_sub(next_ms) < u32::MAX / 2 {
                    adc.start();
                    self.phase = WatchPhase::Converting { since_ms: now_ms };
                }
                None
            }
            WatchPhase::Converting { since_ms } => match adc.result() {
                Some(code) => self.observe(ReferenceCheck::of(code, adc.calibration()), now_ms),
                None if now_ms.wrapping_sub(since_ms) >= REFERENCE_CONVERSION_TIMEOUT_MS => {
                    self.observe(ReferenceCheck::Unreadable, now_ms)
                }
                None => None,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_brown_out_level_is_read_from_the_option_register() {
        // The G474's factory option bytes: 0xFFEF_F8AA (BOR_LEV = 000).
        assert_eq!(
            BorCheck::of_optr(0xFFEF_F8AA),
            BorCheck::BelowGoal(BorLevel::Level0)
        );
        let at_goal = (0xFFEF_F8AA & !(0b111 << 8)) | (4 << 8);
        assert_eq!(
            BorCheck::of_optr(at_goal),
            BorCheck::AtGoal(BorLevel::Level4)
        );
        assert_eq!(BorCheck::of_optr(at_goal).status_number(), 4);
        let reserved = 0xFFEF_F8AA | (0b111 << 8);
        assert_eq!(BorCheck::of_optr(reserved), BorCheck::Reserved(7));
        assert_eq!(BorCheck::of_optr(reserved).status_number(), 255);
        for level in BorLevel::ALL {
            assert_eq!(BorLevel::from_number(level.number()), Some(level));
        }
        assert!(BorLevel::Level3 < BOR_GOAL);
    }

    /// A VREFINT that converts to the code a given VDDA gives, on a clock: each
    /// conversion samples for 5.8 us and ends 6.1 us after its start; one that begins
    /// sampling less than 12 us (ST's longest `tstart_vrefint`) after `VREFEN` reads the
    /// buffer still starting (its output at half its value).
    struct Fake {
        vdda: f32,
        cal: u16,
        pending: bool,
        converts: bool,
        /// Time since `VREFEN` [us] (`None`: not enabled).
        since_enable_us: Option<f32>,
    }

    impl ReferenceAdc for Fake {
        fn calibration(&self) -> u16 {
            self.cal
        }
        fn enable(&mut self) {
            self.since_enable_us.get_or_insert(0.0);
        }
        fn wait_us(&mut self, us: u32) {
            if let Some(t) = self.since_enable_us.as_mut() {
                *t += us as f32;
            }
        }
        fn start(&mut self) {
            self.pending = true;
        }
        fn result(&mut self) -> Option<u16> {
            let done = self.pending && self.converts;
            self.pending &= !done;
            let sampled_at = self.since_enable_us;
            if done {
                self.wait_us(0);
                if let Some(t) = self.since_enable_us.as_mut() {
                    *t += 6.1;
                }
            }
            let settled = sampled_at.is_some_and(|t| t >= 12.0);
            let code = f32::from(self.cal) * 3.0 / self.vdda;
            done.then(|| if settled { code } else { code / 2.0 }.round() as u16)
        }
    }

    #[test]
    fn the_start_up_measurement_is_bounded() {
        let mut adc = Fake {
            vdda: 3.3,
            cal: 1655,
            pending: false,
            converts: true,
            since_enable_us: None,
        };
        // A conversion within 12 us of VREFEN (the buffer starting) would read VDDA twice
        // too high: the former check's kept conversion sampled at 6.1 us.
        assert!(
            matches!(measure_now(&mut adc), ReferenceCheck::InBand(v) if (v - 3.3).abs() < 0.01)
        );
        adc.converts = false;
        assert_eq!(measure_now(&mut adc), ReferenceCheck::Unreadable);
    }

    /// The status line's VDDA is 0 before the start-up check and when unreadable, the
    /// measured one in band and out of band; a commissioning stores it only in band.
    #[test]
    fn the_watch_gives_the_measured_vdda() {
        let mut w = ReferenceWatch::new(REFERENCE_PERIOD_MS);
        assert_eq!((w.vdda_v(), w.in_band_v(), w.latest()), (0.0, None, None));
        w.observe(ReferenceCheck::InBand(3.3), 0);
        assert_eq!((w.vdda_v(), w.in_band_v()), (3.3, Some(3.3)));
        w.observe(ReferenceCheck::OutOfBand(3.0), 1_000);
        assert_eq!((w.vdda_v(), w.in_band_v()), (3.0, None));
        w.observe(ReferenceCheck::Unreadable, 2_000);
        assert_eq!((w.vdda_v(), w.in_band_v()), (0.0, None));
    }

    /// A conversion every 1 s from the last result, started by the first period at or after
    /// its time (a late one too); one not done within 200 ms is unreadable.
    #[test]
    fn the_watch_converts_each_second_and_waits_200_ms_for_a_result() {
        let mut adc = Fake {
            vdda: 3.3,
            cal: 1655,
            pending: false,
            converts: false,
            since_enable_us: Some(100.0),
        };
        let mut w = ReferenceWatch::new(REFERENCE_PERIOD_MS);
        w.observe(ReferenceCheck::InBand(3.3), 0);
        assert_eq!(w.poll(999, &mut adc), None);
        assert!(!adc.pending, "due at 1 000 ms, not before");
        assert_eq!(w.poll(1_013, &mut adc), None);
        assert!(adc.pending, "started 13 ms late");
        assert_eq!(w.poll(1_212, &mut adc), None, "199 ms: still waiting");
        let unreadable = Some(ReferenceChange::Flagged(ReferenceCheck::Unreadable));
        assert_eq!(w.poll(1_213, &mut adc), unreadable);
    }

    /// RM0440's `BOR_LEV` thresholds (falling, about): 1.7, 2.0, 2.2, 2.5, 2.8 V, each level
    /// higher than the one before; the goal's 2.8 V is below the NUCLEO's 3.3 V supply.
    #[test]
    fn each_brown_out_level_has_the_reference_manuals_threshold() {
        let volts = BorLevel::ALL.map(BorLevel::falling_v);
        assert_eq!(volts, [1.7, 2.0, 2.2, 2.5, 2.8]);
        assert!(BOR_GOAL.falling_v() < 3.3);
    }

    /// A commissioning that ends with a measurement in hand puts its gain into force at
    /// once: the readings scale with VDDA, so a VDDA 1.5 % below the commissioned one
    /// (3.25 V against 3.30 V) gives a gain of 0.985 now, not one measurement later.
    #[test]
    fn a_commissioning_with_a_measurement_puts_its_gain_into_force() {
        let mut gain = ReferenceGain::default();
        let now = gain.commissioned(Some(3.30), Some(ReferenceCheck::InBand(3.25)));
        let expected = 3.25 / 3.30;
        assert!(now.is_some_and(|g| (g - expected).abs() < 1e-6), "{now:?}");
        assert!((gain.in_force() - expected).abs() < 1e-6);
    }

    /// The gain follows VDDA beyond its deadband of 0.2 % only: 3.30 V commissioned, a
    /// measurement of 3.2967 V (-0.1 %) changes nothing, one of 3.2868 V (-0.4 %) puts
    /// 0.996 into force.
    #[test]
    fn the_gain_moves_only_beyond_its_deadband() {
        let mut gain = ReferenceGain::default();
        assert_eq!(gain.commissioned(Some(3.30), None), None);
        assert_eq!(gain.commissioned_v(), Some(3.30));
        assert_eq!(gain.observe(ReferenceCheck::InBand(3.2967)), None);
        assert_eq!(gain.in_force(), 1.0);
        let moved = gain.observe(ReferenceCheck::InBand(3.2868));
        assert!(moved.is_some_and(|g| (g - 0.996).abs() < 1e-4), "{moved:?}");
        assert!((gain.in_force() - 0.996).abs() < 1e-4);
        // No commissioned VDDA: no correction, the gain back to 1.
        assert_eq!(gain.commissioned(None, None), Some(1.0));
        assert_eq!(gain.commissioned_v(), None);
    }
}
