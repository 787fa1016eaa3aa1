//! The effect library: named physical effects the simplified model can be extended with.
//!
//! Every effect implements [`EffectModel`]: which [`EffectId`] it is (its name in the
//! JSON documents and on the command line, `docs/design.md`), a physical description, the
//! way it changes the model equations in words and its parameters, each declared once as
//! an [`EffectParam`] (name, unit, meaning, physical range and its source; all declared
//! as one [`About`]), and [`EffectModel::setup`]: the effect set up on a log
//! ([`FitSetup`]: its parameters with start, bounds and scale on this log, [`FitParam`])
//! and its [`Contribution`] to the model for its typed values (e.g. [`WindageValues`],
//! built from the fit's values with a `Result`: a count that does not match is an
//! [`EffectValuesError`], never a dropped effect): what it writes into the model's
//! physical channels ([`crate::simplified_model::ModelTerms`]) and a sentence a
//! drives engineer understands for fitted values. The trait's other methods have defaults
//! (voltages needed, nothing required first, no time constant, not confusable); an effect
//! writes what differs. [`model_of`] gives the model of a kind (the registry: one line per
//! effect). (The simulator injects the same effects with `monitor_sim::EffectSpec`.)
//!
//! The effects, their parameters and the changes to the model are listed in
//! docs/design.md §9; its table of the parameters is checked against the declarations
//! (`crates/monitor-analysis/tests/analysis/effect_parameters.rs`).
//!
//! With `d_axis_dynamics` or `cross_coupling_dynamics` in the model, the model is the
//! full-order machine of `simplified_model::simulate` (inverse-Gamma form, states I_ds,
//! I_qs, psi_R d and q, w_m); each dynamics effect left out replaces its part by the
//! paper's simplification; with all four in it is the full-order T-equivalent machine
//! driven by the measured voltages. The two that add no parameter only switch a state of
//! the model on ([`StateSwitch`]).

mod coulomb_friction;
mod cross_coupling_dynamics;
mod current_dynamics;
mod d_axis_dynamics;
mod flux_dynamics;
mod impedance;
mod iron_loss;
mod load_torque;
mod phase_asymmetry;
pub mod plausible;
mod rotor_asymmetry;
mod saturation;
mod setup;
mod supply_unbalance;
mod switch;
mod thermal_drift;
mod user_law;
mod windage;

pub use coulomb_friction::{CoulombFriction, CoulombFrictionValues};
pub use cross_coupling_dynamics::CROSS_COUPLING_DYNAMICS;
pub use current_dynamics::{CurrentDynamics, CurrentDynamicsValues};
pub use d_axis_dynamics::D_AXIS_DYNAMICS;
pub use flux_dynamics::{FluxDynamics, FluxDynamicsValues};
pub use impedance::{z1_pos, z2_neg, z2_neg_at};
pub use iron_loss::{IronLoss, IronLossValues};
pub use load_torque::{load_segments, LoadLevels, LoadSegment, LoadTorque};
pub use phase_asymmetry::{asymmetry_phase, PhaseAsymmetry, PhaseAsymmetryValues};
pub use rotor_asymmetry::{RotorAsymmetry, RotorAsymmetryValues, DELTA_BASIS, DELTA_RANGE};
pub use saturation::{Saturation, SaturationValues, FLUX_SPAN_MIN};
pub use setup::{
    declared_values, outside, with_unit, Contribution, EffectParam, EffectValuesError, FitParam,
    FitSetup, SetupError, DIMENSIONLESS,
};
pub use supply_unbalance::{SupplyUnbalance, SupplyUnbalanceValues};
pub use switch::StateSwitch;
pub use thermal_drift::{
    ThermalDrift, ThermalDriftValues, Windings, ALPHA_AL_PER_K, ALPHA_CU_PER_K,
};
pub use user_law::LawEffect;
pub use windage::{Windage, WindageValues};

use super::prep::Prepared;
use super::simplified_model::MachineConstants;
use monitor_laws::EffectId;
use monitor_laws::Law;
use std::sync::Arc;

