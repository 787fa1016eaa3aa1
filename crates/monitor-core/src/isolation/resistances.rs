//! Rs and Rr read apart from one steady operating point: how a loosening connection is
//! told from a warm winding.
//!
//! A warmer winding raises Rs and Rr by the same factor `1 + alpha dT` (copper and the
//! rotor's aluminium differ by 0.1 %/K in alpha: 0.3 % over 30 K); a connection that
//! loosens, a corroded lug or a cracked stator conductor raises Rs alone. The difference of
//! the two read at the same point, `Rs/Rs0 - Rr/Rr0`, is therefore free of the winding's
//! temperature (and of a bias in ohms the file's inductances put on both readings, unlike
//! their ratio), and a rise of it is an Rs change nothing thermal explains.
//!
//! # The equations
//! From the steady state of the T-equivalent machine (the module docs of
//! [`crate::isolation`]; paper eqs. 13-23 with `d/dt = 0`) the stator impedance the
//! measured vectors give, `Z = V / I`, is
//! `Z = Rs + j we Ls + A / (Rr + j ws Lr)` with `A = we ws Lm^2` and the slip frequency
//! `ws = we - wr`. With the inductances taken from the parameter file, its imaginary part
//! holds Rr alone and its real part then gives Rs:
//!
//! - `Im Z - we Ls = -A ws Lr / (Rr^2 + ws^2 Lr^2)`, so
//!   `Rr^2 = A ws Lr / (we Ls - Im Z) - ws^2 Lr^2`;
//! - `Rs = Re Z - A Rr / (Rr^2 + ws^2 Lr^2)`.
//!
//! Both are exact for the model. They rest on the file's inductances: `we Ls - Im Z` is a
//! small difference of two large reactances, so a file whose Lm is 1 % off moves the
//! excess by 30 % (and 30 K of heating then moves it by 3 %; leakages 5 % off: 4 % and
//! 1.4 %); a reading outside [`SPLIT_FACTOR_RANGE`] of the file's
//! values is refused as the file's error, not the machine's. A file identified on the
//! motor (`sim-host identify`) or one within a few per cent gives a bias that depends on the
//! operating point (the trend normalises on load for it), not on the temperature.

use super::SteadyPoint;
use crate::MotorModel;

/// The slip below which the rotor's resistance is not read (|ws| / we): near synchronous
/// speed the rotor branch carries almost no current and `Rr^2` is the difference of two
/// nearly equal terms.
pub const MIN_SPLIT_SLIP: f64 = 0.002;

/// The range of `Rs/Rs_file` and `Rr/Rr_file` a reading may have: 25 K cooler to 160 K
/// warmer than the file (the heating range the isolation accepts) with the file 30 % off
/// either way. Outside it the file's inductances, not the machine, made the reading.
pub const SPLIT_FACTOR_RANGE: (f64, f64) = (0.6, 2.1);

/// Rs and Rr read from one steady point ([`resistance_split`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResistanceSplit {
    /// Stator resistance [ohm].
    pub rs_ohm: f64,
    /// Rotor resistance referred to the stator [ohm].
    pub rr_ohm: f64,
    /// `Rs / Rs_file`.
    pub rs_factor: f64,
    /// `Rr / Rr_file`.
    pub rr_factor: f64,
}

impl ResistanceSplit {
    /// `Rs/Rs_file - Rr/Rr_file`: the stator's resistance change beyond the rotor's, free
    /// of the winding's temperature (module docs) [fraction of the file's values].
    pub fn stator_excess(&self) -> f64 {
        self.rs_factor - self.rr_factor
    }
}

/// Rs and Rr of the machine at the steady point `q`, with the inductances of `motor`
/// (module docs for the equations).
///
/// `None` when the point cannot carry it: no voltage or current, a slip below
/// [`MIN_SPLIT_SLIP`] (or negative: a generating machine), an impedance whose reactance is
/// not below `we Ls` (the rotor branch must lower it), or a result outside
/// [`SPLIT_FACTOR_RANGE`] of the file's values (or not finite).
pub fn resistance_split(motor: &MotorModel, q: &SteadyPoint) -> Option<ResistanceSplit> {
    let (vd, vq) = (f64::from(q.v.d), f64::from(q.v.q));
    let (id, iq) = (f64::from(q.i.d), f64::from(q.i.q));
    let i2 = id * id + iq * iq;
    let we = f64::from(q.we_rad_s);
    let ws = we - f64::from(q.wr_rad_s);
    if !(i2 > 0.0 && i2.is_finite() && we > 0.0 && ws / we >= MIN_SPLIT_SLIP) {
        return None;
    }
    // Z = V / I = V conj(I) / |I|^2.
    let (zr, zi) = ((vd * id + vq * iq) / i2, (vq * id - vd * iq) / i2);
    let (ls, lr, lm) = (
        f64::from(motor.ls_h),
        f64::from(motor.lr_h),
        f64::from(motor.lm_h),
    );
    let a = we * ws * lm * lm;
    let drop = we * ls - zi;
    if !(drop > 0.0) {
        return None;
    }
    let rr_sq = a * ws * lr / drop - ws * ws * lr * lr;
    if !(rr_sq > 0.0) {
        return None;
    }
    let rr = sqrt(rr_sq);
    let rs = zr - a * rr / (rr_sq + ws * ws * lr * lr);
    let split = ResistanceSplit {
        rs_ohm: rs,
        rr_ohm: rr,
        rs_factor: rs / f64::from(motor.rs_ohm),
        rr_factor: rr / f64::from(motor.rr_ohm),
    };
    let (lo, hi) = SPLIT_FACTOR_RANGE;
    let ok = [split.rs_factor, split.rr_factor]
        .iter()
        .all(|k| (lo..=hi).contains(k));
    ok.then_some(split)
}

