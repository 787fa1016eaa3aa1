//! An effect set up on a log: its fitted parameters, typed, and what it contributes to the
//! model for given values.

use super::sig;
use crate::analysis::prep::Prepared;
use crate::analysis::simplified_model::{MachineConstants, ModelTerms};
use crate::params::PlausibleRange;
use std::sync::Arc;

/// Why an effect cannot be fitted on a log (one line, the effect's name put before it by
/// the caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SetupError {
    /// The log has no phase voltages (the model is driven by V_qs).
    #[error("needs the voltage columns va_V, vb_V, vc_V (the model is driven by V_qs)")]
    NoVoltages,
    /// The log has no speed column; `because` says what the effect reads from it (empty:
    /// nothing more to say).
    #[error("needs the speed column wm_rad_s{}", because_of(because))]
    NoSpeed {
        /// What the effect uses the speed for.
        because: &'static str,
    },
    /// The log holds nothing the effect could fit (the reason in words).
    #[error("{0}")]
    NothingToFit(&'static str),
}

/// ` (because)`, or nothing.
fn because_of(because: &str) -> String {
    if because.is_empty() {
        String::new()
    } else {
        format!(" ({because})")
    }
}

/// One fitted parameter of an effect: its name and unit (JSON key and unit), where the fit
/// starts, the bounds it keeps to, its typical magnitude, and the physical range a fitted
/// value must lie in to be plausible, with the range's source.
#[derive(Debug, Clone, PartialEq)]
pub struct FitParam {
    /// Name (JSON key; for `load_torque` one per segment).
    pub name: String,
    /// Unit.
    pub unit: &'static str,
    /// Initial value.
    pub init: f64,
    /// Lower bound of the fit.
    pub lo: f64,
    /// Upper bound of the fit.
    pub hi: f64,
    /// Typical magnitude (finite-difference steps and conditioning), > 0.
    pub scale: f64,
    /// Physical range: a fitted value outside it is not plausible.
    pub plausible: PlausibleRange,
    /// Where [`FitParam::plausible`] comes from.
    pub basis: &'static str,
}

impl FitParam {
    /// A parameter fitted from `init` within `lo..=hi`, of magnitude `scale`; plausible
    /// anywhere within the bounds until [`FitParam::physical`] says otherwise.
    pub fn new(
        name: impl Into<String>,
        unit: &'static str,
        init: f64,
        (lo, hi): (f64, f64),
        scale: f64,
    ) -> Self {
        FitParam {
            name: name.into(),
            unit,
            init,
            lo,
            hi,
            scale,
            plausible: PlausibleRange { lo, hi },
            basis: "the fit's bounds",
        }
    }

    /// The parameter with the physical range `lo..=hi` from `basis`.
    pub fn physical(mut self, (lo, hi): (f64, f64), basis: &'static str) -> Self {
        self.plausible = PlausibleRange { lo, hi };
        self.basis = basis;
        self
    }

    /// The parameter with the physical range `lo * scale ..= hi * scale` from `basis` (a
    /// range relative to a scale of the machine or the log).
    pub fn physical_scaled(self, (lo, hi): (f64, f64), scale: f64, basis: &'static str) -> Self {
        self.physical((lo * scale, hi * scale), basis)
    }

    /// Why the value `v` is not physically plausible (`None`: it is), naming value, unit,
    /// range and the range's basis.
    pub fn implausible_because(&self, v: f64) -> Option<String> {
        outside(&self.name, self.unit, v, &self.plausible, self.basis)
    }
}

/// Why the value `v` of quantity `name` [`unit`] is not physically plausible (`None`: it
/// lies in `range`): `name = v unit is outside the physical range lo..hi unit (basis)`,
/// numbers to 3 significant digits.
pub fn outside(
    name: &str,
    unit: &str,
    v: f64,
    range: &PlausibleRange,
    basis: &str,
) -> Option<String> {
    (!range.contains(v)).then(|| {
        format!(
            "{name} = {} {unit} is outside the physical range {}..{} {unit} ({basis})",
            sig(v),
            sig(range.lo),
            sig(range.hi)
        )
    })
}

/// What an effect set up on a log contributes to the model: the effect with the numbers
/// its set-up took from the data (for example the load-step times).
pub trait Contribution: Send + Sync {
    /// Writes the effect's contribution for parameter values `p` (in the set-up's order)
    /// into `terms`.
    fn contribute(&self, p: &[f64], d: &Prepared, n: &MachineConstants, terms: &mut ModelTerms);
    /// The fitted values `p` in words a drives engineer understands.
    fn describe(&self, p: &[f64], d: &Prepared, n: &MachineConstants) -> String;
}

/// An effect set up on a log ([`super::EffectModel::setup`]): its parameters, other
/// starting points for the fit, and its contribution to the model.
#[derive(Clone)]
pub struct FitSetup {
    /// The fitted parameters, in the order of the values the fit passes.
    pub params: Vec<FitParam>,
    /// Other starting values the fit also tries, each a whole set of values (empty: the
    /// parameters' `init` only). For a cost with separate valleys: an amplitude and a
    /// phase, started half a turn off, descend to the amplitude's zero bound, where the
    /// phase's gradient vanishes and the fit stays. The start that ends at the lowest cost
    /// wins (`crate::analysis::fit::fit`).
    pub alt_init: Vec<Vec<f64>>,
    contribution: Arc<dyn Contribution>,
}

impl std::fmt::Debug for FitSetup {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitSetup")
            .field("params", &self.params)
            .field("alt_init", &self.alt_init)
            .finish_non_exhaustive()
    }
}

impl FitSetup {
    /// A set-up without parameters whose contribution is `c`.
    pub fn new(c: impl Contribution + 'static) -> Self {
        FitSetup {
            params: Vec::new(),
            alt_init: Vec::new(),
            contribution: Arc::new(c),
        }
    }

    /// The set-up with parameter `p` appended.
    pub fn param(mut self, p: FitParam) -> Self {
        self.params.push(p);
        self
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// True when the effect has no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The initial values, in order.
    pub fn init(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.init).collect()
    }

    /// Starts the fit from `values` instead (ignored unless there is one per parameter).
    pub fn start_from(&mut self, values: &[f64]) {
        if values.len() == self.params.len() {
            for (p, v) in self.params.iter_mut().zip(values) {
                p.init = *v;
            }
        }
    }

    /// The reasons the values `p` are not physically plausible (empty: plausible): one line
    /// per parameter outside its range ([`FitParam::implausible_because`]).
    pub fn implausible(&self, p: &[f64]) -> Vec<String> {
        self.params
            .iter()
            .zip(p)
            .filter_map(|(q, v)| q.implausible_because(*v))
            .collect()
    }

    /// The effect's contribution to the model for the values `p` ([`Contribution`]).
    pub fn contribute(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut ModelTerms,
    ) {
        self.contribution.contribute(p, d, n, terms);
    }

    /// The values `p` in words ([`Contribution::describe`]).
    pub fn describe(&self, p: &[f64], d: &Prepared, n: &MachineConstants) -> String {
        self.contribution.describe(p, d, n)
    }
}
