//! `iron_loss`: core loss.

use super::{plausible, rated_flux_wb, sync_speed_mech};
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Core loss.
pub struct IronLoss;

impl EffectModel for IronLoss {
    fn kind(&self) -> EffectKind {
        EffectKind::IronLoss
    }
    fn description(&self) -> &'static str {
        "Eddy-current and hysteresis losses in the core draw a current in phase with the air-gap voltage, modelled as a resistance Rfe across the magnetising branch."
    }
    fn equations(&self) -> &'static str {
        "I_qs(measured) = I_qs(torque, eq. 28) + omega_s Ls i_f / Rfe; only the torque part drives eq. (29); Rs carries the core-loss current too (V_qs - Rs i_fe in eq. 28); the flux current is I_ds + omega_s sigma Ls I_qs / Rfe; and the voltage-model frame, built from the terminal current, is turned by (Lr/Lm) sigma Ls omega_s Ls / (Lm Rfe) against the rotor flux, which the model undoes."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "g_fe_s",
            unit: "S",
            description: "core-loss conductance 1/Rfe",
        }]
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, String> {
        let w = sync_speed_mech(d, n) * n.np;
        let xm = w * n.lm_h;
        let mut s = FitSetup::default();
        s.push(
            "g_fe_s",
            "S",
            1.0 / (100.0 * xm),
            -0.2 / xm,
            1.0 / xm,
            0.02 / xm,
        );
        s.range(
            -0.01 / xm,
            1.0 / (plausible::RFE_OVER_XM_MIN * xm),
            plausible::G_FE_BASIS,
        );
        s.data.push(xm);
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
        terms.g_fe_s = p[0];
    }
    fn describe(&self, s: &FitSetup, p: &[f64], d: &Prepared, n: &MachineConstants) -> String {
        let xm = s.data.first().copied().unwrap_or(1.0);
        let psi = rated_flux_wb(d);
        let w = sync_speed_mech(d, n) * n.np;
        let p_fe = 1.5 * (w * psi).powi(2) * p[0];
        if p[0] <= 0.0 {
            return "no core loss found (fitted conductance not positive)".into();
        }
        format!(
            "core loss resistance Rfe about {:.0} ohm ({:.0} x Xm), about {:.0} W of iron loss at the highest supply frequency of the log",
            1.0 / p[0],
            1.0 / (p[0] * xm),
            p_fe
        )
    }
}
