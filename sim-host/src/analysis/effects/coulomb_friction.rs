//! `coulomb_friction`: dry friction.

use super::{plausible, Confusion};
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Dry friction.
pub struct CoulombFriction;

impl EffectModel for CoulombFriction {
    fn kind(&self) -> EffectKind {
        EffectKind::CoulombFriction
    }
    fn confused_with(&self) -> &'static [Confusion] {
        &[Confusion {
            with: EffectKind::LoadTorque,
            within: 1.10,
        }]
    }
    fn description(&self) -> &'static str {
        "Dry friction (bearings, seals, brushes): a constant torque opposing rotation whatever the speed."
    }
    fn equations(&self) -> &'static str {
        "J dw_m/dt = Kf I_qs - (B + Bl) w_m - Tc tanh(w_m / 1 rad/s)  (eq. 29 plus a constant friction torque)."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "torque_nm",
            unit: "N m",
            description: "dry friction torque Tc",
        }]
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, String> {
        let t = n.torque_scale_nm;
        let mut s = FitSetup::default();
        s.push("torque_nm", "N m", 0.01 * t, -0.1 * t, t, 0.05 * t);
        s.range(
            plausible::COULOMB_RATIO.0 * t,
            plausible::COULOMB_RATIO.1 * t,
            plausible::COULOMB_BASIS,
        );
        Ok(s)
    }
    fn apply(
        &self,
        _s: &FitSetup,
        p: &[f64],
        _d: &Prepared,
        _n: &MachineConstants,
        terms: &mut EffectTerms,
    ) {
        terms.coulomb_nm = p[0];
    }
    fn describe(&self, _s: &FitSetup, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        format!(
            "constant friction torque of about {:.2} N m ({:.1} % of the rated torque estimate {:.1} N m), independent of speed",
            p[0],
            100.0 * p[0] / n.torque_scale_nm,
            n.torque_scale_nm
        )
    }
}