/// What a log must carry for an effect to be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Needs {
    /// Needs the phase voltages (all model-based effects: the model is driven by V_qs).
    pub voltages: bool,
    /// Needs the measured speed.
    pub speed: bool,
}

impl Needs {
    /// The phase voltages (every effect of the model driven by V_qs: the default).
    pub const VOLTAGES: Needs = Needs::of(true, false);
    /// The phase voltages and the measured speed.
    pub const VOLTAGES_AND_SPEED: Needs = Needs::of(true, true);
    /// Only the currents.
    pub const CURRENTS: Needs = Needs::of(false, false);

    const fn of(voltages: bool, speed: bool) -> Needs {
        Needs { voltages, speed }
    }

    /// Whether the log `d` carries what is needed.
    ///
    /// # Errors
    /// The first channel missing ([`SetupError::NoVoltages`], [`SetupError::NoSpeed`]).
    pub fn met_by(self, d: &Prepared) -> Result<(), SetupError> {
        if self.voltages && !d.channels.voltages {
            return Err(SetupError::NoVoltages);
        }
        if self.speed && !d.channels.speed {
            return Err(SetupError::NoSpeed { because: "" });
        }
        Ok(())
    }
}

/// An effect another one is easily confused with on some logs, and how close their
/// penalised held-back errors must be for `explain` to let the log's evidence
/// ([`EffectModel::evidence`]) decide between them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Confusion {
    /// The other effect.
    pub with: EffectId,
    /// The other effect's score may be up to this factor above this one's (>= 1).
    pub within: f64,
    /// What kind of log tells the two apart where this one does not.
    pub apart_by: ApartBy,
}

/// What tells two confusable effects apart ([`Confusion::apart_by`]), where a log fits them
/// alike (the ladder's end, `explain::ladder`'s `Alike`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ApartBy {
    /// A reversal of the shaft (or a run down to standstill): dry friction changes sign
    /// with the speed, a constant load torque does not; on a shaft that turns one way the
    /// two are one torque.
    Reversal,
    /// Two supply phases exchanged at the motor's terminals: a winding's asymmetry moves
    /// with the winding, a supply's unbalance stays with the supply; at one connection and
    /// one operating point both add the same negative-sequence current.
    SwappedPhases,
    /// A start, or a run over a wide range of speed: a fan's torque `k w |w|` grows with the
    /// square of the speed, a viscous `B w` in proportion to it; over a narrow range of
    /// speed the two are one slope.
    SpeedRange,
}

/// Facts measured on the log, beside the fit, that can tell confusable effects apart.
#[derive(Debug, Clone, Copy)]
pub struct EffectEvidence<'a> {
    /// Negative-sequence over positive-sequence supply voltage (`None`: no voltages).
    pub voltage_unbalance: Option<f64>,
    /// True when the unbalance analysis names a faulty phase (the current unbalance is more
    /// than the supply's voltage unbalance accounts for).
    pub winding_suspected: bool,
    /// Rated torque estimate of the machine [N m].
    pub torque_scale_nm: f64,
    /// The effect's own fitted values, in its set-up's order.
    pub fitted: &'a [f64],
}

/// A supply negative-sequence voltage above this (0.2 %) is a measured supply unbalance.
pub const VOLTAGE_UNBALANCE_MIN: f64 = 0.002;

/// Load torque levels that all agree within this fraction (3 %) of the rated torque are a
/// constant torque: the step the observer proposed is not there.
pub const LOAD_STEP_MIN: f64 = 0.03;

/// True when the supply's measured voltage unbalance accounts for the current unbalance.
pub(crate) fn supply_unbalanced(e: &EffectEvidence<'_>) -> bool {
    !e.winding_suspected && e.voltage_unbalance.unwrap_or(0.0) > VOLTAGE_UNBALANCE_MIN
}

/// The sentence of a fit whose values are not physical (`why`: one reason per value, as
/// [`outside`] words them): it says so, and gives no reading of the values (a fit that
/// needs 400 K of heating is not "about 34 K of heating").
pub fn not_physical(why: &[String]) -> String {
    format!("not physical, so no explanation: {}", why.join("; "))
}

