//! Levenberg-Marquardt fit of the base parameters and the effects' parameters.
//!
//! Output-error fit: the model is simulated over the log for every trial parameter vector
//! and the residuals are the per-channel errors divided by each channel's RMS (the same
//! weighting as `normalized_rms_error`), on the training samples only (held-back windows
//! are used by `explain` to rank honestly). Base parameters carry weak Gaussian priors
//! around their nominal values (sd 15 % for Ra and Ls, 30 % for J, 50 % for B+Bl, each scaled by
//! [`PRIOR_WEIGHT`] so that one sd costs as much as a 0.01 normalized error), so a
//! parameter the data cannot identify stays near nominal instead of wandering. The Jacobian
//! is by forward differences (one simulation per parameter, in parallel with rayon); the
//! solver is [`super::lm`] (apart from the model; it reports how it ended, [`FitResult::report`]);
//! bounds are enforced by clamping.

use super::effects::{EffectModel, EffectValuesError, FitSetup};
use super::lm::{self, LeastSquares};
use super::metrics::{measured, predicted, Weights};
use super::prep::Prepared;
use super::simplified_model::{
    rotations, simulate, simulate_rot, BaseParams, InputNoise, MachineConstants, ModelTerms,
    Prediction, Rotations,
};

mod identifiability;
pub mod machine;
pub mod simex;

use identifiability::Gram;
pub use identifiability::{jacobian, Jacobian, ParameterSensitivity, IDENTIFIED_MIN};

/// An effect set up on the data, with its parameter values.
pub struct ActiveEffect<'a> {
    /// The library entry.
    pub effect: &'a dyn EffectModel,
    /// Its data-dependent set-up.
    pub setup: FitSetup,
}

/// Result of a fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Fitted base parameters.
    pub base: BaseParams,
    /// Fitted parameters of each effect, in the order given.
    pub effect_params: Vec<Vec<f64>>,
    /// How the solver ended (iterations, final cost, reason).
    pub report: lm::Report,
    /// The effects' values corrected for the inputs' sensor noise by SIMEX ([`simex`]),
    /// where an effect of the fit is biased by it
    /// ([`EffectModel::biased_by_input_noise`]); `None` otherwise. What is reported and
    /// judged plausible ([`FitResult::reported`]); `effect_params` stay what the model
    /// predicts with, so that errors compare like with like.
    pub corrected: Option<Vec<Vec<f64>>>,
}

impl FitResult {
    /// The effects' values to report and judge: the SIMEX-corrected ones where there are
    /// ([`FitResult::corrected`]), else the fitted ones.
    pub fn reported(&self) -> &[Vec<f64>] {
        self.corrected.as_deref().unwrap_or(&self.effect_params)
    }
}

/// Weight of the base parameters' priors relative to the data (whose residuals are scaled
/// so that their sum of squares is the squared normalized error).
pub const PRIOR_WEIGHT: f64 = 0.01;

/// Number of base parameters.
pub const N_BASE: usize = 4;

/// Which of the four base parameters a fit frees and how their priors weigh: one prior
/// standard deviation (15 % of Ra and Ls, 30 % of J, half the B + Bl scale) costs as much
/// as a normalized error of `prior_weight`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseSpec {
    /// Free parameters, in the order of [`BaseParams`] (Ra, Ls, B + Bl, J).
    pub free: [bool; N_BASE],
    /// Free parameters that carry a prior (a parameter without one is held only by its
    /// bounds).
    pub prior: [bool; N_BASE],
    /// The priors' weight (see the type's doc).
    pub prior_weight: f64,
    /// How many of the fit's first effects hold their start values (0: every effect's
    /// values are free): a screening fit of a candidate added to a model fitted before
    /// frees only the candidate's values and the base parameters, a few simulations per
    /// iteration where the whole model's values would take many.
    pub hold_first: usize,
}

impl BaseSpec {
    /// No base parameter free: the start values are kept.
    pub const FIXED: BaseSpec = BaseSpec {
        free: [false; N_BASE],
        prior: [false; N_BASE],
        prior_weight: PRIOR_WEIGHT,
        hold_first: 0,
    };
    /// All four free with their priors at [`PRIOR_WEIGHT`] (`compare`'s and `explain`'s
    /// fit).
    pub const PAPER: BaseSpec = BaseSpec {
        free: [true; N_BASE],
        prior: [true; N_BASE],
        prior_weight: PRIOR_WEIGHT,
        hold_first: 0,
    };

