//! How many turns are shorted (JSON `unbalance.shorted_turns`): the fraction `mu` of the
//! named phase's turns, from the winding's measured change of `I2/I1`, by inverting the
//! turn-fault loop of Tallam, Habetler and Harley ("Transient model for induction machines
//! with stator winding turn faults", IEEE Trans. Ind. Appl. 38(3), 2002) at the measured
//! operating point with the parameter file; or, where the user learned one from labelled
//! runs of the same motor, from that calibration ([`TurnCalibration`]), said so in
//! `basis`.
//!
//! It consumes only the finished judgement ([`UnbalanceReport`]) and the model: it runs once
//! at the end of a replay.
//!
//! # The inversion (`docs/isolation.md`, "How many turns")
//! 1. The loop's ratio from the change `c = M - R` of the judged stretch `M` against its
//!    reference `R`, for a short in phase `k` (`a = e^{j 2 pi/3}`):
//!    `M = (R + r a^k) / (1 + r)`, so `r = c a^-k / (1 - M a^-k)`.
//! 2. Tallam's loop: `r = (mu/3) Z1 / Z_f` with
//!    `Z_f = P Rw (1 - 2 mu/3) + r_f / mu + j w mu P Lls / 3`, `Z1 = Z(s)` the
//!    T-equivalent circuit's positive-sequence impedance at the operating point, `Rw` the
//!    winding's phase resistance, `Lls` its leakage, `P` the parallel paths of the phase
//!    (a double-star winding has 2: the shorted turns lie in one path, whose resistance is
//!    `P Rw`), `r_f` the fault path's resistance.
//! 3. `mu |Z1| / (3 |r|) = |Z_f(mu)|` has one root in `(0, 1]`: the left side grows with
//!    `mu`, the right side falls. It is found by bisection.
//!
//! The terminals see only `r`: `mu` and `r_f` are not separable from a steady state (both
//! enter through `Re Z_f / mu`). The estimate takes `r_f` = [`FAULT_RESISTANCE_OF_RS`] of
//! `Rw` (a short through a switch or a burnt spot, the simulator's default), its interval
//! the range [`FAULT_RESISTANCE_RANGE`], the winding resistance from
//! [`WINDING_RESISTANCE_LOW`] of the file's (a nameplate file's Rs holds the iron losses)
//! to the file's, `Z1` over the operating point's range, and `|r|` within two spreads of
//! the judgement.

use super::UnbalanceReport;
use super::{abs, Complex32, FULL_LOAD_SLIP_MAX};
pub use crate::options::TurnLevelOptions;
pub use crate::turn_calibration::{LabelledRun, TurnCalibration};
use monitor_core::sequence::{equivalent_impedance, slip_for_current};
use monitor_core::{MotorModel, Phase};
use serde::Serialize;

/// The fault path's resistance the estimate takes, as a fraction of the winding's phase
/// resistance (the simulator's default `fault_resistance_ohm`, Rs/10).
pub const FAULT_RESISTANCE_OF_RS: f32 = 0.1;
/// The fault path's resistance the interval spans (fractions of the phase resistance):
/// what `tests/replay/turn_fault.rs` injects, from a nearly bolted short to one through a fifth
/// of the phase's resistance.
pub const FAULT_RESISTANCE_RANGE: (f32, f32) = (0.05, 0.2);
/// The lowest winding resistance the interval takes, as a fraction of the file's Rs: a
/// nameplate file's Rs holds the iron and stray losses, and a winding's DC resistance is
/// about 0.5-0.65 of it (`monitor_io::nameplate`).
pub const WINDING_RESISTANCE_LOW: f32 = 0.5;

/// Where a shorted-turn level comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LevelBasis {
    /// The turn-fault model inverted with the parameter file; no labels.
    Physics,
    /// A calibration learned from labelled runs of the same motor ([`TurnCalibration`]).
    Calibration,
}

/// The shorted fraction of a phase's turns (JSON `unbalance.shorted_turns` and
/// `unbalance.shorted_turns_physics`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShortedTurns {
    /// The phase (JSON "a", "b", "c").
    pub phase: Phase,
    /// The estimated fraction of the phase's turns shorted, 0..1.
    pub fraction: f32,
    /// The interval's low end (fraction of the turns).
    pub low: f32,
    /// Its high end.
    pub high: f32,
    /// Where it comes from.
    pub basis: LevelBasis,
    /// `|r|`, the loop's share of the healthy `I1` (step 1 of the module docs): what the
    /// estimate and a calibration read.
    pub loop_ratio: f32,
}

