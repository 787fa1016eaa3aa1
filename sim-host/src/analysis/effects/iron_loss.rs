//! `iron_loss`: core loss.

use super::{
    plausible, rated_flux_wb, sync_speed_mech, About, Contribution, EffectModel, FitParam,
    FitSetup, ParamSpec, SetupError,
};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Core loss.
#[derive(Debug, Clone, Copy)]
pub struct IronLoss;

/// Iron loss set up on a log: the magnetising reactance at the log's highest supply
/// frequency.
struct OnLog {
    /// Xm [ohm].
    xm_ohm: f64,
}

/// What `IronLoss` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::IronLoss,
    description: "Eddy-current and hysteresis losses in the core draw a current in phase with the air-gap voltage, modelled as a resistance Rfe across the magnetising branch.",
    equations: "I_qs(measured) = I_qs(torque, eq. 28) + omega_s Ls i_f / Rfe; only the torque part drives eq. (29); Rs carries the core-loss current too (V_qs - Rs i_fe in eq. 28); the flux current is I_ds + omega_s sigma Ls I_qs / Rfe; and the voltage-model frame, built from the terminal current, is turned by (Lr/Lm) sigma Ls omega_s Ls / (Lm Rfe) against the rotor flux, which the model undoes.",
    parameters: &[ParamSpec {
        name: "g_fe_s",
        unit: "S",
        description: "core-loss conductance 1/Rfe",
    }],
};

impl EffectModel for IronLoss {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let w = sync_speed_mech(d, n) * n.np;
        let xm = w * n.lm_h;
        Ok(FitSetup::new(OnLog { xm_ohm: xm }).param(
            FitParam::new(
                "g_fe_s",
                "S",
                1.0 / (100.0 * xm),
                (-0.2 / xm, 1.0 / xm),
                0.02 / xm,
            )
            .physical(
                (-0.01 / xm, 1.0 / (plausible::RFE_OVER_XM_MIN * xm)),
                plausible::G_FE_BASIS,
            ),
        ))
    }
}

impl Contribution for OnLog {
    /// The core-loss conductance.
    fn contribute(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        if let &[g_fe_s] = p {
            t.magnetising.core_loss_s += g_fe_s;
        }
    }
    fn describe(&self, p: &[f64], d: &Prepared, n: &MachineConstants) -> String {
        let &[g] = p else {
            return String::new();
        };
        let xm = self.xm_ohm;
        let psi = rated_flux_wb(d);
        let w = sync_speed_mech(d, n) * n.np;
        let p_fe = 1.5 * (w * psi).powi(2) * g;
        if g <= 0.0 {
            return "no core loss found (fitted conductance not positive)".into();
        }
        format!(
            "core loss resistance Rfe about {:.0} ohm ({:.0} x Xm), about {:.0} W of iron loss at the highest supply frequency of the log",
            1.0 / g,
            1.0 / (g * xm),
            p_fe
        )
    }
}
