//! `current_dynamics`: the stator current transient (La dI/dt).

use super::plausible;
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Stator current transient (La dI/dt).
pub struct CurrentDynamics;

impl EffectModel for CurrentDynamics {
    fn kind(&self) -> EffectKind {
        EffectKind::CurrentDynamics
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn description(&self) -> &'static str {
        "The stator current cannot jump: the transient inductance La = sigma Ls delays I_qs by Ta = La/Ra (a few ms) after every voltage change."
    }
    fn equations(&self) -> &'static str {
        "La dI_qs/dt = V_qs - Ra I_qs - Psi omega_r (eq. 28 with its derivative term) instead of the quasi-static I_qs = (V_qs - Psi omega_r)/Ra."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[ParamSpec {
            name: "la_h",
            unit: "H",
            description: "transient inductance La = sigma Ls",
        }]
    }
    fn setup(&self, _d: &Prepared, n: &MachineConstants) -> Result<FitSetup, String> {
        let mut s = FitSetup::default();
        s.push(
            "la_h",
            "H",
            n.la_h,
            0.3 * n.la_h,
            3.0 * n.la_h,
            0.2 * n.la_h,
        );
        s.range(
            plausible::DYNAMICS_RATIO.0 * n.la_h,
            plausible::DYNAMICS_RATIO.1 * n.la_h,
            plausible::DYNAMICS_BASIS,
        );
        s.data.push(n.la_h);
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
        terms.la_h = Some(p[0]);
    }
    fn describe(&self, s: &FitSetup, p: &[f64], _d: &Prepared, n: &MachineConstants) -> String {
        format!(
            "stator current lags voltage changes: La = {:.1} mH (nominal sigma Ls = {:.1} mH), electrical time constant about {:.1} ms",
            1000.0 * p[0],
            1000.0 * s.data.first().copied().unwrap_or(0.0),
            1000.0 * p[0] / n.ra_ohm
        )
    }
}
