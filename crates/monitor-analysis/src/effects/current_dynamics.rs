//! `current_dynamics`: the stator current transient (La dI/dt).

use super::{
    declared_values, dynamics_param, plausible, About, Contribution, EffectModel, EffectParam,
    EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// Stator current transient (La dI/dt).
#[derive(Debug, Clone, Copy)]
pub struct CurrentDynamics;

/// The effect's parameter.
const PARAMS: [EffectParam; 1] = [EffectParam {
    name: "la_h",
    unit: "H",
    doc: "transient inductance La = sigma Ls",
    range: plausible::DYNAMICS_RATIO,
    per: Some("the nominal sigma Ls"),
    basis: plausible::DYNAMICS_BASIS,
}];

/// The effect's fitted value ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentDynamicsValues {
    /// The transient inductance La = sigma Ls [H].
    pub la_h: f64,
}

impl TryFrom<&[f64]> for CurrentDynamicsValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [la_h] = declared_values(EffectId::CURRENT_DYNAMICS, &PARAMS, v)?;
        Ok(CurrentDynamicsValues { la_h })
    }
}

/// What `CurrentDynamics` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::CURRENT_DYNAMICS,
    description: "The stator current cannot jump: the transient inductance La = sigma Ls delays I_qs by Ta = La/Ra (a few ms) after every voltage change.",
    equations: "La dI_qs/dt = V_qs - Ra I_qs - Psi omega_r (eq. 28 with its derivative term) instead of the quasi-static I_qs = (V_qs - Psi omega_r)/Ra.",
    parameters: &PARAMS,
};

impl EffectModel for CurrentDynamics {
    fn about(&self) -> &About {
        &ABOUT
    }
    /// The machine's own value: followed where the base parameters are refitted as the
    /// machine's.
    fn derived_from_machine(&self, n: &MachineConstants) -> Option<Vec<f64>> {
        Some(vec![n.la_h])
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let [p] = &PARAMS;
        Ok(FitSetup::new(*self, vec![dynamics_param(p, n.la_h)])?)
    }
}

impl Contribution for CurrentDynamics {
    type Values = CurrentDynamicsValues;
    fn values(&self, v: &[f64]) -> Result<CurrentDynamicsValues, EffectValuesError> {
        CurrentDynamicsValues::try_from(v)
    }
    /// The stator current's derivative term with the fitted La.
    fn contribute(
        &self,
        p: &CurrentDynamicsValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        t.dynamics.stator_current_la_h = Some(p.la_h);
    }
    fn describe(&self, p: &CurrentDynamicsValues, _d: &Prepared, n: &MachineConstants) -> String {
        let la_h = p.la_h;
        format!(
            "stator current lags voltage changes: La = {:.1} mH (nominal sigma Ls = {:.1} mH), electrical time constant about {:.1} ms",
            1000.0 * la_h,
            1000.0 * n.la_h,
            1000.0 * la_h / n.ra_ohm
        )
    }
}
