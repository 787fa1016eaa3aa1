//! What a parameter file's values must be to be a real induction machine: the plausible
//! ranges with their sources ([`plausible`](mod@plausible)) and the check
//! ([`ParamFile::check_plausible`]).

use super::ParamFile;
use std::f64::consts::TAU;

/// A closed range `lo..=hi` of plausible values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// Smallest plausible value.
    pub lo: f64,
    /// Largest plausible value.
    pub hi: f64,
}

impl PlausibleRange {
    /// The range `lo..=hi`.
    pub const fn new(lo: f64, hi: f64) -> Self {
        PlausibleRange { lo, hi }
    }

    /// True for a finite `x` in `lo..=hi`.
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite() && x >= self.lo && x <= self.hi
    }
}

/// The plausible ranges of a parameter file ([`ParamFile::check_plausible`]): induction
/// machines from about 0.1 kW to 1 MW, line-fed or inverter-fed at their rated point.
///
/// The file has no rated power, so most checks are ratios that need none. Where the
/// values come from (each range is wider than every machine listed, so that a real
/// machine is never refused and a unit or typing error of 10x to 1000x is):
/// - the four machines of Krause, Wasynczuk and Sudhoff, *Analysis of Electric Machinery
///   and Drive Systems* (3 hp / 220 V, 50 hp / 460 V, 500 hp / 2300 V, 2250 hp / 2300 V,
///   all 60 Hz, 4 poles; the 3 hp one is the repository's reference motor): Lm/Ls
///   0.972..0.983, sigma 0.034..0.055, X/Rs 62..457, Lr/Rr 0.087..1.6 s, Rr/Rs 0.71..2.6,
///   H estimate 0.88..2.8 s;
/// - the repository's 2.2 kW Gamma-model reference machine (Ls = Lm): Lm/Lr 0.914, sigma
///   0.086, X/Rs 21, Lr/Rr 0.11 s, Rr/Rs 0.68, H estimate 0.089 s;
/// - textbook per-unit values for the small end (0.1 kW, 2 to 8 poles: Rs up to about
///   0.1 pu and X/Rs down to about 5, Lr/Rr down to about 20 ms, rotor inertia 1e-4 to
///   1e-3 kg m^2).
pub mod plausible {
    use super::PlausibleRange as R;

    /// Number of poles: even, 2..=24 (3000 rpm down to 250 rpm at 50 Hz; the core's own
    /// limit is 254).
    pub const POLES: core::ops::RangeInclusive<u32> = 2..=24;
    /// Supply frequency `f_hz` [Hz]: 1..400 (400 Hz: aircraft supplies and high-speed
    /// motors; high-speed spindles above that are outside this product's scope).
    pub const F_HZ: R = R::new(1.0, 400.0);
    /// Line-to-line voltage `v_ll_rms` [V]: 10..15000 (low-voltage battery drives up to
    /// 13.8 kV medium-voltage machines).
    pub const V_LL_RMS: R = R::new(10.0, 15_000.0);
    /// Lm/Ls: 0.8..=1 (1 = a Gamma-model machine with no stator leakage; below 0.8 the
    /// stator leakage would exceed a quarter of Lm).
    pub const LM_OVER_LS: R = R::new(0.8, 1.0);
    /// Lm/Lr: 0.8..=1 (1 = an inverse-Gamma-model machine with no rotor leakage).
    pub const LM_OVER_LR: R = R::new(0.8, 1.0);
    /// Leakage coefficient sigma = 1 - Lm^2/(Ls Lr): 0.01..0.25.
    pub const SIGMA: R = R::new(0.01, 0.25);
    /// Magnetising reactance over stator resistance, 2 pi f Ls / Rs, at the file's
    /// frequency: 2..1000.
    pub const X_OVER_RS: R = R::new(2.0, 1000.0);
    /// Rotor time constant Lr/Rr [s]: 0.005..5.
    pub const ROTOR_TIME_CONSTANT_S: R = R::new(0.005, 5.0);
    /// Rr/Rs: 0.1..10.
    pub const RR_OVER_RS: R = R::new(0.1, 10.0);
    /// Inertia constant estimate H = (J omega_m^2 / 2) / S0 [s], omega_m = 2 pi f / Np the
    /// synchronous mechanical speed and S0 = V_ll^2 / (2 pi f Ls) the no-load (magnetising)
    /// reactive power standing in for the rated power: 0.002..100. Real machines have H
    /// of about 0.02 s (0.1 kW, motor alone) to 2 s, and up to about 30 s with a
    /// flywheel or a large fan on the shaft (J is rotor plus load). S0 is 0.3 to 1.1 times
    /// the rated power (no-load current 25 % to 60 % of rated at power factor 0.7 to 0.9),
    /// hence the extra margin of about 4x at both ends.
    pub const INERTIA_CONSTANT_S: R = R::new(0.002, 100.0);
    /// Rotor bars of the cage, the optional `rotor_bars` key: 8..=300 (small motors have
    /// about 16-30 bars, large ones up to about 150; below 8 a cage has fewer bars than a
    /// two-pole machine's pole pitch needs for the broken-bar relation
    /// `monitor_core::rotor_cage`, whose `3n < N` a single broken bar must meet).
    pub const ROTOR_BARS: core::ops::RangeInclusive<u32> = 8..=300;
}