/// A number with 3 significant digits, for messages.
pub fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor();
    if (-3.0..5.0).contains(&mag) {
        let dec = (2.0 - mag).max(0.0) as usize;
        format!("{x:.dec$}")
    } else {
        format!("{x:.2e}")
    }
}

/// What an effect is, in words: the documentation [`EffectModel::about`] gives.
#[derive(Debug, Clone, Copy)]
pub struct About {
    /// Which effect.
    pub kind: EffectId,
    /// Physical description, one or two sentences.
    pub description: &'static str,
    /// How the effect changes the model equations (text with the equation).
    pub equations: &'static str,
    /// The parameters, each declared once (empty: none; `load_torque` declares the
    /// pattern of its per-segment levels).
    pub parameters: &'static [EffectParam],
}

/// How a physical effect of the library changes the simplified model. An effect declares
/// what it is ([`EffectModel::about`]) and writes its [`EffectModel::setup`]; every other
/// method has a default that holds for most effects.
pub trait EffectModel: Send + Sync {
    /// What the effect is, in words.
    fn about(&self) -> &About;
    /// Which effect (its name in the documents is `kind().name()`).
    fn kind(&self) -> EffectId {
        self.about().kind
    }
    /// Physical description, one or two sentences (a user's law: its expression).
    fn description(&self) -> &str {
        self.about().description
    }
    /// How the effect changes the model equations (text with the equation; a user's law:
    /// where it acts).
    fn equations(&self) -> &str {
        self.about().equations
    }
    /// The parameters' declarations ([`EffectModel::setup`] gives the data-dependent
    /// list).
    fn parameters(&self) -> &[EffectParam] {
        self.about().parameters
    }
    /// Channels the log must have. Default: the voltages.
    fn needs(&self) -> Needs {
        Needs::VOLTAGES
    }
    /// Effects that must already be in the model before `explain` proposes this one (a
    /// rung of the dynamics ladder that is only a consistent machine on top of another).
    /// Default: none.
    fn requires(&self) -> &'static [EffectId] {
        &[]
    }
    /// True for an effect whose law carries a speed-dependent shaft torque of its own
    /// (windage, Coulomb friction): fitted with it, the viscous friction B + Bl is free to
    /// fall to zero, without the prior that holds it near the file's value
    /// ([`crate::fit::BaseSpec::for_effects`]). Default: false.
    fn takes_viscous_part(&self) -> bool {
        false
    }
    /// True for an effect whose fitted size the inputs' sensor noise biases (errors in
    /// variables: a resistance's rise passes less of the voltages' noise to the currents,
    /// so an output-error fit buys a lower error with a rise that is too large): a fit with
    /// it is corrected by SIMEX (`crate::fit`'s `simex.rs`). Default: false.
    fn biased_by_input_noise(&self) -> bool {
        false
    }
    /// The shaft torque [N m] of a load law of speed alone at the mechanical speed `w`
    /// [rad/s] with the values `values` (in the set-up's order): windage, dry friction, a
    /// load torque of one level, a user's load law of `w` alone. `None` (the default) for
    /// an effect that is not one, or values that do not fit it. The ladder's end asks it
    /// to fit one law of speed in place of two such laws (`explain::ladder`'s `as_one`).
    fn load_torque_at(&self, _values: &[f64], _w_rad_s: f64) -> Option<f64> {
        None
    }
    /// The effect's values as the machine `n` itself has them, for an effect whose
    /// parameters are the machine's own (the rotor time constant Lr/Rr, the transient
    /// inductance sigma Ls): where the base parameters are refitted as the machine's
    /// ([`crate::fit::machine`]) these follow them instead of being fitted beside them, so
    /// that Rr and the leakages are read through the dynamics they set. Default: `None`
    /// (the effect's values are its own).
    fn derived_from_machine(&self, _n: &MachineConstants) -> Option<Vec<f64>> {
        None
    }
    /// The electrical time constant of the dynamics this effect adds to the model on
    /// machine `n` [s], `None` for an effect that changes the steady state (the default).
    /// An effect that declares one is a structural refinement of the model's transients:
    /// `explain` proposes it only on a series that resolves it (at least 3 samples per time
    /// constant) and only on a log with a transient of the model's inputs (a start or a
    /// supply step, [`super::transients::input_transients`]); in steady state the paper's
    /// model is the steady state of the full-order machine, so a dynamics effect that
    /// lowers the error of a log without one is absorbing another effect
    /// (docs/model-vs-measurement.md, "How it works").
    fn time_constant_s(&self, _n: &MachineConstants) -> Option<f64> {
        None
    }
    /// Effects this one is easily confused with (the same equation on some logs). Default:
    /// none.
    fn confused_with(&self) -> &'static [Confusion] {
        &[]
    }
    /// What the log's evidence says about this effect against those it is confused with:
    /// `Some(true)` supports it, `Some(false)` contradicts it, `None` says nothing (the
    /// default). When two confusable candidates are ranked first and second within their
    /// [`Confusion::within`], a first one the evidence contradicts goes second unless the
    /// evidence contradicts the other too.
    fn evidence(&self, _e: &EffectEvidence<'_>) -> Option<bool> {
        None
    }
    /// What a measurement of the log `d` independent of the fit says against the fitted
    /// values `fitted` (in the set-up's order): the reason they are not plausible, or
    /// `None` (the default: nothing). `explain` ranks a contradicted candidate as an
    /// implausible one.
    ///
    /// # Errors
    /// [`EffectValuesError`] when `fitted` does not hold one value per parameter.
    fn contradicted_by(
        &self,
        _d: &Prepared,
        _n: &MachineConstants,
        _fitted: &[f64],
    ) -> Result<Option<String>, EffectValuesError> {
        Ok(None)
    }
    /// The effect set up on this data: its parameters (start, bounds, physical range) and
    /// its contribution to the model, with what it precomputes from the data.
    ///
    /// # Errors
    /// [`SetupError`] when the effect cannot be fitted on this log.
    fn setup(&self, d: &Prepared, n: &MachineConstants) -> Result<FitSetup, SetupError>;
}

