//! The library's closed-form laws, each written once: the simulator injects them
//! (`monitor_sim`'s machine) and the analysis fits them (`monitor_analysis`'s effects) by
//! calling these functions, and each is also a [`Law`] value of the same form as a user's
//! ([`laws`]), so that both kinds are listed, evaluated and compared alike.
//!
//! | law | acts on | value |
//! |---|---|---|
//! | `windage` | load torque | `k w |w|` (fan and air drag) |
//! | `coulomb_friction` | load torque | `Tc tanh(w / w0)` (dry friction, smooth through standstill) |
//! | `load_torque` | load torque | `T0` (a constant torque) |
//! | `saturation` | magnetising inductance | `Lm0 / (1 + (|psi_m| / psi_sat)^n)` |
//! | `thermal_drift` | stator resistance | `R0 (1 + alpha rise (1 - e^{-(t - t0)/tau}))` for `t >= t0` |
//!
//! One more law is not a candidate of the ladder but its yardstick: [`speed_power`], a load
//! torque of speed to a power `T_ref (|w| / w_ref)^n`, the family that holds windage
//! (`n = 2`), a viscous load (`n = 1`) and a constant torque on a shaft that turns one way
//! (`n = 0`). Where two load laws of the ladder's model fit a log only together, the ladder
//! fits this one law in their place to see whether the log tells them apart.

use crate::id::EffectId;
use crate::law::{ActsOn, Law, LawForm, LawOrigin, LawParam};
use crate::vars::LawInputs;
use monitor_core::EffectKind;
use std::sync::Arc;

/// Windage torque `k w |w|` [N m] at mechanical speed `w` [rad/s], `k` [N m s^2/rad^2].
#[inline(always)]
pub fn windage_nm(k_nms2: f64, w_rad_s: f64) -> f64 {
    k_nms2 * w_rad_s * w_rad_s.abs()
}

/// Dry friction `Tc tanh(w / w0)` [N m] at mechanical speed `w` [rad/s]: the friction
/// torque `Tc` [N m] opposing rotation, smoothed over `w0` [rad/s] (> 0) through
/// standstill. 0 without friction (no tanh evaluated).
#[inline(always)]
pub fn coulomb_nm(tc_nm: f64, w0_rad_s: f64, w_rad_s: f64) -> f64 {
    if tc_nm == 0.0 {
        0.0
    } else {
        tc_nm * (w_rad_s / w0_rad_s).tanh()
    }
}

/// The saturation law's Lm [H] at magnetising flux `psi_m` [Wb, peak]:
/// `Lm0 / (1 + (|psi_m| / psi_sat)^n)`, `psi_sat` [Wb] > 0, `n` > 0.
#[inline(always)]
pub fn saturation_lm_h(lm0_h: f64, psi_sat_wb: f64, exponent: f64, psi_m_wb: f64) -> f64 {
    lm0_h / (1.0 + (psi_m_wb.abs() / psi_sat_wb).powf(exponent))
}

/// The temperature rise [K] at `t` [s] of a first-order heating to `rise_k` [K] with time
/// constant `tau_s` [s] (> 0) from `t0_s` [s]: `rise (1 - e^{-(t - t0)/tau})`, 0 before
/// `t0`.
#[inline(always)]
pub fn heating_rise_k(rise_k: f64, tau_s: f64, t0_s: f64, t_s: f64) -> f64 {
    rise_k * (1.0 - (-(t_s - t0_s).max(0.0) / tau_s.max(1e-9)).exp())
}

/// A resistance [ohm] of `r0` [ohm] at a temperature `rise_k` [K] above its own with the
/// temperature coefficient `alpha` [1/K]: `r0 (1 + alpha rise)`.
#[inline(always)]
pub fn warm_resistance_ohm(r0_ohm: f64, alpha_per_k: f64, rise_k: f64) -> f64 {
    r0_ohm * (1.0 + alpha_per_k * rise_k)
}

/// The reference speed of [`speed_power_nm`]: 100 rad/s (955 rpm), about the synchronous
/// speed of a 4-pole 50 Hz machine, so that `T_ref` is a torque of the machine's order
/// whatever the exponent.
pub const SPEED_POWER_REF_RAD_S: f64 = 100.0;

/// A load torque of speed to a power [N m], `T_ref (|w| / w_ref)^n sign(w)` at mechanical
/// speed `w` [rad/s], with `T_ref` [N m] the torque at `w_ref` =
/// [`SPEED_POWER_REF_RAD_S`] and `n` >= 0 the exponent (2: windage, 1: a viscous load);
/// 0 at standstill.
#[inline(always)]
pub fn speed_power_nm(t_ref_nm: f64, exponent: f64, w_rad_s: f64) -> f64 {
    if w_rad_s == 0.0 {
        0.0
    } else {
        t_ref_nm * (w_rad_s.abs() / SPEED_POWER_REF_RAD_S).powf(exponent) * w_rad_s.signum()
    }
}

/// A library law's parameter (its start and bounds are generic: the analysis sets them up
/// on each log).
fn param(name: &'static str, unit: &'static str, start: f64, low: f64, high: f64) -> LawParam {
    LawParam {
        name,
        unit,
        start,
        low,
        high,
    }
}

/// A library law.
fn law(
    kind: EffectKind,
    acts_on: ActsOn,
    params: Vec<LawParam>,
    f: fn(&[f64], &LawInputs) -> f64,
) -> Law {
    Law {
        id: EffectId::library(kind),
        acts_on,
        params,
        form: LawForm::Builtin(f),
        origin: LawOrigin::Library,
    }
}