/// The square root of a positive `x` by Newton's iteration (no `std` in the core),
/// to f64's precision.
fn sqrt(x: f64) -> f64 {
    let mut r = f64::from(crate::math::sqrt(x as f32));
    for _ in 0..3 {
        r = 0.5 * (r + x / r);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::Dq;

    /// A machine's steady point from its own circuit (the textbook equivalent circuit,
    /// written here in f64 complex arithmetic): `V = Z I` at slip frequency `ws`.
    fn point(m: &MotorModel, rs: f64, rr: f64, we: f64, slip: f64) -> SteadyPoint {
        let ws = slip * we;
        let (ls, lr, lm) = (f64::from(m.ls_h), f64::from(m.lr_h), f64::from(m.lm_h));
        // A / (Rr + j ws Lr) = A (Rr - j ws Lr) / (Rr^2 + ws^2 Lr^2).
        let a = we * ws * lm * lm;
        let den = rr * rr + ws * ws * lr * lr;
        let (zr, zi) = (rs + a * rr / den, we * ls - a * ws * lr / den);
        let (id, iq) = (3.0, -7.0);
        SteadyPoint {
            i: Dq {
                d: id as f32,
                q: iq as f32,
            },
            v: Dq {
                d: (zr * id - zi * iq) as f32,
                q: (zr * iq + zi * id) as f32,
            },
            we_rad_s: we as f32,
            wr_rad_s: (we - ws) as f32,
        }
    }

    fn motor() -> MotorModel {
        MotorModel {
            rs_ohm: 0.435,
            rr_ohm: 0.816,
            ls_h: 0.0714,
            lr_h: 0.0714,
            lm_h: 0.0693,
            pole_pairs: 2,
            j_kgm2: 0.089,
            b_nms: 0.0,
            bl_nms: 0.05,
        }
    }

    #[test]
    fn the_circuits_own_resistances_come_back() {
        let m = motor();
        for (rs, rr, slip) in [
            (0.435, 0.816, 0.03),
            (0.50, 0.90, 0.05),
            (0.48, 0.816, 0.01),
        ] {
            let s = resistance_split(&m, &point(&m, rs, rr, 376.99, slip)).expect("split");
            assert!((s.rs_ohm - rs).abs() < 5e-3 * rs, "{s:?} {rs}");
            assert!((s.rr_ohm - rr).abs() < 5e-3 * rr, "{s:?} {rr}");
        }
    }

    #[test]
    fn heating_leaves_no_stator_excess_and_a_loose_connection_does() {
        let m = motor();
        let warm = 1.0 + 0.00393 * 30.0;
        let hot = resistance_split(&m, &point(&m, 0.435 * warm, 0.816 * warm, 376.99, 0.03))
            .expect("split");
        assert!(hot.stator_excess().abs() < 0.005, "{hot:?}");
        let loose =
            resistance_split(&m, &point(&m, 0.435 * 1.1, 0.816, 376.99, 0.03)).expect("split");
        assert!((loose.stator_excess() - 0.1).abs() < 0.01, "{loose:?}");
    }

    /// Against a file whose leakage inductances are a few per cent off (an identified
    /// file's) the reading is biased, 30 K of heating moves the bias
    /// by a fraction of what an Rs +10 % change moves the excess, and that change still
    /// moves it by about its size.
    #[test]
    fn a_file_a_little_off_biases_the_excess_but_not_its_changes() {
        let m = motor();
        // (leakage factor, Lm factor)
        for (dls, dlm) in [(1.05, 1.0), (0.97, 1.0)] {
            let mut off = m;
            off.lm_h *= dlm;
            off.ls_h = off.lm_h + (m.ls_h - m.lm_h) * dls;
            off.lr_h = off.lm_h + (m.lr_h - m.lm_h) * dls;
            let at = |rs: f64, rr: f64| {
                resistance_split(&off, &point(&m, rs, rr, 376.99, 0.03)).map(|s| s.stator_excess())
            };
            let warm = 1.0 + 0.00393 * 30.0;
            let (Some(cold), Some(hot), Some(loose)) = (
                at(0.435, 0.816),
                at(0.435 * warm, 0.816 * warm),
                at(0.435 * 1.1, 0.816),
            ) else {
                panic!("no reading with the file off by {dls} {dlm}");
            };
            // Measured: at most 1.4 % (leakage 5 % high), against the 10 % of the Rs change.
            assert!(
                (hot - cold).abs() < 0.02,
                "{dls} {dlm}: cold {cold} hot {hot}"
            );
            assert!(
                (loose - cold - 0.1).abs() < 0.03,
                "{dls} {dlm}: cold {cold} loose {loose}"
            );
        }
    }

    #[test]
    fn a_point_that_cannot_carry_it_gives_none() {
        let m = motor();
        let mut no_slip = point(&m, 0.435, 0.816, 376.99, 0.03);
        no_slip.wr_rad_s = no_slip.we_rad_s;
        assert!(resistance_split(&m, &no_slip).is_none());
        assert!(resistance_split(&m, &SteadyPoint::default()).is_none());
        let mut nan = point(&m, 0.435, 0.816, 376.99, 0.03);
        nan.v.d = f32::NAN;
        assert!(resistance_split(&m, &nan).is_none());
        // A file whose Ls is 40 % high: no rotor branch fits the point, refused.
        let mut off = m;
        off.ls_h *= 1.4;
        let r = resistance_split(&off, &point(&m, 0.435, 0.816, 376.99, 0.03));
        assert!(r.is_none(), "{r:?}");
    }
}
