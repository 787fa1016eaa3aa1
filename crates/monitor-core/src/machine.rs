//! The machine's parameters: one type as the user writes them, one model the equations use,
//! and the reference machines every part of the workspace tests with.
//!
//! - [`MotorParameters`] and [`SupplyParameters`]: the parameter file's `[motor]` and
//!   `[supply]` sections (`docs/design.md`) (`f64`, SI, per phase, referred to the stator). The
//!   host reads them from TOML (serde behind the `serde` feature); the firmware builds
//!   them in code. They are validated once ([`MotorParameters::validate`]).
//! - [`MotorModel`]: what the equations need (pole pairs instead of poles), in `f32` on the
//!   board and `f64` in the host's analysis and simulator. [`MotorParameters::model`] is the
//!   one conversion; the derived quantities (sigma, Ra, La, Kf/i_f, leakages) are computed
//!   only by [`MotorModel`]'s methods.
//! - [`reference`](mod@reference): the reference machines (2.2 kW and 3 hp).
//!
//! Symbols (the paper's, "Fault Diagnosis of Induction Motor Using D-Q Simplified Model
//! and Parity Equations", Energies 2022, 15(22), 8372, doi:10.3390/en15228372; the models
//! and equations with their sources: `docs/design.md`): `Ls` and `Lr` are the stator and
//! rotor *self* inductances, leakage plus magnetising, `Ls = Lls + Lm`, `Lr = Llr + Lm`
//! (the faults [`crate::Fault::Ls`] and [`crate::Fault::Lr`] scale the *leakages* `Lls`
//! and `Llr`, which the paper's simulator, PSIM, calls Ls and Lr); `sigma = 1 - Lm^2/(Ls Lr)`; `Ra = Rs + (Ls/Lr) Rr` (eq. 24);
//! `La = sigma Ls`; `Kf = (3/2) Np (Lm^2/Lr) i_f` (eq. 25 with `P/2 = Np`).

use crate::error::{ensure, ConfigCheck, ConfigError};
use crate::frames::Real;

/// Nominal machine parameters the equations use, per phase, referred to the stator; `f32`
/// on the board (the default), `f64` on the host. Build from [`MotorParameters::model`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorModel<T = f32> {
    /// Stator resistance Rs [ohm], > 0.
    pub rs_ohm: T,
    /// Rotor resistance Rr referred to the stator [ohm], > 0.
    pub rr_ohm: T,
    /// Stator self inductance Ls = Lls + Lm [H] (leakage plus magnetising), >= Lm. The
    /// fault [`crate::Fault::Ls`] scales the leakage Lls ([`MotorModel::lls_h`]), not this.
    pub ls_h: T,
    /// Rotor self inductance Lr = Llr + Lm [H] (leakage plus magnetising), >= Lm. The
    /// fault [`crate::Fault::Lr`] scales the leakage Llr ([`MotorModel::llr_h`]), not this.
    pub lr_h: T,
    /// Magnetising inductance Lm [H], Lm^2 < Ls Lr.
    pub lm_h: T,
    /// Pole pairs Np (poles / 2), >= 1.
    pub pole_pairs: u8,
    /// Inertia J of rotor and load [kg m^2], > 0.
    pub j_kgm2: T,
    /// Machine friction B on the shaft [N m s/rad], >= 0.
    pub b_nms: T,
    /// Load friction Bl on the shaft [N m s/rad], >= 0 (the paper's load model).
    pub bl_nms: T,
}

impl<T: Real> MotorModel<T> {
    /// Leakage coefficient sigma = 1 - Lm^2/(Ls Lr).
    #[inline]
    pub fn sigma(&self) -> T {
        T::ONE - self.lm_h * self.lm_h / (self.ls_h * self.lr_h)
    }
    /// Rotor resistance as it appears in Ra: (Ls/Lr) Rr [ohm].
    #[inline]
    pub fn rr_referred_ohm(&self) -> T {
        self.ls_h / self.lr_h * self.rr_ohm
    }
    /// Ra = Rs + (Ls/Lr) Rr [ohm] (eq. 24).
    #[inline]
    pub fn ra_ohm(&self) -> T {
        self.rs_ohm + self.rr_referred_ohm()
    }
    /// La = sigma Ls [H] (transient inductance).
    #[inline]
    pub fn la_h(&self) -> T {
        self.sigma() * self.ls_h
    }
    /// Stator leakage inductance Lls = Ls - Lm [H] (zero for a Gamma-model machine).
    #[inline]
    pub fn lls_h(&self) -> T {
        self.ls_h - self.lm_h
    }
    /// Rotor leakage inductance Llr = Lr - Lm [H].
    #[inline]
    pub fn llr_h(&self) -> T {
        self.lr_h - self.lm_h
    }
    /// Np as a number.
    #[inline]
    pub fn np(&self) -> T {
        T::from_u8(self.pole_pairs)
    }
    /// Kf / i_f = 3/2 Np Lm^2/Lr [N m/A^2] (eq. 25 without the i_f factor).
    #[inline]
    pub fn kf_per_if(&self) -> T {
        T::THREE_HALVES * self.np() * self.lm_h * self.lm_h / self.lr_h
    }

