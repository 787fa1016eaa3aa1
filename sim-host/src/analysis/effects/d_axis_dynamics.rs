//! `d_axis_dynamics`: the d-axis stator equation (I_ds predicted).

use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// The d-axis stator equation (I_ds predicted).
pub struct DAxisDynamics;

impl EffectModel for DAxisDynamics {
    fn kind(&self) -> EffectKind {
        EffectKind::DAxisDynamics
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn description(&self) -> &'static str {
        "The flux-producing current is not a constant input: after a start or a supply step, I_ds follows the d-axis voltage through the transient inductance and the rotor flux, which the paper's model (i_f taken from the measurement) does not predict."
    }
    fn equations(&self) -> &'static str {
        "L_sigma dI_ds/dt = V_ds - (Rs + Rr') I_ds + omega_k L_sigma I_qs + (Rr'/L_M) psi_Rd + omega_r psi_Rq (inverse-Gamma form, frame speed omega_k); the predicted I_ds replaces the measured one in the phase currents and drives the flux."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[]
    }
    fn setup(&self, _d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, String> {
        Ok(FitSetup::default())
    }
    fn apply(
        &self,
        _s: &FitSetup,
        _p: &[f64],
        _d: &Prepared,
        _n: &MachineConstants,
        terms: &mut EffectTerms,
    ) {
        terms.d_axis = true;
    }
    fn describe(&self, _s: &FitSetup, _p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        format!(
            "the flux-producing current I_ds follows the d-axis voltage with the stator transient time constant (about {:.1} ms) instead of being a measured constant",
            1000.0 * n.la_h / n.ra_ohm
        )
    }
}