    /// [`BaseSpec::PAPER`] when `fit_base`, else [`BaseSpec::FIXED`].
    pub fn paper(fit_base: bool) -> Self {
        if fit_base {
            Self::PAPER
        } else {
            Self::FIXED
        }
    }

    /// The spec for a model with `effects`: an effect that carries a speed-dependent shaft
    /// torque of its own ([`EffectModel::takes_viscous_part`]: windage, Coulomb friction)
    /// frees B + Bl without its prior, so that the viscous friction can fall to zero where
    /// the effect's law carries the whole load (a fan: k w|w| and no viscous load at all).
    pub fn for_effects(mut self, effects: &[ActiveEffect<'_>]) -> Self {
        if effects.iter().any(|e| e.effect.takes_viscous_part()) {
            self.free[2] = true;
            self.prior[2] = false;
        }
        self
    }

    /// How many prior residuals a fit with this spec has.
    fn n_priors(&self) -> usize {
        (0..N_BASE)
            .filter(|&i| self.free[i] && self.prior[i])
            .count()
    }
}

struct Problem<'a> {
    d: &'a Prepared,
    n: &'a MachineConstants,
    effects: &'a [ActiveEffect<'a>],
    w: &'a Weights,
    btot_scale: f64,
    spec: BaseSpec,
    /// Frame rotations of `d` (the same for every simulation).
    rot: Rotations,
    /// The training samples the residuals use, with their measured channels (fixed).
    targets: Vec<(usize, [f64; 5])>,
    /// 1/sqrt(number of targets).
    norm: f64,
    /// Extra white noise on the model's inputs in every simulation of the fit (`None`: the
    /// measured inputs as they are); SIMEX's refits (`simex.rs`).
    extra_noise: Option<InputNoise>,
}

impl<'a> Problem<'a> {
    fn base(x: &[f64]) -> BaseParams {
        BaseParams {
            ra_scale: x[0],
            ls_scale: x[1],
            btot_nms: x[2],
            j_scale: x[3],
        }
    }

    /// The problem on `d` (the training samples of `w`, their measured channels fixed);
    /// the priors of `spec` are residuals too.
    fn new(
        d: &'a Prepared,
        n: &'a MachineConstants,
        effects: &'a [ActiveEffect<'a>],
        w: &'a Weights,
        spec: BaseSpec,
    ) -> Self {
        let targets = training_targets(d, w);
        Problem {
            d,
            n,
            effects,
            w,
            btot_scale: btot_scale(n, d),
            spec,
            rot: rotations(d),
            norm: 1.0 / (targets.len().max(1) as f64).sqrt(),
            targets,
            extra_noise: None,
        }
    }

    /// The effects' contributions for the effect parameters in `x` (the base parameters do
    /// not enter them).
    fn terms(&self, x: &[f64]) -> Result<ModelTerms, EffectValuesError> {
        let mut terms = ModelTerms::default();
        for (e, p) in effect_values(self.effects, x.get(N_BASE..).unwrap_or(&[]))? {
            e.setup.contribute(p, self.d, self.n, &mut terms)?;
        }
        terms.input_noise = self.extra_noise;
        Ok(terms)
    }

    fn residuals_of(&self, x: &[f64]) -> Vec<f64> {
        self.residuals(x, &self.terms(x))
    }

    /// The residuals of a point the model cannot be run at: 1e3 each (as for a prediction
    /// that ends early).
    fn failed_point(&self) -> Vec<f64> {
        vec![1e3; self.w.n_channels() * self.targets.len() + self.spec.n_priors()]
    }

    /// The same residuals as [`Weights::residuals`] on the training samples (the measured
    /// side precomputed), plus the priors; `terms` must be [`Problem::terms`] of `x`.
    fn residuals_with(&self, x: &[f64], terms: &ModelTerms) -> Vec<f64> {
        let p = simulate_rot(self.d, &self.rot, self.n, &Self::base(x), terms);
        let mut r = data_residuals(self.d, &p, &self.targets, self.w, self.norm, N_BASE);
        // Weak: with the default weight a 15 % deviation of Ra costs as much as a 0.01
        // normalized error.
        let z = [
            (x[0] - 1.0) / 0.15,
            (x[1] - 1.0) / 0.15,
            (x[2] - self.n.btot_nms) / (0.5 * self.btot_scale),
            (x[3] - 1.0) / 0.3,
        ];
        for (i, z) in z.iter().enumerate() {
            if self.spec.free[i] && self.spec.prior[i] {
                r.push(self.spec.prior_weight * z);
            }
        }
        r
    }
}

