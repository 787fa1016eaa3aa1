//! `flux_dynamics`: the rotor flux is not constant.

use super::{dynamics_param, About, Contribution, EffectModel, FitSetup, ParamSpec, SetupError};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Rotor flux not constant.
#[derive(Debug, Clone, Copy)]
pub struct FluxDynamics;

/// What `FluxDynamics` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::FluxDynamics,
    description: "The rotor flux cannot change instantly: it follows the magnetising current with the rotor time constant Lr/Rr, so after a start or a supply step the model's Psi = Ls i_f is wrong for a few hundred ms.",
    equations: "phi = psi_r/Lm, dphi/dt = (i_f - phi)/tau_r; Psi' = sigma Ls i_f + (Lm^2/Lr) phi replaces Ls i_f in eq. (28), the slip term Rr (Ls/Lr) becomes Rr Psi'/(Lr phi), Kf uses phi instead of i_f.",
    parameters: &[ParamSpec {
        name: "tau_r_s",
        unit: "s",
        description: "rotor time constant Lr/Rr",
    }],
};

impl EffectModel for FluxDynamics {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.lr_h / n.rr_ohm)
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        Ok(FitSetup::new(*self).param(dynamics_param("tau_r_s", "s", n.lr_h / n.rr_ohm)))
    }
}

impl Contribution for FluxDynamics {
    /// The rotor flux's dynamics with the fitted rotor time constant.
    fn contribute(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        if let &[tau_r_s] = p {
            t.dynamics.rotor_flux_tau_s = Some(tau_r_s);
        }
    }
    fn describe(&self, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        let &[tau_r_s] = p else {
            return String::new();
        };
        format!(
            "rotor flux lags the magnetising current with a rotor time constant of {:.0} ms (nominal Lr/Rr = {:.0} ms): the model's constant-flux assumption fails in transients",
            1000.0 * tau_r_s,
            1000.0 * (n.lr_h / n.rr_ohm)
        )
    }
}