/// A parameter file value outside the range of real machines: the key, its value, the
/// quantity that is out of range and the range (one line).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct Implausible {
    /// The key blamed (`motor.rs_ohm`, `supply.f_hz`, ...).
    pub key: &'static str,
    /// The whole message.
    pub message: String,
}

/// One ratio check: `quantity` = c * `key`^`exponent` must lie in `range`; blames `key`.
struct RatioCheck {
    key: &'static str,
    value: f64,
    unit: &'static str,
    /// How the quantity is formed, e.g. "lr_h / rr_ohm (rotor time constant, s)".
    what: &'static str,
    quantity: f64,
    range: PlausibleRange,
    exponent: f64,
}

impl RatioCheck {
    fn check(&self) -> Result<(), Implausible> {
        if self.range.contains(self.quantity) {
            return Ok(());
        }
        // The blamed key's own range with the other values as they are.
        let at = |q: f64| self.value * (q / self.quantity).powf(1.0 / self.exponent);
        let (a, b) = (at(self.range.lo), at(self.range.hi));
        let (lo, hi) = (a.min(b), a.max(b));
        Err(Implausible {
            key: self.key,
            message: format!(
                "{} = {} {} is implausible: {} = {}, plausible {}..{} \
                 (so {} {}..{} {} with the other values)",
                self.key,
                number(self.value),
                self.unit,
                self.what,
                number(self.quantity),
                self.range.lo,
                self.range.hi,
                self.key,
                number(lo),
                number(hi),
                self.unit,
            ),
        })
    }
}

/// `x` for a message: four significant digits, in scientific notation when very large or
/// very small.
fn number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-3..1e5).contains(&a) {
        let digits = if a == 0.0 || !a.is_finite() {
            0
        } else {
            (3 - a.log10().floor() as i32).max(0) as usize
        };
        let t = format!("{x:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{x:.3e}")
    }
}

impl ParamFile {
    /// Checks that every value lies in the range of real induction machines
    /// ([`plausible`](mod@plausible) lists the ranges and their sources): each value finite
    /// and positive (B and Bl >= 0), then the poles, the supply, and the ratios Lm/Ls,
    /// Lm/Lr, sigma, 2 pi f Ls/Rs, Lr/Rr, Rr/Rs and the inertia constant. Applied to a file
    /// as it is read ([`ParamFile::from_toml_str`]), not to the scaled copies that faults
    /// and refits make.
    ///
    /// # Errors
    /// The first value out of range: its key, its value, the quantity and the plausible
    /// range (for a ratio also the key's own range with the other values as they are).
    pub fn check_plausible(&self) -> Result<(), Implausible> {
        self.check_signs()?;
        self.check_poles_and_supply()?;
        for c in self.ratio_checks() {
            c.check()?;
        }
        Ok(())
    }

