//! `supply_unbalance`: negative-sequence supply voltage.

use super::impedance::{z2_neg, z2_neg_at};
use super::{
    declared_values, plausible, supply_unbalanced, sync_speed_mech, About, ApartBy, Confusion,
    Contribution, EffectEvidence, EffectModel, EffectParam, EffectValuesError, FitSetup,
    SetupError, VOLTAGE_UNBALANCE_MIN,
};
use crate::prep::{Prepared, C64};
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_laws::EffectId;

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
        let [y_re, y_im] = declared_values(EffectId::SUPPLY_UNBALANCE, &PARAMS, v)?;
        Ok(SupplyUnbalanceValues { y_re, y_im })
    }
}

/// What `SupplyUnbalance` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::SUPPLY_UNBALANCE,
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
            with: EffectId::PHASE_ASYMMETRY,
            within: 1.25,
            apart_by: ApartBy::SwappedPhases,
        }]
    }
    fn evidence(&self, e: &EffectEvidence<'_>) -> Option<bool> {
        Some(supply_unbalanced(e))
    }
    /// A supply unbalance is named only where the supply shows one while its frequency is
    /// steady ([`steady_voltage_unbalance`]): through a V/f ramp or a supply step the
    /// sequence separation's own low-pass leaves a negative sequence in the measured
    /// voltage, and a full-order model driven by that part as well fits better whatever the
    /// supply (on a 22 s V/f log of a balanced converter the fit found "0.4 %" this way).
    fn contradicted_by(
        &self,
        d: &Prepared,
        _n: &MachineConstants,
        fitted: &[f64],
    ) -> Result<Option<String>, EffectValuesError> {
        SupplyUnbalanceValues::try_from(fitted)?;
        Ok(steady_voltage_unbalance(d).and_then(|r| {
            (r < VOLTAGE_UNBALANCE_MIN).then(|| {
                format!(
                    "the supply's negative sequence is {:.2} % where its frequency is steady (below the {:.1} % of a measured unbalance): what the fit took for one is the sequence separation's through frequency changes",
                    100.0 * r,
                    100.0 * VOLTAGE_UNBALANCE_MIN
                )
            })
        }))
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

/// A frequency is steady at a sample when the supply frequency 50 ms on either side is
/// within this share (0.2 %) of it.
const STEADY_FREQUENCY_REL: f64 = 0.002;

/// The supply's negative-sequence voltage over its positive sequence, RMS over the samples
/// where the supply frequency is steady ([`STEADY_FREQUENCY_REL`] over ±50 ms) and at
/// least 1 s from the log's ends and 0.3 s from any unsteady sample (the sequence filter's
/// settling); `None` when the log has no voltages or no such stretch of at least 0.5 s.
pub fn steady_voltage_unbalance(d: &Prepared) -> Option<f64> {
    let len = d.len();
    if d.v_neg.len() != len || d.vq.len() != len || len == 0 {
        return None;
    }
    let dt = d.dt_s.max(1e-9);
    let w = ((0.05 / dt).round() as usize).max(1);
    let settle = ((0.3 / dt).round() as usize).max(1);
    let steady: Vec<bool> = (0..len)
        .map(|k| {
            let (a, b) = (k.saturating_sub(w), (k + w).min(len - 1));
            let f = d.omega_s[k].abs().max(1e-9);
            (d.omega_s[a] - d.omega_s[k]).abs() <= STEADY_FREQUENCY_REL * f
                && (d.omega_s[b] - d.omega_s[k]).abs() <= STEADY_FREQUENCY_REL * f
                && d.omega_s[k].abs() > 1.0
        })
        .collect();
    // Distance to the last unsteady sample, forwards and backwards.
    let mut ok = vec![false; len];
    let mut run = 0usize;
    for k in 0..len {
        run = if steady[k] { run + 1 } else { 0 };
        ok[k] = run > settle;
    }
    run = 0;
    for k in (0..len).rev() {
        run = if steady[k] { run + 1 } else { 0 };
        ok[k] &= run > settle;
    }
    let (mut vn, mut vp, mut count) = (0.0, 0.0, 0usize);
    for k in 0..len {
        if ok[k] {
            vn += d.v_neg[k].norm_sqr();
            vp += d.vq[k] * d.vq[k] + d.vd[k] * d.vd[k];
            count += 1;
        }
    }
    (count as f64 * dt >= 0.5 && vp > 0.0).then(|| (vn / vp).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A balanced supply whose frequency ramps (with the filter's residue on the ramp) shows
    /// no unbalance where it is steady; a 2 % unbalance at a steady frequency shows.
    #[test]
    fn the_unbalance_is_read_where_the_frequency_is_steady() {
        let n = 8000;
        let dt = 5e-4;
        let omega_s: Vec<f64> = (0..n)
            .map(|k| {
                if k < 4000 {
                    100.0 + 0.05 * k as f64
                } else {
                    300.0
                }
            })
            .collect();
        let v_neg: Vec<C64> = (0..n)
            .map(|k| C64::new(if k < 4000 { 10.0 } else { 0.1 }, 0.0))
            .collect();
        let d = Prepared {
            t_s: (0..n).map(|k| k as f64 * dt).collect(),
            dt_s: dt,
            omega_s,
            vq: vec![300.0; n],
            vd: vec![0.0; n],
            v_neg,
            ..Default::default()
        };
        let r = steady_voltage_unbalance(&d).unwrap();
        assert!(r < 0.001, "{r}");
        let d2 = Prepared {
            v_neg: vec![C64::new(6.0, 0.0); n],
            ..d
        };
        let r2 = steady_voltage_unbalance(&d2).unwrap();
        assert!((r2 - 0.02).abs() < 1e-6, "{r2}");
        assert!(SupplyUnbalance
            .contradicted_by(
                &d2,
                &MachineConstants::from_params(&monitor_io::params::ParamFile::reference_2p2kw()),
                &[1.0, 0.0]
            )
            .unwrap()
            .is_none());
    }
}
