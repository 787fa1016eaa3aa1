//! The effects a scenario injects (`[[effects]] name = "..."`), with their parameters,
//! defaults and ranges ([`EffectSpec`]).

use super::scenario::{d_true, invalid, not_negative, positive};
use super::SimError;
use monitor_core::{EffectKind, Phase};
use serde::{Deserialize, Serialize};

/// Main-flux saturation law parameters; see [`EffectSpec::Saturation`].
fn d_sat_exp() -> f64 {
    6.0
}
fn d_sat_ratio() -> f64 {
    1.3
}
fn d_tau_s() -> f64 {
    3.0
}
fn d_alpha() -> f64 {
    0.00393
}
fn d_iron_ratio() -> f64 {
    25.0
}
fn d_coulomb_w() -> f64 {
    1.0
}
fn d_unb() -> f64 {
    0.03
}
fn d_asym() -> f64 {
    0.05
}
fn d_phase_a() -> Phase {
    Phase::A
}

/// A physical effect to inject, with its parameters: `[[effects]] name = "..."`, the name
/// an [`EffectKind`] (the effect library of `docs/design.md`).
///
/// Each variant lists its parameters (TOML keys) with units and defaults. The defaults make a
/// visible but realistic difference on the reference motors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "name", rename_all = "snake_case", deny_unknown_fields)]
pub enum EffectSpec {
    /// Winding temperature rise dT [K] above the parameter file's temperature:
    /// Rs = Rs0 (1 + alpha dT), Rr = Rr0 (1 + alpha dT) (copper alpha = 0.00393 /K;
    /// 20 -> 90 C is +27 %). First-order thermal model, one lumped winding temperature:
    /// - prescribed (default): dT(t) = rise_k (1 - exp(-(t - at_s)/tau_s)) for t >= at_s;
    /// - loss-driven (when `r_th_k_per_w` is given): tau_s d(dT)/dt = r_th P_loss - dT,
    ///   P_loss = stator + rotor copper + iron losses [W].
    ///
    /// The default tau_s = 3 s is accelerated so that short runs show the drift; real
    /// machines have 10 - 60 min. Resistances are updated once per output sample.
    ThermalDrift {
        /// Final temperature rise [K] (prescribed mode), default 60.
        #[serde(default)]
        rise_k: Option<f64>,
        /// Thermal time constant [s], default 3.
        #[serde(default = "d_tau_s")]
        tau_s: f64,
        /// Start of heating [s], default 0.
        #[serde(default)]
        at_s: f64,
        /// Thermal resistance [K/W]; switches to the loss-driven mode.
        #[serde(default)]
        r_th_k_per_w: Option<f64>,
        /// Temperature coefficient of resistance [1/K], default 0.00393 (copper).
        #[serde(default = "d_alpha")]
        alpha_per_k: f64,
        /// Heat the rotor cage too (default true).
        #[serde(default = "d_true")]
        rotor: bool,
    },
    /// Main-flux saturation: Lm(psi_m) = Lm0 / (1 + (|psi_m| / psi_sat)^n), Lm0 = the
    /// parameter file's lm_h (unsaturated value), psi_m = Lm (i_s + i_r) the magnetising
    /// flux linkage [Wb, peak]. Leakages are unchanged, Ls = Lls + Lm and Lr = Llr + Lm follow.
    /// Solved exactly at every derivative evaluation (secant iteration on Lm).
    /// Default psi_sat = 1.3 x rated flux (V_phase,peak / omega_e) and n = 6: Lm is about
    /// 17 % below Lm0 at rated voltage, the no-load current correspondingly larger.
    Saturation {
        /// Saturation flux psi_sat [Wb peak]; default `psi_sat_ratio` x rated flux.
        #[serde(default)]
        psi_sat_wb: Option<f64>,
        /// psi_sat as a multiple of the rated flux when `psi_sat_wb` is not given, default 1.3.
        #[serde(default = "d_sat_ratio")]
        psi_sat_ratio: f64,
        /// Exponent n (> 0), default 6.
        #[serde(default = "d_sat_exp")]
        exponent: f64,
    },
    /// Core loss: a resistance Rfe [ohm] across the magnetising branch, placed at the
    /// air-gap side of Rs (before the stator leakage; exact for the Gamma model, Lls = 0,
    /// and an O(Lls/Lm) approximation otherwise). u = dpsi_s/dt, terminal current
    /// i = i_s + u / Rfe, iron loss P_fe = (3/2) |u|^2 / Rfe.
    /// Default Rfe = 25 x Xm (Xm = 2 pi f_n Lm): 3 % to 4 % of rated power.
    IronLoss {
        /// Core-loss resistance [ohm]; default `rfe_over_xm` x Xm.
        #[serde(default)]
        rfe_ohm: Option<f64>,
        /// Rfe / Xm when `rfe_ohm` is not given, default 25.
        #[serde(default = "d_iron_ratio")]
        rfe_over_xm: f64,
    },
    /// Coulomb (dry) friction: T = Tc tanh(omega_m / omega_0) [N m], smooth near standstill.
    /// Default Tc = 2 % of the rated torque estimate (Bl x synchronous mechanical speed, or
    /// the torque load's largest step), omega_0 = 1 rad/s.
    CoulombFriction {
        /// Friction torque Tc [N m].
        #[serde(default)]
        torque_nm: Option<f64>,
        /// Smoothing speed omega_0 [rad/s] (mechanical), default 1.
        #[serde(default = "d_coulomb_w")]
        omega0_rad_s: f64,
    },
    /// Windage / fan load: T = k omega_m |omega_m| [N m], k in N m s^2/rad^2.
    /// Default k: 5 % of the rated torque estimate at synchronous speed.
    Windage {
        /// Coefficient k [N m s^2 / rad^2].
        #[serde(default)]
        k_nms2: Option<f64>,
    },
    /// The load as a constant torque input instead of Bl omega (replaces a viscous load).
    /// Default torque = Bl x synchronous mechanical speed (the viscous load's value at
    /// synchronous speed), applied from standstill.
    LoadTorque {
        /// Constant load torque [N m].
        #[serde(default)]
        torque_nm: Option<f64>,
    },
    /// Negative-sequence supply voltage: v = V e^{j theta} + k V e^{-j theta + j phi}
    /// (alpha-beta, amplitude-invariant). Default k = 0.03 (3 % voltage unbalance), phi = 0.
    SupplyUnbalance {
        /// Negative-sequence fraction k (0..0.5).
        #[serde(default = "d_unb")]
        fraction: f64,
        /// Negative-sequence angle phi [deg].
        #[serde(default)]
        angle_deg: f64,
    },
    /// Shorted turns in one stator phase (inter-turn short) as they are (Tallam, Habetler,
    /// Harley, IEEE Trans. Ind. Appl. 38(3), 2002): a fraction mu of that phase's turns
    /// shorted through a fault resistance r_f. The shorted turns stay in the winding; the
    /// loop carries the fault current i_f, `(mu Lls/3) di_f/dt = u_k . v_s - R_f i_f`,
    /// `R_f = Rs (1 - 2mu/3) + r_f/mu`, and the terminals draw (2/3) mu i_f u_k on top of the
    /// healthy machine's current (star connection, isolated neutral; `sim::machine` docs).
    /// The negative-sequence current is `I2/I1 = (mu/3) (Z1/Z_f) a^k`. Default mu = 0.05 in
    /// phase a through r_f = Rs/10 (a low-resistance short, as insulation breakdown makes:
    /// the loop draws a few times the rated current). A bolted short (`r_f = 0`) of a few
    /// per cent of the turns draws a loop current of V/Rs, tens of times the rated current.
    PhaseAsymmetry {
        /// Faulty phase, default "a".
        #[serde(default = "d_phase_a")]
        phase: Phase,
        /// Fraction mu of the winding shorted (0..0.5), default 0.05.
        #[serde(default = "d_asym")]
        fraction: f64,
        /// Fault resistance r_f of the short [ohm], >= 0; default a tenth of the phase's
        /// resistance Rs.
        #[serde(default)]
        fault_resistance_ohm: Option<f64>,
    },
    /// Rotor cage asymmetry (broken rotor bars): rotor phase a's resistance is
    /// Rr (1 + delta), the others Rr. In the rotor's own alpha-beta frame (amplitude-invariant
    /// Clarke, isolated neutral) the rotor resistance is the matrix
    /// R_r = Rr I + (2/3) Rr delta e_a e_a^T; in the stator frame it turns with the rotor,
    /// R_r(theta) = Rr I + (2/3) Rr delta u u^T, u = (cos Np theta_m, sin Np theta_m), and the
    /// rotor voltage equation becomes dpsi_r/dt = -R_r(theta) i_r + J omega_r psi_r. The
    /// extra rotor loss is (3/2) i_r^T R_r i_r - (3/2) Rr |i_r|^2.
    ///
    /// Give `delta` (relative resistance asymmetry, 0..10), or `broken_bars` n with `bars`
    /// N: delta = 3n / (N - 3n) (the usual approximation for n adjacent broken bars of an
    /// N-bar cage, Kliman et al., IEEE Trans. Energy Convers. 3(4), 1988; Bellini et al.,
    /// IEEE Trans. Ind. Appl. 37(5), 2001; it ignores the inter-bar currents and the
    /// end-ring redistribution). Default delta = 0.1 (about one broken bar of 28).
    RotorAsymmetry {
        /// Relative rotor phase resistance asymmetry delta [-] (0..10).
        #[serde(default)]
        delta: Option<f64>,
        /// Number of adjacent broken bars n (with `bars`; instead of `delta`).
        #[serde(default)]
        broken_bars: Option<f64>,
        /// Rotor bar count N (with `broken_bars`).
        #[serde(default)]
        bars: Option<f64>,
    },
    /// Rotor flux dynamics (Lr/Rr): always present in the full-order model; a no-op here.
    FluxDynamics {},
    /// Stator current dynamics (La dI/dt): always present in the full-order model; a no-op.
    CurrentDynamics {},
    /// d-axis stator dynamics: always present in the full-order model; a no-op.
    DAxisDynamics {},
    /// Cross-coupling and q-axis rotor flux: always present in the full-order model; a no-op.
    CrossCouplingDynamics {},
}