/// `windage` as a law: `k w |w|` ([`windage_nm`]).
pub fn windage() -> Law {
    law(
        EffectKind::Windage,
        ActsOn::LoadTorque,
        vec![param("k_nms2", "N m s^2/rad^2", 0.0, 0.0, 1.0)],
        |p, x| windage_nm(p[0], x.w_rad_s),
    )
}

/// `coulomb_friction` as a law: `Tc tanh(w / w0)` ([`coulomb_nm`]).
pub fn coulomb_friction() -> Law {
    law(
        EffectKind::CoulombFriction,
        ActsOn::LoadTorque,
        vec![
            param("torque_nm", "N m", 0.0, 0.0, 1e4),
            param("omega0_rad_s", "rad/s", 1.0, 1e-3, 100.0),
        ],
        |p, x| coulomb_nm(p[0], p[1], x.w_rad_s),
    )
}

/// `load_torque` as a law: a constant torque `T0`.
pub fn load_torque() -> Law {
    law(
        EffectKind::LoadTorque,
        ActsOn::LoadTorque,
        vec![param("torque_nm", "N m", 0.0, -1e5, 1e5)],
        |p, _| p[0],
    )
}

/// `saturation` as a law: `Lm0 / (1 + (|psi_m| / psi_sat)^n)` ([`saturation_lm_h`]).
pub fn saturation() -> Law {
    law(
        EffectKind::Saturation,
        ActsOn::MagnetisingInductance,
        vec![
            param("lm0_h", "H", 0.2, 1e-4, 10.0),
            param("psi_sat_wb", "Wb", 1.0, 1e-3, 100.0),
            param("exponent", "1", 6.0, 2.0, 14.0),
        ],
        |p, x| saturation_lm_h(p[0], p[1], p[2], x.psi_m_wb),
    )
}

/// `thermal_drift` of the stator as a law: `R0 (1 + alpha rise (1 - e^{-(t - t0)/tau}))`
/// ([`heating_rise_k`], [`warm_resistance_ohm`]).
pub fn thermal_drift() -> Law {
    law(
        EffectKind::ThermalDrift,
        ActsOn::StatorResistance,
        vec![
            param("r0_ohm", "ohm", 1.0, 1e-4, 1e3),
            param("alpha_per_k", "1/K", 0.00393, 0.0, 0.01),
            param("rise_k", "K", 60.0, -100.0, 400.0),
            param("tau_s", "s", 3.0, 1e-3, 1e5),
            param("at_s", "s", 0.0, -1e5, 1e5),
        ],
        |p, x| warm_resistance_ohm(p[0], p[1], heating_rise_k(p[2], p[3], p[4], x.t_s)),
    )
}

/// `speed_power` as a law: `T_ref (|w| / w_ref)^n sign(w)` ([`speed_power_nm`]), the
/// exponent within 0..5. Not one of [`laws`]: the ladder fits it only in place of two load
/// laws of its model (module doc), never as a candidate of its own, so that a load the
/// library lacks is still said to be one.
pub fn speed_power() -> Law {
    Law {
        id: EffectId::from_static("speed_power"),
        acts_on: ActsOn::LoadTorque,
        params: vec![
            param("t_ref_nm", "N m", 1.0, -1e5, 1e5),
            param("exponent", "1", 2.0, 0.0, 5.0),
        ],
        form: LawForm::Builtin(|p, x| speed_power_nm(p[0], p[1], x.w_rad_s)),
        origin: LawOrigin::Library,
    }
}

/// The library's closed-form laws ([`Law`] values, module doc).
pub fn laws() -> Vec<Arc<Law>> {
    [
        windage(),
        coulomb_friction(),
        load_torque(),
        saturation(),
        thermal_drift(),
    ]
    .into_iter()
    .map(Arc::new)
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each law value evaluates its function (the form a user's law has gives the same
    /// number as the function the simulator and the analysis call).
    #[test]
    fn law_values_are_their_functions() {
        let x = LawInputs {
            t_s: 2.0,
            w_rad_s: -120.0,
            theta_rad: 0.3,
            psi_m_wb: 0.9,
        };
        assert_eq!(windage().eval(&[2e-4], &x), windage_nm(2e-4, -120.0));
        assert!(windage_nm(2e-4, -120.0) < 0.0);
        assert_eq!(
            coulomb_friction().eval(&[3.0, 0.5], &x),
            coulomb_nm(3.0, 0.5, -120.0)
        );
        assert_eq!(load_torque().eval(&[7.5], &x), 7.5);
        let lm = saturation().eval(&[0.3, 0.9, 6.0], &x);
        assert!((lm - 0.15).abs() < 1e-12, "Lm halves at psi_sat: {lm}");
        let r = thermal_drift().eval(&[3.7, 0.00393, 70.0, 3.0, 0.0], &x);
        let rise = 70.0 * (1.0 - (-2.0f64 / 3.0).exp());
        assert!((r - 3.7 * (1.0 + 0.00393 * rise)).abs() < 1e-12);
        assert_eq!(
            heating_rise_k(70.0, 3.0, 5.0, 2.0),
            0.0,
            "no rise before it starts"
        );
        let pump = speed_power().eval(&[10.0, 2.7], &x);
        assert!((pump + 10.0 * 1.2f64.powf(2.7)).abs() < 1e-9, "{pump}");
        assert_eq!(
            speed_power_nm(10.0, 2.0, -120.0),
            windage_nm(10.0 / 1e4, -120.0),
            "n = 2 is windage"
        );
        assert_eq!(speed_power_nm(10.0, 0.0, 0.0), 0.0, "nothing at standstill");
        for l in laws() {
            assert!(l.id.is_library());
            let v = l.eval(&l.starts(), &x);
            assert!(v.is_finite(), "{}: {v}", l.id);
        }
    }
}
