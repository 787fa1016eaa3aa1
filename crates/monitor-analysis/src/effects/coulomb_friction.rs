//! `coulomb_friction`: dry friction.

use super::{
    declared_values, plausible, About, ApartBy, Confusion, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms, SpeedTorque};
use monitor_laws::EffectId;

/// Dry friction.
#[derive(Debug, Clone, Copy)]
pub struct CoulombFriction;

/// Dry friction's parameters.
const PARAMS: [EffectParam; 1] = [EffectParam {
    name: "torque_nm",
    unit: "N m",
    doc: "dry friction torque Tc",
    range: plausible::COULOMB_RATIO,
    per: Some("the rated torque estimate"),
    basis: plausible::COULOMB_BASIS,
}];

/// Dry friction's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoulombFrictionValues {
    /// The friction torque Tc [N m].
    pub torque_nm: f64,
}

impl TryFrom<&[f64]> for CoulombFrictionValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [torque_nm] = declared_values(EffectId::COULOMB_FRICTION, &PARAMS, v)?;
        Ok(CoulombFrictionValues { torque_nm })
    }
}

/// A dry friction torque `Tc tanh(w_m / 1 rad/s)` on the shaft.
#[derive(Debug, Clone, Copy)]
struct DryFriction {
    /// Tc [N m].
    torque_nm: f64,
}

impl SpeedTorque for DryFriction {
    /// The library's dry friction law over 1 rad/s ([`monitor_laws::library::coulomb_nm`],
    /// the simulator's; no tanh when there is no dry friction).
    fn torque_nm(&self, wm_rad_s: f64) -> f64 {
        monitor_laws::library::coulomb_nm(self.torque_nm, 1.0, wm_rad_s)
    }
}

/// What `CoulombFriction` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::COULOMB_FRICTION,
    description: "Dry friction (bearings, seals, brushes): a constant torque opposing rotation whatever the speed.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - Tc tanh(w_m / 1 rad/s)  (eq. 29 plus a constant friction torque).",
    parameters: &PARAMS,
};

impl EffectModel for CoulombFriction {
    fn about(&self) -> &About {
        &ABOUT
    }
    /// The friction carries its torque itself: B + Bl is free to fall to zero.
    fn takes_viscous_part(&self) -> bool {
        true
    }
    fn confused_with(&self) -> &'static [Confusion] {
        &[Confusion {
            with: EffectId::LOAD_TORQUE,
            within: 1.10,
            apart_by: ApartBy::Reversal,
        }]
    }
    fn load_torque_at(&self, values: &[f64], w_rad_s: f64) -> Option<f64> {
        match values {
            [tc] => Some(monitor_laws::library::coulomb_nm(*tc, 1.0, w_rad_s)),
            _ => None,
        }
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let t = n.torque_scale_nm;
        let [torque_nm] = &PARAMS;
        let params = vec![torque_nm.fit(0.01 * t, (-0.1 * t, t), 0.05 * t, t)];
        Ok(FitSetup::new(*self, params)?)
    }
}

impl Contribution for CoulombFriction {
    type Values = CoulombFrictionValues;
    fn values(&self, v: &[f64]) -> Result<CoulombFrictionValues, EffectValuesError> {
        CoulombFrictionValues::try_from(v)
    }
    /// The friction torque on the shaft.
    fn contribute(
        &self,
        p: &CoulombFrictionValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        t.add_speed_torque(DryFriction {
            torque_nm: p.torque_nm,
        });
    }
    fn describe(&self, p: &CoulombFrictionValues, _d: &Prepared, n: &MachineConstants) -> String {
        let tc = p.torque_nm;
        format!(
            "constant friction torque of about {:.2} N m ({:.1} % of the rated torque estimate {:.1} N m), independent of speed",
            tc,
            100.0 * tc / n.torque_scale_nm,
            n.torque_scale_nm
        )
    }
}
