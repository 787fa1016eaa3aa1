//! An effect set up on a log: its fitted parameters, typed, and what it contributes to the
//! model for given values.

use super::sig;
use crate::prep::Prepared;
use crate::simplified_model::{MachineConstants, ModelTerms};
use monitor_io::params::PlausibleRange;
use monitor_laws::EffectId;
use std::sync::Arc;

/// Why an effect cannot be fitted on a log (one line, the effect's name put before it by
/// the caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error, serde::Serialize)]
#[serde(rename_all = "snake_case")]
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
    /// The log holds one flux level: its magnetising current (i_f) spans `span_pct` % of
    /// its median between its 5th and 95th percentiles, below `min_pct` %
    /// ([`super::FLUX_SPAN_MIN`]). A magnetising curve shows where the flux moves (a
    /// start, a supply step); on one level the base Lm is all a log can read.
    #[error(
        "the log holds one flux level (its magnetising current spans {span_pct} % of its median, {min_pct} % needed): the magnetising curve shows only where the flux moves (a start, a supply step)"
    )]
    OneFluxLevel {
        /// The magnetising current's 5-95 % span over its median [%, rounded].
        span_pct: u32,
        /// The least span that shows the curve [%].
        min_pct: u32,
    },
    /// A user's law gives no number (NaN or infinity) on this log at its start values.
    #[error("the law gives no number (NaN or infinity) on this log at its start values")]
    NotFinite,
    /// The set-up's parameters do not match its contribution's typed values.
    #[error(transparent)]
    Values(#[from] EffectValuesError),
}

/// ` (because)`, or nothing.
fn because_of(because: &str) -> String {
    if because.is_empty() {
        String::new()
    } else {
        format!(" ({because})")
    }
}

/// One parameter of an effect, declared once: its name (the JSON key, and the docs'),
/// unit, meaning, physical range and that range's source. The fit's set-up
/// ([`EffectParam::fit`]), the JSON (`parameters`, keyed by the name, with the unit) and
/// docs/design.md's table of the effects' parameters (checked against the declarations by
/// `crates/monitor-analysis/tests/analysis/effect_parameters.rs`) come from it; an effect's typed values (e.g.
/// `WindageValues`) are built from the fit's values in the declarations' order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectParam {
    /// Name: the JSON key (`load_torque`'s levels: the pattern of one key per segment,
    /// `level_k_from_T_s`).
    pub name: &'static str,
    /// Unit (`1`: dimensionless).
    pub unit: &'static str,
    /// What it is, in a few words.
    pub doc: &'static str,
    /// Physical range: a fitted value outside it is not plausible. In `unit` when `per` is
    /// `None`, else a multiple of what `per` names (the set-up gives its value on the log).
    pub range: (f64, f64),
    /// What [`EffectParam::range`] is relative to, in words (`None`: absolute).
    pub per: Option<&'static str>,
    /// Where [`EffectParam::range`] comes from.
    pub basis: &'static str,
}

impl EffectParam {
    /// The parameter fitted from `init` within `lo..=hi`, of magnitude `scale` (> 0), with
    /// its physical range `range` times `per_value`, the value on the log of what
    /// [`EffectParam::per`] names (1 for an absolute range).
    pub fn fit(&self, init: f64, (lo, hi): (f64, f64), scale: f64, per_value: f64) -> FitParam {
        FitParam {
            declared: *self,
            name: self.name.to_string(),
            init,
            lo,
            hi,
            scale,
            plausible: PlausibleRange {
                lo: self.range.0 * per_value,
                hi: self.range.1 * per_value,
            },
        }
    }
}

/// One fitted parameter of an effect set up on a log: its declaration, its JSON key,
/// where the fit starts, the bounds it keeps to, its typical magnitude, and its physical
/// range on this log.
#[derive(Debug, Clone, PartialEq)]
pub struct FitParam {
    /// The declaration (unit, meaning, range and its source).
    pub declared: EffectParam,
    /// The JSON key: the declaration's name (for `load_torque` one key per segment).
    pub name: String,
    /// Initial value.
    pub init: f64,
    /// Lower bound of the fit.
    pub lo: f64,
    /// Upper bound of the fit.
    pub hi: f64,
    /// Typical magnitude (finite-difference steps and conditioning), > 0.
    pub scale: f64,
    /// Physical range on this log: a fitted value outside it is not plausible.
    pub plausible: PlausibleRange,
}

