//! `coulomb_friction`: dry friction.

use super::{
    plausible, About, Confusion, Contribution, EffectModel, FitParam, FitSetup, ParamSpec,
    SetupError,
};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms, SpeedTorque};
use monitor_core::EffectKind;

/// Dry friction.
#[derive(Debug, Clone, Copy)]
pub struct CoulombFriction;

/// A dry friction torque `Tc tanh(w_m / 1 rad/s)` on the shaft.
#[derive(Debug, Clone, Copy)]
struct DryFriction {
    /// Tc [N m].
    torque_nm: f64,
}

impl SpeedTorque for DryFriction {
    fn torque_nm(&self, wm_rad_s: f64) -> f64 {
        // (No tanh when there is no dry friction: 0 x tanh(w) is 0.)
        if self.torque_nm != 0.0 {
            self.torque_nm * (wm_rad_s / 1.0).tanh()
        } else {
            0.0
        }
    }
}

/// What `CoulombFriction` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::CoulombFriction,
    description: "Dry friction (bearings, seals, brushes): a constant torque opposing rotation whatever the speed.",
    equations: "J dw_m/dt = Kf I_qs - (B + Bl) w_m - Tc tanh(w_m / 1 rad/s)  (eq. 29 plus a constant friction torque).",
    parameters: &[ParamSpec {
        name: "torque_nm",
        unit: "N m",
        description: "dry friction torque Tc",
    }],
};

impl EffectModel for CoulombFriction {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn confused_with(&self) -> &'static [Confusion] {
        &[Confusion {
            with: EffectKind::LoadTorque,
            within: 1.10,
        }]
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let t = n.torque_scale_nm;
        let r = plausible::COULOMB_RATIO;
        Ok(FitSetup::new(*self).param(
            FitParam::new("torque_nm", "N m", 0.01 * t, (-0.1 * t, t), 0.05 * t).physical_scaled(
                r,
                t,
                plausible::COULOMB_BASIS,
            ),
        ))
    }
}

impl Contribution for CoulombFriction {
    /// The friction torque on the shaft.
    fn contribute(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        if let &[torque_nm] = p {
            t.add_speed_torque(DryFriction { torque_nm });
        }
    }
    fn describe(&self, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        let &[tc] = p else {
            return String::new();
        };
        format!(
            "constant friction torque of about {:.2} N m ({:.1} % of the rated torque estimate {:.1} N m), independent of speed",
            tc,
            100.0 * tc / n.torque_scale_nm,
            n.torque_scale_nm
        )
    }
}