/// A dynamics effect's parameter `p` about its nominal value `nominal`: fitted within 0.3
/// to 3 times it from the nominal value, plausible within its declared range
/// ([`plausible::DYNAMICS_RATIO`]) of it.
fn dynamics_param(p: &EffectParam, nominal: f64) -> FitParam {
    p.fit(
        nominal,
        (0.3 * nominal, 3.0 * nominal),
        0.2 * nominal,
        nominal,
    )
}

/// The log's duration [s] (at least one sample period; 1 s for an empty series).
fn duration(d: &Prepared) -> f64 {
    match (d.t_s.first(), d.t_s.last()) {
        (Some(a), Some(b)) => (b - a).max(d.dt_s),
        _ => 1.0,
    }
}

/// The log's flux level `|V| / omega_s` [Wb] (V peak phase), as the frequency-weighted
/// mean `sum |V| / sum |omega_s|` over the samples with `|omega_s| > 1 rad/s` (1 Wb when
/// there are none). The plain mean of the ratio was dominated by the first samples of a
/// start, where the frame's frequency is still forming and near zero: on a 1 kHz, 11 kW log
/// with a start and V/f steps it read about 6 Wb for a 1.0 Wb machine, which put the
/// saturation fit's start and range far above the knee and made `iron_loss` report
/// 4222 W for an Rfe of 47 x Xm (about 110 W).
fn rated_flux_wb(d: &Prepared) -> f64 {
    let (mut v, mut w) = (0.0, 0.0);
    for ((&om, &vq), &vd) in d.omega_s.iter().zip(&d.vq).zip(&d.vd) {
        if om.abs() > 1.0 {
            v += vq.hypot(vd);
            w += om.abs();
        }
    }
    if w > 0.0 && v > 0.0 {
        v / w
    } else {
        1.0
    }
}