    /// Checks ranges; the first problem names its field (`motor.rs_ohm`, ...).
    ///
    /// # Errors
    /// [`crate::ConfigErrorKind::MotorParameter`]: a resistance, inductance or J not positive and
    /// finite, B or Bl negative, no pole pair, a self inductance below Lm, or
    /// sigma <= 1e-4 (no leakage at all: the transient inductance La vanishes).
    pub fn validate(&self) -> Result<(), ConfigError> {
        use ConfigCheck::*;
        let positive = |x: T| x.is_finite() && x > T::ZERO;
        let not_negative = |x: T| x.is_finite() && x >= T::ZERO;
        for (ok, check) in [
            (positive(self.rs_ohm), MotorRs),
            (positive(self.rr_ohm), MotorRr),
            (positive(self.ls_h), MotorLs),
            (positive(self.lr_h), MotorLr),
            (positive(self.lm_h), MotorLm),
            (positive(self.j_kgm2), MotorJ),
            (not_negative(self.b_nms), MotorB),
            (not_negative(self.bl_nms), MotorBl),
            (self.pole_pairs > 0, MotorPoles),
            (self.ls_h >= self.lm_h, MotorLsBelowLm),
            (self.lr_h >= self.lm_h, MotorLrBelowLm),
        ] {
            ensure(ok, check)?;
        }
        ensure(self.sigma() > T::from_f64(1e-4), MotorNoLeakage)
    }
}

/// The parameter file's `[motor]` section (`docs/design.md`): nominal T-equivalent parameters
/// per phase, referred to the stator, SI units. Unknown keys are an error when read from
/// TOML (`serde` feature).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct MotorParameters {
    /// Stator resistance Rs [ohm], > 0.
    pub rs_ohm: f64,
    /// Rotor resistance Rr referred to the stator [ohm], > 0.
    pub rr_ohm: f64,
    /// Stator self inductance Ls = Lls + Lm [H] (leakage plus magnetising), >= Lm. The
    /// fault [`crate::Fault::Ls`] scales the leakage Lls ([`MotorModel::lls_h`]), not this.
    pub ls_h: f64,
    /// Rotor self inductance Lr = Llr + Lm [H] (leakage plus magnetising), >= Lm. The
    /// fault [`crate::Fault::Lr`] scales the leakage Llr ([`MotorModel::llr_h`]), not this.
    pub lr_h: f64,
    /// Magnetising inductance Lm [H], > 0, with Lm^2 < Ls Lr.
    pub lm_h: f64,
    /// Number of poles (even, 2..=254). Pole pairs Np = poles / 2.
    pub poles: u32,
    /// Inertia J of rotor and load [kg m^2], > 0.
    pub j_kgm2: f64,
    /// Viscous friction B of the machine, on the shaft [N m s/rad], >= 0.
    pub b_nms: f64,
    /// Viscous load coefficient Bl, on the shaft [N m s/rad], >= 0 (the paper's load model).
    pub bl_nms: f64,
    /// Number of rotor bars of the squirrel cage, where known (optional key; the host's
    /// rotor finding gives a number of broken bars only with it, [`crate::rotor_cage`]).
    /// The equations and the board's motor record do not use it.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub rotor_bars: Option<u32>,
    /// Which magnetising inductance `lm_h` is (optional key `lm_at`, [`LmPoint`]; absent:
    /// [`LmPoint::Rated`], what a no-load test or a nameplate gives). Only a saturation law
    /// (the host's analysis and simulator) reads it; the equations and the board's motor
    /// record do not.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub lm_at: Option<LmPoint>,
}

/// Which magnetising inductance a parameter file's `lm_h` holds: the saturation law
/// `Lm = Lm0 / (1 + (psi_m / psi_sat)^n)` starts from the unsaturated `Lm0`, and a file
/// from a no-load test at rated voltage holds the rated point's, `Lm0` divided by
/// `1 + (psi_m,rated / psi_sat)^n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LmPoint {
    /// The value at the rated flux: a no-load test at rated voltage, a nameplate's estimate
    /// (the default).
    #[default]
    Rated,
    /// The unsaturated value (the linear part of the magnetisation curve): a simulator's
    /// machine, a design calculation.
    Unsaturated,
}