impl FitParam {
    /// The unit (the declaration's).
    pub fn unit(&self) -> &'static str {
        self.declared.unit
    }

    /// Where [`FitParam::plausible`] comes from (the declaration's basis).
    pub fn basis(&self) -> &'static str {
        self.declared.basis
    }

    /// The parameter under the JSON key `name` (the per-segment keys of `load_torque`).
    pub fn named(mut self, name: String) -> Self {
        self.name = name;
        self
    }

    /// Why the value `v` is not physically plausible (`None`: it is), naming value, unit,
    /// range and the range's basis.
    pub fn implausible_because(&self, v: f64) -> Option<String> {
        outside(&self.name, self.unit(), v, &self.plausible, self.basis())
    }
}

/// The fit's values of an effect's parameters in number: `values` in the declared order
/// of `declared`, as an array to destructure into the effect's typed values.
///
/// # Errors
/// [`EffectValuesError::Count`] when `values` does not hold one value per declaration.
pub fn declared_values<const N: usize>(
    effect: EffectId,
    declared: &[EffectParam; N],
    values: &[f64],
) -> Result<[f64; N], EffectValuesError> {
    <[f64; N]>::try_from(values).map_err(|_| EffectValuesError::Count {
        effect,
        expected: declared.len(),
        got: values.len(),
    })
}

/// Fitted values that do not match the effects they are for: never dropped silently.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectValuesError {
    /// An effect got another number of values than it has parameters.
    #[error("{effect}: {got} fitted values for its {expected} parameters")]
    Count {
        /// Which effect.
        effect: EffectId,
        /// Its parameters on this log.
        expected: usize,
        /// The values given.
        got: usize,
    },
    /// Another number of values than the effects have parameters in all.
    #[error("{got} fitted values for the effects' {expected} parameters")]
    Total {
        /// The effects' parameters.
        expected: usize,
        /// The values given.
        got: usize,
    },
    /// Another number of value sets than effects.
    #[error("{got} sets of fitted values for {expected} effects")]
    Effects {
        /// The effects in the model.
        expected: usize,
        /// The value sets given.
        got: usize,
    },
}

/// Why the value `v` of quantity `name` [`unit`] is not physically plausible (`None`: it
/// lies in `range`): `name = v unit is outside the physical range lo..hi unit (basis)`,
/// numbers to 3 significant digits, a dimensionless value without a unit ([`with_unit`]).
pub fn outside(
    name: &str,
    unit: &str,
    v: f64,
    range: &PlausibleRange,
    basis: &str,
) -> Option<String> {
    (!range.contains(v)).then(|| {
        format!(
            "{name} = {} is outside the physical range {}..{} ({basis})",
            with_unit(&sig(v), unit),
            sig(range.lo),
            with_unit(&sig(range.hi), unit)
        )
    })
}

/// The unit SI writes for a dimensionless quantity (the declarations' and the JSON's
/// `unit`): a text never prints it after a number.
pub const DIMENSIONLESS: &str = "1";

/// A number (already formatted) with its unit as a text prints it: `5.00 K`, and a
/// dimensionless value ([`DIMENSIONLESS`], or no unit) as the bare number `5.00`.
pub fn with_unit(number: &str, unit: &str) -> String {
    if unit.is_empty() || unit == DIMENSIONLESS {
        number.to_string()
    } else {
        format!("{number} {unit}")
    }
}

/// What an effect set up on a log contributes to the model: the effect with the numbers
/// its set-up took from the data (for example the load-step times), for its typed values.
pub trait Contribution: Send + Sync + 'static {
    /// The effect's values, typed (one field per declared parameter, e.g.
    /// `WindageValues`).
    type Values;
    /// The fit's values `values` (in the set-up's order) typed.
    ///
    /// # Errors
    /// [`EffectValuesError::Count`] when there is not one value per parameter.
    fn values(&self, values: &[f64]) -> Result<Self::Values, EffectValuesError>;
    /// Writes the effect's contribution for the values `p` into `terms`.
    fn contribute(
        &self,
        p: &Self::Values,
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut ModelTerms,
    );
    /// The values `p` in words a drives engineer understands.
    fn describe(&self, p: &Self::Values, d: &Prepared, n: &MachineConstants) -> String;
}

/// A [`Contribution`] behind the fit's untyped values (what [`FitSetup`] holds).
trait UntypedContribution: Send + Sync {
    fn contribute(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut ModelTerms,
    ) -> Result<(), EffectValuesError>;
    fn describe(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
    ) -> Result<String, EffectValuesError>;
    fn check(&self, p: &[f64]) -> Result<(), EffectValuesError>;
}

