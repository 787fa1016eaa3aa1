//! The names of the physical effects of the effect library (`docs/design.md`): one enum for the
//! simulator (which injects them), the model-vs-measurement analysis (which fits and ranks
//! them) and the command line (which names them). The core computes none of them; it holds
//! the names so that all parts of the workspace share one vocabulary, as they share
//! [`crate::Fault`].

/// A physical effect the paper's simplified model leaves out (`docs/design.md`). The name
/// (`snake_case`, [`EffectKind::name`]) is part of the interface: scenario files, the
/// command line and the JSON reports use it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum EffectKind {
    /// `thermal_drift`: winding resistance rising with temperature (copper +0.393 %/K).
    ThermalDrift,
    /// `saturation`: main-flux saturation, Lm falls with the magnetising current.
    Saturation,
    /// `iron_loss`: a core-loss resistance across the magnetising branch.
    IronLoss,
    /// `coulomb_friction`: a constant friction torque with the sign of the speed.
    CoulombFriction,
    /// `windage`: a load torque proportional to speed squared.
    Windage,
    /// `load_torque`: the load as a torque input instead of Bl omega.
    LoadTorque,
    /// `supply_unbalance`: a negative-sequence supply voltage.
    SupplyUnbalance,
    /// `phase_asymmetry`: one winding differs from the others (inter-turn short).
    PhaseAsymmetry,
    /// `flux_dynamics`: the rotor flux follows i_ds with the rotor time constant Lr/Rr.
    FluxDynamics,
    /// `current_dynamics`: the La dI_qs/dt term of eq. (28).
    CurrentDynamics,
    /// `rotor_asymmetry`: an unequal rotor cage (broken rotor bars): (1 +/- 2s) f sidebands
    /// in the stator current, 2 s f ripple in torque and speed.
    RotorAsymmetry,
    /// `d_axis_dynamics`: the d-axis stator voltage equation (eqs. 13-17 before the
    /// paper takes i_ds as a constant i_f): I_ds is predicted from V_ds, with its
    /// derivative and its coupling to I_qs and the rotor flux, instead of being measured.
    DAxisDynamics,
    /// `cross_coupling_dynamics`: the q-axis rotor flux and the slip coupling between the
    /// axes (the paper sets psi_qr = 0 by orientation, eq. 18): in a transient the flux
    /// leaves the frame's d axis. With every dynamics effect in, the model is the
    /// full-order T-equivalent machine driven by the measured voltages.
    CrossCouplingDynamics,
}

impl EffectKind {
    /// Every effect, in the effect library's order.
    pub const ALL: [EffectKind; 13] = [
        EffectKind::ThermalDrift,
        EffectKind::Saturation,
        EffectKind::IronLoss,
        EffectKind::CoulombFriction,
        EffectKind::Windage,
        EffectKind::LoadTorque,
        EffectKind::SupplyUnbalance,
        EffectKind::PhaseAsymmetry,
        EffectKind::FluxDynamics,
        EffectKind::CurrentDynamics,
        EffectKind::RotorAsymmetry,
        EffectKind::DAxisDynamics,
        EffectKind::CrossCouplingDynamics,
    ];

    /// The name in scenario files, on the command line and in JSON reports
    /// (`thermal_drift`, ..., `cross_coupling_dynamics`).
    pub const fn name(self) -> &'static str {
        match self {
            EffectKind::ThermalDrift => "thermal_drift",
            EffectKind::Saturation => "saturation",
            EffectKind::IronLoss => "iron_loss",
            EffectKind::CoulombFriction => "coulomb_friction",
            EffectKind::Windage => "windage",
            EffectKind::LoadTorque => "load_torque",
            EffectKind::SupplyUnbalance => "supply_unbalance",
            EffectKind::PhaseAsymmetry => "phase_asymmetry",
            EffectKind::FluxDynamics => "flux_dynamics",
            EffectKind::CurrentDynamics => "current_dynamics",
            EffectKind::RotorAsymmetry => "rotor_asymmetry",
            EffectKind::DAxisDynamics => "d_axis_dynamics",
            EffectKind::CrossCouplingDynamics => "cross_coupling_dynamics",
        }
    }

    /// Parses a name of [`EffectKind::name`] (exact, lower case).
    pub fn from_name(s: &str) -> Option<EffectKind> {
        EffectKind::ALL.into_iter().find(|e| e.name() == s)
    }

    /// True for the model's own simplifications (the dynamics the paper's steady-state
    /// model drops), as opposed to physical effects of a particular machine or supply.
    pub fn is_dynamics(self) -> bool {
        matches!(
            self,
            EffectKind::FluxDynamics
                | EffectKind::CurrentDynamics
                | EffectKind::DAxisDynamics
                | EffectKind::CrossCouplingDynamics
        )
    }
}

impl core::fmt::Display for EffectKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_design_names_and_round_trip() {
        let names: [&str; 13] = [
            "thermal_drift",
            "saturation",
            "iron_loss",
            "coulomb_friction",
            "windage",
            "load_torque",
            "supply_unbalance",
            "phase_asymmetry",
            "flux_dynamics",
            "current_dynamics",
            "rotor_asymmetry",
            "d_axis_dynamics",
            "cross_coupling_dynamics",
        ];
        for (e, n) in EffectKind::ALL.iter().zip(names) {
            assert_eq!(e.name(), n);
            assert_eq!(EffectKind::from_name(n), Some(*e));
        }
        assert_eq!(EffectKind::from_name("Thermal_drift"), None);
    }
}