impl EffectSpec {
    /// Which effect.
    pub fn kind(&self) -> EffectKind {
        match self {
            EffectSpec::ThermalDrift { .. } => EffectKind::ThermalDrift,
            EffectSpec::Saturation { .. } => EffectKind::Saturation,
            EffectSpec::IronLoss { .. } => EffectKind::IronLoss,
            EffectSpec::CoulombFriction { .. } => EffectKind::CoulombFriction,
            EffectSpec::Windage { .. } => EffectKind::Windage,
            EffectSpec::LoadTorque { .. } => EffectKind::LoadTorque,
            EffectSpec::SupplyUnbalance { .. } => EffectKind::SupplyUnbalance,
            EffectSpec::PhaseAsymmetry { .. } => EffectKind::PhaseAsymmetry,
            EffectSpec::FluxDynamics {} => EffectKind::FluxDynamics,
            EffectSpec::CurrentDynamics {} => EffectKind::CurrentDynamics,
            EffectSpec::RotorAsymmetry { .. } => EffectKind::RotorAsymmetry,
            EffectSpec::DAxisDynamics {} => EffectKind::DAxisDynamics,
            EffectSpec::CrossCouplingDynamics {} => EffectKind::CrossCouplingDynamics,
        }
    }

    /// The effect with every parameter at its default (as `name = "<kind>"` alone in a
    /// scenario file gives it).
    pub fn with_defaults(kind: EffectKind) -> EffectSpec {
        match kind {
            EffectKind::ThermalDrift => EffectSpec::ThermalDrift {
                rise_k: None,
                tau_s: d_tau_s(),
                at_s: 0.0,
                r_th_k_per_w: None,
                alpha_per_k: d_alpha(),
                rotor: d_true(),
            },
            EffectKind::Saturation => EffectSpec::Saturation {
                psi_sat_wb: None,
                psi_sat_ratio: d_sat_ratio(),
                exponent: d_sat_exp(),
            },
            EffectKind::IronLoss => EffectSpec::IronLoss {
                rfe_ohm: None,
                rfe_over_xm: d_iron_ratio(),
            },
            EffectKind::CoulombFriction => EffectSpec::CoulombFriction {
                torque_nm: None,
                omega0_rad_s: d_coulomb_w(),
            },
            EffectKind::Windage => EffectSpec::Windage { k_nms2: None },
            EffectKind::LoadTorque => EffectSpec::LoadTorque { torque_nm: None },
            EffectKind::SupplyUnbalance => EffectSpec::SupplyUnbalance {
                fraction: d_unb(),
                angle_deg: 0.0,
            },
            EffectKind::PhaseAsymmetry => EffectSpec::PhaseAsymmetry {
                phase: d_phase_a(),
                fraction: d_asym(),
                fault_resistance_ohm: None,
            },
            EffectKind::FluxDynamics => EffectSpec::FluxDynamics {},
            EffectKind::CurrentDynamics => EffectSpec::CurrentDynamics {},
            EffectKind::RotorAsymmetry => EffectSpec::RotorAsymmetry {
                delta: None,
                broken_bars: None,
                bars: None,
            },
            EffectKind::DAxisDynamics => EffectSpec::DAxisDynamics {},
            EffectKind::CrossCouplingDynamics => EffectSpec::CrossCouplingDynamics {},
        }
    }