impl LeastSquares for Problem<'_> {
    /// The effects' terms: only the effects' parameters enter them. (A point whose values
    /// do not match the effects cannot occur: [`fit`] checks its start, and the solver
    /// changes values, not their number; it would count as a failed point.)
    type Cache = Result<ModelTerms, EffectValuesError>;
    fn cache(&self, x: &[f64]) -> Result<ModelTerms, EffectValuesError> {
        self.terms(x)
    }
    fn residuals(&self, x: &[f64], terms: &Result<ModelTerms, EffectValuesError>) -> Vec<f64> {
        match terms {
            Ok(t) => self.residuals_with(x, t),
            Err(_) => self.failed_point(),
        }
    }
    fn keeps_cache(&self, i: usize) -> bool {
        i < N_BASE
    }
}

/// The fit's data residuals of prediction `p` at the training samples `targets` (each with
/// its measured channels): each channel's error times its weight `1/RMS` and `norm`
/// (`1/sqrt(number of targets)`), so that their sum of squares is the squared normalized
/// error; 1e3 where the prediction ended early or is not finite. Room for `extra` more.
pub(crate) fn data_residuals(
    d: &Prepared,
    p: &Prediction,
    targets: &[(usize, [f64; 5])],
    w: &Weights,
    norm: f64,
    extra: usize,
) -> Vec<f64> {
    let inv = &w.inv_rms;
    let nc = w.n_channels();
    let mut r = Vec::with_capacity(nc * targets.len() + extra);
    for (k, m) in targets {
        if p.iq.len() <= *k {
            r.extend(std::iter::repeat_n(1e3, nc));
            continue;
        }
        let q = predicted(d, p, *k);
        for c in 0..5 {
            if inv[c] > 0.0 {
                let e = (q[c] - m[c]) * inv[c] * norm;
                r.push(if e.is_finite() { e } else { 1e3 });
            }
        }
    }
    r
}

/// The training samples of `w` on `d` with their measured channels (what
/// [`data_residuals`] compares with).
pub(crate) fn training_targets(d: &Prepared, w: &Weights) -> Vec<(usize, [f64; 5])> {
    (0..d.len())
        .step_by(w.stride.max(1))
        .filter(|&k| w.train.get(k).copied().unwrap_or(false))
        .map(|k| (k, measured(d, k)))
        .collect()
}

/// Scale of B+Bl for conditioning and its prior: the larger of the nominal value and the
/// viscous coefficient that would carry 20 % of the rated torque at synchronous speed.
pub fn btot_scale(n: &MachineConstants, d: &Prepared) -> f64 {
    let wmax = d.omega_s.iter().fold(0.0f64, |a, &w| a.max(w.abs())) / n.np;
    n.btot_nms.max(0.2 * n.torque_scale_nm / wmax.max(1.0))
}

/// Each effect with its slice of the effect values `values` (laid out in the effects'
/// order, each set-up's parameter count).
///
/// # Errors
/// [`EffectValuesError::Total`] when `values` does not hold one value per parameter of
/// the effects.
fn effect_values<'e, 'v>(
    effects: &'e [ActiveEffect<'e>],
    values: &'v [f64],
) -> Result<Vec<(&'e ActiveEffect<'e>, &'v [f64])>, EffectValuesError> {
    let expected: usize = effects.iter().map(|e| e.setup.len()).sum();
    if values.len() != expected {
        return Err(EffectValuesError::Total {
            expected,
            got: values.len(),
        });
    }
    let mut rest = values;
    Ok(effects
        .iter()
        .map(|e| {
            let (p, tail) = rest.split_at(e.setup.len());
            rest = tail;
            (e, p)
        })
        .collect())
}