impl<C: Contribution> UntypedContribution for C {
    fn contribute(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut ModelTerms,
    ) -> Result<(), EffectValuesError> {
        Contribution::contribute(self, &self.values(p)?, d, n, terms);
        Ok(())
    }
    fn describe(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
    ) -> Result<String, EffectValuesError> {
        Ok(Contribution::describe(self, &self.values(p)?, d, n))
    }
    fn check(&self, p: &[f64]) -> Result<(), EffectValuesError> {
        self.values(p).map(|_| ())
    }
}

/// An effect set up on a log ([`super::EffectModel::setup`]): its parameters, other
/// starting points for the fit, and its contribution to the model. Built with a `Result`:
/// the parameters and every other start are checked against the contribution's typed
/// values.
#[derive(Clone)]
pub struct FitSetup {
    /// The fitted parameters, in the order of the values the fit passes.
    pub params: Vec<FitParam>,
    alt_init: Vec<Vec<f64>>,
    contribution: Arc<dyn UntypedContribution>,
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
    /// The set-up of the parameters `params` (in the order of `c`'s typed values) whose
    /// contribution is `c`.
    ///
    /// # Errors
    /// [`EffectValuesError::Count`] when `c` does not take one value per parameter.
    pub fn new(c: impl Contribution, params: Vec<FitParam>) -> Result<Self, EffectValuesError> {
        let init: Vec<f64> = params.iter().map(|p| p.init).collect();
        c.values(&init)?;
        Ok(FitSetup {
            params,
            alt_init: Vec::new(),
            contribution: Arc::new(c),
        })
    }

    /// The set-up with other starting values the fit also tries, each a whole set of
    /// values. For a cost with separate valleys: an amplitude and a phase, started half a
    /// turn off, descend to the amplitude's zero bound, where the phase's gradient
    /// vanishes and the fit stays. The start that ends at the lowest cost wins
    /// (`crate::fit::fit`).
    ///
    /// # Errors
    /// [`EffectValuesError::Count`] when a start does not hold one value per parameter.
    pub fn with_alt_init(mut self, starts: Vec<Vec<f64>>) -> Result<Self, EffectValuesError> {
        for s in &starts {
            self.contribution.check(s)?;
        }
        self.alt_init = starts;
        Ok(self)
    }

    /// The other starting values ([`FitSetup::with_alt_init`]; empty: the parameters'
    /// `init` only).
    pub fn alt_init(&self) -> &[Vec<f64>] {
        &self.alt_init
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

    /// Starts the fit from `values` and from nowhere else: the other starting values
    /// ([`FitSetup::alt_init`]) are dropped too. For an effect already fitted (a ladder's
    /// nested fit, where the model stood): its valley was chosen when it was fitted. Ignored
    /// unless there is one value per parameter.
    pub fn start_only_from(&mut self, values: &[f64]) {
        if values.len() == self.params.len() {
            self.start_from(values);
            self.alt_init.clear();
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

    /// Why the values `p` are no finding where they sit at a bound of their fit: the solver
    /// pushed them as far as it was let, so the log shows no minimum there (a bound at 0,
    /// no effect at all, does not count; the ladder's own rule, `explain::ladder`). One
    /// line per value: `exponent = 14.0 is at the bound of its fit (2.00..14.0), not a
    /// value the log shows`.
    pub fn pinned(&self, p: &[f64]) -> Vec<String> {
        let at = |v: f64, b: f64| b.is_finite() && b != 0.0 && (v - b).abs() <= 1e-3 * b.abs();
        self.params
            .iter()
            .zip(p)
            .filter(|(q, v)| at(**v, q.lo) || at(**v, q.hi))
            .map(|(q, v)| {
                format!(
                    "{} = {} is at the bound of its fit ({}..{}), not a value the log shows",
                    q.name,
                    with_unit(&sig(*v), q.unit()),
                    sig(q.lo),
                    with_unit(&sig(q.hi), q.unit())
                )
            })
            .collect()
    }

    /// The effect's contribution to the model for the values `p` ([`Contribution`]).
    ///
    /// # Errors
    /// [`EffectValuesError::Count`] when `p` does not hold one value per parameter.
    pub fn contribute(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
        terms: &mut ModelTerms,
    ) -> Result<(), EffectValuesError> {
        self.contribution.contribute(p, d, n, terms)
    }

    /// The values `p` in words ([`Contribution::describe`]).
    ///
    /// # Errors
    /// [`EffectValuesError::Count`] when `p` does not hold one value per parameter.
    pub fn describe(
        &self,
        p: &[f64],
        d: &Prepared,
        n: &MachineConstants,
    ) -> Result<String, EffectValuesError> {
        self.contribution.describe(p, d, n)
    }
}
