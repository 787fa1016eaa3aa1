//! `flux_dynamics`: the rotor flux is not constant.

use super::{
    declared_values, dynamics_param, plausible, About, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// Rotor flux not constant.
#[derive(Debug, Clone, Copy)]
pub struct FluxDynamics;

/// The effect's parameter.
const PARAMS: [EffectParam; 1] = [EffectParam {
    name: "tau_r_s",
    unit: "s",
    doc: "rotor time constant Lr/Rr",
    range: plausible::DYNAMICS_RATIO,
    per: Some("the nominal Lr/Rr"),
    basis: plausible::DYNAMICS_BASIS,
}];

/// The effect's fitted value ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluxDynamicsValues {
    /// The rotor time constant Lr/Rr [s].
    pub tau_r_s: f64,
}

impl TryFrom<&[f64]> for FluxDynamicsValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [tau_r_s] = declared_values(EffectId::FLUX_DYNAMICS, &PARAMS, v)?;
        Ok(FluxDynamicsValues { tau_r_s })
    }
}

/// What `FluxDynamics` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::FLUX_DYNAMICS,
    description: "The rotor flux cannot change instantly: it follows the magnetising current with the rotor time constant Lr/Rr, so after a start or a supply step the model's Psi = Ls i_f is wrong for a few hundred ms.",
    equations: "phi = psi_r/Lm, dphi/dt = (i_f - phi)/tau_r; Psi' = sigma Ls i_f + (Lm^2/Lr) phi replaces Ls i_f in eq. (28), the slip term Rr (Ls/Lr) becomes Rr Psi'/(Lr phi), Kf uses phi instead of i_f.",
    parameters: &PARAMS,
};

impl EffectModel for FluxDynamics {
    fn about(&self) -> &About {
        &ABOUT
    }
    /// The machine's own value: followed where the base parameters are refitted as the
    /// machine's.
    fn derived_from_machine(&self, n: &MachineConstants) -> Option<Vec<f64>> {
        Some(vec![n.lr_h / n.rr_ohm])
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.lr_h / n.rr_ohm)
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let [p] = &PARAMS;
        Ok(FitSetup::new(
            *self,
            vec![dynamics_param(p, n.lr_h / n.rr_ohm)],
        )?)
    }
}

impl Contribution for FluxDynamics {
    type Values = FluxDynamicsValues;
    fn values(&self, v: &[f64]) -> Result<FluxDynamicsValues, EffectValuesError> {
        FluxDynamicsValues::try_from(v)
    }
    /// The rotor flux's dynamics with the fitted rotor time constant.
    fn contribute(
        &self,
        p: &FluxDynamicsValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        t.dynamics.rotor_flux_tau_s = Some(p.tau_r_s);
    }
    fn describe(&self, p: &FluxDynamicsValues, _d: &Prepared, n: &MachineConstants) -> String {
        let tau_r_s = p.tau_r_s;
        format!(
            "rotor flux lags the magnetising current with a rotor time constant of {:.0} ms (nominal Lr/Rr = {:.0} ms): the model's constant-flux assumption fails in transients",
            1000.0 * tau_r_s,
            1000.0 * (n.lr_h / n.rr_ohm)
        )
    }
}
