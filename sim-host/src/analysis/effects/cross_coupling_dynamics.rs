//! `cross_coupling_dynamics`: q-axis rotor flux and cross-coupling.

use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// q-axis rotor flux and cross-coupling.
pub struct CrossCouplingDynamics;

impl EffectModel for CrossCouplingDynamics {
    fn kind(&self) -> EffectKind {
        EffectKind::CrossCouplingDynamics
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn requires(&self) -> &'static [EffectKind] {
        // A dynamic q-axis flux against a measured (not predicted) I_ds is not a consistent
        // machine; without the d-axis equation the model keeps psi_Rq quasi-static.
        &[EffectKind::DAxisDynamics]
    }
    fn description(&self) -> &'static str {
        "In a transient the rotor flux is not on the frame's d axis: a q-axis rotor flux appears and the slip couples the axes (the paper's orientation assumes psi_qr = 0 at every instant)."
    }
    fn equations(&self) -> &'static str {
        "dpsi_Rq/dt = Rr' I_qs - (Rr'/L_M) psi_Rq - (omega_k - omega_r) psi_Rd, dpsi_Rd/dt gains + (omega_k - omega_r) psi_Rq; both current equations gain the omega_k L_sigma cross terms; torque (3/2) Np (psi_Rd I_qs - psi_Rq I_ds)."
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
        terms.cross_coupling = true;
    }
    fn describe(&self, _s: &FitSetup, _p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        format!(
            "the rotor flux leaves the frame's d axis in transients and the axes are coupled through the slip (rotor time constant {:.0} ms)",
            1000.0 * n.lr_h / n.rr_ohm
        )
    }
}
