//! `supply_unbalance`: negative-sequence supply voltage.

use super::impedance::{z2_neg, z2_neg_at};
use super::{plausible, supply_unbalanced, sync_speed_mech, Confusion, Evidence};
use super::{EffectModel, FitSetup, ParamSpec};
use crate::analysis::prep::Prepared;
use crate::analysis::prep::C64;
use crate::analysis::simplified_model::{EffectTerms, MachineConstants};
use monitor_core::EffectKind;

/// Negative-sequence supply voltage.
pub struct SupplyUnbalance;

impl EffectModel for SupplyUnbalance {
    fn kind(&self) -> EffectKind {
        EffectKind::SupplyUnbalance
    }
    fn confused_with(&self) -> &'static [Confusion] {
        // Both add a negative-sequence current; at one operating point they fit alike.
        &[Confusion {
            with: EffectKind::PhaseAsymmetry,
            within: 1.25,
        }]
    }
    fn evidence(&self, e: &Evidence<'_>) -> Option<bool> {
        Some(supply_unbalanced(e))
    }
    fn description(&self) -> &'static str {
        "The supply voltages are not balanced: a negative-sequence voltage drives a negative-sequence current through the machine's small negative-sequence impedance (2f ripple in the d-q frame)."
    }
    fn equations(&self) -> &'static str {
        "i_abc = balanced model current + i_neg, i_neg = (y_re + j y_im) v_neg / conj(Z2(omega_s)), Z2 = Rs + j w Lls + (j w Lm)||(Rr/s2 + j w Llr) at the negative-sequence slip s2 = 1 + omega_r/omega_s (2 without a speed column); the balanced model is driven by the positive-sequence V_qs. Full-order model (all dynamics effects in): the machine is driven by V_pos + (y_re + j y_im) V_neg, and its own equations give the negative-sequence current (through a start, and with the 2f torque and speed ripple)."
    }
    fn parameters(&self) -> &'static [ParamSpec] {
        &[
            ParamSpec {
                name: "y_re",
                unit: "1",
                description:
                    "real part of the negative-sequence admittance relative to nominal 1/Z2",
            },
            ParamSpec {
                name: "y_im",
                unit: "1",
                description:
                    "imaginary part of the negative-sequence admittance relative to nominal 1/Z2",
            },
        ]
    }
    fn setup(&self, _d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, String> {
        let mut s = FitSetup::default();
        s.push("y_re", "1", 0.5, -5.0, 5.0, 0.2);
        s.range(plausible::Y2_RE.0, plausible::Y2_RE.1, plausible::Y2_BASIS);
        s.push("y_im", "1", 0.0, -5.0, 5.0, 0.2);
        s.range(plausible::Y2_IM.0, plausible::Y2_IM.1, plausible::Y2_BASIS);
        Ok(s)
    }
    fn apply(
        &self,
        _s: &FitSetup,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut EffectTerms,
    ) {
        let y = C64::new(p[0], p[1]);
        let add: Vec<C64> = (0..d.len())
            .map(|k| {
                // The measured speed gives the negative-sequence slip; without it the rotor
                // is taken as near synchronous speed (slip 2).
                let w = d.omega_s[k];
                let s2 = match d.omega_r.get(k) {
                    Some(wr) if w.abs() > 1.0 => 1.0 + wr / w,
                    _ => 2.0,
                };
                y * d.v_neg[k] / z2_neg_at(n, w, s2).conj()
            })
            .collect();
        add_neg(terms, add);
        // The full-order model drives the machine with y v_neg instead.
        terms.v_neg_gain = Some(y);
    }
    fn describe(&self, _s: &FitSetup, p: &[f64], d: &Prepared, n: &MachineConstants) -> String {
        let (mut vn, mut vp) = (0.0, 0.0);
        for k in 0..d.len() {
            vn += d.v_neg[k].norm_sqr();
            vp += d.vq[k] * d.vq[k] + d.vd[k] * d.vd[k];
        }
        let ratio = (vn / vp.max(1e-12)).sqrt();
        let w = sync_speed_mech(d, n) * n.np;
        let z = z2_neg(n, w).norm() / C64::new(p[0], p[1]).norm().max(1e-9);
        format!(
            "supply voltage unbalance of {:.1} % (negative sequence / positive sequence); the machine's negative-sequence impedance is about {:.1} ohm (nominal {:.1} ohm)",
            100.0 * ratio,
            z,
            z2_neg(n, w).norm()
        )
    }
}

fn add_neg(terms: &mut EffectTerms, add: Vec<C64>) {
    if terms.i_neg.len() == add.len() {
        for (a, b) in terms.i_neg.iter_mut().zip(add) {
            *a += b;
        }
    } else {
        terms.i_neg = add;
    }
}
