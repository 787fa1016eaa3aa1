//! `current_dynamics`: the stator current transient (La dI/dt).

use super::{dynamics_param, About, Contribution, EffectModel, FitSetup, ParamSpec, SetupError};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Stator current transient (La dI/dt).
#[derive(Debug, Clone, Copy)]
pub struct CurrentDynamics;

/// What `CurrentDynamics` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::CurrentDynamics,
    description: "The stator current cannot jump: the transient inductance La = sigma Ls delays I_qs by Ta = La/Ra (a few ms) after every voltage change.",
    equations: "La dI_qs/dt = V_qs - Ra I_qs - Psi omega_r (eq. 28 with its derivative term) instead of the quasi-static I_qs = (V_qs - Psi omega_r)/Ra.",
    parameters: &[ParamSpec {
        name: "la_h",
        unit: "H",
        description: "transient inductance La = sigma Ls",
    }],
};

impl EffectModel for CurrentDynamics {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        Ok(FitSetup::new(*self).param(dynamics_param("la_h", "H", n.la_h)))
    }
}

impl Contribution for CurrentDynamics {
    /// The stator current's derivative term with the fitted La.
    fn contribute(&self, p: &[f64], _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        if let &[la_h] = p {
            t.dynamics.stator_current_la_h = Some(la_h);
        }
    }
    fn describe(&self, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        let &[la_h] = p else {
            return String::new();
        };
        format!(
            "stator current lags voltage changes: La = {:.1} mH (nominal sigma Ls = {:.1} mH), electrical time constant about {:.1} ms",
            1000.0 * la_h,
            1000.0 * n.la_h,
            1000.0 * la_h / n.ra_ohm
        )
    }
}