/// Each effect with its fitted values `values` (one set per effect, in order).
///
/// # Errors
/// [`EffectValuesError::Effects`] when there is not one set per effect (a set of the
/// wrong length is refused where it is used, [`FitSetup::contribute`]).
fn paired<'e, 'v>(
    effects: &'e [ActiveEffect<'e>],
    values: &'v [Vec<f64>],
) -> Result<impl Iterator<Item = (&'e ActiveEffect<'e>, &'v Vec<f64>)>, EffectValuesError> {
    if effects.len() != values.len() {
        return Err(EffectValuesError::Effects {
            expected: effects.len(),
            got: values.len(),
        });
    }
    Ok(effects.iter().zip(values))
}

/// Fits base parameters (unless `fit_base` is false: nominal values are kept) and the
/// effects' parameters, starting from `start` (base) and each set-up's initial values: the
/// base parameters as [`BaseSpec::paper`] says, for these effects
/// ([`BaseSpec::for_effects`]).
///
/// # Errors
/// [`EffectValuesError`] when an effect refuses its set-up's own values (a set-up whose
/// parameters do not match its contribution).
pub fn fit(
    d: &Prepared,
    n: &MachineConstants,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    start: &BaseParams,
    fit_base: bool,
    max_iter: usize,
) -> Result<FitResult, EffectValuesError> {
    let spec = BaseSpec::paper(fit_base).for_effects(effects);
    fit_spec(d, n, effects, w, start, spec, max_iter)
}

