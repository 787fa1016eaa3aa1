//! `supply_unbalance`: negative-sequence supply voltage.

use super::impedance::{z2_neg, z2_neg_at};
use super::{
    declared_values, plausible, supply_unbalanced, sync_speed_mech, About, Confusion, Contribution,
    EffectEvidence, EffectModel, EffectParam, EffectValuesError, FitSetup, SetupError,
};
use crate::prep::{Prepared, C64};
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_core::EffectKind;

/// Negative-sequence supply voltage.
#[derive(Debug, Clone, Copy)]
pub struct SupplyUnbalance;

/// Supply unbalance's parameters.
const PARAMS: [EffectParam; 2] = [
    EffectParam {
        name: "y_re",
        unit: "1",
        doc: "real part of the negative-sequence admittance relative to nominal 1/Z2",
        range: plausible::Y2_RE,
        per: None,
        basis: plausible::Y2_BASIS,
    },
    EffectParam {
        name: "y_im",
        unit: "1",
        doc: "imaginary part of the negative-sequence admittance relative to nominal 1/Z2",
        range: plausible::Y2_IM,
        per: None,
        basis: plausible::Y2_BASIS,
    },
];

/// Supply unbalance's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SupplyUnbalanceValues {
    /// The negative-sequence admittance relative to nominal 1/Z2, real part [1].
    pub y_re: f64,
    /// Its imaginary part [1].
    pub y_im: f64,
}

impl TryFrom<&[f64]> for SupplyUnbalanceValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [y_re, y_im] = declared_values(EffectKind::SupplyUnbalance, &PARAMS, v)?;
        Ok(SupplyUnbalanceValues { y_re, y_im })
    }
}

/// What `SupplyUnbalance` is ([`About`]).
const ABOUT: About = About {
    kind: EffectKind::SupplyUnbalance,
    description: "The supply voltages are not balanced: a negative-sequence voltage drives a negative-sequence current through the machine's small negative-sequence impedance (2f ripple in the d-q frame).",
    equations: "i_abc = balanced model current + i_neg, i_neg = (y_re + j y_im) v_neg / conj(Z2(omega_s)), Z2 = Rs + j w Lls + (j w Lm)||(Rr/s2 + j w Llr) at the negative-sequence slip s2 = 1 + omega_r/omega_s (2 without a speed column); the balanced model is driven by the positive-sequence V_qs. Full-order model (all dynamics effects in): the machine is driven by V_pos + (y_re + j y_im) V_neg, and its own equations give the negative-sequence current (through a start, and with the 2f torque and speed ripple).",
    parameters: &PARAMS,
};

impl EffectModel for SupplyUnbalance {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn confused_with(&self) -> &'static [Confusion] {
        // Both add a negative-sequence current; at one operating point they fit alike.
        &[Confusion {
            with: EffectKind::PhaseAsymmetry,
            within: 1.25,
        }]
    }
    fn evidence(&self, e: &EffectEvidence<'_>) -> Option<bool> {
        Some(supply_unbalanced(e))
    }
    fn setup(&self, _d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let [y_re, y_im] = &PARAMS;
        let params = vec![
            y_re.fit(0.5, (-5.0, 5.0), 0.2, 1.0),
            y_im.fit(0.0, (-5.0, 5.0), 0.2, 1.0),
        ];
        Ok(FitSetup::new(*self, params)?)
    }
}

impl Contribution for SupplyUnbalance {
    type Values = SupplyUnbalanceValues;
    fn values(&self, v: &[f64]) -> Result<SupplyUnbalanceValues, EffectValuesError> {
        SupplyUnbalanceValues::try_from(v)
    }
    /// The reduced model's negative-sequence current `y v_neg / conj(Z2)` per sample, and
    /// the full-order model's drive `y v_neg` of the machine.
    fn contribute(
        &self,
        p: &SupplyUnbalanceValues,
        d: &Prepared,
        n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        let y = C64::new(p.y_re, p.y_im);
        t.add_negative_sequence_current((0..d.len()).map(|k| {
            // The measured speed gives the negative-sequence slip; without it the rotor
            // is taken as near synchronous speed (slip 2).
            let w = d.omega_s[k];
            let s2 = match d.omega_r.get(k) {
                Some(wr) if w.abs() > 1.0 => 1.0 + wr / w,
                _ => 2.0,
            };
            y * d.v_neg[k] / z2_neg_at(n, w, s2).conj()
        }));
        t.negative_sequence.voltage_gain = Some(y);
    }
    fn describe(&self, p: &SupplyUnbalanceValues, d: &Prepared, n: &MachineConstants) -> String {
        let (y_re, y_im) = (p.y_re, p.y_im);
        let (mut vn, mut vp) = (0.0, 0.0);
        for k in 0..d.len() {
            vn += d.v_neg[k].norm_sqr();
            vp += d.vq[k] * d.vq[k] + d.vd[k] * d.vd[k];
        }
        let ratio = (vn / vp.max(1e-12)).sqrt();
        let w = sync_speed_mech(d, n) * n.np;
        let z = z2_neg(n, w).norm() / C64::new(y_re, y_im).norm().max(1e-9);
        format!(
            "supply voltage unbalance of {:.1} % (negative sequence / positive sequence); the machine's negative-sequence impedance is about {:.1} ohm (nominal {:.1} ohm)",
            100.0 * ratio,
            z,
            z2_neg(n, w).norm()
        )
    }
}