    /// Each value finite and positive (B and Bl >= 0).
    fn check_signs(&self) -> Result<(), Implausible> {
        let (m, s) = (&self.motor, &self.supply);
        let fail = |key: &'static str, message: String| Err(Implausible { key, message });
        for (key, v, unit) in [
            ("motor.rs_ohm", m.rs_ohm, "ohm"),
            ("motor.rr_ohm", m.rr_ohm, "ohm"),
            ("motor.ls_h", m.ls_h, "H"),
            ("motor.lr_h", m.lr_h, "H"),
            ("motor.lm_h", m.lm_h, "H"),
            ("motor.j_kgm2", m.j_kgm2, "kg m^2"),
            ("supply.v_ll_rms", s.v_ll_rms, "V"),
            ("supply.f_hz", s.f_hz, "Hz"),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return fail(
                    key,
                    format!(
                        "{key} must be positive and finite, got {} {unit}",
                        number(v)
                    ),
                );
            }
        }
        for (key, v) in [("motor.b_nms", m.b_nms), ("motor.bl_nms", m.bl_nms)] {
            if !(v.is_finite() && v >= 0.0) {
                return fail(
                    key,
                    format!("{key} must be >= 0 and finite, got {} N m s/rad", number(v)),
                );
            }
        }
        Ok(())
    }

    /// The poles (even, in [`plausible::POLES`]), the rotor bars where given
    /// ([`plausible::ROTOR_BARS`]), the supply frequency and voltage.
    fn check_poles_and_supply(&self) -> Result<(), Implausible> {
        let (m, s) = (&self.motor, &self.supply);
        let fail = |key: &'static str, message: String| Err(Implausible { key, message });
        if !(plausible::POLES.contains(&m.poles) && m.poles.is_multiple_of(2)) {
            return fail(
                "motor.poles",
                format!(
                    "motor.poles = {} is implausible: plausible is an even number in {}..={}",
                    m.poles,
                    plausible::POLES.start(),
                    plausible::POLES.end()
                ),
            );
        }
        if let Some(n) = m.rotor_bars.filter(|n| !plausible::ROTOR_BARS.contains(n)) {
            return fail(
                "motor.rotor_bars",
                format!(
                    "motor.rotor_bars = {n} is implausible: plausible {}..={}",
                    plausible::ROTOR_BARS.start(),
                    plausible::ROTOR_BARS.end()
                ),
            );
        }
        for (key, v, unit, r) in [
            ("supply.f_hz", s.f_hz, "Hz", plausible::F_HZ),
            ("supply.v_ll_rms", s.v_ll_rms, "V", plausible::V_LL_RMS),
        ] {
            if !r.contains(v) {
                return fail(
                    key,
                    format!(
                        "{key} = {} {unit} is implausible: plausible {}..{} {unit}",
                        number(v),
                        r.lo,
                        r.hi
                    ),
                );
            }
        }
        Ok(())
    }

    /// The ratio checks of [`ParamFile::check_plausible`], in order; each blames one key.
    fn ratio_checks(&self) -> [RatioCheck; 7] {
        let (m, s) = (&self.motor, &self.supply);
        let x_ohm = TAU * s.f_hz * m.ls_h;
        let w_mech = TAU * s.f_hz / f64::from(m.poles / 2);
        let s0_var = s.v_ll_rms * s.v_ll_rms / x_ohm;
        let check = |key, value, unit, what, quantity, range, exponent| RatioCheck {
            key,
            value,
            unit,
            what,
            quantity,
            range,
            exponent,
        };
        [
            check("motor.ls_h", m.ls_h, "H", "lm_h / ls_h", m.lm_h / m.ls_h, plausible::LM_OVER_LS, -1.0),
            check("motor.lr_h", m.lr_h, "H", "lm_h / lr_h", m.lm_h / m.lr_h, plausible::LM_OVER_LR, -1.0),
            // 1 - sigma = Lm^2 / (Ls Lr): a power law in Lm.
            check(
                "motor.lm_h",
                m.lm_h,
                "H",
                "1 - sigma = lm_h^2 / (ls_h lr_h)",
                m.lm_h * m.lm_h / (m.ls_h * m.lr_h),
                PlausibleRange {
                    lo: 1.0 - plausible::SIGMA.hi,
                    hi: 1.0 - plausible::SIGMA.lo,
                },
                2.0,
            ),
            check("motor.rs_ohm", m.rs_ohm, "ohm", "2 pi f_hz ls_h / rs_ohm", x_ohm / m.rs_ohm, plausible::X_OVER_RS, -1.0),
            check(
                "motor.rr_ohm",
                m.rr_ohm,
                "ohm",
                "lr_h / rr_ohm (rotor time constant, s)",
                m.lr_h / m.rr_ohm,
                plausible::ROTOR_TIME_CONSTANT_S,
                -1.0,
            ),
            check("motor.rr_ohm", m.rr_ohm, "ohm", "rr_ohm / rs_ohm", m.rr_ohm / m.rs_ohm, plausible::RR_OVER_RS, 1.0),
            check(
                "motor.j_kgm2",
                m.j_kgm2,
                "kg m^2",
                "inertia constant estimate H = j_kgm2 omega_sync^2 / (2 S0), S0 = v_ll_rms^2 / (2 pi f_hz ls_h), in s",
                0.5 * m.j_kgm2 * w_mech * w_mech / s0_var,
                plausible::INERTIA_CONSTANT_S,
                1.0,
            ),
        ]
    }
}