/// The loop ratio `r` of the judged stretch and its uncertainty on `|r|` (two spreads,
/// mapped as `r` is), for the named phase; `None` without a named phase or a judged
/// stretch.
pub fn loop_ratio(u: &UnbalanceReport) -> Option<(Phase, Complex32, f32)> {
    let phase = u.suspect_phase?;
    let seg = u.segments.get(u.judged_segment?)?;
    let polar = |m: f32, deg: f32| Complex32::from_polar(m, deg.to_radians());
    let m = polar(seg.negative_sequence_ratio, seg.angle_deg);
    let c = polar(u.winding_ratio, u.angle_deg);
    let turn = Complex32::from_polar(1.0, -(phase.index() as f32) * std::f32::consts::TAU / 3.0);
    let den = Complex32::new(1.0, 0.0) - m * turn;
    if abs(den) <= 1e-3 {
        return None;
    }
    let r = c * turn / den;
    Some((phase, r, 2.0 * u.spread / abs(den)))
}

/// Tallam's `|Z_f|` (module docs, step 2) at fraction `mu`.
fn z_f(mu: f32, rw: f32, rf: f32, x_lls: f32, paths: f32) -> f32 {
    let re = paths * rw * (1.0 - 2.0 * mu / 3.0) + rf / mu;
    let im = mu * paths * x_lls / 3.0;
    re.hypot(im)
}