impl MotorParameters {
    /// Which magnetising inductance `lm_h` is ([`MotorParameters::lm_at`], absent:
    /// [`LmPoint::Rated`]).
    pub fn lm_point(&self) -> LmPoint {
        self.lm_at.unwrap_or_default()
    }

    /// The model the equations use, in `f32` (board) or `f64` (host): the workspace's one
    /// conversion from the parameter file. Pole pairs are `poles / 2` (saturating at 255).
    pub fn model<T: Real>(&self) -> MotorModel<T> {
        MotorModel {
            rs_ohm: T::from_f64(self.rs_ohm),
            rr_ohm: T::from_f64(self.rr_ohm),
            ls_h: T::from_f64(self.ls_h),
            lr_h: T::from_f64(self.lr_h),
            lm_h: T::from_f64(self.lm_h),
            pole_pairs: u8::try_from(self.poles / 2).unwrap_or(u8::MAX),
            j_kgm2: T::from_f64(self.j_kgm2),
            b_nms: T::from_f64(self.b_nms),
            bl_nms: T::from_f64(self.bl_nms),
        }
    }

    /// Checks physical ranges; the first problem names its key (`motor.<key>`).
    ///
    /// # Errors
    /// [`crate::ConfigErrorKind::MotorParameter`]: `poles` odd, below 2 or above 254, or any
    /// check of [`MotorModel::validate`].
    pub fn validate(&self) -> Result<(), ConfigError> {
        ensure(
            (2..=254).contains(&self.poles) && self.poles.is_multiple_of(2),
            ConfigCheck::MotorPoles,
        )?;
        self.model::<f64>().validate()
    }
}

/// The parameter file's `[supply]` section: the stiff three-phase source the motor is
/// connected to.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SupplyParameters {
    /// Line-to-line RMS voltage [V], > 0.
    pub v_ll_rms: f64,
    /// Frequency [Hz], > 0.
    pub f_hz: f64,
}

impl SupplyParameters {
    /// Peak phase-to-neutral voltage sqrt(2/3) V_ll,rms [V].
    pub fn v_phase_peak(&self) -> f64 {
        self.v_ll_rms * V_PHASE_PEAK_PER_V_LL_RMS
    }
    /// Angular frequency 2 pi f [rad/s].
    pub fn omega_rad_s(&self) -> f64 {
        core::f64::consts::TAU * self.f_hz
    }
    /// Checks that both values are positive and finite.
    ///
    /// # Errors
    /// [`crate::ConfigErrorKind::Supply`] naming `supply.v_ll_rms` or `supply.f_hz`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        ensure(positive(self.v_ll_rms), ConfigCheck::SupplyVoltage)?;
        ensure(positive(self.f_hz), ConfigCheck::SupplyFrequency)
    }
}

/// sqrt(2/3): peak phase-to-neutral voltage per line-to-line RMS volt.
pub const V_PHASE_PEAK_PER_V_LL_RMS: f64 = 0.816_496_580_927_726;

/// A machine with its supply: one of the reference machines ([`reference`](mod@reference)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceMachine {
    /// A short name for reports ("2.2 kW", "3 hp").
    pub name: &'static str,
    /// The machine.
    pub motor: MotorParameters,
    /// Its rated supply.
    pub supply: SupplyParameters,
}

/// The reference machines (2.2 kW and 3 hp), defined here once for the firmware, the
/// simulator, the analysis and every test.
pub mod reference {
    use super::{MotorParameters, ReferenceMachine, SupplyParameters};

    /// "2.2 kW": 400 V, 50 Hz, 4 poles, T-equivalent with no stator leakage (the
    /// Gamma model of a common 2.2 kW machine). `bl_nms` is chosen so that Bl omega gives
    /// the rated 14.6 N m at about 1430 rpm (149.7 rad/s): 14.6 / 149.7 = 0.0975 N m s/rad.
    pub const MOTOR_2P2KW: ReferenceMachine = ReferenceMachine {
        name: "2.2 kW",
        motor: MotorParameters {
            rs_ohm: 3.7,
            rr_ohm: 2.5,
            ls_h: 0.245,
            lr_h: 0.268,
            lm_h: 0.245,
            poles: 4,
            j_kgm2: 0.015,
            b_nms: 0.005,
            bl_nms: 0.0975,
            rotor_bars: None,
            lm_at: Some(super::LmPoint::Unsaturated),
        },
        supply: SupplyParameters {
            v_ll_rms: 400.0,
            f_hz: 50.0,
        },
    };