/// Highest synchronous mechanical speed of the log [rad/s] (at least 1).
pub fn sync_speed_mech(d: &Prepared, n: &MachineConstants) -> f64 {
    let mut m = 0.0f64;
    for &w in &d.omega_s {
        m = m.max(w.abs());
    }
    (m / n.np).max(1.0)
}

/// The library's effects, each once, in the library's order (the core's
/// `EffectKind::ALL`), `thermal_drift` as `thermal` gives it.
fn library_with(thermal: ThermalDrift) -> Vec<Box<dyn EffectModel>> {
    vec![
        Box::new(thermal),
        Box::new(Saturation),
        Box::new(IronLoss),
        Box::new(CoulombFriction),
        Box::new(Windage),
        Box::new(LoadTorque),
        Box::new(SupplyUnbalance),
        Box::new(PhaseAsymmetry),
        Box::new(FluxDynamics),
        Box::new(CurrentDynamics),
        Box::new(RotorAsymmetry),
        Box::new(D_AXIS_DYNAMICS),
        Box::new(CROSS_COUPLING_DYNAMICS),
    ]
}

/// The model of an effect of the library (`None` for a name the library does not have: a
/// user's law is found in a [`Registry`]).
pub fn model_of(id: impl Into<EffectId>) -> Option<Box<dyn EffectModel>> {
    let id = id.into();
    library().into_iter().find(|m| m.kind() == id)
}

/// The whole library, in the library's order.
pub fn library() -> Vec<Box<dyn EffectModel>> {
    library_with(ThermalDrift::TOGETHER)
}

/// The ladder's library: [`library`] with the windings' temperatures fitted apart
/// ([`ThermalDrift::APART`]: the ladder reads Rs and Rr apart in its base rung, so a stator
/// heating alone is not taken for both windings), and one rise for both
/// ([`ThermalDrift::TOGETHER`]) as a candidate of its own, last: each round fits both laws,
/// and the one with one parameter fewer wins where the log cannot tell the windings apart.
/// On the 3 hp machine's 40 s log at 2 kHz warming by 50 K, the two rises apart are not
/// told apart (corrected for the voltages' noise, 36 K and 56 K, and 5 % of the error
/// beyond the floor removed); one rise for both is (59 K, 12 %, named).
pub fn ladder_library() -> Vec<Box<dyn EffectModel>> {
    let mut v = library_with(ThermalDrift::APART);
    v.push(Box::new(ThermalDrift::TOGETHER));
    v
}

/// The effects an analysis may use: the library's, then a user's laws ([`LawEffect`]), one
/// list of entries of one kind. Its names are open: a user's law is named by its file.
#[derive(Debug, Clone, Default)]
pub struct Registry {
    laws: Vec<Arc<Law>>,
}

impl Registry {
    /// The library alone.
    pub fn library() -> Registry {
        Registry::default()
    }

    /// The library and the laws `laws` (a user's law file's).
    pub fn with_laws(laws: &[Arc<Law>]) -> Registry {
        Registry {
            laws: laws.to_vec(),
        }
    }

    /// The users' laws.
    pub fn laws(&self) -> &[Arc<Law>] {
        &self.laws
    }

    /// Every entry: the library's effects ([`library`]), then the users' laws.
    pub fn models(&self) -> Vec<Box<dyn EffectModel>> {
        self.with_library(library())
    }

    /// Every entry for the ladder: [`ladder_library`], then the users' laws.
    pub fn ladder_models(&self) -> Vec<Box<dyn EffectModel>> {
        self.with_library(ladder_library())
    }

    fn with_library(&self, mut v: Vec<Box<dyn EffectModel>>) -> Vec<Box<dyn EffectModel>> {
        v.extend(
            self.laws
                .iter()
                .map(|l| Box::new(LawEffect::new(Arc::clone(l))) as Box<dyn EffectModel>),
        );
        v
    }

    /// The entry named `id`.
    pub fn model_of(&self, id: EffectId) -> Option<Box<dyn EffectModel>> {
        model_of(id).or_else(|| {
            self.laws
                .iter()
                .find(|l| l.id == id)
                .map(|l| Box::new(LawEffect::new(Arc::clone(l))) as Box<dyn EffectModel>)
        })
    }