/// The fraction `mu` at which Tallam's loop draws `|r|` (module docs, step 3): `z1` the
/// machine's `|Z1|` [ohm], `rw` the winding's phase resistance, `rf` the fault path's
/// [ohm], `x_lls` the stator leakage reactance `w Lls` [ohm], `paths` the parallel paths.
/// 1 where even all the turns would draw less; 0 for no loop.
pub fn fraction_for_loop(r: f32, z1: f32, rw: f32, rf: f32, x_lls: f32, paths: f32) -> f32 {
    if r.is_nan() || r <= 0.0 || z1 <= 0.0 {
        return 0.0;
    }
    let f = |mu: f32| mu * z1 / (3.0 * r) - z_f(mu, rw, rf, x_lls, paths);
    let (mut lo, mut hi) = (1e-5f32, 1.0f32);
    if f(hi) < 0.0 {
        return 1.0;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The machine's `|Z1|` at the judged stretch [ohm], the estimate's and the interval's
/// ends (module docs): measured as `|V1/I1| |1 + r|` where voltages are logged (the
/// faulty current holds the loop's share); else the model's at the slip from the speed
/// (the slip within [`super::SLIP_MODEL_UNCERTAINTY`]); else at the slip where the model
/// draws the healthy part of the current, `|I1| / |1 + r|` (within
/// [`super::CURRENT_MODEL_UNCERTAINTY`]); else from no load to [`FULL_LOAD_SLIP_MAX`].
fn z1_range(u: &UnbalanceReport, m: &MotorModel, we: f32, v_peak: f32, r: Complex32) -> [f32; 3] {
    use super::OperatingPointSource as Op;
    let z1_at = |s: f32| abs(equivalent_impedance(m, we, s));
    let one_r = abs(Complex32::new(1.0, 0.0) + r);
    let seg = u.judged_segment.and_then(|k| u.segments.get(k));
    if let Some(v1) = seg.and_then(|s| s.v1) {
        let z = abs(v1) * one_r;
        return [z, z, z];
    }
    match (u.operating_point, u.slip, seg) {
        (Some(Op::Speed), Some(s), _) => {
            let k = 1.0 + super::SLIP_MODEL_UNCERTAINTY;
            [z1_at(s), z1_at(s / k), z1_at(s * k)]
        }
        (Some(Op::CurrentMagnitude), Some(_), Some(seg)) => {
            let i1 = seg.i1_peak_a / one_r.max(1e-3);
            let at = |i: f32| z1_at(slip_for_current(m, v_peak, we, i));
            let e = super::CURRENT_MODEL_UNCERTAINTY;
            [at(i1), at((1.0 - e) * i1), at((1.0 + e) * i1)]
        }
        _ => {
            let (a, b) = (z1_at(1e-4), z1_at(FULL_LOAD_SLIP_MAX));
            [(a * b).sqrt(), a, b]
        }
    }
}

/// The model's estimate (module docs): `None` without a named phase. `v_peak`: the
/// supply's phase voltage [V, peak]; `we` its angular frequency [rad/s].
pub fn physics(
    u: &UnbalanceReport,
    m: &MotorModel,
    we: f32,
    v_peak: f32,
    opts: &TurnLevelOptions,
) -> Option<ShortedTurns> {
    let (phase, r, dr) = loop_ratio(u)?;
    let paths = f32::from(opts.parallel_paths.get());
    let z1s = z1_range(u, m, we, v_peak, r);
    let x_lls = we * (m.ls_h - m.lm_h);
    let rs = m.rs_ohm;
    let at = |x: f32, z1: f32, rw: f32, rf_of_rs: f32| {
        fraction_for_loop(x, z1, rw, rf_of_rs * rs, x_lls, paths)
    };
    let x = abs(r);
    let fraction = at(x, z1s[0], rs, FAULT_RESISTANCE_OF_RS);
    let mut low = fraction;
    let mut high = fraction;
    for z1 in z1s {
        for rw in [WINDING_RESISTANCE_LOW * rs, rs] {
            low = low.min(at((x - dr).max(1e-6), z1, rw, FAULT_RESISTANCE_RANGE.0));
            high = high.max(at(x + dr, z1, rw, FAULT_RESISTANCE_RANGE.1));
        }
    }
    Some(ShortedTurns {
        phase,
        fraction,
        low,
        high,
        basis: LevelBasis::Physics,
        loop_ratio: x,
    })
}

/// How large a short the judged stretch could hide: the fraction of a phase's turns whose
/// loop draws the least change that names a phase (JSON `unbalance.shorted_turns_reach`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TurnReach {
    /// The fraction with the file's winding and the default fault resistance (0..1).
    pub fraction: f32,
    /// The largest over the operating point's, the winding resistance's and the fault
    /// resistance's ranges: no short of more than this stays below the least change.
    pub high: f32,
    /// Where it comes from.
    pub basis: LevelBasis,
    /// The least change it is read from (fraction of `|I1|`).
    pub least_change: f32,
}

/// The loop ratio a change of `least` (fraction of `|I1|`) of the judged stretch reads as,
/// in the phase where it reads largest (`r = c a^-k / (1 - M a^-k)`, module docs step 1):
/// `None` without a judged stretch or a least change.
fn least_loop_ratio(u: &UnbalanceReport, least: f32) -> Option<f32> {
    let seg = u.segments.get(u.judged_segment?)?;
    if !(least.is_finite() && least > 0.0) {
        return None;
    }
    let m = Complex32::from_polar(seg.negative_sequence_ratio, seg.angle_deg.to_radians());
    Phase::ALL
        .iter()
        .map(|p| {
            let turn =
                Complex32::from_polar(1.0, -(p.index() as f32) * std::f32::consts::TAU / 3.0);
            least / abs(Complex32::new(1.0, 0.0) - m * turn).max(1e-3)
        })
        .reduce(f32::max)
}

/// How large a short this log could hide ([`TurnReach`]): the model's fraction for the least
/// change that names a phase (`None` without a judged stretch, or where no change names one).
pub fn reach(
    u: &UnbalanceReport,
    m: &MotorModel,
    we: f32,
    v_peak: f32,
    opts: &TurnLevelOptions,
) -> Option<TurnReach> {
    let x = least_loop_ratio(u, u.least_change)?;
    if let Some(cal) = &opts.calibration {
        let f = |x: f32| {
            Phase::ALL
                .iter()
                .filter_map(|p| cal.fraction(*p, x))
                .map(|v| v.clamp(0.0, 1.0))
                .reduce(f32::max)
        };
        let fraction = f(x)?;
        return Some(TurnReach {
            fraction,
            high: f(x + 2.0 * cal.scatter).unwrap_or(fraction).max(fraction),
            basis: LevelBasis::Calibration,
            least_change: u.least_change,
        });
    }
    let paths = f32::from(opts.parallel_paths.get());
    let r = Complex32::new(x, 0.0);
    let z1s = z1_range(u, m, we, v_peak, r);
    let x_lls = we * (m.ls_h - m.lm_h);
    let rs = m.rs_ohm;
    let at =
        |z1: f32, rw: f32, rf_of_rs: f32| fraction_for_loop(x, z1, rw, rf_of_rs * rs, x_lls, paths);
    let fraction = at(z1s[0], rs, FAULT_RESISTANCE_OF_RS);
    let mut high = fraction;
    for z1 in z1s {
        for rw in [WINDING_RESISTANCE_LOW * rs, rs] {
            high = high.max(at(z1, rw, FAULT_RESISTANCE_RANGE.1));
        }
    }
    Some(TurnReach {
        fraction,
        high,
        basis: LevelBasis::Physics,
        least_change: u.least_change,
    })
}

/// The calibration's estimate for the same reading (`None` without a named phase);
/// the interval is the calibration's scatter and the judgement's two spreads on `|r|`.
pub fn calibrated(u: &UnbalanceReport, cal: &TurnCalibration) -> Option<ShortedTurns> {
    let (phase, r, dr) = loop_ratio(u)?;
    let x = abs(r);
    let w = dr.hypot(2.0 * cal.scatter);
    let f = |x: f32| cal.fraction(phase, x).map(|v| v.clamp(0.0, 1.0));
    Some(ShortedTurns {
        phase,
        fraction: f(x)?,
        low: f((x - w).max(0.0))?,
        high: f(x + w)?,
        basis: LevelBasis::Calibration,
        loop_ratio: x,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tallam's loop forward, in double precision (the module docs' step 2, written anew):
    /// `|r| = (mu/3) |Z1| / |Z_f|`.
    fn forward(mu: f64, z1: f64, rw: f64, rf: f64, x: f64, p: f64) -> f64 {
        let re = p * rw * (1.0 - 2.0 * mu / 3.0) + rf / mu;
        let im = mu * p * x / 3.0;
        mu / 3.0 * z1 / re.hypot(im)
    }

    #[test]
    fn the_inversion_returns_the_fraction_the_loop_was_drawn_with() {
        for p in [1.0, 2.0] {
            for mu in [0.01, 0.05, 0.1, 0.3, 0.6] {
                for rf in [0.0, 0.7, 3.0] {
                    let r = forward(mu, 50.7, 7.06, rf, 2.13, p);
                    let got = fraction_for_loop(r as f32, 50.7, 7.06, rf as f32, 2.13, p as f32);
                    assert!(
                        (f64::from(got) / mu - 1.0).abs() < 1e-3,
                        "mu {mu}, r_f {rf}, P {p}: {got}"
                    );
                }
            }
        }
        // A loop larger than all the turns could draw reads as all of them; none as none.
        assert_eq!(fraction_for_loop(50.0, 50.7, 7.06, 0.7, 2.13, 1.0), 1.0);
        assert_eq!(fraction_for_loop(0.0, 50.7, 7.06, 0.7, 2.13, 1.0), 0.0);
    }

    #[test]
    fn the_fault_resistance_and_the_fraction_trade_against_each_other() {
        // What the terminals cannot separate: a larger fault resistance needs more turns
        // for the same loop.
        let r = forward(0.1, 50.7, 7.06, 0.7, 2.13, 1.0) as f32;
        let bolted = fraction_for_loop(r, 50.7, 7.06, 0.0, 2.13, 1.0);
        let through = fraction_for_loop(r, 50.7, 7.06, 1.4, 2.13, 1.0);
        assert!(bolted < 0.1 && through > 0.1, "{bolted} {through}");
    }

    #[test]
    fn a_calibration_maps_through_its_levels() {
        let run = |phase, fraction, loop_ratio| LabelledRun {
            phase,
            fraction,
            loop_ratio,
        };
        let cal = TurnCalibration::learn(&[
            run(Phase::A, 0.1, 0.09),
            run(Phase::A, 0.1, 0.11),
            run(Phase::A, 0.2, 0.2),
            run(Phase::C, 0.3, 0.6),
        ])
        .expect("a calibration");
        assert_eq!(cal.counts, [2, 0, 1]);
        // The two runs at 10 % scatter by 0.01 about their mean 0.1 (one degree of freedom:
        // sqrt(2 * 0.01^2 / 1)).
        assert!((cal.scatter - 0.014_142).abs() < 1e-4, "{}", cal.scatter);
        let a = |x| cal.fraction(Phase::A, x).expect("points");
        assert!((a(0.05) - 0.05).abs() < 1e-6);
        assert!((a(0.15) - 0.15).abs() < 1e-6);
        // Beyond the last level, on the last segment's slope.
        assert!((a(0.3) - 0.3).abs() < 1e-6);
        // Phase c has its own point; phase b borrows all of them.
        assert!((cal.fraction(Phase::C, 0.3).expect("points") - 0.15).abs() < 1e-6);
        assert!(cal.fraction(Phase::B, 0.1).is_some());
    }
}
