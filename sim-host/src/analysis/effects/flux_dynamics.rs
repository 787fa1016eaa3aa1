//! `flux_dynamics`: the rotor flux is not constant.

use super::plausible;
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Rotor flux not constant.
pub struct FluxDynamics;

impl EffectModel for FluxDynamics {
    fn kind(&self) -> EffectKind {
        EffectKind::FluxDynamics
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.lr_h / n.rr_ohm)
    }
    fn description(&self) -> &'static str {
        "The rotor flux cannot change instantly: it follows the magnetising current with the rotor time constant Lr/Rr, so after a start or a supply step the model's Psi = Ls i_f is wrong for a few hundred ms."
    }
    fn equations(&self) -> &'static str {
        "phi = psi_r/Lm, dphi/dt = (i_f - phi)/tau_r; Psi' = sigma Ls i_f + (Lm^2/Lr) phi replaces Ls i_f in eq. (28), the slip term Rr (Ls/Lr) becomes Rr Psi'/(Lr phi), Kf uses phi instead of i_f."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "tau_r_s",
            unit: "s",
            description: "rotor time constant Lr/Rr",
        }]
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, String> {
        let tau = n.lr_h / n.rr_ohm;
        let mut s = FitSetup::default();
        s.push("tau_r_s", "s", tau, 0.3 * tau, 3.0 * tau, 0.2 * tau);
        s.range(
            plausible::DYNAMICS_RATIO.0 * tau,
            plausible::DYNAMICS_RATIO.1 * tau,
            plausible::DYNAMICS_BASIS,
        );
        s.data.push(tau);
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
        terms.tau_r_s = Some(p[0]);
    }
    fn describe(&self, s: &FitSetup, p: &[f64], _d: &Prepared, _n: &MachineConstants) -> String {
        format!(
            "rotor flux lags the magnetising current with a rotor time constant of {:.0} ms (nominal Lr/Rr = {:.0} ms): the model's constant-flux assumption fails in transients",
            1000.0 * p[0],
            1000.0 * s.data.first().copied().unwrap_or(0.0)
        )
    }
}
