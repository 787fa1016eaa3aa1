//! `d_axis_dynamics`: the d-axis stator equation (I_ds predicted instead of measured).

use super::{About, StateSwitch};
use monitor_laws::EffectId;

/// The d-axis stator equation: I_ds predicted from V_ds.
pub const D_AXIS_DYNAMICS: StateSwitch = StateSwitch {
    about: About {
        kind: EffectId::D_AXIS_DYNAMICS,
        description: "The flux-producing current is not a constant input: after a start or a supply step, I_ds follows the d-axis voltage through the transient inductance and the rotor flux, which the paper's model (i_f taken from the measurement) does not predict.",
        equations: "L_sigma dI_ds/dt = V_ds - (Rs + Rr') I_ds + omega_k L_sigma I_qs + (Rr'/L_M) psi_Rd + omega_r psi_Rq (inverse-Gamma form, frame speed omega_k); the predicted I_ds replaces the measured one in the phase currents and drives the flux.",
        parameters: &[],
    },
    requires: &[],
    switch_on: |d| d.stator_d_axis = true,
    summary: |n| {
        format!(
            "the flux-producing current I_ds follows the d-axis voltage with the stator transient time constant (about {:.1} ms) instead of being a measured constant",
            1000.0 * n.la_h / n.ra_ohm
        )
    },
};