    /// Checks the parameters' ranges.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key (`effects.<name>.<parameter>`).
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            EffectSpec::ThermalDrift { .. } => self.validate_thermal(),
            EffectSpec::Saturation { .. } | EffectSpec::IronLoss { .. } => self.validate_core(),
            EffectSpec::CoulombFriction { .. }
            | EffectSpec::Windage { .. }
            | EffectSpec::LoadTorque { .. } => self.validate_shaft(),
            EffectSpec::SupplyUnbalance { .. } | EffectSpec::PhaseAsymmetry { .. } => {
                self.validate_unbalance()
            }
            EffectSpec::FluxDynamics {}
            | EffectSpec::CurrentDynamics {}
            | EffectSpec::DAxisDynamics {}
            | EffectSpec::CrossCouplingDynamics {} => Ok(()),
            EffectSpec::RotorAsymmetry { .. } => self.rotor_delta().map(|_| ()),
        }
    }

    /// The key of parameter `p` of this effect, `effects.<name>.<p>`.
    fn key(&self, p: &str) -> String {
        format!("effects.{}.{p}", self.kind().name())
    }

    /// `thermal_drift`'s ranges: a finite rise of at least -200 K (or a thermal
    /// resistance, not both), a positive time constant, the rest not negative.
    fn validate_thermal(&self) -> Result<(), SimError> {
        let k = |p: &str| self.key(p);
        let EffectSpec::ThermalDrift {
            rise_k,
            tau_s,
            at_s,
            r_th_k_per_w,
            alpha_per_k,
            ..
        } = self
        else {
            return Ok(());
        };
        if let Some(r) = rise_k {
            if !r.is_finite() || *r < -200.0 {
                return invalid(&k("rise_k"), format!("must be finite, >= -200, got {r}"));
            }
        }
        if rise_k.is_some() && r_th_k_per_w.is_some() {
            return invalid(&k("rise_k"), "give rise_k or r_th_k_per_w, not both".into());
        }
        positive(&k("tau_s"), *tau_s)?;
        not_negative(&k("at_s"), *at_s)?;
        if let Some(r) = r_th_k_per_w {
            not_negative(&k("r_th_k_per_w"), *r)?;
        }
        not_negative(&k("alpha_per_k"), *alpha_per_k)
    }

    /// `saturation`'s and `iron_loss`'s values: positive.
    fn validate_core(&self) -> Result<(), SimError> {
        let k = |p: &str| self.key(p);
        match self {
            EffectSpec::Saturation {
                psi_sat_wb,
                psi_sat_ratio,
                exponent,
            } => {
                if let Some(p) = psi_sat_wb {
                    positive(&k("psi_sat_wb"), *p)?;
                }
                positive(&k("psi_sat_ratio"), *psi_sat_ratio)?;
                positive(&k("exponent"), *exponent)
            }
            EffectSpec::IronLoss {
                rfe_ohm,
                rfe_over_xm,
            } => {
                if let Some(r) = rfe_ohm {
                    positive(&k("rfe_ohm"), *r)?;
                }
                positive(&k("rfe_over_xm"), *rfe_over_xm)
            }
            _ => Ok(()),
        }
    }

    /// The shaft's torques: friction and windage not negative, a load torque finite.
    fn validate_shaft(&self) -> Result<(), SimError> {
        let k = |p: &str| self.key(p);
        match self {
            EffectSpec::CoulombFriction {
                torque_nm,
                omega0_rad_s,
            } => {
                if let Some(t) = torque_nm {
                    not_negative(&k("torque_nm"), *t)?;
                }
                positive(&k("omega0_rad_s"), *omega0_rad_s)
            }
            EffectSpec::Windage { k_nms2: Some(v) } => not_negative(&k("k_nms2"), *v),
            EffectSpec::LoadTorque { torque_nm: Some(t) } if !t.is_finite() => {
                invalid(&k("torque_nm"), format!("must be finite, got {t}"))
            }
            _ => Ok(()),
        }
    }

    /// The unbalances: fractions in 0..0.5, a finite angle, a fault resistance not
    /// negative.
    fn validate_unbalance(&self) -> Result<(), SimError> {
        let k = |p: &str| self.key(p);
        let fraction = |key: &str, f: f64| {
            if f.is_finite() && (0.0..=0.5).contains(&f) {
                Ok(())
            } else {
                invalid(key, format!("must be in 0..0.5, got {f}"))
            }
        };
        match self {
            EffectSpec::SupplyUnbalance {
                fraction: f,
                angle_deg,
            } => {
                fraction(&k("fraction"), *f)?;
                if angle_deg.is_finite() {
                    Ok(())
                } else {
                    invalid(&k("angle_deg"), "must be finite".into())
                }
            }
            EffectSpec::PhaseAsymmetry {
                fraction: f,
                fault_resistance_ohm: rf,
                ..
            } => {
                fraction(&k("fraction"), *f)?;
                rf.map_or(Ok(()), |r| not_negative(&k("fault_resistance_ohm"), r))
            }
            _ => Ok(()),
        }
    }

    /// The rotor resistance asymmetry delta of a `rotor_asymmetry` effect (0 for any
    /// other effect): `delta`, or 3n/(N - 3n) from `broken_bars` n and `bars` N.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key when a value is out of range or the keys do not
    /// go together.
    pub fn rotor_delta(&self) -> Result<f64, SimError> {
        let EffectSpec::RotorAsymmetry {
            delta,
            broken_bars,
            bars,
        } = *self
        else {
            return Ok(0.0);
        };
        let k = |p: &str| format!("effects.rotor_asymmetry.{p}");
        let bad = |key: &str, message: String| -> Result<f64, SimError> {
            Err(SimError::Invalid {
                key: key.to_string(),
                message,
            })
        };
        match (delta, broken_bars, bars) {
            (Some(_), Some(_), _) => bad(&k("delta"), "give delta or broken_bars, not both".into()),
            (Some(d), None, _) if d.is_finite() && (0.0..=10.0).contains(&d) => Ok(d),
            (Some(d), None, _) => bad(&k("delta"), format!("must be in 0..10, got {d}")),
            (None, Some(n), Some(nb)) => {
                if !(nb.is_finite() && nb >= 6.0) {
                    return bad(&k("bars"), format!("must be at least 6, got {nb}"));
                }
                if !(n.is_finite() && n >= 0.0 && 3.0 * n < nb) {
                    return bad(
                        &k("broken_bars"),
                        format!("must be in 0..{} (N/3) for {nb} bars, got {n}", nb / 3.0),
                    );
                }
                let d = monitor_core::rotor_cage::delta_of_broken_bars(n, nb);
                if d <= 10.0 {
                    Ok(d)
                } else {
                    bad(&k("broken_bars"), format!("gives delta = {d} > 10"))
                }
            }
            (None, Some(_), None) => bad(&k("bars"), "broken_bars needs the bar count bars".into()),
            (None, None, _) => Ok(d_rotor_delta()),
        }
    }
}

fn d_rotor_delta() -> f64 {
    0.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_effect_kind_parses_with_defaults() {
        for kind in EffectKind::ALL {
            let text = format!("name = \"{}\"", kind.name());
            let parsed: EffectSpec = toml::from_str(&text).unwrap();
            assert_eq!(parsed, EffectSpec::with_defaults(kind));
            assert_eq!(parsed.kind(), kind);
        }
    }
}