/// [`fit`] with the base parameters freed and weighed as `spec` says (taken as given).
///
/// # Errors
/// As [`fit`].
pub fn fit_spec(
    d: &Prepared,
    n: &MachineConstants,
    effects: &[ActiveEffect<'_>],
    w: &Weights,
    start: &BaseParams,
    spec: BaseSpec,
    max_iter: usize,
) -> Result<FitResult, EffectValuesError> {
    let prob = Problem::new(d, n, effects, w, spec);
    let (x, bounds) = start_and_bounds(start, effects, prob.btot_scale);
    let free = free_values(effects, spec, x.len());
    prob.terms(&x)?;
    // From `x`, then from each effect's other starts (`FitSetup::alt_init`, one effect's
    // at a time): the lowest final cost wins.
    let mut best = lm::solve(&prob, x.clone(), &bounds, &free, max_iter);
    let mut o = N_BASE;
    for e in effects {
        let k = e.setup.len();
        for alt in e.setup.alt_init() {
            let mut y = x.clone();
            y[o..o + k].copy_from_slice(alt);
            let r = lm::solve(&prob, y, &bounds, &free, max_iter);
            if r.1.cost < best.1.cost {
                best = r;
            }
        }
        o += k;
    }
    let (x, report) = best;
    let renoised = |nz| Problem {
        extra_noise: Some(nz),
        ..Problem::new(d, n, effects, w, spec)
    };
    let mut f = result_at(effects, &x, report)?;
    // Only where the biased effect's values move: a screening fit that holds the model's
    // values (and its drift among them) reads nothing the noise biases.
    let mut moved = effects.iter().skip(spec.hold_first);
    if moved.any(|e| e.effect.biased_by_input_noise()) {
        if let Some(c) = simex::corrected(d, renoised, &x, &bounds, &free, max_iter) {
            f.corrected = Some(result_at(effects, &c, report)?.effect_params);
        }
    }
    Ok(f)
}

/// The fit's result at the values `x` (base, then each effect's).
fn result_at(
    effects: &[ActiveEffect<'_>],
    x: &[f64],
    report: lm::Report,
) -> Result<FitResult, EffectValuesError> {
    Ok(FitResult {
        base: Problem::base(x),
        effect_params: effect_values(effects, x.get(N_BASE..).unwrap_or(&[]))?
            .into_iter()
            .map(|(_, p)| p.to_vec())
            .collect(),
        report,
        corrected: None,
    })
}

/// The indices of the values a fit of `n` values moves: the base parameters `spec` frees,
/// and every effect's value but those of the first `spec.hold_first` effects.
fn free_values(effects: &[ActiveEffect<'_>], spec: BaseSpec, n: usize) -> Vec<usize> {
    let held: usize = effects
        .iter()
        .take(spec.hold_first)
        .map(|e| e.setup.len())
        .sum();
    (0..n)
        .filter(|&i| {
            if i < N_BASE {
                spec.free[i]
            } else {
                i >= N_BASE + held
            }
        })
        .collect()
}

/// The fit's start (the base parameters `start`, then each effect's initial values) and
/// its bounds: Ra and Ls scales 0.3-3 and 0.5-2, B + Bl 0 to 50x the rated-torque scale
/// `bs` [N m s], J scale 0.2-5; each effect's plausible bounds.
fn start_and_bounds(
    start: &BaseParams,
    effects: &[ActiveEffect<'_>],
    bs: f64,
) -> (Vec<f64>, lm::Bounds) {
    let mut x = vec![
        start.ra_scale,
        start.ls_scale,
        start.btot_nms,
        start.j_scale,
    ];
    let mut lo = vec![0.3, 0.5, 0.0, 0.2];
    let mut hi = vec![3.0, 2.0, 50.0 * bs, 5.0];
    let mut scale = vec![0.05, 0.05, 0.2 * bs, 0.1];
    for q in effects.iter().flat_map(|e| &e.setup.params) {
        x.push(q.init);
        lo.push(q.lo);
        hi.push(q.hi);
        scale.push(q.scale);
    }
    (x, lm::Bounds { lo, hi, scale })
}

/// The effects' terms for fitted values.
///
/// # Errors
/// [`EffectValuesError`] when `f` does not hold one set of values per effect, each with
/// one value per parameter.
pub fn terms(
    d: &Prepared,
    n: &MachineConstants,
    effects: &[ActiveEffect<'_>],
    f: &FitResult,
) -> Result<ModelTerms, EffectValuesError> {
    let mut terms = ModelTerms::default();
    for (e, p) in paired(effects, &f.effect_params)? {
        e.setup.contribute(p, d, n, &mut terms)?;
    }
    Ok(terms)
}

/// Simulates the model with fitted values.
///
/// # Errors
/// As [`terms`].
pub fn predict(
    d: &Prepared,
    n: &MachineConstants,
    effects: &[ActiveEffect<'_>],
    f: &FitResult,
) -> Result<Prediction, EffectValuesError> {
    Ok(simulate(d, n, &f.base, &terms(d, n, effects, f)?))
}

/// A fitted model as a value: the effects set up on a series, the fitted base and effect
/// values, and how the solve ended. [`FittedModel::predict`] runs it on a series (the one
/// its set-ups were made on); `Display` says what it is in one line.
pub struct FittedModel<'a> {
    /// The effects in the model with their set-ups.
    pub effects: Vec<ActiveEffect<'a>>,
    /// The fitted values and the solver's report.
    pub fit: FitResult,
}

impl FittedModel<'_> {
    /// The model's prediction on `d` (the series its effects were set up on).
    ///
    /// # Errors
    /// As [`terms`]: the fitted values do not match the effects.
    pub fn predict(
        &self,
        d: &Prepared,
        n: &MachineConstants,
    ) -> Result<Prediction, EffectValuesError> {
        predict(d, n, &self.effects, &self.fit)
    }
}

impl std::fmt::Display for FittedModel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use super::effects::sig;
        let b = &self.fit.base;
        f.write_str("paper's model")?;
        for e in &self.effects {
            write!(f, " + {}", e.effect.kind())?;
        }
        write!(
            f,
            "; Ra x{}, Ls x{}, B+Bl {} N m s/rad, J x{}",
            sig(b.ra_scale),
            sig(b.ls_scale),
            sig(b.btot_nms),
            sig(b.j_scale)
        )?;
        for (e, p) in self.effects.iter().zip(&self.fit.effect_params) {
            for (q, v) in e.setup.params.iter().zip(p) {
                write!(
                    f,
                    "; {} = {}",
                    q.name,
                    super::effects::with_unit(&sig(*v), q.unit())
                )?;
            }
        }
        let r = &self.fit.report;
        write!(
            f,
            "; fit {} after {} iterations, cost {}",
            r.termination,
            r.iterations,
            sig(r.cost)
        )
    }
}

#[cfg(test)]
mod fitted_model_tests;