    /// Angular frequency of the 3 hp machine's 60 Hz reactances [rad/s].
    const W_60HZ: f64 = 2.0 * core::f64::consts::PI * 60.0;

    /// "3 hp": the textbook 3 hp machine (Krause, Wasynczuk and Sudhoff, *Analysis of
    /// Electric Machinery and Drive Systems*): 220 V, 60 Hz, 4 poles, Xls = Xlr = 0.754 ohm
    /// and Xm = 26.13 ohm at 60 Hz, so Lls = Llr = 0.754/(2 pi 60) = 2.0 mH and
    /// Lm = 26.13/(2 pi 60) = 69.3 mH; J 0.089 kg m^2; B 0.002 and Bl 0.045 N m s/rad (the
    /// example parameter file's).
    pub const MOTOR_3HP: ReferenceMachine = ReferenceMachine {
        name: "3 hp",
        motor: MotorParameters {
            rs_ohm: 0.435,
            rr_ohm: 0.816,
            ls_h: 26.13 / W_60HZ + 0.754 / W_60HZ,
            lr_h: 26.13 / W_60HZ + 0.754 / W_60HZ,
            lm_h: 26.13 / W_60HZ,
            poles: 4,
            j_kgm2: 0.089,
            b_nms: 0.002,
            bl_nms: 0.045,
            rotor_bars: None,
            lm_at: Some(super::LmPoint::Unsaturated),
        },
        supply: SupplyParameters {
            v_ll_rms: 220.0,
            f_hz: 60.0,
        },
    };
}

#[cfg(test)]
mod tests {
    use super::reference::{MOTOR_2P2KW, MOTOR_3HP};
    use super::*;

    #[test]
    fn reference_machines_are_valid_and_match_design() {
        for m in [MOTOR_2P2KW, MOTOR_3HP] {
            assert_eq!(m.motor.validate(), Ok(()), "{}", m.name);
            assert_eq!(m.supply.validate(), Ok(()), "{}", m.name);
        }
        // 3 hp: Xm = 26.13 ohm and Xls = 0.754 ohm at 60 Hz.
        let m = MOTOR_3HP.motor;
        let w = MOTOR_3HP.supply.omega_rad_s();
        assert!((w * m.lm_h - 26.13).abs() < 1e-9);
        assert!((w * (m.ls_h - m.lm_h) - 0.754).abs() < 1e-9);
        // 2.2 kW: Bl omega = 14.6 N m at 149.7 rad/s.
        assert!((MOTOR_2P2KW.motor.bl_nms * 149.7 - 14.6).abs() < 0.01);
        assert!((MOTOR_2P2KW.supply.v_phase_peak() - 326.6).abs() < 0.1);
    }

    #[test]
    fn one_conversion_keeps_the_derived_quantities() {
        let p = MOTOR_3HP.motor;
        let (m32, m64) = (p.model::<f32>(), p.model::<f64>());
        assert_eq!(m64.pole_pairs, 2);
        // sigma, Ra, La agree between the precisions to f32 rounding.
        for (a, b) in [
            (m32.sigma() as f64, m64.sigma()),
            (m32.ra_ohm() as f64, m64.ra_ohm()),
            (m32.la_h() as f64, m64.la_h()),
            (m32.kf_per_if() as f64, m64.kf_per_if()),
        ] {
            assert!((a - b).abs() < 1e-5 * b.abs(), "{a} vs {b}");
        }
        // Ra = Rs + (Ls/Lr) Rr = Rs + Rr for equal leakages.
        assert!((m64.ra_ohm() - (0.435 + 0.816)).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_name_their_key() {
        let mut p = MOTOR_2P2KW.motor;
        p.rr_ohm = -1.0;
        assert_eq!(p.validate().map_err(|e| e.field()), Err("motor.rr_ohm"));
        let mut p = MOTOR_2P2KW.motor;
        p.poles = 3;
        assert_eq!(p.validate().map_err(|e| e.field()), Err("motor.poles"));
        let mut p = MOTOR_2P2KW.motor;
        p.lr_h = p.lm_h; // no leakage at all: sigma = 0
        assert_eq!(p.validate().map_err(|e| e.field()), Err("motor.lm_h"));
        let s = SupplyParameters {
            v_ll_rms: f64::NAN,
            f_hz: 50.0,
        };
        assert_eq!(s.validate().map_err(|e| e.field()), Err("supply.v_ll_rms"));
    }
}
