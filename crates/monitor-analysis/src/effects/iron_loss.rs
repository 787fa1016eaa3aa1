//! `iron_loss`: core loss.

use super::{
    declared_values, plausible, rated_flux_wb, sync_speed_mech, About, Contribution, EffectModel,
    EffectParam, EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// Core loss.
#[derive(Debug, Clone, Copy)]
pub struct IronLoss;

/// Iron loss set up on a log: the magnetising reactance at the log's highest supply
/// frequency.
struct IronLossOnLog {
    /// Xm [ohm].
    xm_ohm: f64,
}

/// Iron loss's parameters: the conductance's range runs from a slightly negative one
/// (1 % of 1/Xm) to 1/Rfe for the least plausible Rfe, [`plausible::RFE_OVER_XM_MIN`] x Xm.
const PARAMS: [EffectParam; 1] = [EffectParam {
    name: "g_fe_s",
    unit: "S",
    doc: "core-loss conductance 1/Rfe",
    range: (-0.01, 1.0 / plausible::RFE_OVER_XM_MIN),
    per: Some("1/Xm at the log's highest supply frequency"),
    basis: plausible::G_FE_BASIS,
}];

/// Iron loss's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IronLossValues {
    /// The core-loss conductance 1/Rfe [S].
    pub g_fe_s: f64,
}

impl TryFrom<&[f64]> for IronLossValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [g_fe_s] = declared_values(EffectId::IRON_LOSS, &PARAMS, v)?;
        Ok(IronLossValues { g_fe_s })
    }
}

/// What `IronLoss` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::IRON_LOSS,
    description: "Eddy-current and hysteresis losses in the core draw a current in phase with the air-gap voltage, modelled as a resistance Rfe across the magnetising branch.",
    equations: "I_qs(measured) = I_qs(torque, eq. 28) + omega_s Ls i_f / Rfe; only the torque part drives eq. (29); Rs carries the core-loss current too (V_qs - Rs i_fe in eq. 28); the flux current is I_ds + omega_s sigma Ls I_qs / Rfe; and the voltage-model frame, built from the terminal current, is turned by (Lr/Lm) sigma Ls omega_s Ls / (Lm Rfe) against the rotor flux, which the model undoes.",
    parameters: &PARAMS,
};

impl EffectModel for IronLoss {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let w = sync_speed_mech(d, n) * n.np;
        let xm = w * n.lm_h;
        let [g_fe_s] = &PARAMS;
        let params = vec![g_fe_s.fit(
            1.0 / (100.0 * xm),
            (-0.2 / xm, 1.0 / xm),
            0.02 / xm,
            1.0 / xm,
        )];
        Ok(FitSetup::new(IronLossOnLog { xm_ohm: xm }, params)?)
    }
}

impl Contribution for IronLossOnLog {
    type Values = IronLossValues;
    fn values(&self, v: &[f64]) -> Result<IronLossValues, EffectValuesError> {
        IronLossValues::try_from(v)
    }
    /// The core-loss conductance.
    fn contribute(
        &self,
        p: &IronLossValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        t.magnetising.core_loss_s += p.g_fe_s;
    }
    fn describe(&self, p: &IronLossValues, d: &Prepared, n: &MachineConstants) -> String {
        let g = p.g_fe_s;
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
