//! `cross_coupling_dynamics`: the q-axis rotor flux and the slip coupling between the axes.

use super::{About, StateSwitch};
use monitor_laws::EffectId;

/// The q-axis rotor flux and the cross-coupling. A dynamic q-axis flux against a measured
/// (not predicted) I_ds is not a consistent machine, so it needs `d_axis_dynamics` first;
/// without the d-axis equation the model keeps psi_Rq quasi-static.
pub const CROSS_COUPLING_DYNAMICS: StateSwitch = StateSwitch {
    about: About {
        kind: EffectId::CROSS_COUPLING_DYNAMICS,
        description: "In a transient the rotor flux is not on the frame's d axis: a q-axis rotor flux appears and the slip couples the axes (the paper's orientation assumes psi_qr = 0 at every instant).",
        equations: "dpsi_Rq/dt = Rr' I_qs - (Rr'/L_M) psi_Rq - (omega_k - omega_r) psi_Rd, dpsi_Rd/dt gains + (omega_k - omega_r) psi_Rq; both current equations gain the omega_k L_sigma cross terms; torque (3/2) Np (psi_Rd I_qs - psi_Rq I_ds).",
        parameters: &[],
    },
    requires: &[EffectId::D_AXIS_DYNAMICS],
    switch_on: |d| d.rotor_flux_q_axis = true,
    summary: |n| {
        format!(
            "the rotor flux leaves the frame's d axis in transients and the axes are coupled through the slip (rotor time constant {:.0} ms)",
            1000.0 * n.lr_h / n.rr_ohm
        )
    },
};
