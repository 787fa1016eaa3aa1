//! A small generic effect for the rungs of the dynamics ladder that add no parameter: each
//! only switches one state of the full-order machine on ([`StateSwitch`]).

use super::{
    declared_values, About, Contribution, EffectModel, EffectValuesError, FitSetup, SetupError,
};
use crate::prep::Prepared;
use crate::simplified_model::{Dynamics, MachineConstants, ModelTerms};
use monitor_laws::EffectId;

/// An effect that only turns a state of the full-order machine on: no parameters, nothing
/// precomputed; its contribution sets its state in [`ModelTerms::dynamics`]. Its time
/// constant is the stator transient one, La/Ra (`explain` proposes it only on a log with a
/// start or a supply step that the series resolves).
#[derive(Debug, Clone, Copy)]
pub struct StateSwitch {
    /// What it is (no parameters).
    pub about: About,
    /// Effects that must be in the model first ([`EffectModel::requires`]).
    pub requires: &'static [EffectId],
    /// Turns the state on.
    pub switch_on: fn(&mut Dynamics),
    /// What it means on machine `n`, in words ([`Contribution::describe`]).
    pub summary: fn(&MachineConstants) -> String,
}

impl EffectModel for StateSwitch {
    fn about(&self) -> &About {
        &self.about
    }
    fn requires(&self) -> &'static [EffectId] {
        self.requires
    }
    fn time_constant_s(&self, n: &MachineConstants) -> Option<f64> {
        Some(n.la_h / n.ra_ohm)
    }
    fn setup(&self, _d: &Prepared, _n: &MachineConstants) -> Result<FitSetup, SetupError> {
        Ok(FitSetup::new(*self, Vec::new())?)
    }
}

impl Contribution for StateSwitch {
    /// No values.
    type Values = ();
    fn values(&self, v: &[f64]) -> Result<(), EffectValuesError> {
        let [] = declared_values(self.about.kind, &[], v)?;
        Ok(())
    }
    fn contribute(&self, _p: &(), _d: &Prepared, _n: &MachineConstants, t: &mut ModelTerms) {
        (self.switch_on)(&mut t.dynamics);
    }
    fn describe(&self, _p: &(), _d: &Prepared, n: &MachineConstants) -> String {
        (self.summary)(n)
    }
}