    /// Every entry's name, the library's first.
    pub fn names(&self) -> Vec<EffectId> {
        self.models().iter().map(|m| m.kind()).collect()
    }

    /// The entry named `name`, `None` when neither the library nor a user's law has it.
    pub fn find(&self, name: &str) -> Option<EffectId> {
        self.names().into_iter().find(|id| id.name() == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::EffectKind;

    /// The flux level of a log that begins with a start: the frame's frequency forms from
    /// 1.5 rad/s to 314 rad/s in the first 0.3 s while the voltage is already 325 V (the
    /// ratio there is up to 217 Wb), then 3 s of steady running at 325 / 314 = 1.035 Wb.
    /// The plain mean of the ratio reads 1.44 Wb (+39 %); the frequency-weighted mean
    /// 1.084 Wb (+4.7 %: the forming stretch still counts with its share of the frequency).
    #[test]
    fn the_flux_level_is_not_thrown_by_a_start() {
        let (n0, n) = (300usize, 3300usize);
        let omega_s: Vec<f64> = (0..n)
            .map(|k| {
                if k < n0 {
                    1.5 + (314.0 - 1.5) * k as f64 / n0 as f64
                } else {
                    314.0
                }
            })
            .collect();
        let d = Prepared {
            vq: vec![325.0; n],
            vd: vec![0.0; n],
            omega_s,
            ..Default::default()
        };
        let psi = rated_flux_wb(&d);
        assert!((psi / (325.0 / 314.0) - 1.0).abs() < 0.06, "{psi}");
        let plain: f64 = d.vq.iter().zip(&d.omega_s).map(|(v, w)| v / w).sum::<f64>() / n as f64;
        assert!(plain > 1.3, "the case must throw the plain mean: {plain}");
    }

    /// The declarations that replace `explain`'s effect-named rules: confusions are
    /// mutual, and the evidence tells each pair apart.
    #[test]
    fn confusable_effects_declare_each_other_and_their_evidence() {
        for model in library() {
            let kind = model.kind();
            for c in model.confused_with() {
                assert!(c.within >= 1.0, "{kind}");
                assert!(
                    model_of(c.with)
                        .expect("a library effect")
                        .confused_with()
                        .iter()
                        .any(|b| b.with == kind && b.within == c.within),
                    "{kind} -> {} not mutual",
                    c.with
                );
            }
        }
        let ev = |v: Option<f64>, winding: bool, fitted: &'static [f64]| EffectEvidence {
            voltage_unbalance: v,
            winding_suspected: winding,
            torque_scale_nm: 10.0,
            fitted,
        };
        // A 3 % supply unbalance with no winding suspected: the supply.
        let supply = ev(Some(0.03), false, &[]);
        assert_eq!(SupplyUnbalance.evidence(&supply), Some(true));
        assert_eq!(PhaseAsymmetry.evidence(&supply), Some(false));
        // A balanced supply, or a winding named: the winding.
        for e in [ev(Some(0.001), false, &[]), ev(Some(0.03), true, &[])] {
            assert_eq!(SupplyUnbalance.evidence(&e), Some(false));
            assert_eq!(PhaseAsymmetry.evidence(&e), Some(true));
        }
        // Load levels 2 % of rated apart are one constant torque; 30 % apart a step.
        assert_eq!(
            LoadTorque.evidence(&ev(None, false, &[4.0, 4.2])),
            Some(false)
        );
        assert_eq!(
            LoadTorque.evidence(&ev(None, false, &[4.0, 7.0])),
            Some(true)
        );
        assert_eq!(CoulombFriction.evidence(&ev(None, false, &[4.0])), None);
    }

    #[test]
    fn every_effect_kind_has_its_model() {
        for kind in EffectKind::ALL {
            assert_eq!(model_of(kind).map(|m| m.kind()), Some(EffectId::from(kind)));
        }
        assert_eq!(library().len(), EffectKind::ALL.len());
    }
}
