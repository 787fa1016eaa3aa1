//! `phase_asymmetry`: one stator winding differs.

use super::impedance::z1_pos;
use super::{
    declared_values, plausible, supply_unbalanced, About, ApartBy, Confusion, Contribution,
    EffectEvidence, EffectModel, EffectParam, EffectValuesError, FitSetup, Needs, SetupError,
};
use crate::prep::{Prepared, C64};
use crate::simplified_model::{MachineConstants, ModelTerms, WindingAsymmetryTerm};
use crate::unbalance::{operating_point, winding_named_by, NAMED_WINDING_MIN};
use monitor_laws::EffectId;

/// One stator winding differs.
#[derive(Debug, Clone, Copy)]
pub struct PhaseAsymmetry;

/// The shorted turns set up on a log: the full-order form's loop admittance over `c`,
/// `y / c = 1 / conj(Z1)` at the log's mean operating point ([`WindingAsymmetryTerm`]).
struct PhaseAsymmetryOnLog {
    y_over_c: C64,
}

/// The winding asymmetry a fitted `c` (i_neg = c conj(i_pos)) points at, named by the
/// workspace's one faulty-phase method (`monitor_core::sequence`): in the core's phasor
/// convention `I2/I1 = conj(c)`; the correction `arg Z1` is taken at the slip of the log's
/// mean operating point `slip` and supply `w` [rad/s]. Returns the phase and the least
/// fraction of that phase's turns shorted (a bolted short; a fault resistance means more).
pub fn asymmetry_phase(
    c: C64,
    n: &MachineConstants,
    w: f64,
    slip: f64,
) -> (monitor_core::Phase, f64) {
    use monitor_core::sequence::{asymmetry_correction_rad, min_shorted_fraction, suspect_phase};
    let (we, s) = (w.abs().max(1.0) as f32, slip as f32);
    let corr = asymmetry_correction_rad(&n.core_model, we, s);
    let phase = suspect_phase(-(c.arg() as f32), corr);
    let eps = min_shorted_fraction(&n.core_model, we, s, c.norm() as f32);
    (phase, f64::from(eps))
}

/// Phase asymmetry's parameters.
const PARAMS: [EffectParam; 2] = [
    EffectParam {
        name: "c_re",
        unit: "1",
        doc: "real part of i_neg / conj(i_pos)",
        range: plausible::ASYM_C,
        per: None,
        basis: plausible::ASYM_BASIS,
    },
    EffectParam {
        name: "c_im",
        unit: "1",
        doc: "imaginary part of i_neg / conj(i_pos)",
        range: plausible::ASYM_C,
        per: None,
        basis: plausible::ASYM_BASIS,
    },
];

/// Phase asymmetry's fitted values ([`PARAMS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseAsymmetryValues {
    /// i_neg / conj(i_pos), real part [1].
    pub c_re: f64,
    /// Its imaginary part [1].
    pub c_im: f64,
}

impl TryFrom<&[f64]> for PhaseAsymmetryValues {
    type Error = EffectValuesError;
    fn try_from(v: &[f64]) -> Result<Self, EffectValuesError> {
        let [c_re, c_im] = declared_values(EffectId::PHASE_ASYMMETRY, &PARAMS, v)?;
        Ok(PhaseAsymmetryValues { c_re, c_im })
    }
}

/// What `PhaseAsymmetry` is ([`About`]).
const ABOUT: About = About {
    kind: EffectId::PHASE_ASYMMETRY,
    description: "One stator winding differs from the other two (inter-turn short, bad joint): the machine draws a negative-sequence current proportional to its load current even from a balanced supply.",
    equations: "Reduced model: i_abc = balanced model current + i_neg, i_neg = (c_re + j c_im) conj(i_pos). Shorted turns (a fraction mu of phase k through r_f; Tallam, Habetler, Harley 2002) give c = (mu/(3 R_f)) e^{j 2 th_k} conj(Z1), R_f = Rs (1 - 2mu/3) + r_f/mu. Full-order model (all dynamics effects in): the machine stays symmetric and the terminals draw the shorted loop's current |y| v + y conj(v), y = c / conj(Z1) at the log's mean operating point, so c means the same in both.",
    parameters: &PARAMS,
};

impl EffectModel for PhaseAsymmetry {
    fn about(&self) -> &About {
        &ABOUT
    }
    fn confused_with(&self) -> &'static [Confusion] {
        &[Confusion {
            with: EffectId::SUPPLY_UNBALANCE,
            within: 1.25,
            apart_by: ApartBy::SwappedPhases,
        }]
    }
    fn evidence(&self, e: &EffectEvidence<'_>) -> Option<bool> {
        Some(!supply_unbalanced(e))
    }
    fn needs(&self) -> Needs {
        Needs::CURRENTS
    }
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError> {
        let (w, slip) = operating_point(d, n);
        let k = C64::new(1.0, 0.0) / z1_pos(n, w, slip).conj();
        let k = if k.re.is_finite() && k.im.is_finite() {
            k
        } else {
            C64::new(0.0, 0.0)
        };
        let [c_re, c_im] = &PARAMS;
        let params = vec![
            c_re.fit(0.01, (-1.0, 1.0), 0.02, 1.0),
            c_im.fit(0.0, (-1.0, 1.0), 0.02, 1.0),
        ];
        Ok(FitSetup::new(PhaseAsymmetryOnLog { y_over_c: k }, params)?)
    }
}

impl Contribution for PhaseAsymmetryOnLog {
    type Values = PhaseAsymmetryValues;
    fn values(&self, v: &[f64]) -> Result<PhaseAsymmetryValues, EffectValuesError> {
        PhaseAsymmetryValues::try_from(v)
    }
    /// The shorted turns in their two forms (`c` and `y`).
    fn contribute(
        &self,
        p: &PhaseAsymmetryValues,
        _d: &Prepared,
        _n: &MachineConstants,
        t: &mut ModelTerms,
    ) {
        let c = C64::new(p.c_re, p.c_im);
        t.stator_winding = Some(WindingAsymmetryTerm {
            c,
            y: c * self.y_over_c,
        });
    }
    /// The winding named by the unbalance analysis' rule
    /// ([`crate::unbalance::winding_named_by`]): a phase only for a winding part
    /// beyond a healthy machine's own asymmetry, with the supply's part taken out.
    fn describe(&self, p: &PhaseAsymmetryValues, d: &Prepared, n: &MachineConstants) -> String {
        let c = C64::new(p.c_re, p.c_im);
        let part = winding_named_by(d, n, c);
        match part.named {
            Some((ph, eps)) => format!(
                "phase {} winding differs: negative-sequence current {:.1} % of the positive-sequence current; shorted turns in that phase, at least {:.1} % of its turns (a bolted short; a fault resistance means more)",
                ph.name(),
                100.0 * c.norm(),
                100.0 * eps,
            ),
            None => format!(
                "negative-sequence current {:.1} % of the positive-sequence current, the winding's part of it {:.1} % (the supply's taken out): within a healthy machine's own asymmetry of {:.0} %, so no winding is named",
                100.0 * c.norm(),
                100.0 * part.ratio,
                100.0 * NAMED_WINDING_MIN,
            ),
        }
    }
}
